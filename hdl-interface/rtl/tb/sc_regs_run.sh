#!/bin/sh
# Runs the register block's testbench with Icarus Verilog: prints PASS, exits 1 on a failure.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
iverilog -g2005 -Wall -I "$here" -s sc_regs_tb -o "$out/sc_regs_tb.vvp" \
    "$here/../sc_regs.v" "$here/sc_regs_tb.v"
vvp -n "$out/sc_regs_tb.vvp" | tee "$out/log"
grep -q '^PASS sc_regs_tb' "$out/log"
