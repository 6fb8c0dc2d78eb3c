#!/usr/bin/env bash
# Installs Debian's HDL tools for `cwisim rtl`'s co-simulation and synthesis
# (crates/rtl/tests/) and its place and route (`cwisim rtl --fpga`): Icarus Verilog
# (iverilog, vvp), Verilator, Yosys, nextpnr-ice40 and the IceStorm tools (icepack,
# icetime, icebox_vlog) — only those missing. The tests run it themselves when they find a tool missing, so
# `cargo test --workspace` needs nothing installed by hand; .ci/run runs it first so that
# its output stands apart from the tests'.
set -euo pipefail
# One install at a time: the tests of one binary run on threads, and each that finds a
# tool missing runs this script (apt-get takes its locks once, and refuses a second
# caller). The lock is shared with the project's other install script; what is missing
# is looked at once it is held, so a caller that waited finds the tools installed.
exec 9>"${TMPDIR:-/tmp}/cwisim-apt-install.lock"
flock 9
missing=()
command -v iverilog >/dev/null 2>&1 && command -v vvp >/dev/null 2>&1 || missing+=(iverilog)
command -v verilator >/dev/null 2>&1 || missing+=(verilator)
command -v yosys >/dev/null 2>&1 || missing+=(yosys)
command -v nextpnr-ice40 >/dev/null 2>&1 || missing+=(nextpnr-ice40)
command -v icepack >/dev/null 2>&1 && command -v icetime >/dev/null 2>&1 || missing+=(fpga-icestorm)
if [ "${#missing[@]}" -eq 0 ]; then
    echo "iverilog: $(iverilog -V 2>/dev/null | head -n 1)"
    echo "verilator: $(verilator --version 2>/dev/null)"
    echo "yosys: $(yosys -V 2>/dev/null)"
    echo "nextpnr-ice40: $(nextpnr-ice40 --version 2>&1 | head -n 1)"
    echo "icestorm: $(command -v icepack) $(command -v icetime)"
    exit 0
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
    sudo="sudo"
fi
echo "== installing Debian's ${missing[*]} (apt-get) for cwisim rtl's co-simulation, synthesis and place and route"
# and wait, rather than fail, while another program (an upgrade) holds apt's lock
$sudo apt-get -o DPkg::Lock::Timeout=600 update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -qq "${missing[@]}" >/dev/null
iverilog -V 2>/dev/null | head -n 1
verilator --version
yosys -V
nextpnr-ice40 --version 2>&1 | head -n 1
command -v icepack icetime
