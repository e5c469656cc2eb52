#!/usr/bin/env python3
"""stereocal against OpenCV on the same real frames, accuracy and time side by side.

Each rectified ETH3D pair in ../shared/data/real/eth3d_two_view (or $STEREOCAL_REAL_DATA)
becomes one moving-head sequence with an exactly injected verge (`stereocal inject`, as in
bench/injected_real.sh); so does `playground` resized for frames of KITTI's size (scaled to
1352 wide with cv2.INTER_AREA, the centre 392 rows kept, the intrinsics scaled and shifted to
match; `stereocal inject` crops the warped frames to 1264x376, which the fabric takes whole:
KITTI's 1264x372 would run as a 1264x368 window). Both methods then read the same PNG files with the same
calib.toml:

* stereocal: `stereocal run --truth --json` (default settings).
* OpenCV: SIFT (cv2.SIFT_create(), default settings) on both images, brute-force L2 matching
  (BFMatcher, k=2, left image as query) with Lowe's ratio test at 0.8, cv2.findEssentialMat
  (RANSAC, prob 0.999, threshold 1 px) and cv2.recoverPose. When the left and right camera
  matrices are equal the points go in as pixels with that K; otherwise each side is
  normalised with its own K and an identity K is used (the threshold becomes 1 px / mean fx).
  The verge is the yaw of recoverPose's R (it maps left-camera coordinates into
  right-camera coordinates): for cameras yawed by alpha_l, alpha_r about their y axes,
  R = Ry(alpha_r)^T Ry(alpha_l) = Ry(alpha_l - alpha_r), so verge = atan2(R[0,2], R[2,2]).
  The script checks this sign on a rendered sequence (`stereocal synth`, exact truth) first.

Errors are computed as stereocal computes them on real data: the median of (estimate - truth)
is the pair's constant rectification residual and is removed, then median / p95 / max of
|error| over the frames with an estimate. A frame has no OpenCV estimate when the ratio test
leaves fewer than 5 matches, findEssentialMat finds no E, or recoverPose finds no point in
front of both cameras. A second OpenCV row keeps only the "firm" poses, those with at least 5
points in front of both cameras: with a 6 cm baseline and a far scene the translation is weak,
and recoverPose often keeps only a handful of points although its R is near the right one.

Time is wall time per frame pair without PNG decoding on both sides (stereocal's whole
command, decoding included, is also timed, in a table of its own): stereocal's
ms_per_frame_pair covers fabric model, driver, estimator and filter (decoding runs in another
thread); OpenCV's covers SIFT on both images, matching, E and pose (images are decoded
before the clock starts). Each scene runs RUNS rounds, stereocal then OpenCV in each, so that
both methods see the same spells of a shared machine: the table gives each method's median
time over the rounds and the speed-up as the ratio of the medians, with the range of the
rounds' own ratios beside it. Errors are from the first round (stereocal's are the same in
every round).

The first run makes bench/.venv (python3 -m venv) and installs numpy,
opencv-python-headless and scipy into it (bench/drives.py's venv, which this script shares);
the script then re-runs itself inside that venv.

Usage: bench/compare_opencv.py [FRAMES] [--keep]   (FRAMES defaults to 60)
"""

import os
import sys

from drives import ROOT, built_binary, ensure_venv_and_reexec, in_venv, sh
# (scene, size to resize and centre-crop to, or None for the original).
SCENES = (("terrace", None), ("playground", None), ("playground", (1352, 392)))
MOTION = "moving"
RATIO = 0.8
MIN_POINTS = 5  # fewest ratio-test matches to try E; fewest points in front for a "firm" pose
RUNS = 3  # rounds per scene: a whole `stereocal run` command, then OpenCV on the same frames


# ---------------------------------------------------------------------------------------------
# Everything below runs inside the venv.

def read_calib(path):
    """calib.toml -> {'left': {fx, fy, cx, cy}, 'right': {...}, 'baseline_m': b}."""
    try:
        import tomllib
        with open(path, "rb") as f:
            return tomllib.load(f)
    except ImportError:  # Python < 3.11: the file is flat enough for a tiny parser.
        out = {}
        table = out
        for line in open(path):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            if line.startswith("["):
                table = out.setdefault(line.strip("[]").strip(), {})
            else:
                k, v = (s.strip() for s in line.split("=", 1))
                table[k] = float(v)
        return out


def read_truth(path):
    truth = {}
    with open(path) as f:
        next(f)
        for line in f:
            frame, verge = line.strip().split(",")
            truth[int(frame)] = float(verge)
    return truth


def stats(estimates, truth, remove_residual=True):
    """estimates: {frame: deg or None}. Median offset removed, then |error| statistics,
    percentiles interpolated linearly as stereocal does."""
    import numpy as np
    pairs = [(e, truth[i]) for i, e in sorted(estimates.items()) if e is not None]
    diff = np.array([e - t for e, t in pairs])
    offset = float(np.median(diff)) if remove_residual and len(diff) else 0.0
    err = np.abs(diff - offset)
    pick = (lambda q: float(np.percentile(err, q))) if len(err) else (lambda q: None)
    return {
        "frames": len(estimates),
        "estimated_frames": len(pairs),
        "median_abs_err_deg": pick(50),
        "p95_abs_err_deg": pick(95),
        "max_abs_err_deg": float(err.max()) if len(err) else None,
        "residual_removed_deg": offset,
    }


class OpenCvVerge:
    def __init__(self, calib):
        import cv2
        import numpy as np
        self.cv2, self.np = cv2, np
        l, r = calib["left"], calib["right"]
        self.kl = np.array([[l["fx"], 0, l["cx"]], [0, l["fy"], l["cy"]], [0, 0, 1]], float)
        self.kr = np.array([[r["fx"], 0, r["cx"]], [0, r["fy"], r["cy"]], [0, 0, 1]], float)
        self.same_k = bool(np.array_equal(self.kl, self.kr))
        self.sift = cv2.SIFT_create()
        self.matcher = cv2.BFMatcher(cv2.NORM_L2)

    def _normalise(self, pts, k):
        return (pts - k[:2, 2]) / self.np.array([k[0, 0], k[1, 1]])

    def estimate(self, img_l, img_r):
        """Verge in degrees (None when OpenCV gives no pose), ratio matches, pose inliers."""
        cv2, np = self.cv2, self.np
        kp_l, des_l = self.sift.detectAndCompute(img_l, None)
        kp_r, des_r = self.sift.detectAndCompute(img_r, None)
        if des_l is None or des_r is None or len(kp_l) < 2 or len(kp_r) < 2:
            return None, 0, 0
        good = [m for m, n in (p for p in self.matcher.knnMatch(des_l, des_r, k=2) if len(p) == 2)
                if m.distance < RATIO * n.distance]
        if len(good) < MIN_POINTS:
            return None, len(good), 0
        p_l = np.float64([kp_l[m.queryIdx].pt for m in good])
        p_r = np.float64([kp_r[m.trainIdx].pt for m in good])
        if self.same_k:
            k, thresh = self.kl, 1.0
        else:
            p_l, p_r = self._normalise(p_l, self.kl), self._normalise(p_r, self.kr)
            k = np.eye(3)
            thresh = 1.0 / np.mean([self.kl[0, 0], self.kl[1, 1], self.kr[0, 0], self.kr[1, 1]])
        e, mask = cv2.findEssentialMat(p_l, p_r, k, method=cv2.RANSAC, prob=0.999,
                                       threshold=thresh)
        if e is None or e.shape[0] < 3:
            return None, len(good), 0
        n_pose, rot, _t, _mask = cv2.recoverPose(e[:3], p_l, p_r, k, mask=mask)
        if n_pose < 1:
            return None, len(good), 0
        # rot maps left-camera coordinates to right-camera coordinates = Ry(alpha_l - alpha_r).
        verge = float(np.degrees(np.arctan2(rot[0, 2], rot[2, 2])))
        return verge, len(good), int(n_pose)


def run_opencv(seq_dir):
    """OpenCV on every pair of seq_dir; decoding outside the clock."""
    import time
    import cv2
    import numpy as np
    cv2.setRNGSeed(1)
    calib = read_calib(os.path.join(seq_dir, "calib.toml"))
    est = OpenCvVerge(calib)
    names_l = sorted(os.listdir(os.path.join(seq_dir, "left")))
    names_r = sorted(os.listdir(os.path.join(seq_dir, "right")))
    assert len(names_l) == len(names_r), "left and right counts differ"
    estimates, firm, matches, elapsed = {}, {}, [], 0.0
    for i, (nl, nr) in enumerate(zip(names_l, names_r)):
        img_l = cv2.imread(os.path.join(seq_dir, "left", nl), cv2.IMREAD_GRAYSCALE)
        img_r = cv2.imread(os.path.join(seq_dir, "right", nr), cv2.IMREAD_GRAYSCALE)
        if img_l is None or img_r is None:
            raise SystemExit(f"cannot read pair {nl}/{nr} in {seq_dir}")
        t0 = time.perf_counter()
        verge, m, n = est.estimate(img_l, img_r)
        elapsed += time.perf_counter() - t0
        estimates[i] = verge
        firm[i] = verge if n >= MIN_POINTS else None
        if verge is not None:
            matches.append(m)
    truth = read_truth(os.path.join(seq_dir, "truth.csv"))
    out = stats(estimates, truth)
    # The same poses, keeping only those with at least MIN_POINTS points in front of both
    # cameras: with a short baseline and a far scene the translation is weak and recoverPose
    # often finds only a handful (its R is then still near the right one).
    out["firm"] = stats(firm, truth)
    out["ms_per_frame_pair"] = 1e3 * elapsed / max(len(names_l), 1)
    out["median_matches"] = float(np.median(matches)) if matches else None
    out["same_k"] = est.same_k
    out["estimates"] = estimates
    return out


def sign_check(binary, work):
    """OpenCV's verge on a rendered sequence with exact truth (no offset removed): the
    median estimate must lie nearer the truth than its negation (a flipped sign would put it
    near -truth). Single frames are noisy (about 0.3 deg spread, one outlier of 1.3 deg), so
    this checks the sign, not the accuracy."""
    frames = 5
    seq = os.path.join(work, "synth_road")
    sh([binary, "synth", "--scene", "road", "--frames", str(frames), "--seed", "1",
        "--trajectory", "manual", "--out", seq])
    import numpy as np
    res = run_opencv(seq)
    truth = read_truth(os.path.join(seq, "truth.csv"))
    got = [(res["estimates"][i], truth[i]) for i in sorted(truth)]
    est = [e for e, _ in got if e is not None]
    t = float(np.median([t for _, t in got]))
    m = float(np.median(est)) if est else None
    ok = m is not None and t != 0 and abs(m - t) < abs(m + t)
    desc = ", ".join("none" if e is None else f"{e:+.3f}" for e, _ in got)
    print(f"Sign check: `stereocal synth --scene road --frames {frames} --seed 1 --trajectory "
          f"manual` (exact truth {t:+.3f} deg; left and right K differ, so the normalised-point "
          f"path): OpenCV verge per frame {desc}, median "
          f"{'none' if m is None else f'{m:+.3f}'}: sign {'ok' if ok else 'WRONG'}.\n")
    if not ok:
        raise SystemExit("OpenCV verge sign check failed; not trusting the comparison")


def resized_pair(left_png, right_png, cams, size, out_dir):
    """The pair scaled to `size[0]` wide (INTER_AREA) and cropped to the centre `size[1]` rows,
    written as PNGs into `out_dir`, with the intrinsics to match (pixel centres at integers:
    c' = (c + 0.5) s - 0.5, minus the crop offset for cy)."""
    import cv2

    os.makedirs(out_dir)
    out, y0, s = [], None, None
    for name, path in (("im0.png", left_png), ("im1.png", right_png)):
        img = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        h, w = img.shape
        s = size[0] / w
        scaled = cv2.resize(img, (size[0], round(h * s)), interpolation=cv2.INTER_AREA)
        if scaled.shape[0] < size[1]:
            raise SystemExit(f"{path}: {scaled.shape[0]} rows after scaling, need {size[1]}")
        y0 = (scaled.shape[0] - size[1]) // 2
        dst = os.path.join(out_dir, name)
        cv2.imwrite(dst, scaled[y0:y0 + size[1]])
        out.append(dst)
    scaled_cams = {
        cam: {"fx": c["fx"] * s, "fy": c["fy"] * s, "cx": (c["cx"] + 0.5) * s - 0.5,
              "cy": (c["cy"] + 0.5) * s - 0.5 - y0}
        for cam, c in cams.items()
    }
    return out[0], out[1], scaled_cams


def main():
    import argparse
    import json
    import platform
    import shutil
    import tempfile
    import time
    import cv2
    import numpy as np

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("frames", nargs="?", type=int, default=60)
    ap.add_argument("--keep", action="store_true", help="keep the work directory")
    args = ap.parse_args()

    data = os.path.join(os.environ.get("STEREOCAL_REAL_DATA",
                                       os.path.join(ROOT, "..", "shared", "data", "real")),
                        "eth3d_two_view")
    if not os.path.isfile(os.path.join(data, "geometry.json")):
        raise SystemExit(f"no real data at {data} (set STEREOCAL_REAL_DATA)")
    binary = built_binary()
    geometry = json.load(open(os.path.join(data, "geometry.json")))["scenes"]

    work = tempfile.mkdtemp(prefix="compare_opencv.")
    try:
        sign_check(binary, work)
        rows = []
        for scene, resize in SCENES:
            g = geometry[scene]
            left_png = os.path.join(data, scene, "im0.png")
            right_png = os.path.join(data, scene, "im1.png")
            cams = {cam: {k: float(g[cam][k]) for k in ("fx", "fy", "cx", "cy")}
                    for cam in ("cam0", "cam1")}
            if resize is not None:
                scene = f"{scene}_resized"
                left_png, right_png, cams = resized_pair(left_png, right_png, cams, resize,
                                                         os.path.join(work, scene))
            toml = os.path.join(work, f"{scene}.toml")
            with open(toml, "w") as f:
                f.write(f"baseline_m = {g['stereo']['baseline_m']!r}\n")
                for side, cam in (("left", "cam0"), ("right", "cam1")):
                    f.write(f"[{side}]\n")
                    for k in ("fx", "fy", "cx", "cy"):
                        f.write(f"{k} = {cams[cam][k]!r}\n")
            seq = os.path.join(work, f"{scene}_{MOTION}")
            print(f"{scene}: inject {args.frames} frames, run stereocal, run OpenCV",
                  file=sys.stderr)
            sh([binary, "inject", "--left-image", left_png,
                "--right-image", right_png, "--calib", toml,
                "--frames", str(args.frames), "--motion", MOTION, "--out", seq])
            run = [binary, "run", "--left", os.path.join(seq, "left"),
                   "--right", os.path.join(seq, "right"),
                   "--calib", os.path.join(seq, "calib.toml"),
                   "--truth", os.path.join(seq, "truth.csv"),
                   "--out", os.path.join(work, f"out_{scene}"), "--json"]
            # RUNS rounds, each the whole command (process start to exit, PNG decoding and
            # the written verge.csv / verge.png included) and then OpenCV: the whole command's
            # pairs/s slowest to fastest, both methods' median per-pair times, and the
            # rounds' own ratios.
            walls, rounds = [], []
            for _ in range(RUNS):
                t0 = time.perf_counter()
                sc_round = json.loads(sh(run))
                walls.append(time.perf_counter() - t0)
                rounds.append((sc_round, run_opencv(seq)))
            ours_ms = [o["ms_per_frame_pair"] for o, _ in rounds]
            cv_ms = [c["ms_per_frame_pair"] for _, c in rounds]
            sc, cvr = rounds[0]
            sc["whole_pairs_per_s"] = sorted(sc["frames"] / w for w in walls)
            sc["round_ratios"] = sorted(c / o for o, c in zip(ours_ms, cv_ms))
            sc["ms_per_frame_pair"] = float(np.median(ours_ms))
            cvr["ms_per_frame_pair"] = float(np.median(cv_ms))
            size = cv2.imread(os.path.join(seq, "left", sorted(os.listdir(
                os.path.join(seq, "left")))[0]), cv2.IMREAD_GRAYSCALE).shape
            rows.append((scene, f"{size[1]}x{size[0]}", sc, cvr))
            if args.keep:
                print(f"  sequence kept in {seq}", file=sys.stderr)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)

    f = lambda v: "-" if v is None else "%.4f°" % v
    print(f"Injected-verge real frames, motion `{MOTION}`, {args.frames} pairs per scene; "
          f"same PNG files and calib.toml for both. OpenCV {cv2.__version__}: SIFT defaults, "
          f"BFMatcher L2 + ratio {RATIO}, findEssentialMat RANSAC 0.999 / 1 px, recoverPose. "
          f"Errors after removing each method's median (estimate - truth) offset; "
          f"\"estimated\" counts frames with a pose; \"firm poses\" keeps only the poses "
          f"with >= {MIN_POINTS} points in front of both cameras (same run, same times). "
          f"Matches are ratio-test matches (stereocal at its default ratio 0.6, OpenCV at "
          f"{RATIO}). Speed-up = OpenCV ms/pair / stereocal ms/pair.\n")
    print("| scene | size | method | estimated | raw median | raw p95 | raw max "
          "| residual removed | median matches | ms/pair | pairs/s | stereocal speed-up |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for scene, size, sc, cvr in rows:
        ratio = cvr["ms_per_frame_pair"] / sc["ms_per_frame_pair"]
        firm = dict(cvr["firm"], ms_per_frame_pair=cvr["ms_per_frame_pair"])
        spread = "%.1f–%.1f" % (sc["round_ratios"][0], sc["round_ratios"][-1])
        for name, r, extra in (("stereocal", sc, "%.1fx (%s)" % (ratio, spread)),
                               ("OpenCV SIFT + 5-pt RANSAC", cvr, "-"),
                               (f"OpenCV, firm poses only (>= {MIN_POINTS} pts in front)",
                                firm, "-")):
            mm = r.get("median_matches")
            cells = [scene, size, name, "%d/%d" % (r["estimated_frames"], r["frames"]),
                     f(r["median_abs_err_deg"]), f(r["p95_abs_err_deg"]),
                     f(r["max_abs_err_deg"]), f(r["residual_removed_deg"]),
                     "-" if mm is None else "%.0f" % mm,
                     "%.2f" % r["ms_per_frame_pair"],
                     "%.1f" % (1000.0 / r["ms_per_frame_pair"]), extra]
            print("| " + " | ".join(cells) + " |")
    print(f"\nWhole `stereocal run` command, process start to exit (PNG decoding, fabric "
          f"model, driver, estimator, filter, verge.csv and verge.png), {RUNS} runs per "
          f"scene, slowest to fastest:\n")
    print("| scene | size | pairs | whole-command pairs/s |")
    print("|---|---|---|---|")
    for scene, size, sc, _ in rows:
        rates = ", ".join("%.1f" % r for r in sc["whole_pairs_per_s"])
        print(f"| {scene} | {size} | {sc['frames']} | {rates} |")
    print(f"\nTimes: wall ms per pair, the median of {RUNS} alternated rounds for each method "
          f"(speed-up: the ratio of the medians; in brackets the range of the rounds' own "
          f"ratios), PNG decoding excluded on both sides (stereocal: "
          f"fabric model + driver + estimator + filter; OpenCV: SIFT on both images + matching "
          f"+ E + pose, {cv2.getNumThreads()} OpenCV threads). Measured on a "
          f"{os.cpu_count()}-core machine shared with other jobs ({platform.machine()}): "
          f"timings are noisy.")


if __name__ == "__main__":
    if not in_venv():
        ensure_venv_and_reexec(os.path.abspath(__file__))
    main()
