#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# PROGRAM draws N over every model in MODELS_DIR (make-real-models.sh's), or SKIPPED when there
# are none (no ../shared).   run-rejected-draws.sh PROGRAM N MODELS_DIR
set -euo pipefail
shopt -s nullglob
models=("$3"/*.cbrdf)
if [ ${#models[@]} -eq 0 ]; then
  echo "SKIPPED: no models in $3 (../shared is absent)"
  exit 0
fi
exec "$1" draws "$2" "${models[@]}"
