#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Regenerates the figures of the README and docs/benchmarks.md in docs/ with the project's own
# tools: the quickstart's report on the built-in measured materials (the same sweep), then its mean
# frontier and the reference / decoded / difference sphere renders of the paper's three materials.
#   Usage: tools/scripts/make-docs-figures.sh [BUILD_DIR]   (BUILD_DIR must hold a built `cbrdf`)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
if [ ! -x "$build/cbrdf" ]; then
  echo "make-docs-figures: no $build/cbrdf: build it first (tools/scripts/quickstart.sh, or cmake --preset quickstart)" >&2
  exit 1
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$build/cbrdf" report --builtin measured --sweep slices=3,6 components=1,2,4 bits=6,8,12,auto \
  --baselines separable --progress never -o "$out" | sed -n '/^Summary:/,$p' | grep -v '^Full report:' > "$out/summary.txt"
mkdir -p "$root/docs/spheres"
cp "$out/frontier_mean.svg" "$root/docs/frontier.svg"
for m in blue-metallic-paint nickel yellow-matte-plastic; do
  for kind in reference decoded difference; do
    cp "$out/sphere_${m}_${kind}.png" "$root/docs/spheres/${m}_${kind}.png"
  done
done
cp "$out/summary.txt" "$root/docs/summary.txt"
echo "make-docs-figures: wrote docs/frontier.svg, docs/spheres/*.png and docs/summary.txt"
