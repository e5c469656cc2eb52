#!/usr/bin/env python3
"""Match by match: how much of the drives' differential is which matches each run finds.

For every rectified real sequence `bench/drives.py` uses, the untouched frames and each injected
trajectory (`stereocal inject`, the same three) run through `stereocal run --matches` (default
settings, or those given after `--`), which writes every frame's point pairs consistent with its
estimate (`matches.csv`, docs/ARCHITECTURE.md). An injected pair is mapped back into its source
frame through the yaws the injection gave that frame (`encoders.csv`): a ray x of the injected
camera is the ray Ry(a) x of the untouched one, so a mapped-back match measures the untouched
frame's geometry and its verge is the untouched one's, the injected verge gone. Matches of the
two runs whose left points lie within MATCH_PX of each other (full-resolution pixels) are the
same scene point found again.

Per frame, then median (and max) over the frames both runs estimated:

* matches: consistent pairs a frame, untouched / injected;
* found again: the untouched frame's matches the injected run also used, as a fraction;
* untouched residual σ: the robust σ (1.4826 MAD) of the untouched refit's residuals (pixels,
  Sampson distance), the spread of the matches' own errors about the verge they give;
* redraw: rms over the matches found again of the change of their vertical disparity (pixels),
  what the injection's resampling and a new refinement move a match that both runs use;
* differential of a refit: one verge-only refit (two yaws, each camera about its own y axis, as
  `stereocal run`'s default model; a Cauchy-robust weighted least-squares fit of the Sampson
  distances, weights from matches.csv) on each run's own matches, and on the matches found
  again alone; |injected - untouched| of the refits, median / max. The refit holds no roll and
  no window, so it is not `stereocal run`'s estimate, whose differential (from verge.csv) is the
  last column; it compares the two sets of matches with one yardstick.

Were the differential the noise of the matches both runs use, the refit on the matches found
again would carry it; were it which matches each run finds, that refit would shed it.

Control rows, `shift X, Y`, need no verge at all: the untouched frames resampled X pixels to
the left and Y up (OpenCV's bicubic, SHIFT_MARGIN whole pixels cropped off every side, the
principal points moved with them), so every scene point lands off the grid it sat on and
nothing else changes; one row per phase of SHIFTS, and a row pooling their frames. Their
differential is the verge's change where the truth is none: what resampling and the matches a
new sampling phase gives cost by themselves. Pooled over several phases it is a steadier figure
than any one trajectory's (four draws of each frame's matches, not one), for comparing settings.

The first run makes bench/.venv (as bench/drives.py) with numpy, opencv-python-headless and
scipy, and re-runs itself inside it.

Usage: bench/match_overlap.py [--keep] [-- RUN_ARGS...]
  --keep      keep the work directory (injected sequences, matches.csv files)
  RUN_ARGS    extra flags for every `stereocal run` (e.g. -- --misalignment window-frame-pitch)
"""

import os
import sys

from drives import (FRAME_RATES, TRAJECTORIES, built_binary, ensure_venv_and_reexec, essential,
                    in_venv, normalised, read_calib, read_truth, read_verge_csv, real_data,
                    rectified_sequences, sampson, sh, split_run_args)

# Two left points closer than this (pixels) are one scene point found again: the fabric's
# keypoints sit on whole pixels and the mapped-back point anywhere between them, so the same
# point lands within half a pixel's diagonal (0.71 px) of it.
MATCH_PX = 0.75
# Where the refit's Cauchy loss turns (pixels): the scale of a good match's vertical error on
# the drive (its robust σ is about 0.1 px), so that a match several σ out weighs little.
CAUCHY_PX = 0.1
# The controls' shifts (pixels, x and y): half a pixel in both directions, the phase farthest
# from the original grid, in each direction alone, and a quarter and three quarters between;
# and their crop (whole pixels a side), beyond the bicubic kernel's reach of 2.
SHIFTS = ((0.5, 0.5), (0.5, 0.0), (0.0, 0.5), (0.25, 0.75))
SHIFT_MARGIN = 8


def read_matches(path):
    """matches.csv -> {frame: (left N x 2, right N x 2, weight N)} pixels."""
    import numpy as np
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    out = {}
    for f in np.unique(data[:, 0]).astype(int):
        rows = data[data[:, 0] == f]
        out[int(f)] = (rows[:, 1:3], rows[:, 3:5], rows[:, 5])
    return out


def read_yaws(path):
    """encoders.csv (frame,left_yaw_deg,right_yaw_deg) -> [(left, right)] radians."""
    import numpy as np
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return [(np.radians(l), np.radians(r)) for l, r in data[:, 1:3]]


def ry(a):
    import numpy as np
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def mapped_back(x, yaw):
    """Rays (N x 2) of a camera turned by `yaw` as rays of the untouched camera."""
    import numpy as np
    h = np.hstack([x, np.ones((len(x), 1))]) @ ry(yaw).T
    return h[:, :2] / h[:, 2:3]


def verge_refit(xl, xr, w, f):
    """Verge (deg) of the two-yaw model fitted to calibrated rays, weights `w`, and the robust
    σ (1.4826 MAD, pixels) of its unweighted residuals."""
    import numpy as np
    import scipy.optimize

    lh = np.hstack([xl, np.ones((len(xl), 1))])
    rh = np.hstack([xr, np.ones((len(xr), 1))])
    residuals = lambda p: sampson(essential(*p), lh, rh) * f

    fit = scipy.optimize.least_squares(lambda p: residuals(p) * np.sqrt(w), [0.0, 0.0],
                                       loss="cauchy", f_scale=CAUCHY_PX)
    r = residuals(fit.x)
    return float(np.degrees(fit.x[0] - fit.x[1])), float(1.4826 * np.median(np.abs(r)))


def shifted(src, dst, shift):
    """The sequence `src` resampled `shift` = (x, y) pixels to the left and up, cropped by
    SHIFT_MARGIN a side to a size the fabric takes (multiples of 8), with calib.toml's principal
    points moved: pixel p of the output shows what pixel p + SHIFT_MARGIN + shift of the input
    did."""
    import cv2
    import numpy as np
    import re
    off = (SHIFT_MARGIN + shift[0], SHIFT_MARGIN + shift[1])
    for side in ("left", "right"):
        os.makedirs(os.path.join(dst, side))
        for name in sorted(os.listdir(os.path.join(src, side))):
            img = cv2.imread(os.path.join(src, side, name), cv2.IMREAD_GRAYSCALE)
            if img is None:
                raise SystemExit(f"cannot read {side}/{name}")
            h, w = img.shape
            size = ((w - 2 * SHIFT_MARGIN) // 8 * 8, (h - 2 * SHIFT_MARGIN) // 8 * 8)
            m = np.float32([[1, 0, off[0]], [0, 1, off[1]]])
            out = cv2.warpAffine(img.astype(np.float32), m, size,
                                 flags=cv2.INTER_CUBIC | cv2.WARP_INVERSE_MAP)
            cv2.imwrite(os.path.join(dst, side, os.path.splitext(name)[0] + ".png"),
                        np.clip(np.rint(out), 0, 255).astype(np.uint8))
    with open(os.path.join(src, "calib.toml")) as f:
        text = f.read()
    # Every principal-point line (both cameras) moves by the same offset.
    moved = re.sub(r"^c([xy])\s*=\s*(\S+)\s*$",
                   lambda m: f"c{m.group(1)} = {float(m.group(2)) - off['xy'.index(m.group(1))]!r}",
                   text, flags=re.M)
    with open(os.path.join(dst, "calib.toml"), "w") as f:
        f.write(moved)


def run_matches(binary, seq, out, run_args):
    sh([binary, "run", "--left", os.path.join(seq, "left"), "--right",
        os.path.join(seq, "right"), "--calib", os.path.join(seq, "calib.toml"), "--out", out,
        "--matches", "--json", *run_args])
    return read_matches(os.path.join(out, "matches.csv")), read_verge_csv(
        os.path.join(out, "verge.csv"))


def compare(untouched, injected, cams_u, cams_i, yaws, f):
    """Per-frame figures of one trajectory against the untouched run (see the module doc)."""
    import numpy as np
    rows = []
    for frame, (ul, ur, uw) in sorted(untouched.items()):
        if frame not in injected:
            continue
        il, ir, iw = injected[frame]
        al, ar = yaws[frame]
        xul, xur = normalised(ul, cams_u[0]), normalised(ur, cams_u[1])
        xil = mapped_back(normalised(il, cams_i[0]), al)
        xir = mapped_back(normalised(ir, cams_i[1]), ar)
        dist = np.linalg.norm(xul[:, None, :] - xil[None, :, :], axis=2) * f
        nearest = dist.argmin(axis=1)
        again = dist[np.arange(len(xul)), nearest] < MATCH_PX
        cu, ci = np.nonzero(again)[0], nearest[again]
        redraw = ((xir - xil)[ci, 1] - (xur - xul)[cu, 1]) * f
        (all_u, sigma_u), (all_i, _) = verge_refit(xul, xur, uw, f), verge_refit(xil, xir, iw, f)
        common = (verge_refit(xil[ci], xir[ci], iw[ci], f)[0]
                  - verge_refit(xul[cu], xur[cu], uw[cu], f)[0]) if len(cu) >= 12 else None
        rows.append({"n_u": len(xul), "n_i": len(xil), "again": len(cu) / len(xul),
                     "redraw": float(np.sqrt(np.mean(redraw ** 2))) if len(cu) else None,
                     "sigma_u": sigma_u, "all": all_i - all_u, "common": common})
    return rows


def main():
    import argparse
    import shutil
    import tempfile
    import numpy as np

    argv, run_args = split_run_args(sys.argv[1:])
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--keep", action="store_true", help="keep the work directory")
    args = ap.parse_args(argv)

    data = real_data()
    if not os.path.isdir(data):
        raise SystemExit(f"no real data at {data} (set STEREOCAL_REAL_DATA)")
    binary = built_binary()
    work = tempfile.mkdtemp(prefix="match_overlap.")
    table = []
    try:
        for name, d in rectified_sequences(data):
            seq_args = run_args
            if "--fps" not in run_args and name in FRAME_RATES:
                seq_args = ["--fps", f"{FRAME_RATES[name]:g}", *run_args]
            calib = read_calib(os.path.join(d, "calib.toml"))
            cams_u = (calib["left"], calib["right"])
            f = float(np.mean([c[k] for c in cams_u for k in ("fx", "fy")]))
            print(f"{name}: untouched", file=sys.stderr)
            m_u, v_u = run_matches(binary, d, os.path.join(work, f"{name}_untouched_out"),
                                   seq_args)
            shifts = {f"shift {x:g}, {y:g}": (x, y) for x, y in SHIFTS}
            pooled = ([], [])
            for traj in (*shifts, *TRAJECTORIES):
                print(f"{name}: {traj}", file=sys.stderr)
                seq = os.path.join(work, f"{name}_{traj}".replace(" ", "").replace(",", "_"))
                out = seq + "_out"
                if traj in shifts:
                    shifted(d, seq, shifts[traj])
                    yaws = [(0.0, 0.0)] * len(v_u)
                    truth = [0.0] * len(v_u)
                else:
                    sh([binary, "inject", "--left", os.path.join(d, "left"), "--right",
                        os.path.join(d, "right"), "--calib", os.path.join(d, "calib.toml"),
                        "--motion", traj, "--out", seq])
                    yaws = read_yaws(os.path.join(seq, "encoders.csv"))
                    truth = read_truth(os.path.join(seq, "truth.csv"))
                inj = read_calib(os.path.join(seq, "calib.toml"))
                m_i, v_i = run_matches(binary, seq, out, seq_args)
                rows = compare(m_u, m_i, cams_u, (inj["left"], inj["right"]), yaws, f)
                ours = [abs(i["raw"] - u["raw"] - t) for i, u, t in zip(v_i, v_u, truth)
                        if i["raw"] is not None and u["raw"] is not None]
                table.append((name, traj, rows, ours))
                if traj in shifts:
                    pooled[0].extend(rows)
                    pooled[1].extend(ours)
                    if traj == list(shifts)[-1]:
                        table.append((name, f"shift, {len(shifts)} phases pooled", *pooled))
    finally:
        if args.keep:
            print(f"work directory kept: {work}", file=sys.stderr)
        else:
            shutil.rmtree(work, ignore_errors=True)

    med = lambda v: float(np.median(v)) if len(v) else float("nan")
    mx = lambda v: float(np.max(v)) if len(v) else float("nan")
    flags = " ".join(run_args) if run_args else "default settings"
    print(f"Match by match (`stereocal run --matches`, {flags}): the injected runs' matches "
          f"mapped back into their source frames; found again within {MATCH_PX} px. Medians "
          f"over the frames (max where two figures are given); refits verge-only, Cauchy "
          f"{CAUCHY_PX} px.\n")
    print("| sequence | trajectory | matches a frame: untouched / injected | found again "
          "| untouched residual σ, px | redraw, rms px | differential of a refit, all matches: median / max "
          "| differential of a refit, matches found again: median / max "
          "| differential, `stereocal run`: median / max |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, traj, rows, ours in table:
        pick = lambda k: [r[k] for r in rows if r[k] is not None]
        absd = lambda k: np.abs(pick(k))
        print(f"| {name} | {traj} | {med(pick('n_u')):.0f} / {med(pick('n_i')):.0f} "
              f"| {100 * med(pick('again')):.0f}% | {med(pick('sigma_u')):.3f} "
              f"| {med(pick('redraw')):.3f} "
              f"| {med(absd('all')):.4f}° / {mx(absd('all')):.3f}° "
              f"| {med(absd('common')):.4f}° / {mx(absd('common')):.3f}° "
              f"| {med(ours):.4f}° / {mx(ours):.3f}° |")


if __name__ == "__main__":
    if not in_venv():
        ensure_venv_and_reexec(os.path.abspath(__file__))
    main()
