#!/usr/bin/env bash
# Installs the `cwisim` Python package from this clone into the Python that `python3`
# (or $PYTHON) runs — a virtual environment's, if one is active — with what its tests and
# the Dask sweeps need, all from PyPI: maturin (the build), NumPy, pytest, Dask
# distributed. The native module is compiled by maturin (cargo, release profile) in the
# workspace's target directory. Used by .ci/run; named by the README.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
python="${PYTHON:-python3}"
# maturin's build backend runs the `maturin` program: that of this Python's environment,
# active or not
PATH="$("$python" -c 'import sysconfig; print(sysconfig.get_path("scripts"))'):$PATH"
export PATH
"$python" -m pip install --quiet --disable-pip-version-check -r "$here/requirements-test.txt"
# no build isolation: the maturin just installed builds it (no second download)
"$python" -m pip install --quiet --disable-pip-version-check --no-build-isolation "$here"
"$python" -c "import cwisim; print('cwisim', cwisim.__name__, 'installed for', __import__('sys').version.split()[0])"
