#!/usr/bin/env python3
"""Labels each scan of a real CARMEN log with the room it stands in, from a human room
segmentation of the same building drawn as ipa_room_segmentation's test maps are
(`<map>.png`, the plan: white floor; `<map>_gt_segmentation.png`: white rooms between grey
lines), so that obsgroup's groups on the real log can be scored against rooms
(rooms_dev's score.py, `examples/evaluate_grouping --log LOG --labels LABELS.json`).

The plan is registered to obsgroup's own map of the log: the free cells of OUTDIR/occupancy.pgm
(from `obsgroup partition LOG -o OUTDIR`) are matched to the plan's white floor over mirror,
rotation and scale, the translation by FFT cross-correlation. Each observation's laser pose
(its log line, from partition.json's `sources`) is then looked up in the segmentation: the
white region (4-connected) it stands in, or the nearest within 10 pixels. The largest visited
region is the corridor, the others rooms. Look at --overlay before trusting the labels.

Usage, from the repository (numpy, scipy, Pillow):
  python3 scripts/label_log_from_segmentation.py OUTDIR PLAN.png SEGMENTATION.png LABELS.json
      [--resolution 0.05] [--transform T.json] [--overlay OVERLAY.png]"""
import argparse
import gzip
import itertools
import json
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw
from scipy import ndimage, signal


def map_cells(outdir, value):
    """World (x, y) of the cells of occupancy.pgm holding `value` (254 free, 0 occupied)."""
    pgm = np.array(Image.open(outdir / "occupancy.pgm"))
    meta = dict(line.split(":", 1) for line in (outdir / "occupancy.yaml").read_text().splitlines() if ":" in line)
    resolution = float(meta["resolution"])
    ox, oy = [float(v) for v in meta["origin"].strip(" []").split(",")[:2]]
    rows, cols = np.nonzero(pgm == value)
    return np.stack([ox + (cols + 0.5) * resolution, oy + (pgm.shape[0] - 1 - rows + 0.5) * resolution], 1)


def transformed(points, t):
    """Plan pixel (column, row from the top) of world points under transform t."""
    a = np.deg2rad(t["theta_deg"])
    rotation = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    mirror = np.array([-1.0, 1.0]) if t["mirror"] else np.array([1.0, 1.0])
    q = t["scale"] * (points * mirror) @ rotation.T - np.array(t["corner"])
    pixel = np.floor(q / t["resolution"]).astype(int)
    return pixel[:, 0] + t["shift"][0], t["height"] - 1 - (pixel[:, 1] + t["shift"][1])


def register(free, plan_white, resolution):
    """The mirror, rotation, scale and shift that put most free cells on the plan's floor."""
    target = np.where(np.flipud(plan_white), 1.0, -1.0)  # row 0 at the bottom, as y grows
    height, width = plan_white.shape

    def score(mirror, theta, scale):
        t = {"mirror": mirror, "theta_deg": theta, "scale": scale, "corner": [0.0, 0.0], "resolution": resolution,
             "shift": [0, 0], "height": 0}
        a = np.deg2rad(theta)
        rotation = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        q = scale * (free * (np.array([-1.0, 1.0]) if mirror else 1.0)) @ rotation.T
        t["corner"] = q.min(0).tolist()
        pixel = np.floor((q - q.min(0)) / resolution).astype(int)
        rows, cols = pixel[:, 1].max() + 1, pixel[:, 0].max() + 1
        if rows > height + 400 or cols > width + 400:
            return -1.0, t
        image = np.zeros((rows, cols))
        image[pixel[:, 1], pixel[:, 0]] = 1.0
        c = signal.fftconvolve(target, image[::-1, ::-1], mode="full")
        k = np.unravel_index(np.argmax(c), c.shape)
        t["shift"] = [int(k[1] - (cols - 1)), int(k[0] - (rows - 1))]
        t["height"] = height
        return float(c[k] / len(free)), t

    best = (-2.0, None)
    for mirror, theta in itertools.product((False, True), np.arange(0.0, 360.0, 3.0)):
        best = max(best, score(mirror, theta, 1.0), key=lambda s: s[0])
    mirror, theta = best[1]["mirror"], best[1]["theta_deg"]
    for th, scale in itertools.product(np.arange(theta - 3, theta + 3.1, 1.0), np.arange(0.8, 1.26, 0.05)):
        best = max(best, score(mirror, th, scale), key=lambda s: s[0])
    theta, scale0 = best[1]["theta_deg"], best[1]["scale"]
    for th, scale in itertools.product(np.arange(theta - 1, theta + 1.1, 0.5), np.arange(scale0 - 0.04, scale0 + 0.041, 0.01)):
        best = max(best, score(mirror, th, scale), key=lambda s: s[0])
    best[1]["score"] = best[0]
    return best[1]


def laser_poses(partition):
    """The laser pose (x, y) of each observation, from its log line."""
    lines = {int(s.rsplit(":", 1)[1]) for s in partition["sources"]}
    words = {}
    opener = gzip.open if partition["input"].endswith(".gz") else open
    with opener(partition["input"], "rt") as f:
        for number, line in enumerate(f, 1):
            if number in lines:
                words[number] = line.split()
    poses = []
    for source in partition["sources"]:
        w = words[int(source.rsplit(":", 1)[1])]
        if w[0] == "FLASER":
            n = int(w[1])
            poses.append([float(w[2 + n]), float(w[3 + n])])
        elif w[0] == "ROBOTLASER1":
            n = int(w[8])
            k = 9 + n
            k += 1 + int(w[k])
            poses.append([float(w[k]), float(w[k + 1])])
        else:
            raise SystemExit(f"{source}: not a FLASER or ROBOTLASER1 line")
    return np.array(poses)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("outdir", type=Path)
    parser.add_argument("plan", type=Path)
    parser.add_argument("segmentation", type=Path)
    parser.add_argument("labels", type=Path)
    parser.add_argument("--resolution", type=float, default=0.05, help="metres per plan pixel")
    parser.add_argument("--transform", type=Path, help="a transform written by an earlier run (skips the search)")
    parser.add_argument("--overlay", type=Path, help="draws the poses, by label, over the segmentation")
    args = parser.parse_args()
    if args.labels.exists():
        raise SystemExit(f"{args.labels} exists: not overwritten")

    plan = np.array(Image.open(args.plan).convert("L"))
    if args.transform:
        t = json.loads(args.transform.read_text())
    else:
        t = register(map_cells(args.outdir, 254), plan >= 250, args.resolution)
        args.labels.with_suffix(".transform.json").write_text(json.dumps(t) + "\n")
    print(f"registration: mirror {t['mirror']}, rotation {t['theta_deg']:.1f} deg, scale {t['scale']:.2f}, "
          f"{100 * t.get('score', float('nan')):.0f}% of free cells on the plan's floor less those off it")

    segmentation = np.array(Image.open(args.segmentation).convert("L"))
    white = segmentation >= 250
    region, _ = ndimage.label(white)
    sizes = np.bincount(region.ravel())
    distance, (near_row, near_col) = ndimage.distance_transform_edt(~white, return_indices=True)
    partition = json.loads((args.outdir / "partition.json").read_text())
    x, y = transformed(laser_poses(partition), t)
    x = np.clip(x, 0, white.shape[1] - 1)
    y = np.clip(y, 0, white.shape[0] - 1)
    of_scan = [int(region[near_row[b, a], near_col[b, a]]) if distance[b, a] < 10 else 0 for a, b in zip(x, y)]
    visited = sorted(set(of_scan) - {0})
    corridor = max(visited, key=lambda r: sizes[r])
    index = {r: k for k, r in enumerate(visited)}
    names = [f"region_{r}" for r in visited]
    kinds = ["corridor" if r == corridor else "room" for r in visited]
    labels = [index.get(r, -1) for r in of_scan]
    args.labels.write_text(json.dumps({"names": names, "kinds": kinds, "labels": labels}) + "\n")
    print(f"{len(labels)} scans: {kinds.count('room')} rooms visited, {labels.count(-1)} scans in no region")
    if args.overlay:
        image = Image.open(args.segmentation).convert("RGB")
        draw = ImageDraw.Draw(image)
        colours = np.random.RandomState(1).randint(0, 200, (len(visited) + 1, 3))
        for a, b, label in zip(x, y, labels):
            draw.ellipse([a - 2, b - 2, a + 2, b + 2], fill=tuple(int(v) for v in colours[label]))
        image.save(args.overlay)


if __name__ == "__main__":
    main()
