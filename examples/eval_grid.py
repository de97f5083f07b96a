#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Evaluate a decoded model on a grid of directions and compare it with the table.

    PYTHONPATH=build/python /usr/bin/python3 examples/eval_grid.py MODEL.cbrdf [--table MERL.binary]
    PYTHONPATH=build/python /usr/bin/python3 examples/eval_grid.py --sample plastic

The grid: theta_i and theta_o from 0 to 85 degrees, phi_o - phi_i over [0, 360) degrees, in one
batch (Model.eval: vectorized in C++, threads, the GIL released). The comparison:
  * against the model's own table (Model.table(), what `cbrdf decode` writes) at the pairs' nearest
    MERL bins: the continuous evaluation against its tabulation (differs by the within-bin
    variation);
  * against the source table (--table, or the built-in sample), if given: the codec's error;
  * at the bins' own grid angles, eval against bin_value: equal up to rounding.
"""
import argparse
import sys
import time

import numpy as np

import cbrdf


def grid(n_theta=18, n_phi=36):
    t = np.radians(np.linspace(0.0, 85.0, n_theta))
    p = np.radians(np.arange(n_phi) * 360.0 / n_phi)
    ti, to, dp = np.meshgrid(t, t, p, indexing="ij")
    wi = np.stack([np.sin(ti), np.zeros_like(ti), np.cos(ti)], axis=-1).reshape(-1, 3)
    wo = np.stack([np.sin(to) * np.cos(dp), np.sin(to) * np.sin(dp), np.cos(to)],
                  axis=-1).reshape(-1, 3)
    return wi, wo


def table_at(table, wi, wo):
    """The table's values (N, 3) at the pairs' nearest bins; NaN where not measured."""
    h, d, p = cbrdf.nearest_bin(wi, wo)
    return table[:, h, d, p].T


def summary(label, test, ref):
    ok = np.isfinite(ref) & (ref > 0)
    rel = np.abs(test[ok] - ref[ok]) / ref[ok]
    print(f"{label:<34} {ok.sum():>7} values: median relative difference {np.median(rel):.2e}, "
          f"90th percentile {np.percentile(rel, 90):.2e}")
    return rel


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("model", nargs="?", help="a .cbrdf file")
    ap.add_argument("--table", help="the source MERL .binary to compare with")
    ap.add_argument("--sample", help="encode this built-in sample first (default plastic)")
    ap.add_argument("--n-theta", type=int, default=18)
    ap.add_argument("--n-phi", type=int, default=36)
    a = ap.parse_args(argv)

    source = None
    if a.model:
        model = cbrdf.decode(a.model)
    else:
        source = cbrdf.sample_table(a.sample or "plastic")
        model = cbrdf.decode(cbrdf.encode(source, bits=12))
    if a.table:
        source = cbrdf.read_merl(a.table)
    print(model)

    wi, wo = grid(a.n_theta, a.n_phi)
    t0 = time.perf_counter()
    rgb = model.eval(wi, wo)
    dt = time.perf_counter() - t0
    print(f"evaluated {len(wi)} direction pairs in {dt * 1e3:.2f} ms")

    summary("model vs its own table", rgb, table_at(model.table(), wi, wo))
    if source is not None:
        summary("model vs the source table", rgb, table_at(source, wi, wo))

    # At bin grid angles (theta_h and theta_d bins > 0, both directions above the horizon), the
    # continuous evaluation reproduces the bin values.
    h, d, p = np.meshgrid(np.arange(1, 90, 4), np.arange(1, 90, 4), np.arange(0, 180, 9),
                          indexing="ij")
    bwi, bwo = cbrdf.bin_directions(h, d, p)
    up = (bwi[..., 2] > 1e-6) & (bwo[..., 2] > 1e-6)
    at_bins = model.eval(bwi[up], bwo[up])
    bins = np.stack([model.bin_value(c, h[up], d[up], p[up]) for c in range(3)], axis=-1)
    worst = float(np.max(np.abs(at_bins - bins) / np.maximum(np.abs(bins), 1e-300)))
    print(f"eval at {up.sum()} bin grid angles vs bin_value: largest relative difference "
          f"{worst:.1e}")
    model.close()
    return 0 if worst < 1e-9 else 1


if __name__ == "__main__":
    sys.exit(main())
