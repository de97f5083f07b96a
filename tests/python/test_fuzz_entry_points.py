# SPDX-License-Identifier: MIT
"""A random-input campaign over the Python module's entry points (issue 31).

libFuzzer has no practical harness for a CPython extension, so this drives the entry points with
seeded random inputs: mutated .cbrdf and MERL bytes (plain and through strided views), arguments
of every Python and NumPy kind, shapes and dtypes. Every call must return or raise cbrdf.Error,
ValueError or TypeError; any other exception is a failure, and the campaign runs in a child
process, so a crash (the segfaults of issue 31) fails the test with the seed that found it.
Longer campaigns: CBRDF_PY_FUZZ_ROUNDS=N (default 150 per entry point).
"""
import os
import subprocess
import sys
from pathlib import Path

import cbrdf
from conftest import REPO

CAMPAIGN = r'''
import sys, random, numpy as np, cbrdf
rounds, golden_dir, merl_path, seed = int(sys.argv[1]), sys.argv[2], sys.argv[3], int(sys.argv[4])
rng = random.Random(seed)
nrng = np.random.default_rng(seed)
ALLOWED = (cbrdf.Error, ValueError, TypeError, OverflowError)
goldens = [open(p, "rb").read() for p in sorted(__import__("glob").glob(golden_dir + "/*.cbrdf"))]
merl = open(merl_path, "rb").read()
calls = {"ok": 0, "refused": 0}

def attempt(name, fn):
    try:
        fn()
        calls["ok"] += 1
    except ALLOWED:
        calls["refused"] += 1
    except BaseException as e:
        print(f"FAIL {name}: {type(e).__name__}: {e}", flush=True)
        raise SystemExit(3)

def mutate(b):
    b = bytearray(b)
    for _ in range(rng.randint(1, 8)):
        kind = rng.randrange(4)
        if kind == 0 and b:
            b[rng.randrange(len(b))] ^= 1 << rng.randrange(8)
        elif kind == 1 and b:
            del b[rng.randrange(len(b)):]
        elif kind == 2:
            at = rng.randrange(len(b) + 1)
            b[at:at] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        elif b:
            at = rng.randrange(len(b))
            b[at:at + 8] = rng.choice([b"\xff" * 8, b"\x00" * 8, np.float64(np.nan).tobytes(),
                                       np.float64(-1e308).tobytes()])
    return bytes(b)

def strided(b):
    wide = np.zeros(2 * len(b) + 1, np.uint8)
    wide[1::2] = np.frombuffer(b, np.uint8) if b else wide[1::2]
    return rng.choice([memoryview(wide)[1::2], memoryview(np.frombuffer(b, np.uint8))[::-1],
                       bytearray(b), b])

WEIRD = [None, "a", "", "0", 1.7, float("nan"), float("inf"), -1, 0, 2**63, -2**70, True,
         object(), [1, 2], (0, 0, 1), {}, 1 + 2j, np.float32(0.5), np.int8(-3), np.uint64(2**64 - 1),
         np.array([]), np.zeros((2, 3)), np.array(["x"]), b"\x00", "out\x00.bin"]

def direction_array():
    n = rng.choice([0, 1, 3, 17])
    shape = rng.choice([(n, 3), (3,), (n, 2), (n, 3, 1), (n,)])
    dtype = rng.choice([np.float64, np.float32, np.int64, np.complex128, np.bool_, object])
    a = nrng.normal(size=shape)
    if a.ndim and a.shape[-1] == 3:
        a = a / np.maximum(np.linalg.norm(a, axis=-1, keepdims=True), 1e-300)
        a[..., 2] = np.abs(a[..., 2])
    try:
        a = a.astype(dtype)
    except Exception:
        pass
    if rng.random() < 0.2:
        a = a[::-1] if a.ndim else a
    return rng.choice([a, rng.choice(WEIRD)])

table0 = cbrdf._cbrdf._Table.sample("lambertian")
models = []
for b in goldens:
    models.append(cbrdf.decode(b))
for r in range(rounds):
    g = rng.choice(goldens)
    attempt("decode", lambda: cbrdf.decode(strided(mutate(g))))
    attempt("info", lambda: cbrdf.info(strided(mutate(g))))
    attempt("read_merl", lambda: cbrdf.read_merl(strided(mutate(merl[:rng.choice([12, 4096, len(merl)])]))))
    m = rng.choice(models)
    attempt("eval", lambda: m.eval(direction_array(), direction_array(),
                                   rng.choice([0, 1, -1, 2.5, None, 300])))
    attempt("sample", lambda: m.sample(direction_array(), rng.choice([nrng.random((3, 2)),
                                       np.array([0.5, 0.5]), rng.choice(WEIRD)])))
    attempt("sample_pdf", lambda: m.sample_pdf(direction_array(), direction_array()))
    attempt("bin_value", lambda: m.bin_value(*[rng.choice(WEIRD + [0, 1, 89, np.arange(3)])
                                              for _ in range(4)]))
    key = rng.choice(["bits", "components", "slices", "family", "loss", "level", "placement",
                      "threads", "target_bytes", "target_psnr", "max_error", "mixture_copulas",
                      "source_name", "lossless"])
    # Only arguments refused before fitting: a weird value, or a target with a residual option.
    attempt("encode", lambda: cbrdf.encode(table0, **{key: rng.choice(WEIRD[:-3])},
                                           target_bytes=1e5, max_error=0.01))
    attempt("write_merl", lambda: cbrdf.write_merl(rng.choice(WEIRD), rng.choice(WEIRD)))
    if rng.random() < 0.05:
        attempt("uninitialized", lambda: getattr(cbrdf.Model.__new__(cbrdf.Model),
                                                 rng.choice(["info", "bits", "nbytes"])))
print("done", calls, flush=True)
'''


def test_random_inputs_never_crash_or_raise_unexpected_errors(work):
    rounds = int(os.environ.get("CBRDF_PY_FUZZ_ROUNDS", "150"))
    env = dict(os.environ)
    # The folder this cbrdf was imported from (PYTHONPATH may be relative to another cwd).
    package = str(Path(cbrdf.__file__).resolve().parents[1])
    env["PYTHONPATH"] = package + os.pathsep + env.get("PYTHONPATH", "")
    for seed in (1, 2):
        p = subprocess.run([sys.executable, "-c", CAMPAIGN, str(rounds),
                            str(REPO / "tests" / "data" / "golden"), str(work / "plastic.binary"),
                            str(seed)], capture_output=True, text=True, env=env, timeout=900,
                           cwd=work)
        assert p.returncode == 0, f"seed {seed}: exit {p.returncode}\n{p.stdout[-3000:]}\n" \
                                  f"{p.stderr[-3000:]}"
        assert "done" in p.stdout
