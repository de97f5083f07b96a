# SPDX-License-Identifier: MIT
"""Issue 40 item 9: every public entry point raises cbrdf.Error for a bad argument.

The sweep below calls every public function, constructor and method of the package with a bad
value in one argument at a time (the others valid): lone surrogates in every str, huge and
negative ints in every int, NaN and infinities in every float, wrong types everywhere, wrong array
shapes and dtypes. Each call must raise cbrdf.Error, and exactly the documented kind of it:
cbrdf.ArgumentTypeError (also a TypeError) for a value of the wrong type, a plain cbrdf.Error
(a ValueError) for a value of the right type outside its domain. Never a bare TypeError,
OverflowError, RuntimeError, UnicodeError or SystemError, never pybind11's own messages, and the
message names the argument.

The cases are keyed by the package's public names (``cbrdf.__all__`` and ``cbrdf.Model``'s public
methods) and by each function's parameters (``inspect.signature``): a new function or parameter
without a case fails ``test_every_entry_point_and_parameter_has_a_case``.
"""
import inspect
import math
import os
import re
from pathlib import Path

import numpy as np
import pytest

import cbrdf

T = "type"  # the wrong type: cbrdf.ArgumentTypeError, a TypeError
V = "value"  # the right type, outside the domain: cbrdf.Error (a ValueError), not a TypeError

UNENCODABLE = "\ud800"  # a lone surrogate that no encoding (not even surrogateescape) can write

# Bad values per kind of argument, with the kind of error each must raise.
TEXT_BAD = [("\udcff", V), ("\ud800", V), ("a\udc80b", V), ("no such name", V), (5, T), (2.5, T),
            ([], T), ({}, T), (object(), T), (b"frank", T), (True, T)]
INT_BAD = [(2**40, V), (2**64, V), (-2**63, V), (-1, V), (2.5, T), (math.nan, T), (math.inf, T),
           (None, T), (True, T), ("3", T), (b"3", T), ("\udcff", T), ([], T), (object(), T),
           (1 + 0j, T)]
# bits, components, slices: an int or "auto" (a str is the right type, "3" a bad value).
COUNT_BAD = [(2**40, V), (2**64, V), (-2**63, V), (-1, V), ("3", V), ("\udcff", V), (2.5, T),
             (math.nan, T), (None, T), (True, T), (b"3", T), ([], T), (object(), T)]
REAL_BAD = [(math.nan, V), (math.inf, V), (-math.inf, V), (2**1100, V), (-1.0, V), ("0.5", T),
            ("\udcff", T), ([], T), (object(), T), (True, T), (1 + 2j, T), (b"1", T)]
FLAG_BAD = [(None, T), ("no", T), ("\udcff", T), (2.5, T), ([], T), (object(), T), (2, V),
            (-1, V)]
PATH_BAD = [(UNENCODABLE, V), ("a\x00b", V), (None, T), (5, T), (2.5, T), ([], T), (object(), T)]
SOURCE_BAD = [(UNENCODABLE, V), ("a\x00b", V), (None, T), (5, T), (2.5, T), ([], T), ({}, T),
              (object(), T)]
TABLE_BAD = [(None, T), ({}, T), (object(), T), (UNENCODABLE, V), ("a\x00b", V),
             (np.zeros((3, 90, 90)), V), (np.zeros((2, 2), complex), T), (np.array(["x"]), T),
             (np.full(cbrdf.SHAPE, np.inf), V)]
MASK_BAD = [({}, T), (object(), T), ("x", T), (np.zeros((2, 2), bool), V), (np.zeros((2, 2)), T),
            (np.zeros(cbrdf.SHAPE, complex), T)]
DIRS_BAD = [(None, T), ("x", T), ({}, T), (object(), T), (np.zeros((2, 3), complex), T),
            (np.array([[True, False, True]]), T), (np.zeros((4, 4)), V), ([1.0, 2.0], V),
            ([[math.nan, 0.0, 1.0], [0.0, 0.0, 1.0]], V),
            ([[0.0, 0.0, 1.0], [0.0, 0.0, 2.0]], V)]
U_BAD = [(None, T), ("x", T), ({}, T), (object(), T), (np.zeros((2, 2), complex), T),
         (np.zeros((4, 3)), V), ([[0.5, 0.5], [math.nan, 0.5]], V), ([0.5], V)]
INDEX_BAD = [(2**64, V), (-2**63, V), (2**40, V), (-1, V), (np.array([2**64 - 1], np.uint64), V),
             (2.5, T), (None, T), ("1", T), ("\udcff", T), (object(), T), (True, T),
             (np.array([1.5]), T), ([2**70], T)]
LIGHTS_BAD = [(None, T), (5, T), ("ab", T), ([object()], T), ([None], T), ([math.nan], V),
              ([math.inf], V), ([], V), ([2**1100], V)]
NMV_BAD = [(math.inf, V), (0.0, V), (1, V), ("x", T), (None, T), (object(), T), (True, T),
           (1j, T), ([], T)]


DEF = type("Default", (), {"__repr__": lambda self: "DEF"})()  # "the valid value" in CASES


def without(bad, *values):
    """`bad` less the cases whose value is one of `values` (the values a parameter accepts)."""
    return [(v, k) for v, k in bad if not any(v is x or (type(v) is type(x) and v == x)
                                              for x in values)]


def positive(bad):
    """A real parameter whose domain is (0, max]: 0 is refused too."""
    return bad + [(0.0, V)]


@pytest.fixture(scope="module")
def env(work, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("errors")
    table = cbrdf.sample_table("lambertian")
    model = cbrdf.decode(work / "plastic.cbrdf")
    data = (work / "plastic.cbrdf").read_bytes()
    return dict(tmp=tmp, table=table, model=model, data=data, work=work)


W = np.array([[0.0, 0.6, 0.8], [0.0, 0.0, 1.0]])
U = np.array([[0.5, 0.5], [0.25, 0.75]])


# name -> (call(env, **overrides), {parameter: bad values}). `call` passes valid values for every
# parameter not overridden, so each failure is the swept argument's.
def _model(e):
    return e["model"]


CASES = {
    "read_merl": (lambda e, source=DEF, units="physical":
                  cbrdf.read_merl(e["work"] / "plastic.binary" if source is DEF else source,
                                  units=units),
                  {"source": SOURCE_BAD, "units": TEXT_BAD + [(None, T)]}),
    "write_merl": (lambda e, path=DEF, table=DEF, mask=None, units="physical",
                   not_measured_value=-1.0:
                   cbrdf.write_merl(e["tmp"] / "w.binary" if path is DEF else path,
                                    e["table"] if table is DEF else table, mask, units=units,
                                    not_measured_value=not_measured_value),
                   {"path": PATH_BAD, "table": TABLE_BAD, "mask": MASK_BAD,
                    "units": TEXT_BAD + [(None, T)], "not_measured_value": NMV_BAD}),
    "merl_bytes": (lambda e, table=DEF, mask=None, units="physical", not_measured_value=-1.0:
                   cbrdf.merl_bytes(e["table"] if table is DEF else table, mask, units=units,
                                    not_measured_value=not_measured_value),
                   {"table": TABLE_BAD, "mask": MASK_BAD, "units": TEXT_BAD + [(None, T)],
                    "not_measured_value": NMV_BAD}),
    "encode": (lambda e, **kw: cbrdf.encode(kw.pop("table", e["table"]),
                                            **{"slices": 1, "bits": 8, **kw}),
               {"table": TABLE_BAD, "bits": COUNT_BAD, "components": COUNT_BAD,
                "slices": COUNT_BAD, "family": TEXT_BAD + [(None, T)],
                "loss": TEXT_BAD + [(None, T)], "level": INT_BAD,
                "placement": TEXT_BAD + [(None, T)], "naive_marginals": FLAG_BAD,
                "threads": INT_BAD, "target_bytes": positive(REAL_BAD),
                "target_psnr": positive(REAL_BAD), "max_error": REAL_BAD,
                "lossless": FLAG_BAD, "mask": MASK_BAD,
                "source_name": without(TEXT_BAD, "no such name"),
                "mixture_copulas": TEXT_BAD, "format_version": TEXT_BAD + [(None, T)],
                "metadata": TEXT_BAD + [(None, T)], "residual_steps": TEXT_BAD,
                "progress": [(5, T), ("x", T), (object(), T)]}),
    "decode": (lambda e, source=DEF: cbrdf.decode(e["data"] if source is DEF else source),
               {"source": SOURCE_BAD}),
    "Model": (lambda e, source=DEF: cbrdf.Model(e["data"] if source is DEF else source),
              {"source": SOURCE_BAD}),
    "info": (lambda e, source=DEF: cbrdf.info(e["data"] if source is DEF else source),
             {"source": SOURCE_BAD}),
    "sample_table": (lambda e, name="lambertian", units="physical":
                     cbrdf.sample_table(name, units=units),
                     {"name": TEXT_BAD + [(None, T)], "units": TEXT_BAD + [(None, T)]}),
    "sample": (lambda e, name="lambertian", units="physical": _deprecated_sample(name, units),
               {"name": TEXT_BAD + [(None, T)], "units": TEXT_BAD + [(None, T)]}),
    "samples": (lambda e, kind=None: cbrdf.samples(kind), {"kind": TEXT_BAD}),
    "sphere_psnr": (lambda e, reference=DEF, test=DEF, tonemapped=True, size=16,
                    light_angles=(45.0,):
                    cbrdf.sphere_psnr(e["table"] if reference is DEF else reference,
                                      e["model"] if test is DEF else test, tonemapped,
                                      size=size, light_angles=light_angles),
                    {"reference": TABLE_BAD, "test": TABLE_BAD, "tonemapped": FLAG_BAD,
                     "size": INT_BAD + [(0, V), (8193, V)], "light_angles": LIGHTS_BAD}),
    "sphere_metrics": (lambda e, reference=DEF, test=DEF, size=16, light_angles=(45.0,):
                       cbrdf.sphere_metrics(e["table"] if reference is DEF else reference,
                                            e["model"] if test is DEF else test, size=size,
                                            light_angles=light_angles),
                       {"reference": TABLE_BAD, "test": TABLE_BAD,
                        "size": INT_BAD + [(0, V), (8193, V)], "light_angles": LIGHTS_BAD}),
    "brdf_metrics": (lambda e, reference=DEF, test=DEF:
                     cbrdf.brdf_metrics(e["table"] if reference is DEF else reference,
                                        e["table"] if test is DEF else test),
                     {"reference": TABLE_BAD, "test": TABLE_BAD}),
    "estimate_noise": (lambda e, table=DEF:
                       cbrdf.estimate_noise(e["table"] if table is DEF else table),
                       {"table": TABLE_BAD}),
    "render_sphere": (lambda e, brdf=DEF, light_angle_deg=45.0, size=16:
                      cbrdf.render_sphere(e["table"] if brdf is DEF else brdf, light_angle_deg,
                                          size=size),
                      {"brdf": TABLE_BAD, "light_angle_deg": without(REAL_BAD, -1.0),
                       "size": INT_BAD + [(0, V), (8193, V)]}),
    "nearest_bin": (lambda e, wi=W, wo=W: cbrdf.nearest_bin(wi, wo),
                    {"wi": DIRS_BAD, "wo": DIRS_BAD}),
    "bin_directions": (lambda e, theta_h=1, theta_d=2, phi_d=3:
                       cbrdf.bin_directions(theta_h, theta_d, phi_d),
                       {"theta_h": INDEX_BAD, "theta_d": INDEX_BAD, "phi_d": INDEX_BAD}),
    "set_thread_limit": (lambda e, n=0: cbrdf.set_thread_limit(n),
                         {"n": INT_BAD + [(257, V)]}),
    "thread_limit": (lambda e: cbrdf.thread_limit(), {}),
    "Model.table": (lambda e, units="physical": _model(e).table(units=units),
                    {"units": TEXT_BAD + [(None, T)]}),
    "Model.eval": (lambda e, wi=W, wo=W, threads=0: _model(e).eval(wi, wo, threads),
                   {"wi": DIRS_BAD, "wo": DIRS_BAD, "threads": INT_BAD}),
    "Model.eval_pair": (lambda e, wi=W[0], wo=W[1]: _model(e).eval_pair(wi, wo),
                        {"wi": DIRS_BAD + [(W, V)], "wo": DIRS_BAD + [(W, V)]}),
    "Model.sample": (lambda e, wo=W, u=U, threads=0: _model(e).sample(wo, u, threads),
                     {"wo": DIRS_BAD, "u": U_BAD, "threads": INT_BAD}),
    "Model.sample_pdf": (lambda e, wi=W, wo=W, threads=0: _model(e).sample_pdf(wi, wo, threads),
                         {"wi": DIRS_BAD, "wo": DIRS_BAD, "threads": INT_BAD}),
    "Model.pdf": (lambda e, wo=W, wi=W, threads=0: _model(e).pdf(wo, wi, threads),
                  {"wo": DIRS_BAD, "wi": DIRS_BAD, "threads": INT_BAD}),
    "Model.bin_value": (lambda e, channel=0, theta_h=1, theta_d=2, phi_d=3:
                        _model(e).bin_value(channel, theta_h, theta_d, phi_d),
                        {"channel": INDEX_BAD + [(3, V)], "theta_h": INDEX_BAD + [(90, V)],
                         "theta_d": INDEX_BAD + [(90, V)], "phi_d": INDEX_BAD + [(180, V)]}),
    "Model.write_merl": (lambda e, path=DEF:
                         _model(e).write_merl(e["tmp"] / "m.binary" if path is DEF else path),
                         {"path": PATH_BAD}),
    "Model.close": (lambda e: cbrdf.decode(e["data"]).close(), {}),
    # Records that Model.slices builds; made by hand, they check their argument's layout.
    "Component": (lambda e, d=DEF: cbrdf.Component(_component_dict(e) if d is DEF else d),
                  {"d": [(None, T), (5, T), ([], T), ({}, V), ({"family": "frank"}, V)]}),
    "Channel": (lambda e, comps=DEF: cbrdf.Channel([_component_dict(e)] if comps is DEF
                                                    else comps),
                {"comps": [(None, T), (5, T), ([], V), ([None], T), ([{}], V)]}),
    "Slice": (lambda e, d=DEF: cbrdf.Slice(_slice_dict(e) if d is DEF else d),
              {"d": [(None, T), (5, T), ([], T), ({}, V), ({"theta_d_begin": 0}, V)]}),
}


def _deprecated_sample(name, units):
    with pytest.warns(DeprecationWarning, match="use cbrdf.sample_table"):
        return cbrdf.sample(name, units=units)


def _component_dict(e):
    return dict(_model(e)._slices[0]["channels"][0][0])


def _slice_dict(e):
    return dict(_model(e)._slices[0])


# Public names that take no arguments a caller could get wrong, and why.
EXEMPT = {
    "Error": "the exception class itself (raised, not called with user input)",
    "ArgumentTypeError": "the exception class itself",
    "CbrdfWarning": "a warning class (issued by encode, not called with user input)",
    "TargetNotMetWarning": "a warning class", "NoisyTableWarning": "a warning class",
    "Encoded": "the bytes encode returns (a bytes subclass, made by encode with its facts)",
    "ErrorCode": "a namespace of constants",
    "MerlArray": "an ndarray view (as np.asarray, any array-like); the functions that take it "
                 "check it, swept above through `table`",
    "MERL_SCALE": "a constant", "SHAPE": "a constant", "__version__": "a constant",
    "Model.__enter__": "returns the model", "Model.__exit__": "closes the model",
}


def _public_callables():
    names = [n for n in cbrdf.__all__ if callable(getattr(cbrdf, n))]
    for n in dir(cbrdf.Model):
        if n.startswith("_") and n not in ("__enter__", "__exit__"):
            continue
        if isinstance(inspect.getattr_static(cbrdf.Model, n), property):
            continue  # read-only attributes: nothing to pass
        names.append("Model." + n)
    return names


def _callable(name):
    obj = cbrdf
    for part in name.split("."):
        obj = getattr(obj, part)
    return obj


def _parameters(name):
    fn = _callable(name)
    params = inspect.signature(fn).parameters
    return [p for p in params if p != "self"]


def test_every_entry_point_and_parameter_has_a_case():
    missing = [n for n in _public_callables() if n not in CASES and n not in EXEMPT]
    assert not missing, f"public names without a case in CASES or EXEMPT: {missing}"
    for name, (_, params) in CASES.items():
        sig = _parameters(name)
        assert sorted(sig) == sorted(params), (name, sig, sorted(params))


def _sweep():
    for name, (_, params) in CASES.items():
        for param, bad in params.items():
            for i, (value, kind) in enumerate(bad):
                yield pytest.param(name, param, value, kind, id=f"{name}-{param}-{i}")


PYBIND_WORDS = ("incompatible function arguments", "Unable to cast", "_cbrdf", "pybind11",
                "Invoked with")


def check_error(err, kind, needle):
    """`err` is the documented kind of cbrdf.Error and its message names `needle`."""
    assert isinstance(err, cbrdf.Error), f"{type(err).__name__}: {err}"
    assert isinstance(err, ValueError)
    assert err.code != cbrdf.ErrorCode.INTERNAL, str(err)
    if kind == T:
        assert isinstance(err, cbrdf.ArgumentTypeError) and isinstance(err, TypeError), \
            f"{type(err).__name__} for a wrong type: {err}"
        assert err.code == cbrdf.ErrorCode.INVALID_ARGUMENT and err.exit_code == 2, repr(err)
    else:
        assert not isinstance(err, TypeError), f"a TypeError for a value: {err}"
    msg = str(err)
    for w in PYBIND_WORDS:
        assert w not in msg, msg
    assert re.search(r"(^|[^\w])" + re.escape(needle) + r"($|[^\w])", msg), \
        f"the message does not name {needle!r}: {msg}"
    msg.encode("utf-8")  # printable and loggable: no lone surrogate leaks into a message


@pytest.mark.parametrize("name,param,value,kind", list(_sweep()))
def test_bad_argument_raises_cbrdf_error(env, name, param, value, kind):
    call = CASES[name][0]
    try:
        call(env, **{param: value})
    except cbrdf.Error as err:
        check_error(err, kind, param)
    except BaseException as err:  # noqa: B902: anything else is the bug this test pins
        pytest.fail(f"{name}({param}={value!r}) raised {type(err).__name__}: {err}")
    else:
        pytest.fail(f"{name}({param}={value!r}) returned instead of raising cbrdf.Error")
    finally:
        cbrdf.set_thread_limit(0)


@pytest.mark.parametrize("name", list(CASES))
def test_valid_arguments_work(env, name):
    """Every case's baseline call succeeds, so each refusal above is the swept argument's."""
    CASES[name][0](env)


@pytest.mark.parametrize("name", list(CASES))
def test_wrong_arity_and_unknown_keywords_are_argument_type_errors(env, name):
    fn = _callable(name)
    if name.startswith("Model."):
        fn = getattr(env["model"], name.split(".")[1])
    with pytest.raises(cbrdf.ArgumentTypeError) as e:
        fn(not_a_keyword=1)
    assert isinstance(e.value, TypeError) and "not_a_keyword" in str(e.value), str(e.value)
    with pytest.raises(cbrdf.ArgumentTypeError):
        fn(*range(30))


def test_the_issues_two_calls(env):
    """The two calls of the issue: pybind11's RuntimeError and TypeError before."""
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.encode(env["table"], source_name="\udcff")
    assert not isinstance(e.value, TypeError) and "source_name" in str(e.value), str(e.value)
    with pytest.raises(cbrdf.Error) as e:
        cbrdf.set_thread_limit(2**40)
    assert not isinstance(e.value, TypeError), repr(e.value)
    assert str(e.value) == "set_thread_limit: n must be 0 to 256, not 1099511627776"


def test_non_utf8_paths_work(env):
    """Paths follow os.fsencode: a surrogate-escaped str (what os.listdir gives), a PathLike or,
    where only a path is meant, bytes name a non-UTF-8 file; bytes elsewhere are the contents."""
    tmp = os.fsencode(str(env["tmp"]))
    as_bytes = tmp + b"/t\xff.binary"
    as_text = os.fsdecode(as_bytes)
    cbrdf.write_merl(as_bytes, env["table"])
    assert os.path.exists(as_bytes)
    np.testing.assert_array_equal(cbrdf.read_merl(as_text, units="stored"),
                                  cbrdf.read_merl(Path(as_text), units="stored"))
    model_path = tmp + b"/m\xfe.cbrdf"
    with open(model_path, "wb") as f:
        f.write(env["data"])
    m = cbrdf.decode(os.fsdecode(model_path))
    assert m.file == os.fsdecode(model_path), repr(m.file)
    assert m.info["file"] == os.fsdecode(model_path)
    assert cbrdf.info(Path(os.fsdecode(model_path)))["bytes"] == len(env["data"])
    m.write_merl(tmp + b"/back\xfd.binary")
    assert os.path.exists(tmp + b"/back\xfd.binary")
    # The default source name of such a file is recorded as the command records it.
    data = cbrdf.encode(as_text, slices=1, bits=8)
    assert cbrdf.info(data)["metadata"]["source"] == "t\ufffd.binary"
    # An error naming such a path is readable text, not a UnicodeDecodeError.
    missing = os.fsdecode(tmp + b"/none\xff.cbrdf")
    for call in (lambda: cbrdf.decode(missing), lambda: cbrdf.info(missing),
                 lambda: cbrdf.read_merl(missing), lambda: cbrdf.encode(missing)):
        with pytest.raises(cbrdf.Error) as e:
            call()
        assert e.value.code == cbrdf.ErrorCode.NOT_FOUND, repr(e.value)
        assert "none\\xff.cbrdf" in str(e.value), str(e.value)
        str(e.value).encode("utf-8")
