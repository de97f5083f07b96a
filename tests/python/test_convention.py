# SPDX-License-Identifier: MIT
"""One (wi, wo) convention and rejected draws safe to pass on (issue 42), as Python sees them.

Model.sample_pdf(wi, wo) is the sampler's density in eval's order; Model.pdf(wo, wi) warns and
returns the same values. A rejected draw's wi, (0, 0, 0), evaluates to 0 in eval and the pdfs.
The pairs and C's f and pdf come from tests/convention/convention_reference.c (the C API), so
Python's answers are compared with C's; the rejected draws run over the 20 real materials that
tests/convention/make-real-models.sh encodes (skipped without ../shared)."""
import os
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

import cbrdf
from conftest import BUILD, CLI, REPO

GOLDEN = REPO / "tests" / "data" / "golden"
PAIR_MODELS = ["v1.3-frank6-b10", "v1.3-mixture3-b12", "v1.3-residual-frank6-b10"]
REFERENCE = BUILD / "tests" / "convention" / "convention_reference"
DEPRECATION = ("Model.pdf(wo, wi) is deprecated: use Model.sample_pdf(wi, wo), whose arguments "
               "are in the (wi, wo) order of eval")


def directions(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


@pytest.fixture(scope="module")
def golden():
    return cbrdf.Model(GOLDEN / "v1.3-mixture3-b12.cbrdf")


def pairs(n=500, seed=7):
    rng = np.random.default_rng(seed)
    return (directions(rng.uniform(0, 89, n), rng.uniform(0, 360, n)),
            directions(rng.uniform(0, 89, n), rng.uniform(0, 360, n)))


def test_pdf_warns_with_the_new_name_and_returns_sample_pdf_swapped(golden):
    wi, wo = pairs()
    with pytest.warns(DeprecationWarning) as caught:
        old = golden.pdf(wo, wi)
    assert [str(w.message) for w in caught] == [DEPRECATION]
    assert Path(caught[0].filename).name == Path(__file__).name  # points at the caller's line
    new = golden.sample_pdf(wi, wo)
    assert np.array_equal(old, new)
    # The density is not symmetric, so equal values prove the arguments were swapped.
    assert np.mean(new != golden.sample_pdf(wo, wi)) > 0.9
    with pytest.warns(DeprecationWarning):
        assert golden.pdf(wo[0], wi[0]) == new[0]  # single vectors alike
    # The same values as before the rename: the pdf each draw reports, with (wo, wi).
    u = np.random.default_rng(3).random((len(wo), 2))
    drawn, pdf, _ = golden.sample(wo, u)
    ok = pdf > 0
    with pytest.warns(DeprecationWarning):
        assert np.array_equal(golden.pdf(wo[ok], drawn[ok]), pdf[ok])


def test_sample_pdf_does_not_warn(golden):
    wi, wo = pairs(50)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        p = golden.sample_pdf(wi, wo, threads=1)
        golden.sample_pdf(wi=wi[0], wo=wo[0])
    assert p.shape == (50,) and np.all(p > 0)


def test_zero_vector_rows_evaluate_to_zero(golden):
    wi, wo = pairs(64)
    wi[::4] = 0.0  # rejected draws
    wo[1::8] = 0.0
    wo[2::8] = -0.0
    zero = np.all(wi == 0, axis=1) | np.all(wo == 0, axis=1)
    rgb = golden.eval(wi, wo)
    assert not np.isnan(rgb).any() and np.all(rgb[zero] == 0) and np.all(rgb[~zero] > 0)
    f32 = golden.eval(wi.astype(np.float32), wo.astype(np.float32))
    assert f32.dtype == np.float32 and np.all(f32[zero] == 0)
    assert golden.eval_pair(np.zeros(3), wo[0]) == (0.0, 0.0, 0.0)
    p = golden.sample_pdf(wi, wo)
    assert np.all(p[zero] == 0) and np.all(p[~zero] > 0)
    with pytest.warns(DeprecationWarning):
        assert np.array_equal(golden.pdf(wo, wi), p)
    # Only exactly (0, 0, 0): anything else short of unit length is still refused, saying why.
    for bad in ([0.0, 0.0, 1e-3], [1e-200, 0.0, 0.0]):
        with pytest.raises(cbrdf.Error, match=r"or \(0, 0, 0\) \(a rejected draw\)"):
            golden.eval(np.array(bad), wo[0])
        with pytest.raises(cbrdf.Error, match="wo must be a finite unit vector"):
            golden.sample_pdf(wi[1], np.array(bad))
    # Sampling still refuses a zero wo, as the C API does (it is not a drawn direction).
    with pytest.raises(cbrdf.Error, match="wo must be a finite unit vector, not"):
        golden.sample(np.zeros(3), np.array([0.5, 0.5]))


@pytest.mark.parametrize("name", PAIR_MODELS)
def test_eval_and_sample_pdf_equal_c_on_the_same_pairs(name):
    if not REFERENCE.exists():
        pytest.skip(f"{REFERENCE} is not built")
    path = GOLDEN / f"{name}.cbrdf"
    out = subprocess.run([str(REFERENCE), "pairs", str(path)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    rows = np.loadtxt(out.stdout.splitlines())
    assert rows.shape[0] >= 300
    wi, wo, f, pdf = rows[:, 0:3], rows[:, 3:6], rows[:, 6:9], rows[:, 9]
    m = cbrdf.Model(path)
    np.testing.assert_allclose(m.eval(wi, wo), f, rtol=1e-12, atol=0)
    np.testing.assert_allclose(m.sample_pdf(wi, wo), pdf, rtol=1e-12, atol=0)
    # The pairs catch a swapped order: most of them change density when swapped.
    assert np.mean(np.abs(m.sample_pdf(wo, wi) - pdf) > 1e-6 * pdf) > 0.5


def real_models():
    """The 20 real materials encoded (make-real-models.sh, shared with ctest's fixture
    real_models and cached in the build tree), or skip without ../shared."""
    script = REPO / "tests" / "convention" / "make-real-models.sh"
    out_dir = BUILD / "real-models"
    run = subprocess.run([str(script), str(CLI), str(out_dir), str(REPO.parent / "shared"),
                          str(BUILD)], capture_output=True, text=True, env=dict(os.environ))
    assert run.returncode == 0, run.stderr
    if "SKIPPED" in run.stdout:
        pytest.skip(run.stdout.strip())
    return sorted(out_dir.glob("*.cbrdf"))


def test_rejected_draws_pass_straight_back_into_eval_and_sample_pdf():
    paths = real_models()
    assert len(paths) >= 20
    per_elevation = 100_000 // len(paths) // 16
    rng = np.random.default_rng(42)
    draws = rejected = 0
    for path in paths:
        m = cbrdf.Model(path)
        theta = np.repeat(np.linspace(0, 89, 16), per_elevation)
        wo = directions(theta, rng.uniform(0, 360, theta.size))
        wi, pdf, weight = m.sample(wo, rng.random((theta.size, 2)))
        f = m.eval(wi, wo)  # raised for the rejected draws before issue 42
        p = m.sample_pdf(wi, wo)
        assert not (np.isnan(f).any() or np.isnan(p).any() or np.isnan(pdf).any())
        bad = pdf == 0
        assert np.all(wi[bad] == 0) and np.all(f[bad] == 0) and np.all(p[bad] == 0)
        assert np.all(weight[bad] == 0)
        assert np.array_equal(p[~bad], pdf[~bad])
        draws += theta.size
        rejected += int(bad.sum())
    assert draws >= 99_000 and rejected > 0
