#!/usr/bin/env bash
# Installs the `cwisim` Python package from this clone into the Python that `python3`
# (or $PYTHON) runs — a virtual environment's, if one is active — with what its tests,
# DataFrames, the Dask sweeps and the first-hour notebook need, and builds the release
# `cwisim` binary the tests compare the package with. Needs a Rust toolchain (cargo, as
# for the rest of the workspace) and the network (PyPI, crates.io). In three steps, each
# announced:
#   1. from PyPI (requirements-test.txt): maturin (the build), NumPy, pandas, pytest, Dask
#      distributed, matplotlib, nbclient, nbformat, ipykernel, and what they need (about
#      75 packages);
#   2. cargo: the release `cwisim` binary, target/release/cwisim (the same build as
#      `cargo build --release --workspace`: nothing rebuilt when that has run);
#   3. maturin (through pip): the package, its native module a release build in the
#      workspace's target directory.
# On a terminal pip and cargo show their own progress; piped, pip is quiet. Used by
# .ci/run (through the README's Python section); named by the README and docs/PYTHON.md.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
python="${PYTHON:-python3}"
if ! command -v cargo >/dev/null; then
  echo "install.sh: cargo not found: the package and the cwisim binary are built from this clone's Rust code; install a Rust toolchain (https://rustup.rs) first" >&2
  exit 1
fi
# maturin's build backend runs the `maturin` program: that of this Python's environment,
# active or not
PATH="$("$python" -c 'import sysconfig; print(sysconfig.get_path("scripts"))'):$PATH"
export PATH
pip=("$python" -m pip install --disable-pip-version-check)
if [ -t 1 ]; then
  verbose=(--verbose) # the build backend's output (cargo's progress) too
else
  pip+=(--quiet)
  verbose=()
fi
version="$("$python" -c 'import sys; print(sys.version.split()[0])')"
echo "install.sh 1/3: from PyPI into Python $version ($("$python" -c 'import sys; print(sys.prefix)')): maturin, NumPy, pandas, pytest, Dask distributed, matplotlib, nbclient, nbformat, ipykernel and what they need"
"${pip[@]}" -r "$here/requirements-test.txt"
echo "install.sh 2/3: cargo build --release --locked --workspace --bin cwisim (the command line the tests compare the package with)"
(cd "$root" && cargo build --release --locked --workspace --bin cwisim)
echo "install.sh 3/3: the cwisim package (maturin: its native module, a release build)"
# no build isolation: the maturin just installed builds it (no second download)
"${pip[@]}" "${verbose[@]}" --no-build-isolation "$here"
target="$(cd "$root" && cargo metadata --format-version 1 --no-deps --locked |
  "$python" -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')"
"$python" - "$target/release/cwisim" <<'PY'
import sys
from importlib.metadata import version

import cwisim

print(f"install.sh: cwisim {version('cwisim')} installed for Python {sys.version.split()[0]} "
      f"({sys.executable}), with {len(cwisim.renderers())} renderers; the command line: {sys.argv[1]}")
PY
