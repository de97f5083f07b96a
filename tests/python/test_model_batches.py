# SPDX-License-Identifier: MIT
"""Model.eval (float32 and float64) and Model.sample go through the library's batch kernels: their
results equal the C API's single calls (cbrdf_model_eval_f32, cbrdf_model_eval,
cbrdf_model_sample) bit for bit, whatever the layout of the caller's arrays (C-contiguous,
strided, Fortran order, one row broadcast)."""
import ctypes

import numpy as np
import pytest

import cbrdf

F32 = np.ctypeslib.ndpointer(np.float32, flags="C")
F64 = np.ctypeslib.ndpointer(np.float64, flags="C")


@pytest.fixture(scope="module")
def c_model(work, decoder_lib):
    """The C API's handle on the same file as the `model` fixture."""
    lib = decoder_lib
    lib.cbrdf_model_open_file.restype = ctypes.c_void_p
    lib.cbrdf_model_open_file.argtypes = [ctypes.c_char_p]
    lib.cbrdf_model_free.argtypes = [ctypes.c_void_p]
    lib.cbrdf_model_eval.argtypes = [ctypes.c_void_p, F64, F64, F64]
    lib.cbrdf_model_eval_f32.argtypes = [ctypes.c_void_p, F32, F32, F32]
    lib.cbrdf_model_sample.argtypes = [ctypes.c_void_p, F64, ctypes.c_double, ctypes.c_double,
                                       F64, ctypes.POINTER(ctypes.c_double), F64]
    h = lib.cbrdf_model_open_file(str(work / "plastic.cbrdf").encode())
    assert h
    yield lib, h
    lib.cbrdf_model_free(h)


def directions(n, rng, dtype=np.float64):
    """Unit vectors, a tenth of them below the horizon."""
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    v[:, 2] = np.abs(v[:, 2]) * np.where(rng.random(n) < 0.1, -1, 1)
    return v.astype(dtype)


def c_eval(c_model, wi, wo):
    lib, h = c_model
    f32 = wi.dtype == np.float32
    call = lib.cbrdf_model_eval_f32 if f32 else lib.cbrdf_model_eval
    out = np.zeros((len(wi), 3), wi.dtype)
    rgb = np.zeros(3, wi.dtype)
    for k in range(len(wi)):
        assert call(h, np.ascontiguousarray(wi[k]), np.ascontiguousarray(wo[k]), rgb) == 0
        out[k] = rgb
    return out


def same_bits(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_eval_equals_the_c_single_calls_bitwise(model, c_model, dtype):
    rng = np.random.default_rng(11)
    n = 1500  # more than the kernels' blocks of 32 pairs, with a partial block
    wi, wo = directions(n, rng, dtype), directions(n, rng, dtype)
    ref = c_eval(c_model, wi, wo)
    assert np.count_nonzero(ref) > n  # not all below the horizon
    assert same_bits(model.eval(wi, wo), ref)
    assert same_bits(model.eval(wi, wo, threads=1), ref)
    # One row broadcast against the batch, either side.
    assert same_bits(model.eval(wi, wo[7]), c_eval(c_model, wi, np.tile(wo[7], (n, 1))))
    assert same_bits(model.eval(wi[3], wo), c_eval(c_model, np.tile(wi[3], (n, 1)), wo))
    assert same_bits(model.eval(wi[3], wo[7]), c_eval(c_model, wi[3:4], wo[7:8])[0])


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_eval_of_any_layout_equals_the_contiguous_call(model, dtype):
    rng = np.random.default_rng(12)
    wi, wo = directions(4000, rng, dtype), directions(4000, rng, dtype)
    ref = model.eval(wi[::2], wo[::2].copy())
    assert not wi[::2].flags.c_contiguous
    assert same_bits(model.eval(wi[::2], wo[::2]), ref)
    fortran = np.asfortranarray(wi[::2])
    assert same_bits(model.eval(fortran, wo[::2]), ref)
    # Columns of a wider array (a renderer's record of position and direction).
    wide = np.zeros((2000, 6), dtype)
    wide[:, 3:] = wi[::2]
    assert same_bits(model.eval(wide[:, 3:], wo[::2]), ref)


def c_sample(c_model, wo, u):
    lib, h = c_model
    n = len(wo)
    wi, pdf, weight = np.zeros((n, 3)), np.zeros(n), np.zeros((n, 3))
    w, p, g = np.zeros(3), ctypes.c_double(), np.zeros(3)
    for k in range(n):
        assert lib.cbrdf_model_sample(h, np.ascontiguousarray(wo[k]), u[k, 0], u[k, 1], w,
                                      ctypes.byref(p), g) == 0
        wi[k], pdf[k], weight[k] = w, p.value, g
    return wi, pdf, weight


def test_sample_equals_the_c_single_calls_bitwise(model, c_model):
    rng = np.random.default_rng(13)
    n = 3000  # several of the sampler's chunks of 1024 draws, the last one partial
    wo = directions(n, rng)
    u = rng.random((n, 2))
    u[:20] = [[-0.5, 0.3], [1.0, 0.2], [0.4, 1.5], [0.0, 0.0]] * 5  # clamped into [0, 1)
    ref = c_sample(c_model, wo, u)
    rejected = ref[1] == 0
    assert 0.05 < rejected.mean() < 0.5  # wo below the horizon (a tenth), wi reflected below it
    for threads in (0, 1):
        got = model.sample(wo, u, threads=threads)
        for a, b in zip(got, ref):
            assert same_bits(a, b)
    # Rejected rows are all zero.
    wi, pdf, weight = model.sample(wo, u)
    assert not wi[rejected].any() and not weight[rejected].any()
    # One row of wo, or of u, broadcast; strided inputs.
    for a, b in zip(model.sample(wo[5], u), c_sample(c_model, np.tile(wo[5], (n, 1)), u)):
        assert same_bits(a, b)
    for a, b in zip(model.sample(wo, u[9]), c_sample(c_model, wo, np.tile(u[9], (n, 1)))):
        assert same_bits(a, b)
    for a, b in zip(model.sample(wo[::3], np.asfortranarray(u[::3])), c_sample(c_model, wo[::3],
                                                                             u[::3])):
        assert same_bits(a, b)
    one = model.sample(wo[5], u[9])
    assert one[0].shape == (3,) and one[1].shape == () and one[2].shape == (3,)
    for a, b in zip(one, c_sample(c_model, wo[5:6], u[9:10])):
        assert same_bits(a, b.reshape(a.shape))


def test_bad_batches_keep_their_messages(model):
    wo = np.tile([0.0, 0.6, 0.8], (4, 1))
    with pytest.raises(cbrdf.Error, match=r"u\[1\] must be two finite numbers in \[0, 1\)"):
        model.sample(wo, [[0.5, 0.5], [np.nan, 0.5], [0.1, 0.1], [0.2, 0.2]])
    bad = wo.copy()
    bad[2] = [0, 0, 2.0]
    with pytest.raises(cbrdf.Error, match=r"wo\[2\] must be a finite unit vector"):
        model.sample(bad, [0.5, 0.5])
    with pytest.raises(cbrdf.Error, match=r"wi\[2\] must be a finite unit vector"):
        model.eval(bad.astype(np.float32), wo.astype(np.float32))


def test_a_broadcast_row_over_many_runs_equals_the_tiled_batch(model):
    # More rows than one block of a broadcast row's copies (32,768), the last run partial.
    rng = np.random.default_rng(14)
    n = 70_001
    wi, wo = directions(n, rng), directions(1, rng)[0]
    wo[2] = abs(wo[2]) + 0.1
    wo /= np.linalg.norm(wo)
    tiled = np.tile(wo, (n, 1))
    for dtype in (np.float32, np.float64):
        assert same_bits(model.eval(wi.astype(dtype), wo.astype(dtype)),
                         model.eval(wi.astype(dtype), tiled.astype(dtype)))
    u = rng.random((n, 2))
    for a, b in zip(model.sample(wo, u), model.sample(tiled, u)):
        assert same_bits(a, b)
    for a, b in zip(model.sample(wi[:n // 2], u[5]), model.sample(wi[:n // 2],
                                                                  np.tile(u[5], (n // 2, 1)))):
        assert same_bits(a, b)
