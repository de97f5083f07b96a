# SPDX-License-Identifier: MIT
"""MERL tables: read_merl / write_merl against the command's files, byte for byte."""
import numpy as np
import pytest

import cbrdf


def test_read_shape_units_and_mask(work):
    t = cbrdf.read_merl(work / "plastic.binary")
    assert isinstance(t, np.ndarray) and t.dtype == np.float64 and t.shape == (3, 90, 90, 180)
    stored = cbrdf.read_merl(work / "plastic.binary", units="stored")
    raw = np.frombuffer((work / "plastic.binary").read_bytes()[12:], dtype="<f8").reshape(t.shape)
    assert np.array_equal(stored.view(np.uint64), raw.view(np.uint64))  # bit for bit
    measured = raw >= 0
    assert np.array_equal(~np.isnan(t), measured)  # NaN marks exactly the not-measured bins
    scale = np.array(cbrdf.MERL_SCALE)[:, None, None, None]
    assert np.array_equal(t[measured], (raw * scale)[measured])  # physical = stored * scale
    info = cbrdf.info(work / "plastic.binary")
    assert int(np.isnan(t[0]).sum()) == info["channels"]["R"]["not_measured"]


def test_read_bytes_and_sample_match_file(work):
    data = (work / "plastic.binary").read_bytes()
    a = cbrdf.read_merl(data, units="stored")
    b = cbrdf.sample_table("plastic", units="stored")
    c = cbrdf.read_merl(work / "plastic.binary", units="stored")
    assert a.tobytes() == b.tobytes() == c.tobytes()
    assert ("plastic" in dict(cbrdf.samples()))


def test_samples_by_kind():
    measured, analytic = cbrdf.samples("measured"), cbrdf.samples("analytic")
    assert cbrdf.samples() == measured + analytic  # measured first
    assert [n for n, _ in measured[:3]] == ["blue-metallic-paint", "nickel", "yellow-matte-plastic"]
    assert "plastic" in dict(analytic) and "plastic" not in dict(measured)
    with pytest.raises(ValueError):
        cbrdf.samples("neural")


@pytest.mark.parametrize("units", ["physical", "stored"])
def test_round_trip_is_byte_identical(work, tmp_path, units):
    src = work / "plastic.binary"
    t = cbrdf.read_merl(src, units=units)
    out = tmp_path / "out.binary"
    cbrdf.write_merl(out, t, units=units)
    assert out.read_bytes() == src.read_bytes()
    assert cbrdf.merl_bytes(t, units=units) == src.read_bytes()


def test_physical_values_survive_without_the_companion(work, tmp_path):
    t = cbrdf.read_merl(work / "plastic.binary")
    plain = np.array(t)  # a plain ndarray: converted as value / scale
    assert not isinstance(plain, cbrdf.MerlArray)
    cbrdf.write_merl(tmp_path / "plain.binary", plain)
    back = cbrdf.read_merl(tmp_path / "plain.binary")
    np.testing.assert_array_equal(np.isnan(back), np.isnan(t))
    np.testing.assert_allclose(back[~np.isnan(t)], t[~np.isnan(t)], rtol=1e-15, atol=0)


def test_modified_array_and_explicit_mask(work, tmp_path):
    t = cbrdf.read_merl(work / "plastic.binary")
    doubled = t * 2.0  # keeps the companion, which must not be used for changed bins
    cbrdf.write_merl(tmp_path / "x2.binary", doubled)
    back = cbrdf.read_merl(tmp_path / "x2.binary")
    m = ~np.isnan(t)
    np.testing.assert_allclose(back[m], 2 * t[m], rtol=1e-15)
    # A mask instead of NaN; not_measured_value is what the file stores there.
    filled = np.nan_to_num(np.asarray(t), nan=0.0)
    cbrdf.write_merl(tmp_path / "m.binary", filled, np.isnan(t), not_measured_value=-2.0)
    st = cbrdf.read_merl(tmp_path / "m.binary", units="stored")
    assert np.all(st[np.isnan(t)] == -2.0)
    assert np.array_equal(np.isnan(cbrdf.read_merl(tmp_path / "m.binary")), np.isnan(t))


@pytest.mark.parametrize("bad,what", [
    (np.zeros((3, 90, 90)), "shape"),
    (np.full((3, 90, 90, 180), np.inf), "inf"),
    (np.full((3, 90, 90, 180), -1.0), "-1"),
])
def test_write_refuses_bad_tables(tmp_path, bad, what):
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.write_merl(tmp_path / "bad.binary", bad)
    assert isinstance(e.value, ValueError)
    assert not (tmp_path / "bad.binary").exists()
    with pytest.raises(cbrdf.Error):
        cbrdf.write_merl(tmp_path / "bad.binary", np.zeros((3, 90, 90, 180)), not_measured_value=1.0)


def test_read_errors_match_the_command(tmp_path, cli):
    from conftest import run_cli
    cases = {
        "missing.binary": None,
        "short.binary": b"\x5a\x00\x00\x00" * 2,
        "dims.binary": np.array([90, 90, 90], "<i4").tobytes() + b"\0" * 64,
    }
    for name, data in cases.items():
        p = tmp_path / name
        if data is not None:
            p.write_bytes(data)
        with pytest.raises(cbrdf.Error) as e:
            cbrdf.read_merl(p)
        r = run_cli("info", p, check=False)
        if data is not None:  # CLI11 refuses a missing file itself, before cbrdf runs
            assert r.returncode == 1
            assert r.stderr.strip() == f"cbrdf: {e.value}"
        assert e.value.code in (cbrdf.ErrorCode.NOT_FOUND, cbrdf.ErrorCode.TRUNCATED,
                                cbrdf.ErrorCode.UNSUPPORTED, cbrdf.ErrorCode.CORRUPT)
