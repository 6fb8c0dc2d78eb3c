#!/usr/bin/env bash
# Installs Debian's HDL tools for `cwisim rtl`'s co-simulation and synthesis
# (crates/rtl/tests/) and its place and route (`cwisim rtl --fpga`): Icarus Verilog
# (iverilog, vvp), Verilator, Yosys, nextpnr-ice40 and the IceStorm tools (icepack,
# icetime, icebox_vlog) — only those missing. The tests run it themselves when they find a tool missing, so
# `cargo test --workspace` needs nothing installed by hand; .ci/run runs it first so that
# its output stands apart from the tests'.
set -euo pipefail
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
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}" >/dev/null
iverilog -V 2>/dev/null | head -n 1
verilator --version
yosys -V
nextpnr-ice40 --version 2>&1 | head -n 1
command -v icepack icetime
