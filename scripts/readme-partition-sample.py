#!/usr/bin/env python3
"""Writes the user guide's sample partition.json from a real run of the main job
(obsgroup partition data/office_2d/office.clf with the defaults), between the
docs/usage.md's <!-- partition-json:begin --> and <!-- partition-json:end --> marks.
Long arrays are cut with "..."; everything else is the run's own values (the
test suite checks the statistics against a run). Usage, from the repository:
  python3 scripts/readme-partition-sample.py [path/to/obsgroup]"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

root = Path(__file__).resolve().parent.parent
exe = sys.argv[1] if len(sys.argv) > 1 else str(root / "build" / "obsgroup")
with tempfile.TemporaryDirectory() as tmp:
    out = Path(tmp) / "out"
    subprocess.run([exe, "partition", "data/office_2d/office.clf", "-o", str(out), "-q"],
                   cwd=root, check=True)
    p = json.loads((out / "partition.json").read_text())


def compact(value):
    return json.dumps(value, separators=(", ", ": "))


def cut(items, keep):
    text = ", ".join(compact(v) for v in items[:keep])
    return "[" + text + (", ...]" if len(items) > keep else "]")


def rounded(value):
    if isinstance(value, float):
        return float(f"{value:.4g}")
    return value


split = p["splits"][0]
split_keys = ["id", "parent", "depth", "size", "kind", "outcome", "accepted", "ncut", "threshold", "eigenvalue",
              "solver", "solver_fell_back", "children"]
split_text = ", ".join(f'"{k}": {compact(rounded(split[k]))}' for k in split_keys if k in split)
members = ", ".join(str(m) for m in split["members"][:2])
timing = {k: (round(v, 2) if isinstance(v, float) else v) for k, v in p["timing_s"].items()}
lines = [
    "```json",
    "{",
    f'  "observations": {p["observations"]},',
    f'  "groups": {cut(p["groups"], 2)},',
    f'  "place_ids": {compact(p["place_ids"])},',
    f'  "sources": {cut(p["sources"], 2)},',
    f'  "stamps": {cut(p["stamps"], 2) if p["stamps"] is not None else "null"},',
    f'  "splits": [{{{split_text}, "members": [{members}, ...]}}, ...],',
    f'  "parameters": {compact(p["parameters"])},',
    f'  "statistics": {compact(p["statistics"])},',
    f'  "warnings": {compact(p["warnings"])},',
    f'  "input": {compact(p["input"])},',
    f'  "timing_s": {compact(timing)}',
    "}",
    "```",
]
readme = root / "docs" / "usage.md"
text = readme.read_text()
begin, end = "<!-- partition-json:begin -->", "<!-- partition-json:end -->"
head, rest = text.split(begin)
_, tail = rest.split(end)
readme.write_text(head + begin + "\n" + "\n".join(lines) + "\n" + end + tail)
print("docs/usage.md: sample partition.json from", p["input"])
