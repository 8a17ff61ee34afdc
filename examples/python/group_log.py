#!/usr/bin/env python3
"""Read a log, group its scans into places and plot them.

    python3 examples/python/group_log.py data/office_2d/office.clf groups.png

Every scan's points are drawn in the world frame, coloured by the place the grouping put it in,
with each place's number at the mean of its poses.
"""

import argparse

import matplotlib

matplotlib.use("Agg")  # files, no window
import matplotlib.pyplot as plt
import numpy as np

import obsgroup


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input", help="any input obsgroup reads: a CARMEN log, a PCD folder, a bag, ...")
    parser.add_argument("output", help="the picture to write (.png, .svg, .pdf)")
    parser.add_argument("--ncut-threshold", type=float, default=None, help="as the command's option")
    args = parser.parse_args()

    scans = obsgroup.read(args.input)
    grouping = obsgroup.Grouping(ncut_threshold=args.ncut_threshold)
    grouping.extend(scans)
    partition = grouping.compute()

    figure, axes = plt.subplots(figsize=(8, 8))
    colours = plt.get_cmap("tab20")
    for g, members in enumerate(partition.groups):
        colour = colours(g % 20)
        # one array per place: the members' points in the world frame, no per-point Python loop
        world = np.concatenate([scans[i].points @ scans[i].pose[:3, :3].T + scans[i].pose[:3, 3] for i in members])
        axes.scatter(world[:, 0], world[:, 1], s=0.3, color=colour, linewidths=0)
        positions = np.array([scans[i].pose[:2, 3] for i in members])
        axes.plot(positions[:, 0], positions[:, 1], ".", color=colour, markersize=4)
        centre = positions.mean(axis=0)
        axes.annotate(str(g), centre, ha="center", va="center", fontsize=11, weight="bold",
                      bbox=dict(boxstyle="circle", facecolor="white", edgecolor=colour))
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.set_title(f"{args.input}: {len(scans)} scans, {len(partition)} places")
    figure.savefig(args.output, dpi=120, bbox_inches="tight")
    print(f"{len(partition)} places; wrote {args.output}")


if __name__ == "__main__":
    main()
