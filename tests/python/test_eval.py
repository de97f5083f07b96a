# SPDX-License-Identifier: MIT
"""Model.eval / sample / bin_value against the C++ evaluator, bit for bit."""
import ctypes

import numpy as np
import pytest

import cbrdf


def random_dirs(n, rng, upper=True):
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    if upper:
        v[:, 2] = np.abs(v[:, 2])
    return v


def test_batch_equals_single_evaluations_bitwise(model):
    rng = np.random.default_rng(1)
    wi, wo = random_dirs(2000, rng), random_dirs(2000, rng)
    rgb = model.eval(wi, wo)
    assert rgb.shape == (2000, 3) and rgb.dtype == np.float64
    single = np.array([model.eval_pair(a, b) for a, b in zip(wi, wo)])
    assert np.array_equal(rgb.view(np.uint64), single.view(np.uint64))
    # Threads do not change a bit (50,000 pairs are split over the pool).
    wi, wo = random_dirs(50000, rng), random_dirs(50000, rng)
    assert np.array_equal(model.eval(wi, wo), model.eval(wi, wo, threads=1))


def test_eval_equals_the_c_api_bitwise(model, work, decoder_lib):
    lib = decoder_lib
    lib.cbrdf_model_open_file.restype = ctypes.c_void_p
    lib.cbrdf_model_open_file.argtypes = [ctypes.c_char_p]
    lib.cbrdf_model_eval_batch.argtypes = [ctypes.c_void_p, ctypes.c_size_t] + [
        np.ctypeslib.ndpointer(np.float64, flags="C")] * 3 + [ctypes.c_int]
    lib.cbrdf_model_free.argtypes = [ctypes.c_void_p]
    h = lib.cbrdf_model_open_file(str(work / "plastic.cbrdf").encode())
    assert h
    try:
        rng = np.random.default_rng(2)
        wi, wo = random_dirs(5000, rng), random_dirs(5000, rng)
        ref = np.zeros((5000, 3))
        assert lib.cbrdf_model_eval_batch(h, 5000, wi, wo, ref, 0) == 0
    finally:
        lib.cbrdf_model_free(h)
    assert np.array_equal(model.eval(wi, wo).view(np.uint64), ref.view(np.uint64))


def test_float32_broadcast_and_horizon(model):
    rng = np.random.default_rng(3)
    wi, wo = random_dirs(1000, rng), random_dirs(1000, rng)
    f32 = model.eval(wi.astype(np.float32), wo.astype(np.float32))
    assert f32.dtype == np.float32 and f32.shape == (1000, 3)
    f64 = model.eval(wi.astype(np.float32).astype(np.float64), wo.astype(np.float32).astype(np.float64))
    np.testing.assert_allclose(f32, f64, rtol=2e-3, atol=1e-6 * f64.max())
    # Mixed precision goes through the float64 path; one (3,) vector broadcasts.
    assert model.eval(wi.astype(np.float32), wo).dtype == np.float64
    n = np.array([0.0, 0.0, 1.0])
    assert np.array_equal(model.eval(wi, n), model.eval(wi, np.tile(n, (1000, 1))))
    assert model.eval(n, n).shape == (3,)
    below = wi.copy()
    below[:, 2] *= -1
    below[:, 2] -= 1e-9
    below /= np.linalg.norm(below, axis=1, keepdims=True)
    assert not model.eval(below, wo).any()
    assert model.eval(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0, 3)


@pytest.mark.parametrize("wi", [
    [[0, 0, 2.0]], [[np.nan, 0, 1]], [[0, 0, np.inf]], np.full((5, 3), 1e-3), np.ones((4, 2)),
    np.ones((2, 3, 3)), "abc",
])
def test_bad_directions_raise(model, wi):
    with pytest.raises(cbrdf.Error) as e:
        model.eval(wi, [0, 0, 1.0])
    assert e.value.code == cbrdf.ErrorCode.INVALID_ARGUMENT
    with pytest.raises(cbrdf.Error):
        model.eval(np.tile([0, 0, 1.0], (3, 1)), np.tile([0, 0, 1.0], (4, 1)))


def test_bin_value_and_table(model):
    t = model.table()
    h, d, p = np.meshgrid(np.arange(0, 90, 7), np.arange(0, 90, 5), np.arange(0, 180, 11),
                          indexing="ij")
    for c in range(3):
        v = model.bin_value(c, h, d, p)
        assert v.shape == h.shape
        ref = t[c, h, d, p]
        m = ~np.isnan(ref)
        np.testing.assert_allclose(v[m], ref[m], rtol=1e-12, atol=0)
    assert isinstance(model.bin_value(0, 1, 2, 3), float)
    with pytest.raises(cbrdf.Error):
        model.bin_value(3, 0, 0, 0)
    with pytest.raises(cbrdf.Error):
        model.bin_value(0, 0, 0, 180)
    # At the bins' grid angles eval equals bin_value up to rounding (theta_h bin 0 excluded:
    # there h is the normal and every phi_d is the same configuration; theta_d bin 0 likewise,
    # where wi = wo).
    wi, wo = cbrdf.bin_directions(h, d, p)
    ok = (wi[..., 2] > 1e-6) & (wo[..., 2] > 1e-6) & (h > 0) & (d > 0)
    rgb = model.eval(wi[ok], wo[ok])
    for c in range(3):
        np.testing.assert_allclose(rgb[:, c], model.bin_value(c, h, d, p)[ok], rtol=1e-9,
                                   atol=1e-12)
    bh, bd, bp = cbrdf.nearest_bin(wi[ok], wo[ok])
    assert bh.dtype == np.int64 and bh.shape == rgb[:, 0].shape


def test_sample_and_pdf(model):
    rng = np.random.default_rng(4)
    wo = random_dirs(20000, rng)
    u = rng.random((20000, 2))
    wi, pdf, weight = model.sample(wo, u)
    assert wi.shape == (20000, 3) and pdf.shape == (20000,) and weight.shape == (20000, 3)
    ok = pdf > 0
    assert ok.mean() > 0.5
    np.testing.assert_allclose(np.linalg.norm(wi[ok], axis=1), 1, atol=1e-9)
    assert np.all(wi[ok, 2] > 0) and not wi[~ok].any() and not weight[~ok].any()
    np.testing.assert_allclose(model.sample_pdf(wi[ok], wo[ok]), pdf[ok], rtol=1e-9)
    f = model.eval(wi[ok], wo[ok])
    np.testing.assert_allclose(weight[ok], f * wi[ok, 2:3] / pdf[ok, None], rtol=1e-12)
    # Deterministic and thread-independent.
    wi1, pdf1, w1 = model.sample(wo, u, threads=1)
    assert np.array_equal(wi, wi1) and np.array_equal(pdf, pdf1)
    # The estimator of the albedo at normal incidence is finite and plausible.
    albedo = model.sample(np.tile([0, 0, 1.0], (20000, 1)), u)[2].mean(axis=0)
    assert np.all(np.isfinite(albedo)) and np.all(albedo > 0) and np.all(albedo < 1.5)
    with pytest.raises(cbrdf.Error):
        model.sample(wo[:2], [[np.nan, 0.5], [0.1, 0.1]])
