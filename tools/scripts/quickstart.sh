#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs what is missing, builds the cbrdf command (Release, no tests), and runs the main job:
# compress the built-in measured materials (neural fits of real MERL measurements) at a few
# settings around the paper's, with the cheap baselines, and write the report. Its last lines are
# the answer: per material the paper's setting, the best setting within its bytes and within a
# quarter of them, and where report.html is.   Usage: tools/scripts/quickstart.sh
# About 5 minutes on 2 cores from a clean build directory (CMakePresets.json: quickstart).
#   CBRDF_BUILD_PREFIX: where the build goes (default the repository's build/).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
build=$(realpath -m "${CBRDF_BUILD_PREFIX:-}build")
tools/scripts/install-deps.sh main
cmake --preset quickstart > /dev/null
cmake --build --preset quickstart -j "$(nproc)"
echo
# The sweep spans the frontier around the paper's setting (frank s6 b12, always measured): one,
# two and four copula components at 6, 8 and 12 bits and at the default `--bits auto`, and 3 slices
# for the small budgets. The
# separable model is the one cheap baseline; the analytic fits and float16 (add
# `--baselines separable,analytic,float16`) would each add about a minute on 2 cores.
"$build/cbrdf" report --builtin measured --sweep slices=3,6 components=1,2,4 bits=6,8,12,auto \
  --baselines separable -o "$build/report"
