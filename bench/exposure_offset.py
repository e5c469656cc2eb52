#!/usr/bin/env python3
"""Does a real drive's verge move with the car? Two signatures of an exposure-time offset.

If the right camera exposes dt seconds after the left one while the car moves at v and turns
at w, the right camera at its exposure sits v*dt further along and is turned by w*dt against
the left camera at its own. Both are geometry the pair really has, not an error of any fit:

* the forward offset tilts the baseline toward the direction of travel by atan(v*dt / b),
  which the two-yaw model sees as both yaws turned alike (the split, the mean of the yaws);
* the turn is a verge: a camera turned by w*dt about its vertical axis. With yaws about the
  cameras' y axes (y down, so a positive yaw turns a camera's view toward +x) and
  verge = a_l - a_r, it changes the verge by -w*dt.

So each signature gives dt, from quantities this script measures with OpenCV alone, not with
the code under test:

* the car's motion between consecutive left frames: SIFT matches of the left and right images
  of frame t triangulated (rectified: depth = f*b / disparity), their left-image points found
  again in frame t+1 (SIFT, ratio 0.8), and cv2.solvePnPRansac (1 px) for the left camera's
  motion; its yaw rate w (camera-to-world, positive turning toward +x) and speed v (metres a
  frame, with the stereo baseline's scale) are each frame's mean of its motion from t-1 and
  to t+1;
* each frame's yaws, the verge-only SIFT fit of bench/drives.py with both yaws free
  (`SiftVerge.fit`): the split s = (a_l + a_r) / 2 gives dt = b*tan(s) / v, each frame's
  alone (which takes the whole split for the offset) and from the regression of b*tan(s) on
  v over the drive (which leaves a constant split to the rig's own baseline direction);
* the verge's regression on w over the drive gives dt = -slope, for the SIFT fit's verge and
  for `stereocal run`'s raw verge (default settings, or those given after `--`).

The table gives, per sequence, the correlation of w and v (a car slowing into its turns makes
them nearly collinear, and then the two signatures cannot be told apart from a verge or split
that follows either), the regression's correlation and dt for both verges, the split's dt
both ways, and the scatter of our untouched verge about its median (median / max of the
absolute deviation: bench/drives.py's untouched absolute figures) as it is and without the
turn term -w*dt, dt taken from the SIFT fit's regression, which owes nothing to the verge it
corrects. Where the verge follows w alike in both fits and the split's dt agrees, part of
what a drive's absolute figures call error is the rig's own verge at the moment of each
exposure.

The first run makes bench/.venv (bench/drives.py's venv: numpy, opencv-python-headless and
scipy) and re-runs itself inside it.

Usage: bench/exposure_offset.py [-- RUN_ARGS...]
"""

import os
import sys

from drives import (FRAME_RATES, SiftVerge, built_binary, ensure_venv_and_reexec, in_venv,
                    read_calib, read_verge_csv, real_data, rectified_sequences, run_ours,
                    split_run_args)

# Lowe's ratio for the frame-to-frame matches, as the stereo matches' (bench/drives.py).
RATIO = 0.8
# Stereo matches used as 3-D points: rows agree within this (pixels; the pair is rectified)
# and the disparity is at least MIN_DISPARITY_PX (nearer than about 390 m on KITTI), so that
# a point's depth is defined.
ROW_PX = 1.0
MIN_DISPARITY_PX = 1.0
# solvePnPRansac's reprojection threshold (pixels): a good match's error on these images.
PNP_PX = 1.0


def motion(sift, matcher, cam, baseline, frame, nxt):
    """(yaw deg, metres) of the left camera from `frame` to `nxt` (each a (left, right) grey
    image pair), or None when too few points."""
    import cv2
    import numpy as np
    kl, dl = sift.detectAndCompute(frame[0], None)
    kr, dr = sift.detectAndCompute(frame[1], None)
    kn, dn = sift.detectAndCompute(nxt[0], None)
    if dl is None or dr is None or dn is None:
        return None

    def ratio(a, b):
        pairs = matcher.knnMatch(a, b, k=2)
        return {m.queryIdx: m.trainIdx for m, n in (p for p in pairs if len(p) == 2)
                if m.distance < RATIO * n.distance}

    stereo, ahead = ratio(dl, dr), ratio(dl, dn)
    obj, img = [], []
    f, cx, cy = cam["fx"], cam["cx"], cam["cy"]
    for i, j in stereo.items():
        if i not in ahead:
            continue
        (xl, yl), (xr, yr) = kl[i].pt, kr[j].pt
        d = xl - xr
        if abs(yl - yr) > ROW_PX or d < MIN_DISPARITY_PX:
            continue
        z = f * baseline / d
        obj.append(((xl - cx) * z / f, (yl - cy) * z / cam["fy"], z))
        img.append(kn[ahead[i]].pt)
    if len(obj) < 6:
        return None
    k = np.array([[f, 0, cx], [0, cam["fy"], cy], [0, 0, 1.0]])
    ok, rvec, tvec, inliers = cv2.solvePnPRansac(
        np.float64(obj), np.float64(img), k, None, reprojectionError=PNP_PX,
        iterationsCount=500, flags=cv2.SOLVEPNP_ITERATIVE)
    if not ok or inliers is None or len(inliers) < 6:
        return None
    rot, _ = cv2.Rodrigues(rvec)
    # x_next = R x + t: the camera's own rotation (camera to world) is R^T, its centre -R^T t.
    yaw = -float(np.degrees(rvec[1, 0]))
    return yaw, float(np.linalg.norm(rot.T @ tvec))


def regression(x, y):
    """(correlation, slope) of y on x."""
    import numpy as np
    x, y = np.asarray(x), np.asarray(y)
    return float(np.corrcoef(x, y)[0, 1]), float(np.polyfit(x, y, 1)[0])


def scatter(v):
    """Median and max of |v - median(v)|."""
    import numpy as np
    dev = np.abs(np.asarray(v) - np.median(v))
    return float(np.median(dev)), float(np.max(dev))


def main():
    import shutil
    import tempfile

    import cv2
    import numpy as np

    argv, run_args = split_run_args(sys.argv[1:])
    if argv:
        raise SystemExit(__doc__)
    data = real_data()
    if not os.path.isdir(data):
        raise SystemExit(f"no real data at {data} (set STEREOCAL_REAL_DATA)")
    binary = built_binary()
    work = tempfile.mkdtemp(prefix="exposure_offset.")
    rows = []
    try:
        for name, d in rectified_sequences(data):
            if name not in FRAME_RATES:
                print(f"left out: {name} (no frame rate known)", file=sys.stderr)
                continue
            period_ms = 1e3 / FRAME_RATES[name]
            calib = read_calib(os.path.join(d, "calib.toml"))
            cam, b = calib["left"], float(calib["baseline_m"])
            names = [sorted(os.listdir(os.path.join(d, side))) for side in ("left", "right")]
            pairs = [tuple(cv2.imread(os.path.join(d, side, n), cv2.IMREAD_GRAYSCALE)
                           for side, n in zip(("left", "right"), pn)) for pn in zip(*names)]
            print(f"{name}: motion between frames", file=sys.stderr)
            cv2.setRNGSeed(1)
            sift, matcher = cv2.SIFT_create(), cv2.BFMatcher(cv2.NORM_L2)
            steps = [motion(sift, matcher, cam, b, pairs[t], pairs[t + 1])
                     for t in range(len(pairs) - 1)]
            print(f"{name}: SIFT yaws", file=sys.stderr)
            fit = SiftVerge(calib)
            yaws = [fit.fit(l, r)[0] for l, r in pairs]
            print(f"{name}: stereocal run", file=sys.stderr)
            seq_args = run_args if "--fps" in run_args else \
                ["--fps", f"{FRAME_RATES[name]:g}", *run_args]
            ours, _ = run_ours(binary, os.path.join(d, "left"), os.path.join(d, "right"),
                               os.path.join(d, "calib.toml"), os.path.join(work, name),
                               seq_args)
            frames = []
            for t in range(len(pairs)):
                near = [steps[j] for j in (t - 1, t) if 0 <= j < len(steps) and steps[j]]
                if not near or yaws[t] is None or ours[t]["raw"] is None:
                    continue
                w = float(np.mean([s[0] for s in near]))
                v = float(np.mean([s[1] for s in near]))
                al, ar = yaws[t]
                frames.append({"w": w, "v": v, "split": (al + ar) / 2,
                               "sift": float(np.degrees(al - ar)), "ours": ours[t]["raw"]})
            w = [f["w"] for f in frames]
            # dt (frames) from each frame's split: b*tan(s) = v*dt.
            dt_split = np.array([b * np.tan(f["split"]) / f["v"] for f in frames])
            regressions = {m: regression(w, [f[m] for f in frames]) for m in ("ours", "sift")}
            # The turn term with the SIFT fit's dt (-slope), which owes nothing to our verge.
            dt_sift = -regressions["sift"][1]
            ours = [f["ours"] for f in frames]
            rows.append({
                "name": name, "frames": f"{len(frames)}/{len(pairs)}",
                "w": (min(w), max(w)),
                "v": (min(f["v"] for f in frames), max(f["v"] for f in frames)),
                "corr_wv": regression(w, [f["v"] for f in frames])[0],
                "split": [float(np.percentile(dt_split, q)) * period_ms for q in (50, 25, 75)],
                "split_on_v": regression([f["v"] for f in frames],
                                         [b * np.tan(f["split"]) for f in frames]),
                "dt": {m: -r[1] * period_ms for m, r in regressions.items()},
                "corr": {m: r[0] for m, r in regressions.items()},
                "scatter": scatter(ours),
                "corrected": scatter([x + wi * dt_sift for x, wi in zip(ours, w)]),
            })
    finally:
        shutil.rmtree(work, ignore_errors=True)

    who = f"`stereocal run`{' ' + ' '.join(run_args) if run_args else ''}"
    print("Exposure-time offset dt of the right camera after the left (ms): from the verge's "
          "regression on the car's yaw rate w, for our verge and the SIFT fit's, and from "
          "the SIFT fit's split and the speed v. Last, our untouched verge's scatter about its "
          f"median, as it is and without the turn term -w*dt of the SIFT fit's dt. Ours: {who}.\n")
    print("| sequence | frames | yaw rate w, °/frame | speed v, m/frame | correlation of w and v "
          "| correlation of verge and w: ours / SIFT | dt from the verge on w: ours / SIFT | "
          "dt from the split: each frame's, median (quartiles) / its regression on v (correlation) "
          "| our scatter: median / max | without -w*dt: median / max |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        (w0, w1), (v0, v1), (q2, q1, q3) = r["w"], r["v"], r["split"]
        (m0, x0), (m1, x1) = r["scatter"], r["corrected"]
        corr_v, dt_v = r["split_on_v"]
        print(f"| {r['name']} | {r['frames']} | {w0:+.2f} to {w1:+.2f} | {v0:.2f} to {v1:.2f} | "
              f"{r['corr_wv']:+.2f} | {r['corr']['ours']:+.2f} / {r['corr']['sift']:+.2f} | "
              f"{r['dt']['ours']:+.2f} / {r['dt']['sift']:+.2f} ms | "
              f"{q2:+.2f} ms ({q1:+.2f} to {q3:+.2f}) / {dt_v * period_ms:+.2f} ms ({corr_v:+.2f}) "
              f"| {m0:.4f}° / {x0:.3f}° | {m1:.4f}° / {x1:.3f}° |")

if __name__ == "__main__":
    if not in_venv():
        ensure_venv_and_reexec(os.path.abspath(__file__))
    main()
