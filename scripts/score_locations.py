#!/usr/bin/env python3
"""Scores `obsgroup locate` of a second run against room labels: is each of
its room scans placed in a place whose scans are mostly of that room?

    scripts/score_locations.py MAP_LABELS.json PARTITION.json RUN_LABELS.json LOCATIONS.json

MAP_LABELS.json labels the scans of the run the places were made from (its
partition.json); RUN_LABELS.json those of the located run (the same file when
both runs followed one route), LOCATIONS.json is what `obsgroup locate` wrote.
A labels file is `{"names": [...], "kinds": ["room"|"corridor", ...],
"labels": [one region index per scan, in log order; -1 for none]}`.

Regions are matched by name. A place's room is the region most of its
labelled scans are of. A located
scan whose own region is a room is right when its place's room is that room;
a scan placed nowhere (`"place": null`) is wrong. Prints one line:
`room_scans= right= unplaced= share=`.
"""
import collections
import json
import sys


def main(argv):
    if len(argv) != 5:
        sys.stderr.write(__doc__)
        return 2
    map_run = json.load(open(argv[1]))
    map_labels = [map_run["names"][k] if k >= 0 else None for k in map_run["labels"]]
    partition = json.load(open(argv[2]))
    run = json.load(open(argv[3]))
    locations = json.load(open(argv[4]))["locations"]
    room_of_place = {}
    for place_id, members in zip(partition["place_ids"], partition["groups"]):
        counts = collections.Counter(map_labels[i] for i in members if map_labels[i] is not None)
        room_of_place[place_id] = counts.most_common(1)[0][0] if counts else None
    room_scans = right = unplaced = 0
    for location in locations:
        region = run["labels"][location["observation"]]
        if region < 0 or run["kinds"][region] != "room":
            continue
        room_scans += 1
        if location["place"] is None:
            unplaced += 1
        elif room_of_place.get(location["place"]) == run["names"][region]:
            right += 1
    share = right / room_scans if room_scans else 0.0
    print(f"room_scans={room_scans} right={right} unplaced={unplaced} share={share:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
