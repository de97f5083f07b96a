#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""tools/scripts/check-layers.py on a small tree that keeps every rule, then on copies of it with
one rule broken (a planted include or CMake line): the clean tree passes, and each plant fails
with its file and line and what to do instead. The real tree is the ctest layer_includes.

Usage: tests/tools/check_layers_test.py     exit 0: every case behaved; 1: one did not
"""
import os
import shutil
import subprocess
import sys
import tempfile

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "scripts",
                      "check-layers.py")

# A tree in the repository's shape: each layer with a public and an internal header, tools that
# include public headers and their own, tests and a fuzz harness.
CLEAN = {
    "format/include/cbrdf/status.h": "#pragma once\n",
    "format/src/byte_reader.h": '#pragma once\n#include "cbrdf/status.h"\n',
    "codec/decoder/include/cbrdf/model.h": '#pragma once\n#include "cbrdf/status.h"\n',
    "codec/decoder/src/bitstream/chunks.h": '#pragma once\n#include "byte_reader.h"\n',
    "codec/encoder/include/cbrdf/metrics.h": '#pragma once\n#include "cbrdf/model.h"\n',
    # A forwarder: the internal name of a public header.
    "codec/encoder/src/metrics.h": "// the public one\n#pragma once\n\n#include \"cbrdf/metrics.h\"\n",
    "codec/encoder/src/fit.cc": '#include "bitstream/chunks.h"\n#include "metrics.h"\n',
    "codec/extras/include/cbrdf/image_io.h": '#pragma once\n#include "cbrdf/metrics.h"\n',
    "codec/extras/src/image_io.cc": '#include "cbrdf/image_io.h"\n',
    "tools/CMakeLists.txt": (
        "file(GLOB RENDER_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/render/*.cc)\n"
        "add_library(cbrdf_render STATIC ${RENDER_SOURCES})\n"
        "add_executable(cbrdf_cli cli/main.cc)\n"
        "add_subdirectory(python)\n"),
    "tools/cli/main.cc": '#include "cbrdf/image_io.h"\n#include "cli.h"\n#include "render/scene.h"\n',
    "tools/cli/cli.h": "#pragma once\n",
    "tools/render/scene.h": '#pragma once\n#include "cbrdf/metrics.h"\n',
    "tools/render/scene.cc": '#include "render/scene.h"\n',
    "tools/python/CMakeLists.txt": (
        "# module.cc: the bindings\n"
        "pybind11_add_module(_cbrdf MODULE ${CMAKE_CURRENT_SOURCE_DIR}/module.cc\n"
        "                    ${CMAKE_CURRENT_SOURCE_DIR}/tables.cc)\n"),
    "tools/python/module.cc": '#include "cbrdf/model.h"\n',
    "tools/python/tables.cc": '#include "cbrdf/model.h"\n',
    "tests/format/status_test.cc": '#include "byte_reader.h"\n',
    "tests/encoder/fit_test.cc": '#include "bitstream/chunks.h"\n#include "metrics.h"\n',
    "tests/tools/report_test.cc": '#include "cbrdf/image_io.h"\n#include "render/scene.h"\n',
    "tests/bench/encode_bench.cc": '#include "cbrdf/metrics.h"\n',
    "fuzz/harness/decode_target.h": '#pragma once\n#include "cbrdf/model.h"\n',
}

# (name, file, text appended, what the report must contain). Each is planted alone.
PLANTS = [
    ("tool includes an internal header", "tools/cli/main.cc", '#include "bitstream/chunks.h"\n',
     ['tools/cli/main.cc:4: includes "bitstream/chunks.h" (codec/decoder/src/bitstream/chunks.h)',
      "not installed", "make what it needs public API"]),
    ("tool includes an internal forwarder", "tools/render/scene.cc", '#include "metrics.h"\n',
     ['tools/render/scene.cc:2: includes "metrics.h" (codec/encoder/src/metrics.h)',
      'include "cbrdf/metrics.h" instead']),
    ("tool test includes format/src", "tests/tools/report_test.cc", '#include "byte_reader.h"\n',
     ['tests/tools/report_test.cc:3: includes "byte_reader.h" (format/src/byte_reader.h)']),
    ("tool test includes an internal header in angle brackets", "tests/tools/report_test.cc",
     "#include <bitstream/chunks.h>\n",
     ["tests/tools/report_test.cc:3: includes <bitstream/chunks.h> "
      "(codec/decoder/src/bitstream/chunks.h)"]),
    ("benchmark includes an internal header", "tests/bench/encode_bench.cc",
     '#include "bitstream/chunks.h"\n', ["tests/bench/encode_bench.cc:2: includes"]),
    ("fuzz harness includes an internal header", "fuzz/harness/decode_target.h",
     '#include "bitstream/chunks.h"\n', ["fuzz/harness/decode_target.h:3: includes"]),
    ("tool includes another tool's source", "tools/python/module.cc", '#include "cli/main.cc"\n',
     ["tools/python/module.cc:2: includes the source file tools/cli/main.cc"]),
    ("tool target compiles another tool's source", "tools/python/CMakeLists.txt",
     "target_sources(_cbrdf PRIVATE ${PROJECT_SOURCE_DIR}/tools/cli/main.cc)\n",
     ["tools/python/CMakeLists.txt:4: target _cbrdf compiles tools/cli/main.cc, a source of "
      "tools/cli/"]),
    ("a target of tools/CMakeLists.txt spans two tools", "tools/CMakeLists.txt",
     "target_sources(cbrdf_cli PRIVATE render/scene.cc)\n",
     ["tools/CMakeLists.txt:5: target cbrdf_cli compiles tools/render/scene.cc"]),
    ("library includes upward", "codec/decoder/src/bitstream/chunks.h",
     '#include "cbrdf/metrics.h"\n',
     ['codec/decoder/src/bitstream/chunks.h:3: includes "cbrdf/metrics.h"', "from layer decoder"]),
]


def write_tree(root, files):
    for rel, text in files.items():
        path = os.path.join(root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)


def run(root):
    r = subprocess.run([sys.executable, SCRIPT, root], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def main():
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        clean = os.path.join(tmp, "clean")
        write_tree(clean, CLEAN)
        code, out = run(clean)
        if code != 0:
            failures.append(f"the clean tree failed (exit {code}):\n{out}")
        for name, rel, text, expected in PLANTS:
            tree = os.path.join(tmp, name.replace(" ", "-").replace("'", ""))
            shutil.copytree(clean, tree)
            with open(os.path.join(tree, rel), "a", encoding="utf-8") as f:
                f.write(text)
            code, out = run(tree)
            missing = [e for e in expected if e not in out]
            if code != 1 or missing or out.count("check-layers: ") != 2:
                failures.append(f"{name}: exit {code} (want 1, one problem), missing {missing}:\n"
                                f"{out}")
    for f in failures:
        print(f"check_layers_test: FAILED: {f}", file=sys.stderr)
    if not failures:
        print(f"check_layers_test: the clean tree passes; {len(PLANTS)} plants fail as they should")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
