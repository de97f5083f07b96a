#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Size versus quality of one material: encode at several settings, decode, measure the report's
tone-mapped sphere PSNR, and draw the curve with matplotlib.

    PYTHONPATH=build/python /usr/bin/python3 examples/size_vs_psnr.py MATERIAL.binary -o curve.png
    PYTHONPATH=build/python /usr/bin/python3 examples/size_vs_psnr.py --sample plastic --quick

Prints one CSV line per setting (slices, components, bits, bytes, PSNR tone-mapped, linear).
"""
import argparse
import sys

import cbrdf


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    src = ap.add_mutually_exclusive_group()
    src.add_argument("material", nargs="?", help="a MERL .binary file")
    src.add_argument("--sample", default=None, help="a built-in sample (cbrdf.samples())")
    ap.add_argument("-o", "--output", default="size_vs_psnr.png", help="the plot (PNG, SVG, PDF)")
    ap.add_argument("--slices", type=int, nargs="+", default=[3, 6, 9])
    ap.add_argument("--bits", type=int, nargs="+", default=[6, 8, 10, 12])
    ap.add_argument("--components", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--quick", action="store_true", help="a few settings only (for tests)")
    a = ap.parse_args(argv)
    if a.quick:
        a.slices, a.bits, a.components = [3, 6], [6, 10], [1]

    name = a.material or a.sample or "plastic"
    reference = cbrdf.read_merl(a.material) if a.material else cbrdf.sample_table(name)

    curves = {}
    print("slices,components,bits,bytes,psnr_tonemapped,psnr_linear")
    for s in a.slices:
        for k in a.components:
            points = []
            for b in a.bits:
                data = cbrdf.encode(reference, slices=s, components=k, bits=b)
                with cbrdf.decode(data) as model:
                    m = cbrdf.sphere_metrics(reference, model)
                points.append((len(data), m["psnr_tonemapped"]))
                print(f"{s},{k},{b},{len(data)},{m['psnr_tonemapped']:.3f},{m['psnr_linear']:.3f}")
            curves[(s, k)] = points

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for (s, k), pts in sorted(curves.items()):
        x, y = zip(*pts)
        ax.plot(x, y, marker="o", label=f"{s} slices" + (f", {k} components" if k > 1 else ""))
    ax.set_xscale("log")
    ax.set_xlabel("file size (bytes)")
    ax.set_ylabel("tone-mapped sphere PSNR (dB)")
    ax.set_title(f"{name}: size vs quality (bits {min(a.bits)}-{max(a.bits)})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.output, dpi=120)
    print(f"wrote {a.output}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
