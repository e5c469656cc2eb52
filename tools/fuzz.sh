#!/usr/bin/env bash
# Runs every cargo-fuzz target of one fuzz crate for N seconds each (default 60), all at once
# (one libFuzzer process per target; give it one core per target):
#
#   bash tools/fuzz.sh FUZZ_DIR [SECONDS]     e.g. bash tools/fuzz.sh shared/fuzz 600
#
# `shared/fuzz/run.sh` and `host/fuzz/run.sh` call it for their crates.
#
# Installs cargo-fuzz if it is missing. Works on the stable toolchain: cargo-fuzz passes
# nightly-only flags (-Zsanitizer=address, ...), which RUSTC_BOOTSTRAP=1 lets stable accept.
# Set FUZZ_SANITIZER=none to build without AddressSanitizer.
#
# libFuzzer writes the inputs it finds into the first corpus directory it is given, so each
# target runs on a scratch directory (removed at exit) with the checked-in seeds in
# corpus/<target>/ read-only after it: the work tree stays clean. A finding makes the script
# fail; the crashing input is kept in FUZZ_DIR/artifacts/<target>/ (ignored by git) and
# replays with `RUSTC_BOOTSTRAP=1 cargo fuzz run <target> artifacts/<target>/crash-...`.
set -euo pipefail

sanitizer="${FUZZ_SANITIZER:-address}"
fuzz_dir="${1:?usage: tools/fuzz.sh FUZZ_DIR [SECONDS]}"
shift
cd "$fuzz_dir"
seconds="${1:-60}"

if ! cargo fuzz --version >/dev/null 2>&1; then
    cargo install cargo-fuzz --locked
fi
export RUSTC_BOOTSTRAP=1

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT

targets=($(cargo fuzz list))
# Build once before starting the runs in parallel, so they do not race on the target dir.
cargo fuzz build -O --sanitizer "$sanitizer"

pids=()
for target in "${targets[@]}"; do
    mkdir -p "$scratch/$target"
    seeds=()
    if [[ -d "corpus/$target" ]]; then
        seeds=("corpus/$target")
    fi
    echo "== fuzzing $target for ${seconds}s (sanitizer: $sanitizer), log in $scratch/$target.log"
    cargo fuzz run -O --sanitizer "$sanitizer" "$target" "$scratch/$target" "${seeds[@]}" \
        -- -max_total_time="$seconds" >"$scratch/$target.log" 2>&1 &
    pids+=("$!")
done

status=0
summary=()
for i in "${!targets[@]}"; do
    target="${targets[$i]}"
    if wait "${pids[$i]}"; then
        summary+=("$target: $(grep -E '^Done [0-9]+ runs' "$scratch/$target.log" | tail -n 1), no finding")
        summary+=("  $(grep -E '^#[0-9]+[[:space:]]+DONE' "$scratch/$target.log" | tail -n 1)")
    else
        status=1
        tail -n 40 "$scratch/$target.log"
        summary+=("$target: FINDING, see artifacts/$target/")
    fi
done

echo "== summary"
printf '%s\n' "${summary[@]}"
exit "$status"
