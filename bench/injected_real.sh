#!/usr/bin/env bash
# Real-image accuracy through the whole chain: each rectified ETH3D pair in
# ../shared/data/real/eth3d_two_view becomes two injected-verge sequences (moving head, fixed
# verge) with `stereocal inject`, and `stereocal run --truth --json` measures them, in both
# Sobel output modes. Prints one markdown table. Usage: bench/injected_real.sh [FRAMES] (default 60).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-60}
data=${STEREOCAL_REAL_DATA:-../shared/data/real}/eth3d_two_view
[ -f "$data/geometry.json" ] || { echo "no real data at $data (set STEREOCAL_REAL_DATA)" >&2; exit 1; }
cargo build --release -q -p stereocal-cli
bin=target/release/stereocal
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| scene | motion | estimated | raw median | raw p95 | raw max | filtered max | filtered span (settled) | residual removed | ms/pair | wire bytes/pair | \`--sobel patches\`: bytes/pair, estimated, raw median |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
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
    # The default Sobel output (whole rows) gives the table's figures; the patch mode runs
    # the same frames for its accuracy and the bytes it saves on the wire.
    for sobel in rows patches; do
      "$bin" run --left "$set_dir/left" --right "$set_dir/right" --calib "$set_dir/calib.toml" \
        --truth "$set_dir/truth.csv" --sobel "$sobel" --out "$work/out_${scene}_${motion}_$sobel" \
        --json > "$work/${scene}_${motion}_$sobel.json" 2>/dev/null
    done
    python3 - "$scene" "$motion" "$work/${scene}_${motion}_rows.json" "$work/${scene}_${motion}_patches.json" <<'PY'
import json, sys
scene, motion = sys.argv[1], sys.argv[2]
j, p = (json.load(open(path)) for path in sys.argv[3:5])
f = lambda v: "-" if v is None else "%.4f°" % v
span = f(j["filtered_span_deg"]) if motion == "fixed" else "-"
cells = [scene, motion, "%d/%d" % (j["estimated_frames"], j["frames"]),
         f(j["median_abs_err_deg"]), f(j["p95_abs_err_deg"]), f(j["max_abs_err_deg"]),
         f(j["filtered_max_abs_err_deg"]), span, f(j["residual_removed_deg"]),
         "%.1f" % j["ms_per_frame_pair"], "{:,}".format(round(j["wire_bytes_per_pair"])),
         "%s, %d/%d, %s" % ("{:,}".format(round(p["wire_bytes_per_pair"])),
                            p["estimated_frames"], p["frames"], f(p["median_abs_err_deg"]))]
print("| " + " | ".join(cells) + " |")
PY
  done
done
