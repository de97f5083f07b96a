# SPDX-License-Identifier: MIT
"""cbrdf.sample_table(name) gives a built-in table; the old name cbrdf.sample(name) gives the same
table with a DeprecationWarning naming the new one; Model.sample called with u split in two says
what it takes."""
import warnings

import numpy as np
import pytest

import cbrdf

DEPRECATION = ("cbrdf.sample(name) is deprecated: use cbrdf.sample_table(name); "
               "Model.sample draws directions")


def test_sample_table_is_the_table_and_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        t = cbrdf.sample_table("plastic")
        stored = cbrdf.sample_table("plastic", units="stored")
    assert t.shape == cbrdf.SHAPE and np.nanmax(t) > 0
    assert stored.shape == cbrdf.SHAPE
    assert "sample_table" in cbrdf.__all__ and "sample" in cbrdf.__all__


def test_the_old_name_warns_and_gives_the_same_table():
    with pytest.warns(DeprecationWarning) as record:
        old = cbrdf.sample("plastic")
    assert [str(w.message) for w in record] == [DEPRECATION]
    assert record[0].filename == __file__  # the caller's line, not the package's
    assert np.array_equal(old, cbrdf.sample_table("plastic"), equal_nan=True)
    with pytest.warns(DeprecationWarning, match="sample_table"):
        with pytest.raises(cbrdf.Error, match=r"^sample: name: "):
            cbrdf.sample("no such material")


def test_sample_with_u_split_in_two_says_what_it_takes(model):
    rng = np.random.default_rng(3)
    wo = np.tile([0.0, 0.6, 0.8], (5, 1))
    u1, u2 = rng.random(5), rng.random(5)
    with pytest.raises(cbrdf.ArgumentTypeError) as e:
        model.sample(wo, u1, u2)
    text = str(e.value)
    assert "Model.sample takes (wo, u, threads=0)" in text
    assert "np.stack([u1, u2], axis=-1)" in text and "cbrdf.sample_table(name)" in text
    assert "only integer scalar arrays" not in text
    # The right call, and threads given by position as before.
    wi, pdf, weight = model.sample(wo, np.stack([u1, u2], axis=-1), 1)
    assert wi.shape == (5, 3) and np.all(pdf > 0)
