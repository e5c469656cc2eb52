#!/usr/bin/env bash
# Builds the SoC in the loop: fetches the core (fetch_core.sh), verilates sc_soc with it and
# the fabric (hdl-interface/rtl), and compiles the harness sim/sc_soc_sim.cpp into
# OUTDIR/sc_soc_sim.
#
#   bash hdl-interface/soc/build.sh OUTDIR
#
# Needs python3 with venv, network access on the first run (pip), verilator and a C++17
# compiler. The core's generated Verilog is not ours: its lint warnings are not shown.
set -euo pipefail

HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
OUT=${1:?usage: build.sh OUTDIR}
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)

bash "$HERE/fetch_core.sh" "$OUT/core" >/dev/null
verilator --cc --exe --build -O3 -j 2 --top-module sc_soc \
    -Wno-fatal -Wno-lint -Wno-style \
    -Mdir "$OUT/obj" -o sc_soc_sim \
    -CFLAGS "-O2 -std=c++17" \
    "$HERE/sc_soc.v" "$OUT/core/VexRiscv_virt.v" "$HERE"/../rtl/*.v "$HERE/sim/sc_soc_sim.cpp" >"$OUT/build.log" 2>&1 \
    || { tail -30 "$OUT/build.log" >&2; echo "build.sh: verilator failed (log: $OUT/build.log)" >&2; exit 1; }
cp "$OUT/obj/sc_soc_sim" "$OUT/sc_soc_sim"
echo "$OUT/sc_soc_sim"
