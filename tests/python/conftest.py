# SPDX-License-Identifier: MIT
"""Shared fixtures of the cbrdf Python tests.

Environment (ctest's python_tests sets all of them; the defaults fit a build in <repo>/build):
  PYTHONPATH       the folder holding the built package (<build>/python)
  CBRDF_BUILD_DIR  the build tree (default <repo>/build)
  CBRDF_CLI        the `cbrdf` command (default <build>/cbrdf)
Run: PYTHONPATH=build/python CBRDF_CLI=build/cbrdf /usr/bin/python3 -m pytest -q tests/python
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("CBRDF_BUILD_DIR", REPO / "build"))
CLI = Path(os.environ.get("CBRDF_CLI", BUILD / "cbrdf"))

try:
    import cbrdf  # noqa: F401
except ImportError:  # not on PYTHONPATH: the build tree's copy
    sys.path.insert(0, str(BUILD / "python"))
    import cbrdf  # noqa: F401


def run_cli(*args, check=True):
    """Runs the cbrdf command; returns the CompletedProcess (text output)."""
    p = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"cbrdf {' '.join(map(str, args))} failed: {p.stderr}")
    return p


def cli_json(*args):
    return json.loads(run_cli(*args).stdout)


@pytest.fixture(scope="session")
def cli():
    if not CLI.exists():
        pytest.fail(f"the cbrdf command is not at {CLI} (set CBRDF_CLI)")
    return CLI


@pytest.fixture(scope="session")
def work(tmp_path_factory, cli):
    """A folder with plastic.binary (cbrdf sample), plastic.cbrdf (cbrdf encode --bits 10) and
    back.binary (cbrdf decode), all written by the command."""
    d = tmp_path_factory.mktemp("cbrdf")
    run_cli("sample", "plastic", "-o", d / "plastic.binary")
    run_cli("encode", d / "plastic.binary", "-o", d / "plastic.cbrdf", "--bits", "10",
            "--no-metrics")
    run_cli("decode", d / "plastic.cbrdf", "-o", d / "back.binary")
    return d


@pytest.fixture(scope="session")
def model(work):
    import cbrdf
    return cbrdf.decode(work / "plastic.cbrdf")


@pytest.fixture(scope="session")
def decoder_lib():
    """The C API (libcbrdf_decoder.so of the build) through ctypes, or skip."""
    import ctypes
    so = BUILD / "libcbrdf_decoder.so"
    if not so.exists():
        pytest.skip(f"{so} is not built (CBRDF_SHARED=OFF)")
    return ctypes.CDLL(str(so))
