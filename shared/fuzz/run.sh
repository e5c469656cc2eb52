#!/usr/bin/env bash
# Runs every cargo-fuzz target of stereocal-wire (the wire accumulator and decoder) for N seconds each
# (default 60): `bash shared/fuzz/run.sh [SECONDS]`. See tools/fuzz.sh.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
exec bash "$here/../../tools/fuzz.sh" "$here" "$@"
