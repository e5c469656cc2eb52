#!/bin/sh
# Bit-exactness of sc_extrema, sc_edge, sc_refine, sc_sobel and sc_cordic against the Rust
# model (firmware/src/fabric: extrema.rs, edge.rs, refine.rs, sobel.rs, cordic.rs), with
# Icarus Verilog, plus `verilator --lint-only -Wall` of each module when verilator is there.
#
#   tb/run.sh                 the checked-in vectors in tb/vectors/ (seconds)
#   tb/run.sh --fresh N SEED  N random vectors per module (plus the fixed edge cases) from
#                             the current model into a temporary directory, then run them;
#                             N = 110000 takes about 10 minutes
#   tb/run.sh --update        regenerate tb/vectors/ (N = 100, SEED = 1)
#
# Vectors come from tb/vecgen.rs, a small program on the `stereocal-firmware` crate that
# prints each function's inputs and results (random inputs and edge cases: extreme cubes,
# plateaus, zero determinants, rounding ties, |offset| at 32767/32768 and at max_offset,
# edge-test equality, Sobel on 0/65535 windows, CORDIC on axes, diagonals and the 19-bit
# extremes, with random clock enables and starts). --fresh and --update build it with cargo
# outside the repository (in $TMPDIR, root Cargo.lock copied, so only the firmware crate and
# its dependencies are built). Record layouts: tb/tb_comb.v, tb/tb_refine.v (the refine
# records driven through the sc_refine pipeline, compared REFINE_LATENCY clocks later),
# tb/tb_cordic.v.
set -eu

TB=$(cd "$(dirname "$0")" && pwd)
RTL=$(dirname "$TB")
ROOT=$(cd "$RTL/../.." && pwd)
TMP=${TMPDIR:-/tmp}/sc_rtl_tb.$$
mkdir -p "$TMP"
trap 'rm -rf "$TMP"' EXIT

gen() { # outdir n seed
    w=${TMPDIR:-/tmp}/sc_rtl_vecgen
    mkdir -p "$w/src"
    cp "$TB/vecgen.rs" "$w/src/main.rs"
    cat > "$w/Cargo.toml" <<EOF
[package]
name = "sc-rtl-vecgen"
version = "0.0.0"
edition = "2021"
publish = false

[dependencies]
stereocal-firmware = { path = "$ROOT/firmware" }

[workspace]

[profile.release]
overflow-checks = true
EOF
    cp "$ROOT/Cargo.lock" "$w/Cargo.lock"
    (cd "$w" && CARGO_TARGET_DIR="$w/target" cargo run --quiet --release -- "$1" "$2" "$3")
}

VEC=$TB/vectors
case "${1:-}" in
    --fresh) VEC=$TMP/vectors; mkdir -p "$VEC"; gen "$VEC" "${2:?N}" "${3:?SEED}" ;;
    --update) mkdir -p "$VEC"; gen "$VEC" 100 1 ;;
    "") ;;
    *) echo "usage: $0 [--fresh N SEED | --update]" >&2; exit 2 ;;
esac

if command -v verilator >/dev/null 2>&1; then
    for m in sc_extrema sc_edge sc_refine sc_sobel sc_cordic; do
        verilator --lint-only -Wall "$RTL/$m.v" --top-module "$m"
    done
    echo "verilator --lint-only -Wall: clean"
fi

lines() { wc -l < "$1" | tr -d ' '; }
iverilog -g2005 -Wall -o "$TMP/comb" \
    -Ptb_comb.NX="$(lines "$VEC/extrema.hex")" -Ptb_comb.NE="$(lines "$VEC/edge.hex")" \
    -Ptb_comb.NS="$(lines "$VEC/sobel.hex")" \
    "$TB/tb_comb.v" "$RTL/sc_extrema.v" "$RTL/sc_edge.v" "$RTL/sc_sobel.v"
iverilog -g2005 -Wall -o "$TMP/refine" -Ptb_refine.N="$(lines "$VEC/refine.hex")" \
    "$TB/tb_refine.v" "$RTL/sc_refine.v"
iverilog -g2005 -Wall -o "$TMP/cordic" -Ptb_cordic.N="$(lines "$VEC/cordic.hex")" \
    "$TB/tb_cordic.v" "$RTL/sc_cordic.v"

vvp -n "$TMP/comb" +extrema="$VEC/extrema.hex" +edge="$VEC/edge.hex" \
    +sobel="$VEC/sobel.hex" | tee "$TMP/comb.log"
vvp -n "$TMP/refine" +refine="$VEC/refine.hex" | tee "$TMP/refine.log"
vvp -n "$TMP/cordic" +cordic="$VEC/cordic.hex" | tee "$TMP/cordic.log"
grep -qx PASS "$TMP/comb.log" && grep -qx PASS "$TMP/refine.log" \
    && grep -qx PASS "$TMP/cordic.log"
