# SPDX-License-Identifier: MIT
"""cbrdf.encode says what `cbrdf encode` prints about a file: a target it could not meet
(TargetNotMetWarning) and a noisy table's note (NoisyTableWarning), in the command's words, and
the same facts as attributes of the bytes it returns (cbrdf.Encoded)."""
import pickle
import subprocess
import warnings

import numpy as np
import pytest

import cbrdf
from conftest import CLI

SIGMA = 0.1  # the injected noise: 10% per bin


@pytest.fixture(scope="module")
def noisy_path(tmp_path_factory):
    """The plastic sample with 10% multiplicative noise, measured only below theta_d = 8 degrees
    (a small table: a targeted encode of it takes about 2 s)."""
    t = np.asarray(cbrdf.sample_table("plastic"))
    rng = np.random.default_rng(3)
    noisy = np.where(t >= 0, t * np.exp(SIGMA * rng.standard_normal(t.shape)), t)
    noisy[:, :, 8:, :] = np.nan
    path = tmp_path_factory.mktemp("noisy") / "noisy.binary"
    cbrdf.write_merl(path, noisy)
    return path


def test_a_missed_target_on_a_noisy_table_warns_as_the_command_prints(noisy_path, tmp_path):
    # The command on the same file, meanwhile (each encode takes about 2 s, mostly on one core).
    out = tmp_path / "noisy.cbrdf"
    command = subprocess.Popen([str(CLI), "encode", str(noisy_path), "-o", str(out),
                                "--target-psnr", "90", "--no-metrics"],
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data = cbrdf.encode(noisy_path, target_psnr=90)
    assert [w.category for w in caught] == [cbrdf.TargetNotMetWarning, cbrdf.NoisyTableWarning]
    assert all(issubclass(w.category, cbrdf.CbrdfWarning) and w.filename == __file__
               for w in caught)
    # The facts, as attributes of the bytes.
    assert isinstance(data, cbrdf.Encoded) and isinstance(data, bytes)
    assert data.target_met is False and data.target_psnr == 90.0 and data.target_bytes is None
    assert data.noisy is True and abs(data.noise_sigma - SIGMA) < 0.01
    assert data.noise_floor_error == pytest.approx(0.5 * data.noise_sigma)
    assert data.psnr_tonemapped < data.psnr_ceiling_tonemapped + 0.5 < 90
    assert data.note.startswith("the input is noisy (about 10% per bin")
    assert data.settings_tried >= 1 and data.slices >= 1 and data.components >= 1
    assert cbrdf.decode(data).bits == data.bits
    # The command: the same bytes, the same figures and note in its words.
    printed = command.communicate()[0]
    assert command.returncode == 0, printed
    assert out.read_bytes() == data
    missed, noisy = (str(w.message) for w in caught)
    closest = (f"{len(data)} bytes, {data.psnr_tonemapped:.2f} dB tone-mapped "
               f"(the target could not be met: this is the closest)")
    assert missed == "encode: target_psnr=90: " + closest
    assert any(line.endswith(": " + closest) for line in printed.splitlines()), printed
    assert noisy == "encode: " + data.note
    assert "note: " + data.note in printed.splitlines()


def test_a_met_target_does_not_warn(noisy_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        data = cbrdf.encode(noisy_path, target_psnr=40)
    assert data.target_met is True and data.psnr_tonemapped >= 40 and data.note is None
    assert data.noisy is None  # nothing to explain: no estimate


def test_an_encode_without_a_target_is_bytes_with_its_bits(noisy_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the command has nothing to say without a target
        data = cbrdf.encode(noisy_path, bits=10, slices=3)
    assert type(data) is cbrdf.Encoded and data == bytes(data) and data[:4] == bytes(data)[:4]
    assert data.bits == 10 and data.target_met is None and data.note is None
    assert data.noisy is None and data.psnr_tonemapped is None
    back = pickle.loads(pickle.dumps(data))
    assert back == data and back.bits == 10 and type(back) is cbrdf.Encoded
    assert cbrdf.decode(data).bits == 10
