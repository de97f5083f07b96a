# SPDX-License-Identifier: MIT
"""The examples/ scripts run and produce what they promise."""
import os
import subprocess
import sys

from conftest import REPO

import cbrdf


def run_example(name, *args, cwd):
    env = dict(os.environ, MPLBACKEND="Agg")
    # The package this test imported, wherever it came from.
    pkg_root = os.path.dirname(os.path.dirname(cbrdf.__file__))
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [pkg_root, env.get("PYTHONPATH")]))
    return subprocess.run([sys.executable, str(REPO / "examples" / name), *map(str, args)],
                          capture_output=True, text=True, cwd=cwd, env=env, timeout=300)


def test_size_vs_psnr(work, tmp_path):
    out = tmp_path / "curve.png"
    r = run_example("size_vs_psnr.py", work / "plastic.binary", "--quick", "-o", out, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.strip().splitlines()
    assert lines[0].startswith("slices,components,bits,bytes")
    rows = [l.split(",") for l in lines[1:]]
    assert len(rows) == 4
    # More bits: more bytes and a higher PSNR, at each slice count.
    for a, b in zip(rows[0::2], rows[1::2]):
        assert int(b[3]) > int(a[3]) and float(b[4]) > float(a[4])
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_eval_grid(work, tmp_path):
    r = run_example("eval_grid.py", work / "plastic.cbrdf", "--table", work / "plastic.binary",
                    "--n-theta", "10", "--n-phi", "12", cwd=tmp_path)
    assert r.returncode == 0, r.stderr + r.stdout
    assert "model vs the source table" in r.stdout and "bin_value" in r.stdout
