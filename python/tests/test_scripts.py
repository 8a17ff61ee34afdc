"""The measuring scripts of scripts/ score what they say they score."""

import json
import subprocess
import sys
from pathlib import Path

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def test_score_locations_counts_room_scans_placed_in_their_rooms_place(tmp_path):
    # The map run: place 5 holds two scans of room A and one of room B, place 9 the corridor.
    map_labels = {"names": ["A", "B", "hall"], "kinds": ["room", "room", "corridor"], "labels": [0, 0, 1, 2, 2]}
    partition = {"groups": [[0, 1, 2], [3, 4]], "place_ids": [5, 9]}
    # The located run names its regions in another order: they are matched by name.
    run_labels = {"names": ["hall", "A", "B"], "kinds": ["corridor", "room", "room"], "labels": [1, 1, 2, 0, -1]}
    locations = {"locations": [
        {"observation": 0, "place": 5, "distance_m": 0.0},   # room A in A's place: right
        {"observation": 1, "place": 9, "distance_m": 0.0},   # room A in the corridor's place: wrong
        {"observation": 2, "place": None, "distance_m": None},  # room B nowhere: wrong, unplaced
        {"observation": 3, "place": 9, "distance_m": 0.0},   # a corridor scan: not scored
        {"observation": 4, "place": 5, "distance_m": 0.0},   # no label: not scored
    ]}
    files = []
    for name, content in [("map.json", map_labels), ("partition.json", partition), ("run.json", run_labels),
                          ("locations.json", locations)]:
        (tmp_path / name).write_text(json.dumps(content))
        files.append(str(tmp_path / name))
    out = subprocess.run([sys.executable, str(SCRIPTS / "score_locations.py"), *files], check=True,
                         capture_output=True, text=True).stdout
    assert out.strip() == "room_scans=3 right=1 unplaced=1 share=0.333"


def test_score_locations_says_how_to_call_it():
    done = subprocess.run([sys.executable, str(SCRIPTS / "score_locations.py")], capture_output=True, text=True)
    assert done.returncode == 2 and "MAP_LABELS.json PARTITION.json" in done.stderr
