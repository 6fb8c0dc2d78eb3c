"""How the tests find the command line: one place (conftest.py), and a missing binary
named with the command that builds it, never a bare FileNotFoundError."""

from __future__ import annotations

import pytest
from conftest import BUILD, ROOT, cli, cli_binary


def test_a_missing_binary_says_how_to_build_it(tmp_path, monkeypatch):
    monkeypatch.setenv("CWISIM_BIN", str(tmp_path / "no-cwisim"))
    for call in [cli_binary, lambda: cli("scenes", cwd=tmp_path)]:
        with pytest.raises(pytest.fail.Exception) as failed:
            call()
        assert BUILD in str(failed.value) and "no-cwisim" in str(failed.value)
    monkeypatch.delenv("CWISIM_BIN")
    monkeypatch.setenv("CARGO_TARGET_DIR", str(tmp_path / "elsewhere"))
    with pytest.raises(pytest.fail.Exception, match="elsewhere/release/cwisim: no cwisim binary"):
        cli_binary()


def test_install_sh_builds_the_binary_the_tests_run():
    """The README's commands, in order, give the tests their binary: install.sh builds it
    with the command the message names."""
    script = (ROOT / "crates" / "python" / "install.sh").read_text()
    assert BUILD in script
    assert "pandas" in (ROOT / "crates" / "python" / "requirements-test.txt").read_text()


def test_no_test_runs_a_binary_of_its_own():
    """Every test reaches the command line through conftest.cli."""
    here = ROOT / "crates" / "python" / "tests"
    paths = [p for p in here.glob("test_*.py") if p.name != "test_install.py"]
    assert len(paths) >= 5
    for path in paths:
        text = path.read_text()
        assert "subprocess" not in text and "release" not in text, path
