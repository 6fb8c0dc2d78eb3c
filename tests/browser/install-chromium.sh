#!/usr/bin/env bash
# Installs Debian's Chromium for the browser test of `cwisim inspect`'s page
# (crates/host/tests/browser.rs), when it is not installed yet. The test runs it itself when
# it finds no Chromium, so `cargo test --workspace` needs nothing installed by hand; .ci/run
# runs it first so that its output stands apart from the tests'.
set -euo pipefail
if command -v chromium >/dev/null 2>&1; then
    echo "chromium: $(chromium --version 2>/dev/null || echo present)"
    exit 0
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
    sudo="sudo"
fi
echo "== installing Debian's chromium (apt-get) for the browser test"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq chromium >/dev/null
chromium --version 2>/dev/null
