#!/usr/bin/env python3
"""Scores obsgroup's place label map against a human room segmentation of the
same floor plan, as room-segmentation papers score theirs.

    scripts/score_room_segmentation.py OUTDIR SEGMENTATION.png POSES.txt
        [--resolution 0.05] [--origin X Y] [--labels labels.json]

OUTDIR is what `obsgroup partition` wrote (places.yaml and its label image).
SEGMENTATION.png is a room segmentation in the form of ipa_room_segmentation's
test maps (`*_gt_segmentation.png`): the floor plan with lines drawn between
rooms; free pixels (grey > 250) are cut into rooms by 8-connectivity, and
pieces of 100 pixels or fewer are dropped, as its evaluation does.
--resolution and --origin place that image in the frame of the poses
(metres per pixel; the position of its lower-left corner). POSES.txt (TUM:
stamp x y z qx qy qz qw) says which rooms were visited: those holding a pose.

Scores (micro-averaged over the visited rooms' floor that carries a place
label): each room's match is the place holding most of its floor; precision
is the sum of the overlaps over the sum of the matches' floor (a place that is
the match of several rooms counts once per room), recall the sum of the
overlaps over the rooms' floor. "Precision over the places' whole floor"
counts each match's floor in every room of the plan, visited or not (a place
that reaches into rooms the robot only looked into pays for it). Both
labelings are compared on cells of half a segmentation pixel: where the place
grid's edges fall on multiples of that (obsgroup's 0.2 m cells on a 0.05 m
plan), each cell lies in one pixel and in one place cell.

--labels (a labels.json of a labelled log: "kinds" per region, "labels" per
pose) adds the same scores without the rooms whose poses are mostly of a
region of kind "corridor".

Needs numpy, scipy and Pillow (Debian: python3-numpy python3-scipy python3-pil).
"""
import argparse
import collections
import json
import os
import sys

import numpy as np
from PIL import Image
from scipy.ndimage import label as connected_components

SUB = 2  # cells per segmentation pixel and axis


def read_map_yaml(path):
    fields = {}
    for line in open(path):
        if ":" in line:
            key, value = line.split(":", 1)
            fields[key.strip()] = value.strip()
    return (os.path.join(os.path.dirname(path), fields["image"]), float(fields["resolution"]),
            [float(v) for v in fields["origin"].strip("[]").split(",")][:2])


def rooms_of(segmentation):
    free = np.array(Image.open(segmentation).convert("L")) > 250
    labels, count = connected_components(free, structure=np.ones((3, 3), int))
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    keep = sizes > 100
    keep[0] = False
    renumber = np.zeros(count + 1, int)
    renumber[np.flatnonzero(keep)] = np.arange(1, keep.sum() + 1)
    return renumber[labels]


def places_on_cells(outdir, shape, resolution, origin):
    image, place_resolution, place_origin = read_map_yaml(os.path.join(outdir, "places.yaml"))
    places = np.array(Image.open(image)).astype(np.int64)  # place id + 1, 0: none; row 0 at the top
    rows, cols = shape
    cell = resolution / SUB
    x = origin[0] + (np.arange(cols * SUB) + 0.5) * cell
    y = origin[1] + rows * resolution - (np.arange(rows * SUB) + 0.5) * cell
    c = np.floor((x - place_origin[0]) / place_resolution + 1e-9).astype(int)
    r = places.shape[0] - 1 - np.floor((y - place_origin[1]) / place_resolution + 1e-9).astype(int)
    out = places[np.clip(r, 0, places.shape[0] - 1)][:, np.clip(c, 0, places.shape[1] - 1)]
    out[(r < 0) | (r >= places.shape[0]), :] = 0
    out[:, (c < 0) | (c >= places.shape[1])] = 0
    return out


def scores(room_of_cell, place_of_cell, rooms):
    on_floor = (room_of_cell > 0) & (place_of_cell > 0)
    # A place's floor in any room of the plan, visited or not.
    whole_size = collections.Counter(place_of_cell[on_floor].tolist())
    inside = np.isin(room_of_cell, rooms)
    floor = int(inside.sum())
    labelled = inside & (place_of_cell > 0)
    room, place = room_of_cell[labelled], place_of_cell[labelled]
    place_size = collections.Counter(place.tolist())
    overlap = matched = matched_whole = room_cells = 0
    for r in rooms:
        held = collections.Counter(place[room == r].tolist())
        if not held:
            continue
        best, count = max(held.items(), key=lambda item: (item[1], -item[0]))
        overlap += count
        matched += place_size[best]
        matched_whole += whole_size[best]
        room_cells += sum(held.values())
    return {"rooms": len(rooms), "precision": overlap / matched if matched else float("nan"),
            "recall": overlap / room_cells if room_cells else float("nan"),
            "precision, whole places": overlap / matched_whole if matched_whole else float("nan"),
            "floor labelled": labelled.sum() / floor if floor else float("nan")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("outdir")
    parser.add_argument("segmentation")
    parser.add_argument("poses")
    parser.add_argument("--resolution", type=float, default=0.05)
    parser.add_argument("--origin", type=float, nargs=2, default=[0.0, 0.0])
    parser.add_argument("--labels")
    parser.add_argument("--json", action="store_true", help="print the scores as JSON")
    args = parser.parse_args()
    rooms = rooms_of(args.segmentation)
    places = places_on_cells(args.outdir, rooms.shape, args.resolution, args.origin)
    room_of_cell = np.kron(rooms, np.ones((SUB, SUB), int))
    poses = np.loadtxt(args.poses, comments="#", ndmin=2)[:, 1:3]
    col = np.floor((poses[:, 0] - args.origin[0]) / args.resolution).astype(int)
    row = np.floor(rooms.shape[0] - (poses[:, 1] - args.origin[1]) / args.resolution).astype(int)
    inside = (row >= 0) & (row < rooms.shape[0]) & (col >= 0) & (col < rooms.shape[1])
    room_of_pose = np.zeros(len(poses), int)
    room_of_pose[inside] = rooms[row[inside], col[inside]]
    visited = sorted(set(room_of_pose[room_of_pose > 0].tolist()))
    result = {"all visited rooms": scores(room_of_cell, places, visited)}
    if args.labels:
        labels = json.load(open(args.labels))
        region = np.array(labels["labels"])
        if len(region) != len(poses):
            sys.exit(f"{args.labels}: {len(region)} labels for {len(poses)} poses")
        kept = [r for r in visited
                if labels["kinds"][collections.Counter(region[room_of_pose == r].tolist()).most_common(1)[0][0]]
                != "corridor"]
        result["rooms without corridors"] = scores(room_of_cell, places, kept)
    if args.json:
        print(json.dumps(result))
        return
    for name, s in result.items():
        print(f"{name}: {s['rooms']} rooms, precision {s['precision']:.3f}, recall {s['recall']:.3f}, "
              f"floor labelled {s['floor labelled']:.3f}, "
              f"precision over the places' whole floor {s['precision, whole places']:.3f}")


if __name__ == "__main__":
    main()
