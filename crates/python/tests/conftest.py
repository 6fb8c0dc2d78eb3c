"""What the tests share: the command line they hold the package to.

The command line is the release binary that crates/python/install.sh builds
(``target/release/cwisim``, under ``$CARGO_TARGET_DIR`` when that is set), or
``$CWISIM_BIN``. When it is missing, a test that needs it fails saying how to build it.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]

#: The command that builds the binary (as crates/python/install.sh runs it).
BUILD = "cargo build --release --locked --workspace --bin cwisim"


def cli_binary() -> Path:
    """The cwisim binary: ``$CWISIM_BIN``, or the workspace's release build."""
    given = os.environ.get("CWISIM_BIN")
    if given:
        path = Path(given)
    else:
        target = Path(os.environ.get("CARGO_TARGET_DIR") or ROOT / "target")
        path = (target if target.is_absolute() else ROOT / target) / "release" / "cwisim"
    if not path.is_file():
        named = " ($CWISIM_BIN)" if given else ""
        pytest.fail(
            f"{path}{named}: no cwisim binary. The tests compare the package with the "
            f"command line: build it with `{BUILD}` in {ROOT} (crates/python/install.sh "
            "does), or set CWISIM_BIN to one",
            pytrace=False,
        )
    return path


def cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    """``cwisim ARGS`` run in ``cwd``, its output captured as text."""
    return subprocess.run(
        [str(cli_binary()), *args], cwd=cwd, capture_output=True, text=True, check=False
    )
