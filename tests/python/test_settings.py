# SPDX-License-Identifier: MIT
"""Issue 41 item 2: cbrdf.encode refuses bad settings in the library's words.

tests/data/bad_settings.json lists settings every front end (the command, the C API, the C++ API
and Python) must refuse with the same sentence: the setting's name in the front end's spelling
("max_error=" here), then one message. Python keeps no range check of its own, so each refusal
here is validate()'s (cbrdf/encoder_settings.h), spelled by the module.
"""
import json
import re
from pathlib import Path

import pytest

import cbrdf

CASES = json.loads((Path(__file__).resolve().parents[1] / "data" / "bad_settings.json")
                   .read_text())
SPELLINGS = {name: s["python"] for name, s in CASES["spellings"].items()}


def python_message(case):
    """The sentence Python must raise: "<spelling> <message>", {name} spelled too."""
    tail = re.sub(r"\{(\w+)\}", lambda m: SPELLINGS[m.group(1)], case["message"])
    return f"{SPELLINGS[case['setting']]} {tail}"


@pytest.fixture(scope="module")
def table():
    return cbrdf.sample_table("lambertian")


def test_the_list_covers_at_least_12_settings_python_takes():
    python_cases = [c for c in CASES["cases"] if c["python"] is not None]
    assert len(python_cases) >= 12
    assert {c["setting"] for c in python_cases} >= {"slices", "bits", "zstd_level", "max_error"}


@pytest.mark.parametrize("case", [c for c in CASES["cases"] if c["python"] is not None],
                         ids=lambda c: f"{c['setting']}-{c['python']}")
def test_bad_setting_is_refused_in_the_librarys_words(table, case):
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.encode(table, **case["python"])
    assert str(e.value) == python_message(case)
    assert e.value.code == cbrdf.ErrorCode.INVALID_ARGUMENT and e.value.exit_code == 2
    assert not isinstance(e.value, TypeError)


def test_every_problem_is_named_at_once(table):
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.encode(table, slices=0, level=23, max_error=20)
    parts = str(e.value).split("; ")
    assert sorted(p.split(" ")[0] for p in parts) == ["level=", "max_error=", "slices="]
