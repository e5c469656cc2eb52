#!/bin/sh
# Runs sc_fabric's testbench (tb/sc_fabric_tb.v) with Icarus Verilog over every module in
# rtl/: prints PASS, exits 1 on a failure.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
iverilog -g2005 -Wall -I "$here" -s sc_fabric_tb -o "$out/sc_fabric_tb.vvp" "$here"/../*.v "$here/sc_fabric_tb.v"
vvp -n "$out/sc_fabric_tb.vvp" | tee "$out/log"
grep -q '^PASS sc_fabric_tb' "$out/log"
