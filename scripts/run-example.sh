#!/usr/bin/env bash
# Builds obsgroup in Release and runs the main job: `obsgroup partition` on the
# simulated office log shipped in data/ (77 scans of a 180-degree laser along a
# corridor and four rooms, as in the paper's Fig. 5). Results go to
# out/office_2d/, which this script owns and replaces on every run.
set -euo pipefail
cd "$(dirname "$0")/.."
# The command alone: the tests and examples need packages the main job does not (.ci/packages.txt).
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_TESTS=OFF -DOBSGROUP_BUILD_EXAMPLES=OFF > /dev/null
cmake --build build -j"$(nproc)" --target obsgroup_cli
./build/obsgroup partition data/office_2d/office.clf -o out/office_2d --force
echo
echo "Pictures: out/office_2d/map.png (map.svg), weights.png, fiedler.png, local_maps/group_NNN.png"
echo "Groups:   out/office_2d/partition.json; local maps: out/office_2d/local_maps/; topology.json/.dot"
