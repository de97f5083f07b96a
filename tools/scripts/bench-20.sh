#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The speed issue's figures side by side on the real materials of ../shared/data (20 of them), in
# one run: per material the Google Benchmark programs of tests/bench/ (cbrdf_bench: evaluation,
# batch evaluation and sampling against the nearest-bin table lookup; cbrdf_encode_bench: default
# encode, rate control, 4 components) and `cbrdf render` of the figure-4 layout from the model and
# from the measured table; then one table with the mean and the worst material. A benchmark, not a
# test: it asserts nothing and CI does not run it. About 20-40 s per material on 2 cores.
#
# Usage: tools/scripts/bench-20.sh BUILD_DIR [--merl DIR] [--out DIR] [MATERIAL...]
#   BUILD_DIR  a build with -DCBRDF_BENCH=ON (Release); needs cbrdf, tests/bench/cbrdf_bench and
#              tests/bench/cbrdf_encode_bench (built here if missing).
#   --merl DIR take NAME.binary from DIR (e.g. /tmp/merl20) instead of making it with
#              ../shared/tools/make-merl.sh into BUILD_DIR/real-materials (the benchmarks' cache).
#   --out DIR  keep the raw results (benchmark JSON, render logs) there (default: a temporary dir).
#   MATERIAL   names from ../shared/data/nbrdf-merl (default: all of them).
#
# Output (stdout), one row per material, then "mean" and "worst" (the worst material per column:
# the smallest speed-up or the largest time or ratio), columns:
#   material        the material
#   eval1 ns        ModelEvaluator::eval per RGB pair, 1 component (BM_EvalModel)
#   eval4 ns        the same, 4 components (BM_EvalModel4)
#   near ns         nearest-bin lookup in the measured table (BM_LookupMeasuredNearest)
#   near/e1         near ns / eval1 ns: the speed-up over the table (target >= 2)
#   near/e4         near ns / eval4 ns (target >= 1)
#   bat1 x          scalar loop / batch eval on 1 thread, per pair (BM_EvalModel / BM_EvalBatch/1;
#                   target >= 4)
#   bat2 x          scalar loop / batch eval on 2 threads (BM_EvalModel / BM_EvalBatch/2)
#   smp1 x, smp2 x  scalar sampling loop / batch sampling on 1 and 2 threads (BM_SampleScalar /
#                   BM_SampleBatch/1, /2)
#   enc s           default encode, all cores (BM_Default)
#   tb3k x, tb12k x --target-bytes 3000 and 12000 over the default encode, wall time (target <= 5)
#   tp45 x, tp50 x  --target-psnr 45 and 50 (tone-mapped dB) over the default encode
#   k4 s            --components 4 encode (target < 2)
#   rmod s          `cbrdf render` of the figure-4 layout, every sphere in the material, one thread,
#                   from the default .cbrdf (best of 3; 1320x240, one sample per pixel)
#   rnear s, rtri s the same from the measured table, nearest-bin and trilinear lookup
#   mod/near, mod/tri  rmod / rnear and rmod / rtri (target <= 1; the paper: 1.06)
#   foot B          the evaluator's footprint in bytes (ModelEvaluator::footprint_bytes, 1 component)
#   tab/foot        the MERL table's 34,992,012 bytes over the footprint
set -euo pipefail

usage() {
  sed -n '10,16p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
[[ $# -ge 1 ]] || usage
BUILD=$(cd "$1" && pwd)
shift
MERL_DIR="" OUT=""
MATERIALS=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --merl) MERL_DIR=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    -h | --help) usage ;;
    *) MATERIALS+=("$1"); shift ;;
  esac
done
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
SHARED=${CBRDF_SHARED_DIR:-$ROOT/../shared}
PY=/usr/bin/python3
if [[ ${#MATERIALS[@]} -eq 0 ]]; then
  [[ -d $SHARED/data/nbrdf-merl ]] || { echo "no $SHARED/data/nbrdf-merl: name the materials" >&2; exit 1; }
  for f in "$SHARED"/data/nbrdf-merl/*.nbrdf; do MATERIALS+=("$(basename "$f" .nbrdf)"); done
fi
if [[ -z $OUT ]]; then
  OUT=$(mktemp -d /tmp/cbrdf-bench20.XXXXXX)
  trap 'rm -rf "$OUT"' EXIT
fi
mkdir -p "$OUT"

for t in cbrdf tests/bench/cbrdf_bench tests/bench/cbrdf_encode_bench; do
  if [[ ! -x $BUILD/$t ]]; then
    echo "building $t" >&2
    ninja -C "$BUILD" "$(basename "$t" | sed 's/^cbrdf$/cbrdf_cli/')" >&2
  fi
done

# The benchmarks read BUILD/real-materials/NAME.binary (and make it there when it is missing).
CACHE=$BUILD/real-materials
mkdir -p "$CACHE"
material_file() {
  local m=$1
  if [[ ! -e $CACHE/$m.binary ]]; then
    if [[ -n $MERL_DIR && -e $MERL_DIR/$m.binary ]]; then
      ln -s "$(cd "$MERL_DIR" && pwd)/$m.binary" "$CACHE/$m.binary"
    else
      bash "$SHARED/tools/make-merl.sh" "$CACHE" "$m" > /dev/null
    fi
  fi
  echo "$CACHE/$m.binary"
}

# The figure-4 layout (render/builtin.h, figure4_one_material) with every sphere in one material.
write_scene() {  # OUT.json MATERIAL_JSON
  "$PY" - "$1" "$2" << 'EOF'
import json, sys
path, material = sys.argv[1], json.loads(sys.argv[2])
scene = {
    "image": {"width": 1320, "height": 240},
    "camera": {"type": "orthographic", "position": [0, 0, 10], "look_at": [0, 0, 0], "height": 2.4},
    "materials": {"m": material},
    "objects": [{"type": "sphere", "center": [(i - 2.5) * 2.2, 0, 0], "radius": 1, "material": "m"}
                for i in range(6)],
    "lights": [{"type": "directional", "to_light": [0.5, 0.45, 0.74], "irradiance": 3.0}],
}
json.dump(scene, open(path, "w"), indent=1)
EOF
}

# Best of 3 one-thread renders, in seconds, from `cbrdf render`'s log.
render_s() {  # SCENE.json
  local best="" s
  for _ in 1 2 3; do
    s=$("$BUILD/cbrdf" render "$1" -o "$OUT/render.exr" --threads 1 |
      sed -n 's/^rendered in \([0-9.]*\) s.*/\1/p')
    [[ -n $s ]] || { echo "render of $1 failed" >&2; exit 1; }
    best=$("$PY" -c "import sys; print(min(float(x) for x in sys.argv[1:] if x))" "$s" $best)
  done
  echo "$best"
}

EVAL_FILTER='BM_(EvalModel|EvalModel4|EvalBatch|SampleScalar|SampleBatch|LookupMeasuredNearest)(/|$)'
ENC_FILTER='BM_(Default|TargetBytes(3000|12000)|TargetPsnr(45|50)|Components4)/'
start=$(date +%s)
for m in "${MATERIALS[@]}"; do
  t0=$(date +%s)
  file=$(material_file "$m")
  d=$OUT/$m
  mkdir -p "$d"
  "$BUILD/tests/bench/cbrdf_bench" "$m" --benchmark_filter="$EVAL_FILTER" \
    --benchmark_min_time=0.05 --benchmark_out="$d/eval.json" --benchmark_out_format=json \
    > "$d/eval.txt" 2>&1
  "$BUILD/tests/bench/cbrdf_encode_bench" "$m" --benchmark_filter="$ENC_FILTER" \
    --benchmark_out="$d/encode.json" --benchmark_out_format=json > "$d/encode.txt" 2>&1
  "$BUILD/cbrdf" -q encode "$file" -o "$d/model.cbrdf"
  write_scene "$d/model.json" "{\"type\": \"cbrdf\", \"file\": \"$d/model.cbrdf\"}"
  write_scene "$d/nearest.json" "{\"type\": \"merl\", \"file\": \"$file\", \"lookup\": \"nearest\"}"
  write_scene "$d/trilinear.json" "{\"type\": \"merl\", \"file\": \"$file\", \"lookup\": \"linear\"}"
  {
    echo "model $(render_s "$d/model.json")"
    echo "nearest $(render_s "$d/nearest.json")"
    echo "trilinear $(render_s "$d/trilinear.json")"
  } > "$d/render.txt"
  echo "$m: $(($(date +%s) - t0)) s" >&2
done
echo "all ${#MATERIALS[@]} materials: $(($(date +%s) - start)) s" >&2

"$PY" - "$OUT" "${MATERIALS[@]}" << 'EOF'
import json, math, sys

out, materials = sys.argv[1], sys.argv[2:]
TABLE_BYTES = 34992012

def runs(path):
    with open(path) as f:
        return json.load(f)["benchmarks"]

def find(bs, name):
    # Names as Google Benchmark prints them: BM_EvalBatch/1/real_time, BM_Default/nickel/...
    for b in bs:
        parts = b["name"].split("/")
        key = "/".join(p for p in parts
                       if p not in ("real_time", "process_time") and not p.startswith("iterations:"))
        if key == name:
            return b
    return None

def ns_per_pair(bs, name):
    b = find(bs, name)
    return 1e9 * b["ns_per_pair"] if b and "ns_per_pair" in b else math.nan

def seconds(b):
    if not b:
        return math.nan
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b.get("time_unit", "ns")]
    return b["real_time"] * scale

# (header, format, worst is the largest?)
COLS = [("eval1 ns", "%.0f", True), ("eval4 ns", "%.0f", True), ("near ns", "%.0f", True),
        ("near/e1", "%.2f", False), ("near/e4", "%.2f", False), ("bat1 x", "%.2f", False),
        ("bat2 x", "%.2f", False), ("smp1 x", "%.2f", False), ("smp2 x", "%.2f", False),
        ("enc s", "%.2f", True), ("tb3k x", "%.2f", True), ("tb12k x", "%.2f", True),
        ("tp45 x", "%.2f", True), ("tp50 x", "%.2f", True),
        ("k4 s", "%.2f", True), ("rmod s", "%.3f", True), ("rnear s", "%.3f", True),
        ("rtri s", "%.3f", True), ("mod/near", "%.2f", True), ("mod/tri", "%.2f", True),
        ("foot B", "%.0f", True), ("tab/foot", "%.0f", False)]

rows = []
for m in materials:
    ev = runs(f"{out}/{m}/eval.json")
    en = runs(f"{out}/{m}/encode.json")
    render = dict(line.split() for line in open(f"{out}/{m}/render.txt"))
    e1, e4 = ns_per_pair(ev, "BM_EvalModel"), ns_per_pair(ev, "BM_EvalModel4")
    near = ns_per_pair(ev, "BM_LookupMeasuredNearest")
    b1, b2 = ns_per_pair(ev, "BM_EvalBatch/1"), ns_per_pair(ev, "BM_EvalBatch/2")
    ss = ns_per_pair(ev, "BM_SampleScalar")
    s1, s2 = ns_per_pair(ev, "BM_SampleBatch/1"), ns_per_pair(ev, "BM_SampleBatch/2")
    enc = seconds(find(en, f"BM_Default/{m}"))
    tb = seconds(find(en, f"BM_TargetBytes3000/{m}"))
    tb12 = seconds(find(en, f"BM_TargetBytes12000/{m}"))
    tp = seconds(find(en, f"BM_TargetPsnr45/{m}"))
    tp50 = seconds(find(en, f"BM_TargetPsnr50/{m}"))
    k4 = seconds(find(en, f"BM_Components4/{m}"))
    fb = find(ev, "BM_EvalModel")
    foot = fb.get("footprint_bytes", math.nan) if fb else math.nan
    rm, rn, rt = (float(render[k]) for k in ("model", "nearest", "trilinear"))
    rows.append((m, [e1, e4, near, near / e1, near / e4, e1 / b1, e1 / b2, ss / s1, ss / s2,
                     enc, tb / enc, tb12 / enc, tp / enc, tp50 / enc, k4, rm, rn, rt, rm / rn, rm / rt, foot,
                     TABLE_BYTES / foot]))

def cell(fmt, v):
    return "-" if not math.isfinite(v) else fmt % v

def summary(pick):
    out = []
    for i, (_, _, larger_worse) in enumerate(COLS):
        vals = [r[1][i] for r in rows if math.isfinite(r[1][i])]
        out.append(pick(vals, larger_worse) if vals else math.nan)
    return out

mean = summary(lambda v, _: sum(v) / len(v))
worst = summary(lambda v, larger: max(v) if larger else min(v))
width = max(len(m) for m in materials + ["material"])
print("%-*s" % (width, "material") + "".join("%10s" % h for h, _, _ in COLS))
for name, vals in rows + [("mean", mean), ("worst", worst)]:
    print("%-*s" % (width, name) + "".join("%10s" % cell(f, v) for (_, f, _), v in zip(COLS, vals)))
EOF
