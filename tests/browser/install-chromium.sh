#!/usr/bin/env bash
# Installs Debian's Chromium for the browser test of `cwisim inspect`'s page
# (crates/host/tests/browser.rs), when it is not installed yet. The test runs it itself when
# it finds no Chromium, so `cargo test --workspace` needs nothing installed by hand; .ci/run
# runs it first so that its output stands apart from the tests'.
set -euo pipefail
# One install at a time: the tests of one binary run on threads, and each that finds a
# tool missing runs this script (apt-get takes its locks once, and refuses a second
# caller). The lock is shared with the project's other install script; what is missing
# is looked at once it is held, so a caller that waited finds the tools installed.
exec 9>"${TMPDIR:-/tmp}/cwisim-apt-install.lock"
flock 9
if command -v chromium >/dev/null 2>&1; then
    echo "chromium: $(chromium --version 2>/dev/null || echo present)"
    exit 0
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
    sudo="sudo"
fi
echo "== installing Debian's chromium (apt-get) for the browser test"
# and wait, rather than fail, while another program (an upgrade) holds apt's lock
$sudo apt-get -o DPkg::Lock::Timeout=600 update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -qq chromium >/dev/null
chromium --version 2>/dev/null
