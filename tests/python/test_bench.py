# SPDX-License-Identifier: MIT
"""Benchmark-like checks: a batch of 10^6 evaluations against a Python loop, and RSS over 10,000
open/close cycles. Both print their numbers; the bounds are generous so that load from other
processes does not fail them."""
import gc
import os
import time

import numpy as np

import cbrdf

MIN_SPEEDUP = 20.0  # the requirement; typically measured well above it
MAX_RSS_GROWTH = 8 << 20  # bytes over 10,000 cycles after a warm-up


def report(capsys, text):
    with capsys.disabled():
        print(f"\n[cbrdf bench] {text}")


def test_batch_is_much_faster_than_a_python_loop(model, capsys):
    rng = np.random.default_rng(5)
    n = 1_000_000
    wi = rng.normal(size=(n, 3))
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo = rng.normal(size=(n, 3))
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    model.eval(wi[:1000], wo[:1000])  # warm-up
    best_batch = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        rgb = model.eval(wi, wo)
        best_batch = min(best_batch, time.perf_counter() - t0)
    assert rgb.shape == (n, 3)
    # The Python loop over single evaluations, on a subset, extrapolated to n.
    m = 20_000
    sub_i, sub_o = wi[:m], wo[:m]
    best_loop = float("inf")
    for _ in range(2):
        t0 = time.perf_counter()
        for k in range(m):
            model.eval_pair(sub_i[k], sub_o[k])
        best_loop = min(best_loop, (time.perf_counter() - t0) * n / m)
    ratio = best_loop / best_batch
    report(capsys, f"10^6 evaluations: batch {best_batch * 1e3:.1f} ms "
                   f"({best_batch * 1e9 / n:.0f} ns/pair, {cbrdf.thread_limit()} threads), "
                   f"Python loop (extrapolated from {m}) {best_loop:.2f} s: {ratio:.0f}x")
    assert ratio >= MIN_SPEEDUP


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_no_leak_over_10000_open_close_cycles(work, tmp_path, capsys):
    # A fully measured table: decoding a real MERL mask costs ~5 ms per file in the library
    # (decode_mask_chunk), which would make 10,000 cycles take a minute; this file takes ~1 ms.
    full = np.nan_to_num(np.asarray(cbrdf.read_merl(work / "plastic.binary")), nan=0.0)
    data = cbrdf.encode(full, bits=8, slices=3)
    path = tmp_path / "full.cbrdf"
    path.write_bytes(data)
    wi = np.array([[0.0, 0.6, 0.8]])
    wo = np.array([[0.0, 0.0, 1.0]])

    def cycle(k):
        m = cbrdf.decode(path if k % 2 else data)
        m.eval(wi, wo)
        if k % 20 == 0:
            _ = m.info
        m.close()
        try:  # an error path too
            cbrdf.decode(data[: 100 + k % 50])
        except cbrdf.Error:
            pass

    for k in range(500):
        cycle(k)
    gc.collect()
    before = rss_bytes()
    t0 = time.perf_counter()
    for k in range(10_000):
        cycle(k)
    gc.collect()
    growth = rss_bytes() - before
    report(capsys, f"10,000 open/eval/close cycles in {time.perf_counter() - t0:.1f} s: "
                   f"RSS {before / 2**20:.1f} MiB -> {(before + growth) / 2**20:.1f} MiB "
                   f"({growth / 1024:+.0f} KiB)")
    assert growth < MAX_RSS_GROWTH
