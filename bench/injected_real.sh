#!/usr/bin/env bash
# Real-image accuracy through the whole chain: each rectified ETH3D pair in
# ../shared/data/real/eth3d_two_view becomes two injected-verge sequences (moving head, fixed
# verge) with `stereocal inject`, and `stereocal run --truth --json` measures them. Prints one
# markdown table. Usage: bench/injected_real.sh [FRAMES] (default 60).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-60}
data=${STEREOCAL_REAL_DATA:-../shared/data/real}/eth3d_two_view
[ -f "$data/geometry.json" ] || { echo "no real data at $data (set STEREOCAL_REAL_DATA)" >&2; exit 1; }
cargo build --release -q -p stereocal
bin=target/release/stereocal
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| scene | motion | estimated | raw median | raw p95 | raw max | filtered max | filtered span (settled) | residual removed | ms/pair |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for scene in terrace playground; do
  # The calibration of the pair, from geometry.json (cam0 = left, cam1 = right).
  python3 - "$data/geometry.json" "$scene" > "$work/$scene.toml" <<'PY'
import json, sys
g = json.load(open(sys.argv[1]))["scenes"][sys.argv[2]]
print(f"baseline_m = {g['stereo']['baseline_m']!r}")
for side, cam in (("left", "cam0"), ("right", "cam1")):
    c = g[cam]
    print(f"[{side}]")
    for k in ("fx", "fy", "cx", "cy"):
        print(f"{k} = {float(c[k])!r}")
PY
  for motion in moving fixed; do
    set_dir="$work/${scene}_$motion"
    "$bin" inject --left-image "$data/$scene/im0.png" --right-image "$data/$scene/im1.png" \
      --calib "$work/$scene.toml" --frames "$frames" --motion "$motion" --out "$set_dir" 2>/dev/null
    "$bin" run --left "$set_dir/left" --right "$set_dir/right" --calib "$set_dir/calib.toml" \
      --truth "$set_dir/truth.csv" --out "$work/out_${scene}_$motion" --json 2>/dev/null \
      | python3 -c '
import json, sys
j = json.load(sys.stdin)
scene, motion = sys.argv[1], sys.argv[2]
f = lambda v: "-" if v is None else "%.4f°" % v
span = f(j["filtered_span_deg"]) if motion == "fixed" else "-"
cells = [scene, motion, "%d/%d" % (j["estimated_frames"], j["frames"]),
         f(j["median_abs_err_deg"]), f(j["p95_abs_err_deg"]), f(j["max_abs_err_deg"]),
         f(j["filtered_max_abs_err_deg"]), span, f(j["residual_removed_deg"]),
         "%.1f" % j["ms_per_frame_pair"]]
print("| " + " | ".join(cells) + " |")
' "$scene" "$motion"
  done
done
