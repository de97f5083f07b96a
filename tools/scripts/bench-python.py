#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""What a call from Python costs over the C batch call it wraps, per pair or draw (issue 42).

    tools/scripts/bench-python.py BUILD [MATERIAL] [--repeats N] [--json]

One run, one model, the same inputs on both sides: BUILD/bench-default.cbrdf, MATERIAL (default
blue-metallic-paint) encoded with the command's defaults, as cbrdf_bench writes it. 65,536
direction pairs (uniform over the upper hemisphere, as cbrdf_bench's) and 32,768 draws (wo as
those, u uniform): at 1 thread and at the library's default thread count,

  float32 eval   Model.eval(wi, wo) on float32 (N, 3)  vs cbrdf_model_eval_batch_f32
  float64 eval   Model.eval(wi, wo) on float64 (N, 3)  vs cbrdf_model_eval_batch
  sample         Model.sample(wo, u)                   vs cbrdf_model_sample_batch

The C calls go through ctypes on BUILD/libcbrdf_decoder.so (a call's own cost, about a
microsecond, is 0.02 ns per pair at this n). Each figure is the best of --repeats calls (default
15), Python and C taking turns, so that other load on the machine affects both alike. Then
cbrdf_bench's BM_CApi_EvalBatch, BM_CApi_EvalBatchF32 and BM_CApi_SampleBatch/n:32768 (1 thread)
are run on the same file for the C figures measured in C. Prints one row per case and the ratio
Python / C (the target: at most 1.2).
"""
import argparse
import ctypes
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

PAIRS = 1 << 16
DRAWS = 1 << 15


def hemisphere(n, rng):
    """cbrdf_bench's random_directions: z uniform in [0, 1), phi uniform."""
    z = rng.random(n)
    phi = 2 * np.pi * rng.random(n)
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def timed(fn):
    """Wall and process CPU seconds of one call."""
    w, c = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - w, time.process_time() - c


def c_api(build):
    lib = ctypes.CDLL(os.path.join(build, "libcbrdf_decoder.so"))
    f64 = np.ctypeslib.ndpointer(np.float64, flags="C")
    f32 = np.ctypeslib.ndpointer(np.float32, flags="C")
    lib.cbrdf_model_open_file.restype = ctypes.c_void_p
    lib.cbrdf_model_open_file.argtypes = [ctypes.c_char_p]
    lib.cbrdf_model_eval_batch.argtypes = [ctypes.c_void_p, ctypes.c_size_t, f64, f64, f64,
                                           ctypes.c_int]
    lib.cbrdf_model_eval_batch_f32.argtypes = [ctypes.c_void_p, ctypes.c_size_t, f32, f32, f32,
                                               ctypes.c_int]
    lib.cbrdf_model_sample_batch.argtypes = [ctypes.c_void_p, ctypes.c_size_t, f64, f64, f64, f64,
                                             f64, ctypes.c_int]
    lib.cbrdf_model_eval_batch_soa.argtypes = [ctypes.c_void_p, ctypes.c_size_t] + [f64] * 9 + [
        ctypes.c_int]
    return lib


def cbrdf_bench(build, material):
    """cbrdf_bench's C API batch figures (ns per pair or draw, 1 thread), by benchmark name."""
    exe = os.path.join(build, "tests", "bench", "cbrdf_bench")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "bench.json")
        r = subprocess.run([exe, material,
                            "--benchmark_filter=BM_CApi_(EvalBatch|EvalBatchF32|SampleBatch/n:32768)/",
                            f"--benchmark_out={out}", "--benchmark_out_format=json"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{exe} failed:\n{r.stderr}")
        with open(out) as f:
            runs = json.load(f)["benchmarks"]
    # ns_per_pair is an inverted rate (seconds per pair in the JSON) of wall time; the CPU time per
    # pair scales it by cpu_time / real_time (on one thread, what other load does not inflate).
    return {b["name"].split("/")[0]: (b["ns_per_pair"] * 1e9,
                                      b["ns_per_pair"] * 1e9 * b["cpu_time"] / b["real_time"])
            for b in runs}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build")
    ap.add_argument("material", nargs="?", default="blue-metallic-paint")
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--json", action="store_true", help="print the rows as JSON")
    a = ap.parse_args()
    build = os.path.abspath(a.build)
    sys.path.insert(0, os.path.join(build, "python"))
    import cbrdf

    # cbrdf_bench first: it writes the material's default file, which both sides then read.
    bench = cbrdf_bench(build, a.material)
    path = os.path.join(build, "bench-default.cbrdf")
    model = cbrdf.decode(path)
    lib = c_api(build)
    handle = lib.cbrdf_model_open_file(path.encode())
    if not handle:
        sys.exit(f"cannot open {path} through the C API")

    rng = np.random.default_rng(42)
    wi, wo = hemisphere(PAIRS, rng), hemisphere(PAIRS, rng)
    wi32, wo32 = wi.astype(np.float32), wo.astype(np.float32)
    draw_wo, u = hemisphere(DRAWS, rng), rng.random((DRAWS, 2))
    rgb, rgb32 = np.empty((PAIRS, 3)), np.empty((PAIRS, 3), np.float32)
    s_wi, s_pdf, s_w = np.empty((DRAWS, 3)), np.empty(DRAWS), np.empty((DRAWS, 3))

    def c_eval(threads):
        assert lib.cbrdf_model_eval_batch(handle, PAIRS, wi, wo, rgb, threads) == 0

    def c_eval32(threads):
        assert lib.cbrdf_model_eval_batch_f32(handle, PAIRS, wi32, wo32, rgb32, threads) == 0

    soa_in = [np.ascontiguousarray(a[:, k]) for a in (wi, wo) for k in range(3)]
    soa_out = [np.empty(PAIRS) for _ in range(3)]

    def c_eval_soa(threads):
        assert lib.cbrdf_model_eval_batch_soa(handle, PAIRS, *soa_in, *soa_out, threads) == 0

    # A renderer's record (position, direction): the directions a strided view, copied by Python.
    record = np.zeros((PAIRS, 6))
    record[:, 3:] = wi

    def c_sample(threads):
        assert lib.cbrdf_model_sample_batch(handle, DRAWS, draw_wo, u, s_wi, s_pdf, s_w,
                                            threads) == 0

    cases = [
        ("float32 eval", PAIRS, lambda t: model.eval(wi32, wo32, threads=t), c_eval32,
         "BM_CApi_EvalBatchF32"),
        ("float64 eval", PAIRS, lambda t: model.eval(wi, wo, threads=t), c_eval,
         "BM_CApi_EvalBatch"),
        ("sample", DRAWS, lambda t: model.sample(wo=draw_wo, u=u, threads=t), c_sample,
         "BM_CApi_SampleBatch"),
    ]
    # The same results on both sides (and the sampler's tables built before timing).
    c_eval32(0)
    assert np.array_equal(model.eval(wi32, wo32), rgb32)
    c_sample(0)
    assert np.array_equal(model.sample(draw_wo, u)[2], s_w)

    # Where the cost goes besides the kernels: a strided float64 wi (copied once by Python)
    # against the contiguous call, and C's interleaved (AoS) batch against its SoA form.
    cases += [
        ("float64 strided", PAIRS, lambda t: model.eval(record[:, 3:], wo, threads=t), c_eval,
         None),
        ("C SoA / AoS", PAIRS, c_eval_soa, c_eval, None),
    ]
    rows = []
    for threads in (1, 0):
        for name, n, py_call, c_call, bench_name in cases:
            py = [float("inf")] * 2
            c = [float("inf")] * 2
            for _ in range(a.repeats):  # taking turns
                py = [min(x, y) for x, y in zip(py, timed(lambda: py_call(threads)))]
                c = [min(x, y) for x, y in zip(c, timed(lambda: c_call(threads)))]
            rows.append({"case": name, "threads": threads or cbrdf.thread_limit(), "n": n,
                         "python_ns": py[0] * 1e9 / n, "c_ns": c[0] * 1e9 / n,
                         "ratio": py[0] / c[0], "cpu_ratio": py[1] / c[1],
                         "cbrdf_bench_ns": bench.get(bench_name, (None,))[0] if threads == 1 else None,
                         "cbrdf_bench_cpu_ns": bench.get(bench_name, (None, None))[1] if threads == 1 else None})
    lib.cbrdf_model_free.argtypes = [ctypes.c_void_p]
    lib.cbrdf_model_free(handle)

    if a.json:
        print(json.dumps({"material": a.material, "rows": rows}, indent=1))
        return
    print(f"{a.material} (bench-default.cbrdf), best of {a.repeats}, ns per pair or draw")
    print("Python/C: wall time; cpu: the process's CPU time (all threads); cbrdf_bench: its C "
          "figure, wall and CPU")
    print(f"{'case':<16} {'threads':>7} {'n':>6} {'Python':>8} {'C':>8} {'Python/C':>9} "
          f"{'cpu':>6} {'cbrdf_bench':>11} {'(cpu)':>6}")
    for r in rows:
        b = f"{r['cbrdf_bench_ns']:.1f}" if r["cbrdf_bench_ns"] else "-"
        bc = f"{r['cbrdf_bench_cpu_ns']:.1f}" if r["cbrdf_bench_cpu_ns"] else "-"
        print(f"{r['case']:<16} {r['threads']:>7} {r['n']:>6} {r['python_ns']:>8.1f} "
              f"{r['c_ns']:>8.1f} {r['ratio']:>9.2f} {r['cpu_ratio']:>6.2f} {b:>11} {bc:>6}")


if __name__ == "__main__":
    main()
