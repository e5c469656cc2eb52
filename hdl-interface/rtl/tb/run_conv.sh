#!/bin/sh
# Runs the convolver testbench (sc_row_conv + sc_col_conv against a direct 2-D convolution with
# one rounding, for the four kernels) with Icarus Verilog: prints PASS, exits 1 on a failure.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
iverilog -g2005 -Wall -s tb_conv -o "$out/tb_conv.vvp" \
    "$here/../sc_row_conv.v" "$here/../sc_col_conv.v" "$here/../sc_linebuf.v" \
    "$here/../sc_ram.v" "$here/../sc_da_dot.v" "$here/tb_conv.v"
vvp -n "$out/tb_conv.vvp" | tee "$out/log"
grep -q '^PASS tb_conv' "$out/log"
