#!/usr/bin/env bash
# Runs every cargo-fuzz target of stereocal (the calibration parser, the image reader and a whole
# session on an edited device stream) for N seconds each
# (default 60): `bash host/fuzz/run.sh [SECONDS]`. See tools/fuzz.sh.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
exec bash "$here/../../tools/fuzz.sh" "$here" "$@"
