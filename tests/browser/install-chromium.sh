#!/usr/bin/env bash
# Installs Debian's Chromium for the browser test of `cwisim inspect`'s page
# (crates/host/tests/browser.rs), when it is not installed yet. Run by .ci/run; run it by
# hand once before `cargo test --workspace` on a new machine.
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
