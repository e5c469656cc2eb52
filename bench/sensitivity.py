#!/usr/bin/env python3
"""Sensitivity of a constant: the README's figures with its value changed in the source.

Each variant replaces one piece of source text by another (it must occur exactly once) in a
scratch worktree of HEAD (uncommitted changes are not seen), rebuilds `stereocal` and measures
the two figures README, "Sensitivity of the constants", defines, each frame alone
(`--misalignment off`):

* the rendered road: `stereocal eval --scene road --frames 200 --seed 1 --misalignment off`;
* the KITTI drive with a verge injected: `stereocal inject --motion moving|fixed` on
  `kitti_odometry_drive` (the defaults' build injects it once), then `stereocal run --truth`.

For each it prints the raw and the filtered median |error| and the filtered span (after the
start-up), at the defaults first. `--filter` measures the filter's constants
(`host/src/kalman.rs`, `SETTLING_FRAMES`) halved and doubled, as their comments quote them.

The scratch worktree and its build stay out of the caller's tree: the worktree is removed at
the end, the build directory (target/sensitivity) is kept so that the next run rebuilds only
what a variant touches.

Usage: bench/sensitivity.py [--filter] [FILE:OLD=>NEW ...]
  e.g. bench/sensitivity.py 'host/src/estimator.rs:search_px: 6,=>search_px: 3,'
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

# The drive script's command runner and data location (its module level is the standard
# library alone; its venv is for its own comparison with OpenCV).
from drives import ROOT, real_data, sh

KALMAN = "host/src/kalman.rs"
SUMMARY = "host/src/output/summary.rs"


def halved_and_doubled(path, name, value, fmt, half, double):
    """Two variants of `name: value,` in `path`, at `half` and `double`."""
    old = f"{name}: {fmt.format(value)},"
    return [(f"{name} {fmt.format(v)}", path, old, f"{name}: {fmt.format(v)},")
            for v in (half, double)]


FILTER = (
    halved_and_doubled(KALMAN, "turning_noise", 100.0, "{:.1f}", 50.0, 200.0)
    + halved_and_doubled(KALMAN, "mode_time_s", 2.0, "{:.1f}", 1.0, 4.0)
    + halved_and_doubled(KALMAN, "min_measurement_sigma_deg", 0.01, "{}", 0.005, 0.02)
    + halved_and_doubled(KALMAN, "initial_rate_sigma", 10.0, "{:.1f}", 5.0, 20.0)
    + halved_and_doubled(KALMAN, "noise_scale_frames", 30, "{}", 15, 60)
    + [(f"NOISE_SCALE_MIN_FRAMES {v}", KALMAN, "NOISE_SCALE_MIN_FRAMES: usize = 12;",
        f"NOISE_SCALE_MIN_FRAMES: usize = {v};") for v in (6, 24)]
    + [(f"SETTLING_FRAMES {v}", SUMMARY, "SETTLING_FRAMES: usize = 8;",
        f"SETTLING_FRAMES: usize = {v};") for v in (4, 16)]
)


def parse_variant(text):
    """`FILE:OLD=>NEW` as (label, file, old, new)."""
    path, sep, rest = text.partition(":")
    old, arrow, new = rest.partition("=>")
    if not (sep and arrow and old):
        raise SystemExit(f"variant {text!r}: expected FILE:OLD=>NEW")
    return (f"{old.strip()} → {new.strip()}", path, old, new)


def substitute(tree, path, old, new):
    full = os.path.join(tree, path)
    try:
        with open(full, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise SystemExit(f"variant file {path}: {e}")
    if text.count(old) != 1:
        raise SystemExit(f"{path}: {old!r} occurs {text.count(old)} times, not once")
    with open(full, "w", encoding="utf-8") as f:
        f.write(text.replace(old, new))


def measure(binary, injected, work):
    """(raw median, filtered median, filtered span) of the road, the moving and fixed drive."""
    def keys(summary):
        return tuple(summary[k] for k in ("median_abs_err_deg", "filtered_median_abs_err_deg",
                                          "filtered_span_deg"))
    out = {"road": keys(json.loads(sh([
        binary, "eval", "--scene", "road", "--frames", "200", "--seed", "1",
        "--misalignment", "off", "--json", "--out", os.path.join(work, "road")])))}
    for motion, seq in injected.items():
        out[motion] = keys(json.loads(sh([
            binary, "run", "--left", os.path.join(seq, "left"),
            "--right", os.path.join(seq, "right"), "--calib", os.path.join(seq, "calib.toml"),
            "--truth", os.path.join(seq, "truth.csv"), "--misalignment", "off", "--json",
            "--out", os.path.join(work, motion)])))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--filter", action="store_true",
                    help="the filter's constants, halved and doubled")
    ap.add_argument("variants", nargs="*", help="FILE:OLD=>NEW")
    args = ap.parse_args()
    variants = (FILTER if args.filter else []) + [parse_variant(v) for v in args.variants]
    kitti = os.path.join(real_data(), "kitti_odometry_drive")
    if not os.path.isdir(kitti):
        raise SystemExit(f"no KITTI drive at {kitti} (set STEREOCAL_REAL_DATA)")
    if sh(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT).strip():
        print("note: uncommitted changes are not measured (the worktree is HEAD)",
              file=sys.stderr)

    work = tempfile.mkdtemp(prefix="sensitivity.")
    tree = os.path.join(work, "tree")
    sh(["git", "worktree", "add", "--detach", tree, "HEAD"], cwd=ROOT)
    env = dict(os.environ, CARGO_TARGET_DIR=os.path.join(ROOT, "target", "sensitivity"))
    binary = os.path.join(env["CARGO_TARGET_DIR"], "release", "stereocal")
    rows = []
    try:
        def build():
            sh(["cargo", "build", "--release", "-q", "-p", "stereocal-cli"], cwd=tree, env=env)

        print("defaults", file=sys.stderr)
        build()
        injected = {}
        for motion in ("moving", "fixed"):
            injected[motion] = os.path.join(work, f"kitti_{motion}")
            sh([binary, "inject", "--left", os.path.join(kitti, "left"),
                "--right", os.path.join(kitti, "right"),
                "--calib", os.path.join(kitti, "calib.toml"),
                "--motion", motion, "--out", injected[motion]])
        rows.append(("defaults", measure(binary, injected, work)))
        for label, path, old, new in variants:
            print(label, file=sys.stderr)
            substitute(tree, path, old, new)
            try:
                build()
                rows.append((label, measure(binary, injected, work)))
            finally:
                sh(["git", "checkout", "--", path], cwd=tree)
    finally:
        subprocess.run(["git", "worktree", "remove", "--force", tree], cwd=ROOT,
                       capture_output=True)
        shutil.rmtree(work, ignore_errors=True)

    f = lambda v: "-" if v is None else f"{v:.4f}°"
    print("Each frame alone (`--misalignment off`); degrees: raw median / filtered median / "
          "filtered span.\n")
    print("| variant | rendered road | KITTI moving | KITTI fixed |")
    print("|---|---|---|---|")
    for label, m in rows:
        cells = [" / ".join(f(v) for v in m[k]) for k in ("road", "moving", "fixed")]
        print(f"| {label} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
