#!/usr/bin/env bash
# Builds obsgroup in Release and runs the main job: partitioning the simulated
# office (77 scans, as in the paper's Fig. 5) and the real office log shipped
# in data/.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)" --target partition_synthetic pcl_grouping
./build/examples/partition_synthetic
echo
echo "Real office log (data/real/localization_demo, 72 scans, poses from the PCD VIEWPOINTs):"
./build/examples/pcl_grouping data/real/localization_demo/pcd/*.pcd
