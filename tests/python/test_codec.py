# SPDX-License-Identifier: MIT
"""encode / decode / info against the command's output; errors on damaged files."""
import json
import random

import numpy as np
import pytest

import cbrdf
from conftest import cli_json, run_cli


def test_encode_path_is_byte_identical_to_the_command(work):
    data = cbrdf.encode(work / "plastic.binary", bits=10)
    assert isinstance(data, bytes)
    assert data == (work / "plastic.cbrdf").read_bytes()


def test_encode_array_is_byte_identical_with_the_source_name(work):
    t = cbrdf.read_merl(work / "plastic.binary")
    data = cbrdf.encode(t, bits=10, source_name="plastic.binary")
    assert data == (work / "plastic.cbrdf").read_bytes()


def test_encode_options_match_the_command(work, tmp_path):
    out = tmp_path / "k2.cbrdf"
    run_cli("encode", work / "plastic.binary", "-o", out, "--bits", "8", "--slices", "3",
            "--components", "2", "--family", "auto", "--loss", "cosine", "--level", "5",
            "--no-metrics")
    data = cbrdf.encode(str(work / "plastic.binary"), bits=8, slices=3, components=2,
                        family="auto", loss="cosine", level=5)
    assert data == out.read_bytes()
    m = cbrdf.decode(data)
    # A mixture in the 1.3 coding (written where smaller since issue 28; 1.1 in the 1.2 coding).
    assert m.version == (1, 3) and m.bits == 8 and len(m.slices) == 3
    assert all(len(c.components) == 2 for s in m.slices for c in s.channels)


def test_mixture_copulas_at_independence_match_the_command(work, tmp_path):
    out = tmp_path / "k2i.cbrdf"
    run_cli("encode", work / "plastic.binary", "-o", out, "--bits", "8", "--slices", "3",
            "--components", "2", "--mixture-copulas", "independence", "--no-metrics")
    data = cbrdf.encode(str(work / "plastic.binary"), bits=8, slices=3, components=2,
                        mixture_copulas="independence")
    assert data == out.read_bytes()
    m = cbrdf.decode(data)
    mixtures = [c for s in m.slices for c in s.channels if len(c.components) == 2]
    assert mixtures and all(k.theta == 0.0 for c in mixtures for k in c.components)
    fitted = cbrdf.encode(str(work / "plastic.binary"), bits=8, slices=3, components=2)
    # Not larger: in the 1.3 coding parameters are fixed-size binary32 (BASE), so copulas at
    # independence no longer save the bytes they saved under zstd in 1.2 (issue 28).
    assert len(data) <= len(fitted)
    with pytest.raises(cbrdf.Error, match="^mixture_copulas= .*'some'"):
        cbrdf.encode(work / "plastic.binary", mixture_copulas="some")


def test_format_version_and_metadata_match_the_command(work, tmp_path):
    for version, meta, want in (("1.2", "full", (1, 0)), ("1.3", "none", (1, 3)),
                                ("auto", "short", (1, 3))):
        out = tmp_path / f"v{version}-{meta}.cbrdf"
        run_cli("encode", work / "plastic.binary", "-o", out, "--bits", "10",
                "--format-version", version, "--metadata", meta, "--no-metrics")
        data = cbrdf.encode(work / "plastic.binary", bits=10, format_version=version,
                            metadata=meta)
        assert data == out.read_bytes()
        assert cbrdf.decode(data).version == want
        tags = [c["tag"] for c in cbrdf.info(data)["chunks"]]
        assert ("mETA" in tags) == (meta != "none")
    # The keywords' defaults are the command's.
    assert cbrdf.encode(work / "plastic.binary", bits=10) == (work / "plastic.cbrdf").read_bytes()
    with pytest.raises(cbrdf.Error, match="format_version") as e:
        cbrdf.encode(work / "plastic.binary", format_version="1.4")
    assert e.value.exit_code == 2
    with pytest.raises(cbrdf.Error, match="metadata") as e:
        cbrdf.encode(work / "plastic.binary", metadata="long")
    assert e.value.exit_code == 2


def test_default_bits_are_chosen_from_the_data_as_the_command_does(work, tmp_path):
    out = tmp_path / "auto.cbrdf"
    run_cli("encode", work / "plastic.binary", "-o", out, "--no-metrics")
    data = cbrdf.encode(work / "plastic.binary")
    assert data == out.read_bytes()
    assert data == cbrdf.encode(work / "plastic.binary", bits="auto")
    assert 6 <= cbrdf.decode(data).bits <= 16
    with pytest.raises(cbrdf.Error, match="^bits= .*auto, not 'most'"):
        cbrdf.encode(work / "plastic.binary", bits="most")


def test_decoded_table_is_byte_identical_to_cbrdf_decode(work, model, tmp_path):
    expected = (work / "back.binary").read_bytes()
    t = model.table()
    cbrdf.write_merl(tmp_path / "a.binary", t)
    assert (tmp_path / "a.binary").read_bytes() == expected
    model.write_merl(tmp_path / "b.binary")
    assert (tmp_path / "b.binary").read_bytes() == expected
    assert cbrdf.merl_bytes(model.table(units="stored"), units="stored") == expected
    back = cbrdf.read_merl(work / "back.binary")
    assert np.array_equal(np.asarray(back), np.asarray(t), equal_nan=True)


def test_info_equals_cbrdf_info_json(work, model):
    for name in ("plastic.cbrdf", "plastic.binary"):
        path = str(work / name)
        assert cbrdf.info(path) == cli_json("info", "--json", path)
    assert model.info == cli_json("info", "--json", str(work / "plastic.cbrdf"))
    data = (work / "plastic.cbrdf").read_bytes()
    assert cbrdf.decode(data).info == dict(model.info, file=None) == cbrdf.info(data)


def test_residual_layer_matches_the_command_and_keeps_its_bound(work, tmp_path):
    out = tmp_path / "e.cbrdf"
    run_cli("encode", work / "plastic.binary", "-o", out, "--bits", "8", "--max-error", "0.02",
            "--no-metrics")
    data = cbrdf.encode(work / "plastic.binary", bits=8, max_error=0.02)
    assert data == out.read_bytes()
    info = cbrdf.info(data)
    assert info == dict(cli_json("info", "--json", str(out)), file=None)
    assert info["version"] == [1, 3]  # the 1.3 coding with a residual layer (issue 28)
    assert info["residual"]["mode"] == 0 and info["residual"]["max_error"] == 0.02
    assert 0 < info["residual"]["stored_bytes"] < info["bytes"]
    assert info["residual"]["coding"] in (0, 1, 2, 3)  # spec 4.6's predictor byte
    src = cbrdf.read_merl(work / "plastic.binary", units="stored")
    dec = cbrdf.decode(data).table(units="stored")
    measured = src >= 0
    assert np.array_equal(np.isnan(dec) | (dec < 0), ~measured)
    k = info["residual"]["knee"]
    err = np.abs(np.log1p(dec[measured] / k) - np.log1p(src[measured] / k))
    assert err.max() <= 0.02 * (1 + 1e-9)
    assert "residual" not in cbrdf.info(work / "plastic.cbrdf")


def test_lossless_decodes_to_the_source_bit_for_bit(work):
    data = cbrdf.encode(work / "plastic.binary", bits=8, lossless=True)
    assert cbrdf.info(data)["residual"]["mode"] == 1
    assert "coding" not in cbrdf.info(data)["residual"]  # the exact table has no codes
    back = cbrdf.merl_bytes(cbrdf.decode(data).table(units="stored"), units="stored")
    assert back == (work / "plastic.binary").read_bytes()


@pytest.mark.parametrize("kwargs, message", [
    (dict(max_error=1e-7), "^max_error= must be from 1e-06 to 16"),
    (dict(max_error=float("nan")), "^max_error= must be from 1e-06 to 16"),
    (dict(max_error=-1), "^max_error= must be from 1e-06 to 16"),
    (dict(max_error=0.01, lossless=True), "exclude each other"),
])
def test_residual_options_are_checked(work, kwargs, message):
    with pytest.raises(cbrdf.Error, match=message) as e:
        cbrdf.encode(work / "plastic.binary", **kwargs)
    assert e.value.exit_code == 2


def test_slices_carry_families_and_parameters(model):
    info = model.info
    assert len(model.slices) == len(info["slices"])
    for s, js in zip(model.slices, info["slices"]):
        assert [s.theta_d_begin, s.theta_d_end] == js["theta_d_bins"]
        for ch, jc in zip(s.channels, js["channels"]):
            assert (ch.family, ch.theta, ch.scale) == (jc["family"], jc["theta"], jc["scale"])
            c = ch.components[0]
            assert c.pdf_h.shape == (90,) and c.pdf_p.shape == (180,)
            assert c.pdf_d.shape == (s.theta_d_end - s.theta_d_begin,)
            assert abs(c.pdf_h.sum() - 1) < 1e-9


@pytest.mark.parametrize("kwargs", [
    dict(bits=5), dict(bits=17), dict(slices=0), dict(slices="many"), dict(components=9),
    dict(family="nope"), dict(loss="l3"), dict(level=0), dict(placement="random"),
    dict(target_bytes=-1), dict(target_bytes=float("nan")), dict(target_psnr=0),
    dict(target_psnr=20, target_bytes=1000), dict(slices="auto", target_psnr=40),
    dict(components=True),
])
def test_bad_options_raise_usage_errors(work, kwargs):
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.encode(work / "plastic.binary", **kwargs)
    assert e.value.code == cbrdf.ErrorCode.INVALID_ARGUMENT
    assert e.value.exit_code == 2 and str(e.value)


def test_encode_refuses_what_the_command_refuses(tmp_path):
    huge = np.full((3, 90, 90, 180), 1e300)
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.encode(huge)
    assert e.value.exit_code == 1
    with pytest.raises(cbrdf.Error):
        cbrdf.encode(tmp_path / "missing.binary")


def damaged(data, rng):
    """A few kinds of damage: truncation, a flipped byte, garbage, an empty file."""
    out = []
    for cut in (0, 5, 11, 12, 40, len(data) // 2, len(data) - 1):
        out.append(("cut%d" % cut, data[:cut]))
    for i in range(12):
        pos = rng.randrange(len(data))
        b = bytearray(data)
        b[pos] ^= 1 << rng.randrange(8)
        out.append(("flip%d" % pos, bytes(b)))
    out.append(("garbage", bytes(rng.randrange(256) for _ in range(300))))
    out.append(("signature-only", data[:12]))
    return out


def test_damaged_files_raise_the_command_s_errors(work, tmp_path):
    data = (work / "plastic.cbrdf").read_bytes()
    for name, bad in damaged(data, random.Random(7)):
        p = tmp_path / f"{name}.cbrdf"
        p.write_bytes(bad)
        r = run_cli("decode", p, "-o", tmp_path / "out.binary", check=False)
        try:
            m = cbrdf.decode(p)
        except cbrdf.Error as e:
            assert isinstance(e, ValueError)
            assert r.returncode == 1, name
            assert r.stderr.strip() == f"cbrdf: {e}", name
            assert e.code in cbrdf.ErrorCode.NAMES and e.code_name == cbrdf.ErrorCode.NAMES[e.code]
            with pytest.raises(cbrdf.Error):
                cbrdf.decode(bad)
            with pytest.raises(cbrdf.Error):
                cbrdf.info(p)
        else:  # a flip in an ancillary chunk's slack can be harmless: then both accept it
            assert r.returncode == 0, name
            m.close()


def test_random_damage_never_crashes(work):
    data = (work / "plastic.cbrdf").read_bytes()
    rng = random.Random(11)
    for _ in range(300):
        b = bytearray(data)
        for _ in range(rng.randrange(1, 4)):
            b[rng.randrange(len(b))] = rng.randrange(256)
        try:
            cbrdf.decode(bytes(b)).close()
        except cbrdf.Error:
            pass


def test_bad_paths(tmp_path):
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.decode(tmp_path / "missing.cbrdf")
    assert e.value.code == cbrdf.ErrorCode.NOT_FOUND
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.decode(tmp_path)
    assert e.value.code == cbrdf.ErrorCode.IO
    with pytest.raises(TypeError):
        cbrdf.decode(12)


def test_closed_model_raises(work):
    with cbrdf.decode(work / "plastic.cbrdf") as m:
        assert not m.closed
    assert m.closed and "closed" in repr(m)
    with pytest.raises(cbrdf.Error):
        m.eval([0, 0, 1.0], [0, 0, 1.0])
    with pytest.raises(cbrdf.Error):
        m.table()
    m.close()  # twice is fine


def test_metrics_reproduce_the_command(work, tmp_path):
    # `cbrdf encode` prints the sphere PSNR of the decoded file against the input (2 decimals).
    r = run_cli("encode", work / "plastic.binary", "-o", tmp_path / "p.cbrdf", "--bits", "10")
    line = [l for l in r.stdout.splitlines() if "sphere PSNR" in l]
    m = cbrdf.sphere_metrics(work / "plastic.binary", work / "back.binary")
    assert f"{m['psnr_linear']:.2f} dB linear, {m['psnr_tonemapped']:.2f} dB tone-mapped" in line[0]
    ref = cbrdf.read_merl(work / "plastic.binary")
    dec = cbrdf.decode(work / "plastic.cbrdf")
    assert cbrdf.sphere_psnr(ref, dec) == m["psnr_tonemapped"]
    assert cbrdf.sphere_psnr(ref, dec, tonemapped=False) == m["psnr_linear"]
    assert len(m["per_light"]) == 3
    assert cbrdf.sphere_psnr(ref, ref) == 100.0
    bm = cbrdf.brdf_metrics(ref, dec)
    assert 0 < bm["rel_rmse"] < 0.1 and bm["bins"][0] == int((~np.isnan(ref[0])).sum())
    img = cbrdf.render_sphere(dec, 45, size=32)
    assert img.shape == (32, 32, 3) and img.dtype == np.float32 and img.max() > 0


def test_residual_steps_visibility_matches_the_command(work, tmp_path):
    out = tmp_path / "v.cbrdf"
    run_cli("encode", work / "plastic.binary", "-o", out, "--bits", "8", "--max-error", "0.05",
            "--residual-steps", "visibility", "--no-metrics")
    data = cbrdf.encode(work / "plastic.binary", bits=8, max_error=0.05,
                        residual_steps="visibility")
    assert data == out.read_bytes()
    one = cbrdf.encode(work / "plastic.binary", bits=8, max_error=0.05, residual_steps="one")
    assert one == cbrdf.encode(work / "plastic.binary", bits=8, max_error=0.05)
    assert len(data) < len(one)  # coarser steps where bins count less in images
    for kwargs, words in (({"residual_steps": "visibility"}, "max_error="),
                          ({"residual_steps": "visibility", "target_psnr": 50.0},
                           "residual_steps= and a target"),
                          ({"residual_steps": "rows", "max_error": 0.05},
                           "residual_steps= must be one or visibility, not 'rows'")):
        with pytest.raises(cbrdf.Error) as e:
            cbrdf.encode(work / "plastic.binary", bits=8, **kwargs)
        assert e.value.exit_code == 2 and words in str(e.value), str(e.value)
