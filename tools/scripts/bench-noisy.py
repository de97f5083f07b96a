#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The ladder on noisy tables against their clean truth (issue 30's numbers).

    tools/scripts/bench-noisy.py BUILD DIR [MATERIAL...] [--modes model,bytes100k,psnr60] [--threads N]

DIR holds NAME.binary (the truth) and NAME-noisy.binary, as ../shared/tools/make-merl.sh --noise
writes them. For each material and mode it encodes NAME-noisy.binary with the built `cbrdf`
(model: the default encode; bytes100k: --target-bytes 100000; psnr60: --target-psnr 60; lossless:
--lossless) and prints one tab-separated row: material, mode, bytes, the tone-mapped sphere PSNR
of the decoded file against the truth and against the input, seconds, and the encoder's note.
The last rows are the means over the materials per mode.

With mode lossless the row also gives the bytes of `xz -9` of NAME-noisy.binary and the entropy
bound of its noise: the sum over measured values v > 0 of log2(s v sqrt(2 pi e) / ulp(v)) bits,
the entropy of normal noise of deviation s v at double precision (s: the channel's estimate,
cbrdf.estimate_noise). Those bits are independent of the noise-free table, so no lossless coder
goes below them even if it knew the truth; zeros, not-measured values, signs and exponents are
counted as free.
"""
import os
import subprocess
import sys
import tempfile
import time


def entropy_bound(cbrdf, path):
    """Bytes: see the module's docstring."""
    import numpy as np
    t = cbrdf.read_merl(path, units="stored")
    sigma = cbrdf.estimate_noise(path)["sigma"]
    bits = 0.0
    for c, name in enumerate("RGB"):
        v = t[c][np.isfinite(t[c]) & (t[c] > 0)]
        h = np.log2(sigma[name] * v * np.sqrt(2 * np.pi * np.e) / np.spacing(v))
        bits += float(np.maximum(h, 0).sum())
    return bits / 8


def main():
    args = sys.argv[1:]
    modes = ["model", "bytes100k", "psnr60"]
    threads = "1"
    if "--modes" in args:
        i = args.index("--modes")
        modes = args[i + 1].split(",")
        del args[i:i + 2]
    if "--threads" in args:
        i = args.index("--threads")
        threads = args[i + 1]
        del args[i:i + 2]
    build, folder, names = args[0], args[1], args[2:]
    sys.path.insert(0, os.path.join(build, "python"))
    import cbrdf
    cli = os.path.join(build, "cbrdf")
    if not names:
        names = sorted(f[:-len("-noisy.binary")] for f in os.listdir(folder)
                       if f.endswith("-noisy.binary"))
    options = {"model": [], "bytes100k": ["--target-bytes", "100000"],
               "psnr60": ["--target-psnr", "60"], "lossless": ["--lossless"]}
    sums = {m: [0.0, 0.0, 0.0, 0] for m in modes}
    lossless = [0.0, 0.0, 0.0, 0]
    print("material\tmode\tbytes\tpsnr_truth\tpsnr_input\tseconds\tnote", flush=True)
    for name in names:
        truth = os.path.join(folder, name + ".binary")
        noisy = os.path.join(folder, name + "-noisy.binary")
        for mode in modes:
            with tempfile.TemporaryDirectory() as tmp:
                out = os.path.join(tmp, "x.cbrdf")
                t0 = time.time()
                r = subprocess.run([cli, "encode", noisy, "-o", out, "--no-metrics", "--threads",
                                    threads] + options[mode], capture_output=True, text=True)
                secs = time.time() - t0
                if r.returncode != 0:
                    print(f"{name}\t{mode}\tFAILED\t\t\t\t{r.stderr.strip()}", flush=True)
                    continue
                data = open(out, "rb").read()
            model = cbrdf.decode(data)
            pt = cbrdf.sphere_psnr(truth, model)
            pi = cbrdf.sphere_psnr(noisy, model)
            note = next((l[6:] for l in (r.stdout + r.stderr).splitlines()
                         if l.startswith("note: ")), "")
            s = sums[mode]
            s[0] += len(data)
            s[1] += pt
            s[2] += pi
            s[3] += 1
            if mode == "lossless":
                xz = len(subprocess.run(["xz", "-9", "-T1", "-c", noisy], capture_output=True,
                                        check=True).stdout)
                bound = entropy_bound(cbrdf, noisy)
                note = f"xz -9 {xz} bytes, entropy bound {bound:.0f} bytes"
                for k, v in enumerate((len(data), xz, bound)):
                    lossless[k] += v
                lossless[3] += 1
            print(f"{name}\t{mode}\t{len(data)}\t{pt:.2f}\t{pi:.2f}\t{secs:.1f}\t{note}", flush=True)
    for mode, s in sums.items():
        if s[3]:
            n = s[3]
            print(f"MEAN({n})\t{mode}\t{s[0] / n:.0f}\t{s[1] / n:.2f}\t{s[2] / n:.2f}\t\t",
                  flush=True)
    if lossless[3]:
        n = lossless[3]
        print(f"LOSSLESS({n}) mean bytes: cbrdf {lossless[0] / n:.0f}, xz -9 {lossless[1] / n:.0f}, "
              f"entropy bound {lossless[2] / n:.0f}; cbrdf / xz {lossless[0] / lossless[1]:.3f}, "
              f"cbrdf / bound {lossless[0] / lossless[2]:.3f}", flush=True)


if __name__ == "__main__":
    main()
