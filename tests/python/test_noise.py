# SPDX-License-Identifier: MIT
"""cbrdf.estimate_noise: the noise estimate of `cbrdf info`, on a smooth sample and the same table
with known multiplicative noise."""
import numpy as np

import cbrdf
from conftest import cli_json


def test_smooth_sample_is_noise_free(work):
    e = cbrdf.estimate_noise(work / "plastic.binary")
    assert not e["noisy"]
    assert max(e["sigma"].values()) < 0.002
    assert e["psnr_ceiling_tonemapped"] == 100.0


def test_injected_noise_is_measured_and_matches_info(work, tmp_path):
    t = cbrdf.read_merl(work / "plastic.binary")
    rng = np.random.default_rng(3)
    noisy = np.where(t >= 0, t * np.exp(0.04 * rng.standard_normal(t.shape)), t)
    e = cbrdf.estimate_noise(noisy)
    assert e["noisy"]
    for s in e["sigma"].values():
        assert abs(s - 0.04) < 0.004
    assert len(e["bands"]) == 6
    assert e["bands"][-1]["theta_d_end"] == 90
    assert abs(e["grazing_growth"] - 1) < 0.2
    assert 20 < e["psnr_ceiling_tonemapped"] < 100
    path = tmp_path / "noisy.binary"
    cbrdf.write_merl(path, noisy)
    assert cbrdf.info(path)["noise"] == e
    assert cli_json("info", "--json", path)["noise"] == e
