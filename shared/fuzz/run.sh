#!/usr/bin/env bash
# Runs every cargo-fuzz target of stereocal-wire for N seconds each (default 60):
#
#   bash shared/fuzz/run.sh [SECONDS]
#
# Installs cargo-fuzz if it is missing. Works on the stable toolchain: cargo-fuzz passes
# nightly-only flags (-Zsanitizer=address, ...), which RUSTC_BOOTSTRAP=1 lets stable accept.
# Set FUZZ_SANITIZER=none to build without AddressSanitizer.
#
# libFuzzer writes the inputs it finds into the first corpus directory it is given, so each
# target runs on a scratch directory (removed at exit) with the checked-in seeds in
# corpus/<target>/ read-only after it: the work tree stays clean. A finding makes the script
# fail; the crashing input is kept in fuzz/artifacts/<target>/ (ignored by git) and replays
# with `RUSTC_BOOTSTRAP=1 cargo fuzz run <target> artifacts/<target>/crash-...`.
set -euo pipefail

seconds="${1:-60}"
sanitizer="${FUZZ_SANITIZER:-address}"
cd "$(dirname "${BASH_SOURCE[0]}")"

if ! cargo fuzz --version >/dev/null 2>&1; then
    cargo install cargo-fuzz --locked
fi
export RUSTC_BOOTSTRAP=1

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT

summary=()
for target in $(cargo fuzz list); do
    mkdir -p "$scratch/$target"
    seeds=()
    if [[ -d "corpus/$target" ]]; then
        seeds=("corpus/$target")
    fi
    echo "== fuzzing $target for ${seconds}s (sanitizer: $sanitizer)"
    cargo fuzz run --sanitizer "$sanitizer" "$target" "$scratch/$target" "${seeds[@]}" \
        -- -max_total_time="$seconds" 2>&1 | tee "$scratch/$target.log"
    summary+=("$target: $(grep -E '^Done [0-9]+ runs' "$scratch/$target.log" | tail -n 1), no finding")
done

echo "== summary"
printf '%s\n' "${summary[@]}"
