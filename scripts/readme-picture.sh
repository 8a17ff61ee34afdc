#!/usr/bin/env bash
# Writes the README's picture, docs/images/localization_demo_map.png: map.png
# of `obsgroup partition` with the defaults on the real log shipped in
# data/real/localization_demo (MRPT's dataset, BSD-3-Clause). Run after a build.
#   bash scripts/readme-picture.sh [path/to/obsgroup]
set -euo pipefail
cd "$(dirname "$0")/.."
exe=${1:-build/obsgroup}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$exe" partition data/real/localization_demo/localization_demo.clf -q -o "$out/run"
mkdir -p docs/images
cp "$out/run/map.png" docs/images/localization_demo_map.png
echo "wrote docs/images/localization_demo_map.png"
