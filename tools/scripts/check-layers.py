#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Checks the layer rule of ARCHITECTURE.md on the source tree: a file includes only from its own
layer or the ones below it, the libraries never include from tools/, and each layer's tests
(tests/LAYER/) include nothing above LAYER. Every quoted #include is resolved the way the compiler
would (the including file's folder first, then every layer's include/ and src/ folders); an include
that resolves to a file of a higher layer is reported with the file, line and both layers.

Usage: tools/scripts/check-layers.py [REPO]     exit 0: the tree is the layer diagram; 1: it is not
"""
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                       os.path.join(os.path.dirname(__file__), "..", ".."))
# Lowest first. A layer may include from itself and every layer before it.
LAYERS = [
    ("format", ["format/include", "format/src"]),
    ("decoder", ["codec/decoder/include", "codec/decoder/src"]),
    ("encoder", ["codec/encoder/include", "codec/encoder/src"]),
    ("extras", ["codec/extras/src"]),
    ("tools", ["tools", "tools/cli"]),
]
RANK = {name: i for i, (name, _) in enumerate(LAYERS)}
# Folders whose files belong to a layer: the libraries' own, and each layer's tests.
MEMBERS = [
    ("format/", "format"), ("codec/decoder/", "decoder"), ("codec/encoder/", "encoder"),
    ("codec/extras/", "extras"), ("tools/", "tools"),
    ("tests/format/", "format"), ("tests/decoder/", "decoder"), ("tests/encoder/", "encoder"),
    ("tests/extras/", "extras"), ("tests/tools/", "tools"),
]
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')
SOURCE = (".h", ".cc", ".c", ".cpp", ".def")


def layer_of(rel):
    for prefix, name in MEMBERS:
        if rel.startswith(prefix):
            return name
    return None


def resolve(rel_file, target):
    """The repository path the include names, and the layer that owns it (None: not ours)."""
    here = os.path.join(ROOT, os.path.dirname(rel_file), target)
    if os.path.isfile(here):
        rel = os.path.relpath(os.path.normpath(here), ROOT)
        return rel, layer_of(rel)
    for name, dirs in LAYERS:
        for d in dirs:
            if os.path.isfile(os.path.join(ROOT, d, target)):
                return os.path.join(d, target), name
    return None, None


def main():
    problems = []
    checked = 0
    for prefix, owner in MEMBERS:
        for dirpath, dirnames, filenames in os.walk(os.path.join(ROOT, prefix)):
            dirnames[:] = [d for d in dirnames if d != "node_modules"]
            for fn in sorted(filenames):
                if not fn.endswith(SOURCE):
                    continue
                rel = os.path.relpath(os.path.join(dirpath, fn), ROOT)
                if layer_of(rel) != owner:
                    continue  # a deeper prefix owns it
                checked += 1
                with open(os.path.join(ROOT, rel), encoding="utf-8") as f:
                    for line_no, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        path, layer = resolve(rel, m.group(1))
                        if layer is not None and RANK[layer] > RANK[owner]:
                            problems.append(f"{rel}:{line_no}: includes \"{m.group(1)}\" ({path}, "
                                            f"layer {layer}) from layer {owner}")
    if checked == 0:
        print(f"check-layers: no source files under {ROOT}", file=sys.stderr)
        return 1
    for p in problems:
        print(f"check-layers: {p}", file=sys.stderr)
    if problems:
        print(f"check-layers: FAILED: {len(problems)} include(s) run upward "
              "(ARCHITECTURE.md: format < decoder < encoder < extras < tools)", file=sys.stderr)
        return 1
    print(f"check-layers: {checked} files, no include runs upward")
    return 0


if __name__ == "__main__":
    sys.exit(main())
