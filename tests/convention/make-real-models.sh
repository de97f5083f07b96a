#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The 20 real materials encoded once, for the rejected-draw tests (tests/convention): each
# ../shared table (made into BUILD/real-materials by ../shared/tools/make-merl.sh when missing,
# as the tests' real_materials_dir() does) through `cbrdf encode` at a fast setting (6 slices, 10
# bits, zstd level 1, no metrics) into OUT_DIR/NAME.cbrdf, kept while newer than the command and
# the table. Without ../shared it says SKIPPED and succeeds (ctest reports the test skipped).
#   make-real-models.sh CLI OUT_DIR SHARED_DIR BUILD_DIR
# CBRDF_REAL_MATERIALS_DIR names another folder of tables; CBRDF_RELEASE_CLI another command (the
# sanitizer suite encodes with the release build's); CBRDF_REAL_MODELS_DIR a folder of models
# this script made before (the release build's), copied with their times so that only those
# older than the command or their table are encoded again.
set -euo pipefail
cli=${CBRDF_RELEASE_CLI:-$1} out=$2 shared=$3 build=$4
if [ ! -d "$shared/data/nbrdf-merl" ] || [ ! -f "$shared/tools/make-merl.sh" ]; then
  echo "SKIPPED: $shared/data/nbrdf-merl is absent: no real materials to encode"
  exit 0
fi
tables=${CBRDF_REAL_MATERIALS_DIR:-$build/real-materials}
mkdir -p "$tables" "$out"
flock "$tables.lock" bash "$shared/tools/make-merl.sh" "$tables" > "$tables.log" 2>&1 ||
  { echo "make-merl.sh failed, see $tables.log" >&2; exit 1; }
exec 9> "$out.lock"
flock 9  # parallel tests: one encodes, the others wait for its files
SECONDS=0
made=0
if [ -n "${CBRDF_REAL_MODELS_DIR:-}" ] && [ -d "$CBRDF_REAL_MODELS_DIR" ] &&
  [ "$(cd "$CBRDF_REAL_MODELS_DIR" && pwd)" != "$(cd "$out" && pwd)" ]; then
  for model in "$CBRDF_REAL_MODELS_DIR"/*.cbrdf; do
    [ -f "$model" ] && cp -p "$model" "$out/"
  done
fi
for table in "$tables"/*.binary; do
  name=$(basename "$table" .binary)
  case $name in *-noisy) continue ;; esac
  dst=$out/$name.cbrdf
  if [ "$dst" -nt "$cli" ] && [ "$dst" -nt "$table" ]; then continue; fi
  "$cli" encode "$table" -o "$dst.tmp" --slices 6 --bits 10 --level 1 --no-metrics \
    --metadata none > /dev/null
  mv "$dst.tmp" "$dst"
  made=$((made + 1))
done
echo "$(ls "$out"/*.cbrdf | wc -l) models in $out ($made encoded in $SECONDS s)"
