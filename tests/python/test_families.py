# SPDX-License-Identifier: MIT
"""The copula families as Python sees them: the library's table (COPULA_FAMILIES), which the
type stub, encode()'s error message and decoded models must agree with."""
import ast
from pathlib import Path

import pytest

import cbrdf


def test_stub_lists_the_tables_families():
    stub = ast.parse(Path(cbrdf.__file__).with_name("__init__.pyi").read_text())
    encode = next(n for n in stub.body if isinstance(n, ast.FunctionDef) and n.name == "encode")
    family = next(a for a in encode.args.args + encode.args.kwonlyargs if a.arg == "family")
    literal = ast.literal_eval(family.annotation.slice)
    assert tuple(literal) == cbrdf.COPULA_FAMILIES + ("auto",)


def test_unknown_family_error_names_every_family():
    table = cbrdf.sample_table("lambertian")
    with pytest.raises(cbrdf.Error) as err:
        cbrdf.encode(table, family="nope")
    assert f"{', '.join(cbrdf.COPULA_FAMILIES)} or auto" in str(err.value)
