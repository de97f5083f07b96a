# SPDX-License-Identifier: MIT
"""cbrdf: a lossy codec for MERL measured BRDFs (the copula model), from Python.

Tables are NumPy arrays of shape (3, 90, 90, 180), float64, indexed
``[channel, theta_h, theta_d, phi_d]`` (channels R, G, B; the MERL bin order),
in physical units (1/sr).  Bins that were not measured (below the horizon) are
NaN in physical arrays.  See ``help(cbrdf.read_merl)`` for the exact rules.

Quick tour::

    import cbrdf, numpy as np
    table = cbrdf.read_merl("plastic.binary")           # (3, 90, 90, 180), NaN = not measured
    data = cbrdf.encode(table, bits=10, slices=6)        # bytes of a .cbrdf file
    model = cbrdf.decode(data)                           # or cbrdf.decode("plastic.cbrdf")
    model.info                                           # what `cbrdf info --json` prints
    rgb = model.eval(wi, wo)                             # (N, 3) -> (N, 3), threaded, GIL released
    wi, pdf, weight = model.sample(wo, u)                # importance sampling
    cbrdf.sphere_psnr(table, model)                      # the report's tone-mapped sphere PSNR

Every error raises :class:`cbrdf.Error` (a ``ValueError``) carrying the stable
error code and the message the ``cbrdf`` command prints; an argument of the wrong
type raises its subclass :class:`cbrdf.ArgumentTypeError`, also a ``TypeError``.
"""

from __future__ import annotations

import functools as _functools
import math as _math
import numbers as _numbers
import operator as _operator
import os as _os
import warnings as _warnings
from typing import Any as _Any

import numpy as _np

from . import _cbrdf

__all__ = [
    "Error",
    "ArgumentTypeError",
    "ErrorCode",
    "CbrdfWarning",
    "TargetNotMetWarning",
    "NoisyTableWarning",
    "Encoded",
    "MerlArray",
    "Model",
    "Slice",
    "Channel",
    "Component",
    "read_merl",
    "write_merl",
    "merl_bytes",
    "encode",
    "decode",
    "info",
    "sample",
    "sample_table",
    "samples",
    "sphere_psnr",
    "sphere_metrics",
    "brdf_metrics",
    "estimate_noise",
    "render_sphere",
    "nearest_bin",
    "bin_directions",
    "set_thread_limit",
    "thread_limit",
    "MERL_SCALE",
    "SHAPE",
    "__version__",
]

__version__: str = _cbrdf.__version__
#: The MERL scale factors (R, G, B): physical value = stored value * scale.
MERL_SCALE: tuple = tuple(_cbrdf.MERL_SCALE)
#: The shape of every table: (channel, theta_h, theta_d, phi_d).
SHAPE = (3, 90, 90, 180)
#: The .cbrdf container version this library writes (major, minor of the newest).
CONTAINER_VERSION: tuple = tuple(_cbrdf.CONTAINER_VERSION)
#: The copula families :func:`encode` fits (``family=``, besides ``"auto"``), from the library's
#: family table: those with a parameter first, then ``"independence"``.
COPULA_FAMILIES: tuple = tuple(_cbrdf.COPULA_FAMILIES)


class ErrorCode:
    """The library's stable error codes (``cbrdf/status.h``); ``Error.code`` is one of them."""

    OK = 0
    IO = 1  #: the operating system refused a read or write
    NOT_FOUND = 2  #: a named file does not exist
    TRUNCATED = 3  #: the data ends before its declared content
    BAD_SIGNATURE = 4  #: not a file of the expected kind
    UNSUPPORTED = 5  #: a newer version or an unknown critical feature
    CORRUPT = 6  #: structurally invalid data
    CHECKSUM = 7  #: a checksum does not match
    LIMIT = 8  #: a declared size exceeds a documented maximum
    INVALID_ARGUMENT = 9  #: a caller passed a value outside its domain
    NUMERIC = 10  #: NaN, Inf or a value outside a parameter's domain in the data
    INTERNAL = 11  #: a bug in cbrdf
    CANCELLED = 12  #: the caller cancelled the operation (encode's ``progress`` returned False)

    #: code -> name, as the library names them ("corrupt", "checksum", ...)
    NAMES: dict = dict(_cbrdf.ERROR_CODES)


class Error(ValueError):
    """An error reported by the cbrdf library.

    ``str(err)`` is the message the ``cbrdf`` command prints after ``cbrdf: ``
    (naming the file, chunk and byte offset where it applies).

    Attributes:
        code: the stable numeric code (:class:`ErrorCode`, ``cbrdf::ErrorCode``).
        code_name: its name, e.g. ``"corrupt"``, ``"checksum"``, ``"not-found"``.
        exit_code: what the ``cbrdf`` command exits with for the same input:
            1 (bad data, a failed read or write) or 2 (bad usage: an option out of range).
        message: the message (the same as ``str(err)``).
    """

    def __init__(self, message: str, code: int = ErrorCode.INTERNAL,
                 code_name: str | None = None, exit_code: int = 1) -> None:
        super().__init__(message)
        self.message = message
        self.code = int(code)
        self.code_name = code_name if code_name is not None else ErrorCode.NAMES.get(code, "unknown")
        self.exit_code = int(exit_code)

    def __str__(self) -> str:
        return self.message

    def __repr__(self) -> str:
        return f"cbrdf.Error({self.message!r}, code={self.code} ({self.code_name}))"


class ArgumentTypeError(Error, TypeError):
    """An argument of the wrong type: None, a list, a str where a number goes, a float where an
    int goes, an array of strings or complex numbers.

    A :class:`cbrdf.Error` (``code`` ``ErrorCode.INVALID_ARGUMENT``, ``exit_code`` 2) and a
    ``TypeError``, so ``except cbrdf.Error`` and ``except TypeError`` both catch it.  A value of
    the right type outside its domain (``level=99``, ``2**64``, a NaN, a str with a lone
    surrogate) raises a plain :class:`cbrdf.Error`, a ``ValueError``.
    """

    def __init__(self, message: str, code: int = ErrorCode.INVALID_ARGUMENT,
                 code_name: str | None = None, exit_code: int = 2) -> None:
        super().__init__(message, code, code_name, exit_code)

    def __repr__(self) -> str:
        return f"cbrdf.ArgumentTypeError({self.message!r})"


_cbrdf._set_error_class(Error, ArgumentTypeError)


# ---- Warnings: what `cbrdf encode` prints about a file it wrote, as Python warnings ------------

class CbrdfWarning(UserWarning):
    """The base of cbrdf's warnings (``warnings.simplefilter("error", cbrdf.CbrdfWarning)``
    makes every one of them an exception; ``"ignore"`` silences them).  :func:`encode` issues
    it itself for a note of the encoder that is neither of the two below."""


class TargetNotMetWarning(CbrdfWarning):
    """:func:`encode` with ``target_psnr`` or ``target_bytes``: no setting met the target and
    the closest file was returned, as ``cbrdf encode`` says "(the target could not be met: this
    is the closest)".  The result's ``target_met`` is False; its ``psnr_tonemapped`` and ``len``
    are what was reached."""


class NoisyTableWarning(CbrdfWarning):
    """:func:`encode` with a target on a noisy table: the ladder stopped at the table's noise
    floor (or kept the model alone) because more bytes would code noise, the note ``cbrdf
    encode`` prints.  The result's ``noisy``, ``noise_sigma``, ``noise_floor_error`` and
    ``psnr_ceiling_tonemapped`` give the estimate (:func:`estimate_noise`)."""


# ---- Arguments: each public entry point checks its own, naming the function and the argument --

def _describe(v: _Any) -> str:
    if isinstance(v, _np.ndarray):
        return f"an array of dtype {v.dtype} and shape {v.shape}"
    r = ascii(v)  # ascii: a lone surrogate in the message would make it unprintable
    return r if len(r) <= 80 else r[:77] + "..."


def _usage(fn: str, message: str) -> Error:
    """A value of the right type outside its domain: bad usage, as the command's exit status 2."""
    return Error(f"{fn}: {message}", ErrorCode.INVALID_ARGUMENT, "invalid-argument", 2)


def _wrong_type(fn: str, name: str, expected: str, v: _Any) -> ArgumentTypeError:
    return ArgumentTypeError(f"{fn}: {name} must be {expected}, not {_describe(v)}")


def _named(fn: str, name: str, err: Error) -> Error:
    """The library's error about an argument, prefixed with the function and argument names."""
    cls = ArgumentTypeError if isinstance(err, ArgumentTypeError) else Error
    return cls(f"{fn}: {name}: {err.message}", err.code, err.code_name, err.exit_code)


class _FromCaller(BaseException):
    """An exception raised by a function the caller passed in (encode's progress), carried
    through _entry's net unchanged: it is the caller's, not a bad argument."""

    def __init__(self, error: BaseException):
        super().__init__(error)
        self.error = error


def _from_caller(fn):
    """`fn` with any exception it raises marked as the caller's (_FromCaller)."""
    def call(*args):
        try:
            return fn(*args)
        except Exception as e:
            raise _FromCaller(e) from None
    return call


def _entry(fn):
    """The public entry point `fn`, raising only cbrdf.Error.

    Each function checks its arguments itself, with messages naming them; this is the net
    under those checks: a TypeError (a wrong argument count or keyword, a conversion nobody
    foresaw) becomes ArgumentTypeError, a ValueError, OverflowError or UnicodeError a
    cbrdf.Error, and anything else Python raises an Error with code INTERNAL (a bug in cbrdf).
    MemoryError and KeyboardInterrupt pass through.
    """
    name = fn.__qualname__.replace(".__init__", "")

    def text(e: BaseException) -> str:
        return (str(e) or type(e).__name__).encode("utf-8", "backslashreplace").decode()

    @_functools.wraps(fn)
    def call(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except _FromCaller as e:
            raise e.error from None
        except Error:
            raise
        except TypeError as e:
            raise ArgumentTypeError(f"{name}: {text(e)}") from e
        except (ValueError, ArithmeticError, LookupError) as e:
            raise _usage(name, text(e)) from e
        except (RuntimeError, SystemError, AttributeError, BufferError) as e:
            raise Error(f"{name}: {type(e).__name__}: {text(e)}", ErrorCode.INTERNAL,
                        "internal", 1) from e

    return call


def _text(fn: str, name: str, v: _Any, none_ok: bool = False) -> str | None:
    if v is None and none_ok:
        return None
    if not isinstance(v, str):
        raise _wrong_type(fn, name, "a str or None" if none_ok else "a str", v)
    try:
        v.encode("utf-8")
    except UnicodeEncodeError as e:
        raise _usage(fn, f"{name} must be text UTF-8 can hold, not {_describe(v)} (a lone "
                         f"surrogate at index {e.start})") from None
    return v


def _int(fn: str, name: str, v: _Any, lo: int, hi: int) -> int:
    if isinstance(v, (bool, _np.bool_)) or not hasattr(type(v), "__index__"):
        raise _wrong_type(fn, name, f"an int from {lo} to {hi}", v)
    i = _operator.index(v)
    if not lo <= i <= hi:
        raise _usage(fn, f"{name} must be {lo} to {hi}, not {i}")
    return i


def _real(fn: str, name: str, v: _Any, finite: bool = True) -> float:
    if isinstance(v, (bool, _np.bool_)) or not isinstance(v, _numbers.Real):
        raise _wrong_type(fn, name, "a real number", v)
    try:
        x = float(v)
    except OverflowError:  # an int beyond the doubles
        x = _math.inf if v > 0 else -_math.inf
    if finite and not _math.isfinite(x):
        raise _usage(fn, f"{name} must be a finite number, not {_describe(v)}")
    return x


def _flag(fn: str, name: str, v: _Any) -> bool:
    """True or False (or 1 and 0): a truthy str such as "no" is refused, not read as True."""
    if isinstance(v, (bool, _np.bool_)):
        return bool(v)
    if isinstance(v, _numbers.Integral):
        if v in (0, 1):
            return bool(v)
        raise _usage(fn, f"{name} must be True or False, not {_describe(v)}")
    raise _wrong_type(fn, name, "True or False", v)


def _path(fn: str, name: str, v: _Any) -> str:
    """A path as os.fspath gives it, decoded as os.fsdecode (a non-UTF-8 name stays that name)."""
    try:
        p = _os.fspath(v)
    except TypeError:
        raise _wrong_type(fn, name, "a path (str, bytes or os.PathLike)", v) from None
    try:
        b = _os.fsencode(p)
    except UnicodeEncodeError:
        raise _usage(fn, f"{name} {_describe(p)} cannot be a file name (a lone surrogate no "
                         "encoding can write)") from None
    if b"\0" in b:
        raise _usage(fn, f"{name} must not hold a NUL byte: {_describe(p)}")
    return p if isinstance(p, str) else _os.fsdecode(p)


_DATA = (bytes, bytearray, memoryview)


class MerlArray(_np.ndarray):
    """A physical-units table that remembers the stored values it was made from.

    :func:`read_merl` and :meth:`Model.table` return this ndarray subclass.  Its
    ``stored`` attribute holds the values exactly as the .binary file stores them
    (physical / scale, not-measured values bit for bit).  :func:`write_merl` uses
    them for every bin whose physical value is unchanged, so writing an array that
    was read (or decoded) reproduces the file byte for byte, although
    ``stored * scale / scale`` does not give ``stored`` back in the last bit for
    about one value in seven.  Bins you change are converted as
    ``value / scale`` (what ``BrdfTable::set_physical`` does).  Arithmetic on a
    MerlArray gives MerlArrays with the same companion; the per-bin check keeps
    that correct.  ``np.asarray(a)`` gives a plain ndarray.
    """

    stored: _np.ndarray | None

    def __new__(cls, physical: _np.ndarray, stored: _np.ndarray | None = None) -> "MerlArray":
        obj = _np.asarray(physical).view(cls)
        obj.stored = stored
        return obj

    def __array_finalize__(self, obj: _Any) -> None:
        if obj is None:
            return
        stored = getattr(obj, "stored", None)
        self.stored = stored if stored is not None and stored.shape == self.shape else None

    def __reduce__(self):  # pickles as a plain array plus the companion
        return (MerlArray, (_np.asarray(self), self.stored))


def _physical_array(pair) -> MerlArray:
    physical, stored = pair
    stored.flags.writeable = False
    return MerlArray(physical, stored)


def _stored_array(stored: _np.ndarray) -> _np.ndarray:
    """A stored-units result: read-only, as documented (the file's values, not a working copy)."""
    stored.flags.writeable = False
    return stored


def _check_units(fn: str, units: _Any) -> None:
    if _text(fn, "units", units) not in ("physical", "stored"):
        raise _usage(fn, f"units must be 'physical' or 'stored', not {_describe(units)}")


def _is_pathlike(x: _Any) -> bool:
    return isinstance(x, (str, _os.PathLike))


def _read_table(fn: str, name: str, source: _Any):
    if isinstance(source, _DATA):
        return _cbrdf._Table.parse(source, "<bytes>")
    return _cbrdf._Table.read(_path(fn, name, source))


@_entry
def read_merl(source: _Any, *, units: str = "physical") -> _np.ndarray:
    """Read a MERL .binary file (a path, or the file's bytes) as a (3, 90, 90, 180) array.

    Args:
        source: a path (str or os.PathLike) or the file's contents (bytes-like).
            90x90x360 files are folded to 180 phi_d bins as ``cbrdf`` does.
        units: ``"physical"`` (default): float64 values in 1/sr
            (stored * :data:`MERL_SCALE`), **NaN where a bin was not measured**
            (the mask is ``np.isnan(table)``).  Returned as a :class:`MerlArray`
            that remembers the stored values, so :func:`write_merl` reproduces the
            file byte for byte.
            ``"stored"``: the file's values exactly, bit for bit (physical / scale;
            negative or NaN where not measured), as a plain read-only array.

    Raises:
        Error: what ``cbrdf info FILE`` would report (not-found, truncated,
            corrupt dims, unsupported dims, +Inf values ...).
    """
    _check_units("read_merl", units)
    physical, stored = _read_table("read_merl", "source", source).arrays()
    if units == "stored":
        return _stored_array(stored)
    return _physical_array((physical, stored))


def _shape_text(shape: tuple) -> str:
    return "(" + ", ".join(map(str, shape)) + ("," if len(shape) == 1 else "") + ")"


def _real_array(fn: str, name: str, v: _Any, kinds: str, what: str) -> _np.ndarray:
    """`v` as an array of SHAPE whose dtype kind is one of `kinds`."""
    try:
        a = _np.asarray(v)
    except (TypeError, ValueError) as e:
        raise _wrong_type(fn, name, what, v) from e
    if a.dtype.kind not in kinds:
        raise _wrong_type(fn, name, what, v)
    if a.shape != SHAPE:
        raise _usage(fn, f"{name} must have the shape (3, 90, 90, 180) (channel, theta_h, "
                         f"theta_d, phi_d), not {_shape_text(a.shape)}")
    return a


def _mask_array(fn: str, mask: _Any) -> _np.ndarray | None:
    if mask is None:
        return None
    m = _real_array(fn, "mask", mask, "biu", "None or a boolean array (True = not measured)")
    return _np.ascontiguousarray(m, dtype=bool)


_TABLE_TYPES = "a table (an array of real numbers, a path, bytes or a Model)"


def _to_table(table: _Any, mask: _Any = None, *, units: str = "physical",
              not_measured_value: float = -1.0, fn: str = "", name: str = "table"):
    """Any table-like input as the C++ table: arrays, paths, bytes, Models, _Tables."""
    return _table_maker(table, mask, units=units, not_measured_value=not_measured_value, fn=fn,
                        name=name)()


def _table_maker(table: _Any, mask: _Any = None, *, units: str = "physical",
                 not_measured_value: float = -1.0, fn: str = "", name: str = "table"):
    """What makes the C++ table of `table`, once the cheap checks (types, shapes) have passed:
    a function taking two tables checks both before it converts either."""
    if isinstance(table, _cbrdf._Table):
        return lambda: table
    if isinstance(table, _cbrdf._Model):
        return table._table
    if _is_pathlike(table) or isinstance(table, _DATA):
        if not isinstance(table, _DATA):
            table = _path(fn, name, table)
        return lambda: _read_table(fn, name, table)
    _check_units(fn, units)
    m = _mask_array(fn, mask)
    nmv = _real(fn, "not_measured_value", not_measured_value, finite=False)
    if not (nmv < 0 or _math.isnan(nmv)):
        raise _usage(fn, "not_measured_value must be negative or NaN (what MERL files store for "
                         f"bins that were not measured), not {_describe(not_measured_value)}")
    a = _real_array(fn, name, table, "fiub", _TABLE_TYPES)
    # The stored values a MerlArray remembers; any other companion is ignored (it only keeps
    # unchanged bins' bits).
    companion = getattr(table, "stored", None)
    if not (isinstance(companion, _np.ndarray) and companion.shape == SHAPE
            and companion.dtype == _np.float64):
        companion = None

    def make():
        try:
            if units == "stored":
                return _cbrdf._Table.from_stored(_np.asarray(a, dtype=_np.float64), m, nmv)
            return _cbrdf._Table.from_physical(_np.asarray(a, dtype=_np.float64), m, companion,
                                               nmv)
        except Error as e:
            raise _named(fn, name, e) from None

    return make


@_entry
def write_merl(path: _Any, table: _Any, mask: _Any = None, *, units: str = "physical",
               not_measured_value: float = -1.0) -> None:
    """Write a table as a MERL .binary (90x90x180), byte-exact with the ``cbrdf`` command.

    The file is written by the same C++ writer as ``cbrdf decode -o`` (atomically:
    a temporary beside it, renamed over it).

    Args:
        path: the output path.
        table: a (3, 90, 90, 180) array (or a :class:`Model`, written as its table).
        mask: optional boolean array of the same shape, True where a bin was not
            measured.  Without it, NaN marks not-measured bins (physical units).
        units: ``"physical"`` (default; value / scale is stored, except that
            unchanged bins of a :class:`MerlArray` keep their stored bits) or
            ``"stored"`` (written verbatim: negative or NaN values are not-measured).
        not_measured_value: the stored value written for not-measured bins that
            have no remembered value (negative or NaN; MERL files use -1).

    Raises:
        Error: a measured value that is negative, NaN (with a mask) or infinite, a
            wrong shape, or a failed write (naming the file).
    """
    path = _path("write_merl", "path", path)
    _to_table(table, mask, units=units, not_measured_value=not_measured_value, fn="write_merl",
              name="table").write(path)


@_entry
def merl_bytes(table: _Any, mask: _Any = None, *, units: str = "physical",
               not_measured_value: float = -1.0) -> bytes:
    """The bytes :func:`write_merl` would write (34,992,012 of them)."""
    return _to_table(table, mask, units=units, not_measured_value=not_measured_value,
                     fn="merl_bytes", name="table").serialize()


@_entry
def samples(kind: str | None = None) -> list:
    """The built-in sample materials, as (name, description) pairs (``cbrdf sample --list``).

    Measured ones (neural fits of real MERL measurements) come first, then analytic ones.

    Args:
        kind: ``"measured"`` or ``"analytic"`` lists only that kind; None lists all.
    """
    if _text("samples", "kind", kind, none_ok=True) not in (None, "measured", "analytic"):
        raise _usage("samples", f"kind must be 'measured', 'analytic' or None, not {kind!r}")
    return [(n, d) for n, k, d in _cbrdf.samples() if kind is None or k == kind]


def _sample_table(fn: str, name: str, units: str) -> _np.ndarray:
    _text(fn, "name", name)
    _check_units(fn, units)
    try:
        t = _cbrdf._Table.sample(name)
    except Error as e:
        raise _named(fn, "name", e) from None
    physical, stored = t.arrays()
    return _stored_array(stored) if units == "stored" else _physical_array((physical, stored))


@_entry
def sample_table(name: str, *, units: str = "physical") -> _np.ndarray:
    """A built-in sample material as a table (what ``cbrdf sample NAME -o FILE`` writes).

    Args:
        name: one of :func:`samples` (e.g. ``"plastic"``).
        units: as in :func:`read_merl`.
    """
    return _sample_table("sample_table", name, units)


@_entry
def sample(name: str, *, units: str = "physical") -> _np.ndarray:
    """Deprecated name of :func:`sample_table` (the same table); warns DeprecationWarning.

    Renamed because :meth:`Model.sample` draws directions, not tables.
    """
    _warnings.warn("cbrdf.sample(name) is deprecated: use cbrdf.sample_table(name); "
                   "Model.sample draws directions", DeprecationWarning, stacklevel=3)
    return _sample_table("sample", name, units)


@_entry
def encode(table: _Any, *, bits: int | str = "auto", components: int | str = 1, slices: int | str = 6,
           family: str = "frank", loss: str = "linear", level: int = 19,
           placement: str = "uniform", naive_marginals: bool = False, threads: int = 0,
           target_bytes: float | None = None, target_psnr: float | None = None,
           max_error: float | None = None, lossless: bool = False,
           mask: _Any = None, source_name: str | None = None,
           mixture_copulas: str | None = None, format_version: str = "auto",
           metadata: str = "short", residual_steps: str | None = None,
           progress: _Any = None) -> Encoded:
    """Fit the copula model to a table and return the bytes of a .cbrdf file.

    With the same input and options the bytes equal those ``cbrdf encode`` writes
    (the fit does not depend on the thread count).

    Args:
        table: a path to a MERL .binary (as ``cbrdf encode PATH``), the file's
            bytes, or a (3, 90, 90, 180) physical array (NaN or ``mask`` = not
            measured; see :func:`write_merl` for the conversion).
        bits: bits per quantized marginal value, 6 to 16 (the quality knob), or
            ``"auto"``: the fewest bits costing at most 0.05 dB tone-mapped and 0.5 dB
            linear sphere PSNR against the unquantized model (``--bits``).
        components: copula components per slice and channel, 1 (the paper's
            model) to 8, or ``"auto"`` (``--components``).
        slices: theta_d slices, 1 to 90, or ``"auto"`` (``--slices``).
        family: ``"frank"`` (the paper's), ``"clayton"``, ``"gumbel"``, ``"joe"``,
            ``"independence"`` or ``"auto"`` (``--family``).
        loss: what the fit minimizes: ``"linear"``, ``"cosine"`` or ``"log"`` (``--loss``).
        level: zstd level 1 to 22: the effort knob (``--level``).
        placement: slice boundaries, ``"uniform"`` or ``"adaptive"`` (``--slice-placement``).
        naive_marginals: the paper's marginals, missing bins as 0 (``--naive-marginals``).
        threads: fitting threads, 0 = the library's limit (``--threads``).
        target_bytes: search slices, components and bits for the best tone-mapped
            sphere PSNR within this many bytes (``--target-bytes``).
        target_psnr: search for the fewest bytes reaching this tone-mapped PSNR
            in dB (``--target-psnr``).  Give at most one target, and neither with
            ``max_error`` or ``lossless`` (refused: the target chooses the residual
            layer itself).  Either target
            searches the whole ladder: the model alone, then the model plus the
            residual layer (container 1.2) when the model cannot reach it.
        max_error: add the residual layer: every measured bin decodes within this
            bound, ``|log1p(decoded / k) - log1p(source / k)| <= max_error`` on
            stored values with k = 1e-4 (scaled down with a table whose values are
            all below 1; a relative bound, 1e-6 to 16;
            ``--max-error``).
        residual_steps: how ``max_error`` bounds the layer: ``"one"`` (every
            measured bin within it, the default) or ``"visibility"`` (it bounds the
            most visible rows, with coarser steps where bins count less in rendered
            images, as a target writes: fewer bytes for the same picture)
            (``--residual-steps``; needs ``max_error``).
        lossless: add the residual layer that makes the decoded table equal to the
            source bit for bit (``--lossless``; excludes ``max_error``).
        mask: with an array, True where a bin was not measured.
        source_name: recorded in the file's metadata; defaults to the input file's
            name (as ``cbrdf encode`` records it), or nothing for arrays.
        mixture_copulas: with 2 or more components, ``"fit"`` each component's
            copula or leave them at ``"independence"`` (about half the fit's time;
            in the 1.2 coding also 6% fewer bytes for about the same tone-mapped
            PSNR per byte).
            ``None``: fit, except that a target searches at independence
            (``--mixture-copulas``).
        format_version: the container's coding: ``"auto"`` (1.3 where smaller),
            ``"1.2"`` (the 1.0-1.2 chunks, for older readers) or ``"1.3"``
            (``--format-version``).
        metadata: the metadata chunk: ``"none"``, ``"short"`` (source file name and
            encoder) or ``"full"`` (also bits and zstd level) (``--metadata``).
        progress: ``None``, or a function ``progress(fraction, stage)`` called on the
            calling thread at least every 50 ms while the encoder works: ``fraction``
            the share done, 0 to 1 and never decreasing (negative when it cannot be
            estimated), ``stage`` one of ``"fit"``, ``"bits"``, ``"residual"``,
            ``"target"``. Returning ``False`` cancels the encode (cbrdf.Error with
            code ``ErrorCode.CANCELLED``); any other return value, ``None`` included,
            goes on. An exception it raises stops the encode and propagates.

    Returns:
        The .cbrdf file's bytes, as an :class:`Encoded` (a ``bytes`` with what the encoder
        chose and found as attributes: ``target_met``, ``psnr_tonemapped``, ``note``,
        ``noisy``, ...).

    Warns:
        TargetNotMetWarning: no setting met ``target_psnr`` or ``target_bytes``; the closest
            file is returned.  The message is the command's: ``"encode: target_psnr=50: 1885
            bytes, 45.60 dB tone-mapped (the target could not be met: this is the closest)"``.
        NoisyTableWarning: with a target, the table is noisy and the search stopped at its
            noise floor (the command's note, e.g. ``"encode: the input is noisy (about 3% per
            bin, see cbrdf info): stopped at its noise floor ..."``).
        CbrdfWarning: any other note of the encoder (a residual layer that cannot be written
            on the table).

    Raises:
        Error: an option out of range (``exit_code`` 2, the message naming every bad
            option as its keyword, ``max_error=``, with its valid values, in the
            library's words, the same as the command's), a table the encoder refuses
            (``exit_code`` 1), or a cancel by ``progress`` (code ``CANCELLED``).
        ArgumentTypeError: an option of the wrong type (a cbrdf.Error and a TypeError).

    The encode runs on the calling thread with the GIL released; it stops within
    about 50 ms of Ctrl-C (KeyboardInterrupt, when called from the main thread), of
    ``progress`` returning False or raising, and leaves no work running behind.
    """
    naive_marginals = _flag("encode", "naive_marginals", naive_marginals)
    lossless = _flag("encode", "lossless", lossless)
    if progress is not None and not callable(progress):
        raise _wrong_type("encode", "progress", "None or a function (fraction, stage)", progress)
    if progress is not None:
        progress = _from_caller(progress)
    # The options are checked in C++ by the library's validate(), before the table is made.
    data, facts = _cbrdf._encode(_table_maker(table, mask, fn="encode", name="table"), bits, components, slices, family, loss, level, placement,
                                 naive_marginals, threads, target_bytes, target_psnr, max_error,
                                 lossless, source_name, mixture_copulas, format_version,
                                 metadata, residual_steps, progress)
    nbytes = facts.pop("nbytes", None)
    result = Encoded(data, **facts)
    _encode_warnings(result, nbytes)
    return result


class Encoded(bytes):
    """The bytes of a .cbrdf file as :func:`encode` returns them: a ``bytes`` (compare, slice,
    write or decode it as one) that also carries what the encoder chose and found, the facts
    ``cbrdf encode`` prints.  ``None`` where an encode has no such fact.

    Attributes:
        bits: bits per marginal code in the file (chosen by ``bits="auto"`` or the search).
        target_psnr, target_bytes: the target asked for, or None.
        target_met: with a target, whether the file meets it (False: the closest file, with a
            :class:`TargetNotMetWarning`); None without one.
        psnr_tonemapped, psnr_linear: with a target, the file's sphere PSNR (dB) against the
            input, as the search measured it.
        slices, components, max_error: with a target, the setting chosen (``max_error`` 0: no
            residual layer).
        settings_tried: with a target, how many settings the search measured.
        note: with a target, the encoder's note ("the input is noisy ...") or None; issued as
            a warning too.
        residual_of_smoothed_input: with a target, whether the residual layer codes the input
            with its noise smoothed out (its bound then holds against that, not the input).
        noisy, noise_sigma: when a target was missed or the encoder left a note, the noise
            estimate (:func:`estimate_noise`): any channel above the noise-free threshold, and
            the largest channel's relative deviation (0.03: 3% per bin).
        noise_floor_error, psnr_ceiling_tonemapped: for a noisy table, the smallest residual
            bound worth coding and the tone-mapped PSNR beyond which a file reproduces noise
            (dB; NaN where not measurable); None otherwise.
    """

    _FACTS = ("bits", "target_psnr", "target_bytes", "target_met", "psnr_tonemapped",
              "psnr_linear", "slices", "components", "max_error", "settings_tried", "note",
              "residual_of_smoothed_input", "noisy", "noise_sigma", "noise_floor_error",
              "psnr_ceiling_tonemapped")

    def __new__(cls, data: bytes = b"", **facts: _Any) -> "Encoded":
        self = super().__new__(cls, data)
        for k in cls._FACTS:
            setattr(self, k, facts.get(k))
        return self


def _encode_warnings(result: Encoded, nbytes: float | None) -> None:
    """The warnings of an encode: what `cbrdf encode` prints about the file, in its words."""
    if result.target_met is False:
        given = (f"target_psnr={result.target_psnr:g}" if result.target_psnr is not None
                 else f"target_bytes={result.target_bytes:g}")
        _warnings.warn(TargetNotMetWarning(
            f"encode: {given}: {nbytes:.0f} bytes, {result.psnr_tonemapped:.2f} dB tone-mapped "
            f"(the target could not be met: this is the closest)"), stacklevel=4)
    if result.note:
        category = NoisyTableWarning if result.noisy else CbrdfWarning
        _warnings.warn(category(f"encode: {result.note}"), stacklevel=4)


def _record(fn: str, name: str, d: _Any, keys: tuple) -> None:
    """A dict as Model.slices builds them, with every key."""
    if not isinstance(d, dict):
        raise _wrong_type(fn, name, "a dict", d)
    missing = [k for k in keys if k not in d]
    if missing:
        raise _usage(fn, f"{name} lacks the keys {missing}")


class Component:
    """One copula term of a slice channel: K c(F1, F2, F3; theta) f1 f2 f3.

    Attributes:
        family: the copula family (``"frank"``, ``"clayton"``, ...).
        theta: the family's parameter in its own convention.
        scale: K, the term's sum over the slice's bins (physical units).
        pdf_h, pdf_d, pdf_p: the marginal probability masses per bin (theta_h: 90,
            theta_d: the slice's width, phi_d: 180), each summing to 1.
    """

    __slots__ = ("family", "theta", "scale", "pdf_h", "pdf_d", "pdf_p")

    @_entry
    def __init__(self, d: dict) -> None:
        _record("Component", "d", d, self.__slots__)
        for k in self.__slots__:
            setattr(self, k, d[k])

    def __repr__(self) -> str:
        return f"Component(family={self.family!r}, theta={self.theta:.6g}, scale={self.scale:.6g})"


class Channel:
    """One colour channel of a slice: a list of :class:`Component` (more than one in a mixture).

    ``family``, ``theta`` and ``scale`` are those of the first component (what
    ``cbrdf info`` shows).
    """

    __slots__ = ("components",)

    @_entry
    def __init__(self, comps: list) -> None:
        if not isinstance(comps, (list, tuple)):
            raise _wrong_type("Channel", "comps", "a list of component dicts", comps)
        if not comps:
            raise _usage("Channel", "comps must hold at least one component")
        for i, c in enumerate(comps):
            _record("Channel", f"comps[{i}]", c, Component.__slots__)
        self.components = [Component(c) for c in comps]

    family = property(lambda self: self.components[0].family)
    theta = property(lambda self: self.components[0].theta)
    scale = property(lambda self: self.components[0].scale)

    def __repr__(self) -> str:
        extra = f", components={len(self.components)}" if len(self.components) > 1 else ""
        return f"Channel(family={self.family!r}, theta={self.theta:.6g}, scale={self.scale:.6g}{extra})"


class Slice:
    """A theta_d slice of the model: bins ``theta_d_begin`` to ``theta_d_end - 1``.

    Attributes:
        theta_d_begin, theta_d_end: the slice's theta_d bins (1 degree each).
        channels: three :class:`Channel` (R, G, B).
    """

    __slots__ = ("theta_d_begin", "theta_d_end", "channels")

    @_entry
    def __init__(self, d: dict) -> None:
        _record("Slice", "d", d, self.__slots__)
        self.theta_d_begin = d["theta_d_begin"]
        self.theta_d_end = d["theta_d_end"]
        self.channels = [Channel(c) for c in d["channels"]]

    def __repr__(self) -> str:
        fams = "/".join(c.family for c in self.channels)
        return f"Slice(theta_d={self.theta_d_begin}-{self.theta_d_end - 1}, {fams})"


class Model(_cbrdf._Model):
    """A decoded .cbrdf model, ready to evaluate (``cbrdf::ModelEvaluator``).

    Make one with :func:`decode`.  A Model holds a few hundred kilobytes, and with a
    residual layer (container 1.2) that layer's 17 to 53 MB (``footprint_bytes``
    counts it); free it early with :meth:`close` or a ``with`` block.  Every method is thread-safe;
    the batch methods release the GIL.

    Directions are unit vectors in the local frame (z = the normal), as arrays of
    shape (N, 3) or a single (3,) vector (broadcast against the other argument).

    Properties: ``info`` (the dict ``cbrdf info --json`` prints), ``slices``
    (:class:`Slice` list), ``bits``, ``version``, ``nbytes`` (the file's size),
    ``not_measured_bins``, ``footprint_bytes`` (the evaluator's tables), ``file``
    (the path, or None), ``closed``.
    """

    @_entry
    def __init__(self, source: _Any) -> None:
        if not isinstance(source, _DATA):
            _path("Model", "source", source)
        super().__init__(source)

    @property
    def slices(self) -> list:
        """The slices with their families, parameters, scales and marginals."""
        return [Slice(s) for s in self._slices]

    @_entry
    def close(self) -> None:
        """Frees the evaluator's tables now (also at the end of a ``with`` block); the model is
        unusable afterwards (``closed`` is True)."""
        super().close()

    @_entry
    def table(self, *, units: str = "physical") -> _np.ndarray:
        """The full MERL table (as ``cbrdf decode -o`` writes it).

        Model values at measured bins; not-measured bins are NaN (physical) or the
        source's stored values bit for bit (``units="stored"``).  Returns a
        :class:`MerlArray`, so ``write_merl(path, model.table())`` writes the same
        bytes as ``cbrdf decode``.
        """
        _check_units("Model.table", units)
        physical, stored = self._table_arrays()
        if units == "stored":
            return _stored_array(stored)
        return _physical_array((physical, stored))

    @_entry
    def eval(self, wi: _Any, wo: _Any, threads: int = 0) -> _np.ndarray:  # noqa: D401
        """The BRDF value (physical RGB, 1/sr) at direction pairs.

        Args:
            wi, wo: (N, 3) arrays of unit vectors (or one (3,) vector, broadcast).
            threads: at most this many threads (0: the library's limit).  One call of
                the batch kernels (``ModelEvaluator::eval_batch``), with the GIL released,
                in chunks of 2048 pairs over the library's thread pool.

        Returns:
            (N, 3) (or (3,) for two single vectors).  When both inputs are float32
            the float32 evaluator (``eval_batch_f32``, equal to ``eval_f32`` per pair bit
            for bit) is used and the result is float32; otherwise float64, equal to
            ``ModelEvaluator::eval`` per pair bit for bit.  C-contiguous float32 or
            float64 arrays are read in place; others are copied once.
            0 at or below the horizon, and 0 where wi or wo is exactly (0, 0, 0), the
            wi of a rejected draw of :meth:`sample` (see :meth:`sample_pdf`).

        Raises:
            Error: any other direction that is not a finite unit vector (|w|^2 within
                1e-3 of 1), naming its index; mismatched lengths or shapes.
        """
        return super().eval(wi, wo, threads)

    @_entry
    def eval_pair(self, wi: _Any, wo: _Any) -> tuple:
        """One pair through ``ModelEvaluator::eval`` directly: an (r, g, b) tuple (a reference
        for :meth:`eval`, which is equal to it bit for bit)."""
        return super().eval_pair(wi, wo)

    @_entry
    def sample(self, wo: _Any, u: _Any, threads: int = 0) -> tuple:
        """Importance-sample incident directions (``cbrdf::BrdfSampler``, default settings).

        Args:
            wo: (N, 3) outgoing unit vectors (or one (3,) vector).
            u: (N, 2) uniform numbers in [0, 1) (clamped into it): one array of
                pairs (u1, u2), e.g. ``np.stack([u1, u2], axis=-1)``.
            threads: at most this many threads (0: the library's limit).

        Returns:
            ``(wi, pdf, weight)``: wi (N, 3) unit vectors, pdf (N,) per unit solid
            angle, weight (N, 3) = f(wi, wo) * cos(theta_i) / pdf.  A rejected
            sample (wo at or below the horizon, or wi reflected below it) has
            wi = 0, pdf = 0 and weight = 0.  As ``cbrdf_model_sample_batch``
            (``BrdfSampler::sample_batch``, with the GIL released), equal to
            ``cbrdf_model_sample`` per draw bit for bit.
        """
        if not isinstance(threads, int) and _np.ndim(threads) > 0:
            # sample(wo, u1, u2): the third argument is threads, and numpy's own refusal of an
            # array there ("only integer scalar arrays ...") would not say why.
            raise ArgumentTypeError(
                f"Model.sample takes (wo, u, threads=0): u is one (N, 2) array of pairs "
                f"(u1, u2), e.g. np.stack([u1, u2], axis=-1), and threads an int, not "
                f"{_describe(threads)} (a built-in table is cbrdf.sample_table(name))")
        return super().sample(wo, u, threads)

    @_entry
    def sample_pdf(self, wi: _Any, wo: _Any, threads: int = 0) -> _np.ndarray:
        """The sampler's density of drawing wi given wo, per unit solid angle: the pdf
        :meth:`sample` returns for a drawn wi (``cbrdf_model_sample_pdf``).

        Args:
            wi, wo: (N, 3) arrays of unit vectors (or one (3,) vector, broadcast), in the
                (wi, wo) order of :meth:`eval`.
            threads: at most this many threads (0: the library's limit).

        Returns:
            (N,) float64 (a float for two single vectors).  0 when wi or wo is at or below
            the horizon, and 0 where either is exactly (0, 0, 0), the wi of a rejected draw,
            so that :meth:`sample`'s output passes on unchecked::

                wi, pdf, weight = model.sample(wo, u)
                f = model.eval(wi, wo)           # 0 for rejected draws
                p = model.sample_pdf(wi, wo)     # equal to pdf; 0 for rejected draws

        Raises:
            Error: any other direction that is not a finite unit vector (|w|^2 within
                1e-3 of 1), naming its index; mismatched lengths or shapes.
        """
        return super().sample_pdf(wi, wo, threads)

    @_entry
    def pdf(self, wo: _Any, wi: _Any, threads: int = 0) -> _np.ndarray:
        """Deprecated: :meth:`sample_pdf` with its arguments in the other order (wo, wi);
        warns DeprecationWarning and returns ``sample_pdf(wi, wo, threads)``."""
        _warnings.warn("Model.pdf(wo, wi) is deprecated: use Model.sample_pdf(wi, wo), whose "
                       "arguments are in the (wi, wo) order of eval", DeprecationWarning,
                       stacklevel=3)
        return super().sample_pdf(wi, wo, threads)

    @_entry
    def bin_value(self, channel: _Any, theta_h: _Any, theta_d: _Any, phi_d: _Any):
        """The model's physical value at MERL bins (``ModelEvaluator::bin_value``).

        Arguments are integers or integer arrays (broadcast together): channel
        0-2, theta_h 0-89, theta_d 0-89, phi_d 0-179.  Ignores the not-measured
        mask.  Returns a float or a float64 array.
        """
        return super().bin_value(channel, theta_h, theta_d, phi_d)

    @_entry
    def write_merl(self, path: _Any) -> None:
        """Write the model's table as a MERL .binary, byte-identical to ``cbrdf decode -o``."""
        super().write_merl(_path("Model.write_merl", "path", path))

    def __enter__(self) -> "Model":
        return self

    def __exit__(self, *exc: _Any) -> None:
        self.close()

    def __repr__(self) -> str:
        if self.closed:
            return "<cbrdf.Model (closed)>"
        src = f" {self.file!r}" if self.file is not None else ""
        return (f"<cbrdf.Model{src}: version {self.version[0]}.{self.version[1]}, "
                f"{self.nbytes} bytes, {len(self._slices)} slices, {self.bits} bits>")


@_entry
def decode(source: _Any) -> Model:
    """Decode a .cbrdf file (a path, or its bytes) into a :class:`Model`.

    Runs the library's full validation (signature, version, chunk bounds,
    checksums, limits, every payload).

    Raises:
        Error: with the code and message ``cbrdf decode`` reports (e.g. code
            ``ErrorCode.CHECKSUM``, "x.cbrdf: chunk 'MARG' at offset 64: ...").
    """
    if isinstance(source, _DATA):
        return Model(bytes(source))
    return Model(_path("decode", "source", source))


@_entry
def info(source: _Any) -> dict:
    """What ``cbrdf info --json`` prints for a .cbrdf or MERL .binary (a path or bytes), as a dict.

    ``json.loads(subprocess.check_output(["cbrdf", "info", "--json", path]))``
    equals ``cbrdf.info(path)`` (for bytes ``file`` is None).
    """
    if isinstance(source, _DATA):
        return _cbrdf._info_bytes(source)
    return _cbrdf._info_path(_path("info", "source", source))


def _metric_table(fn: str, name: str, x: _Any):
    return _table_maker(x, fn=fn, name=name)


def _size(fn: str, size: _Any) -> int:
    return _int(fn, "size", size, 1, 8192)


def _angles(fn: str, name: str, v: _Any) -> list:
    if isinstance(v, (str, bytes)) or not hasattr(v, "__iter__"):
        raise _wrong_type(fn, name, "a sequence of angles in degrees", v)
    out = [_real(fn, f"{name}[{i}]", a) for i, a in enumerate(v)]
    if not out:
        raise _usage(fn, f"{name} must name at least one angle")
    return out


@_entry
def sphere_metrics(reference: _Any, test: _Any, *, size: int = 256,
                   light_angles: tuple = (10.0, 45.0, 75.0)) -> dict:
    """Sphere-image PSNRs of ``test`` against ``reference`` (``cbrdf::sphere_psnr``).

    Both are tables (arrays, paths to .binary files) or :class:`Model` objects
    (measured through their decoded table, as ``cbrdf encode`` and the report
    do).  The defaults are the report's (256 pixels, lights at 10, 45, 75 deg).

    Returns:
        ``{"psnr_linear", "psnr_tonemapped", "per_light": [{"light_angle_deg",
        "psnr_linear": (r, g, b), "psnr_tonemapped": (r, g, b), "exposure"}]}``;
        means over lights and channels in dB, capped at 100 dB.
    """
    return _sphere_metrics("sphere_metrics", reference, test, size, light_angles)


def _sphere_metrics(fn: str, reference: _Any, test: _Any, size: _Any, light_angles: _Any):
    size = _size(fn, size)
    angles = _angles(fn, "light_angles", light_angles)
    ref, tst = _metric_table(fn, "reference", reference), _metric_table(fn, "test", test)
    return _cbrdf._sphere_metrics(ref(), tst(), size, angles)


@_entry
def sphere_psnr(reference: _Any, test: _Any, tonemapped: bool = True, *, size: int = 256,
                light_angles: tuple = (10.0, 45.0, 75.0)) -> float:
    """The report's sphere PSNR in dB: tone-mapped (default) or linear.

    What ``cbrdf encode`` prints as "sphere PSNR of the decoded file against the
    input" and the report's ``psnr_tonemapped`` / ``psnr_linear`` columns.  See
    :func:`sphere_metrics` for the arguments.
    """
    tonemapped = _flag("sphere_psnr", "tonemapped", tonemapped)
    m = _sphere_metrics("sphere_psnr", reference, test, size, light_angles)
    return m["psnr_tonemapped"] if tonemapped else m["psnr_linear"]


@_entry
def brdf_metrics(reference: _Any, test: _Any) -> dict:
    """The report's BRDF-space errors over the reference's measured bins (``cbrdf::brdf_metrics``).

    Returns:
        ``{"rel_rmse", "log_rmse", "cos_rmse"}`` (means over channels, the
        report's columns), the per-channel ``"rel_rmse_rgb"``, ``"log_rmse_rgb"``,
        ``"cos_rmse_rgb"`` and ``"bins"`` (measured bins per channel).
    """
    ref = _metric_table("brdf_metrics", "reference", reference)
    tst = _metric_table("brdf_metrics", "test", test)
    return _cbrdf._brdf_metrics(ref(), tst())


@_entry
def estimate_noise(table: _Any) -> dict:
    """The table's measurement noise, estimated from the table alone (``cbrdf::estimate_noise``).

    ``table`` is an array or a path to a .binary file.  The same as the ``"noise"``
    entry of :func:`info` on a .binary file and of ``cbrdf info --json``.

    Returns:
        ``{"sigma": {"R", "G", "B"}`` (relative deviation: 0.03 is 3%; near 0 for a
        smooth table), ``"bands"`` (``[{"theta_d_begin", "theta_d_end", "sigma"}]``,
        six bands of 15 degrees), ``"grazing_growth"`` (the last band's sigma over the
        first's), ``"noisy"``, ``"psnr_ceiling_tonemapped"``, ``"psnr_ceiling_linear"``
        (dB: coding closer to the table than this reproduces its noise; the string
        ``"not measurable"`` where it cannot be measured, e.g. when the simulated noise
        overflows a table whose values span 1e-30 to 1e30)``}``.
    """
    return _cbrdf._estimate_noise(_to_table(table, fn="estimate_noise", name="table"))


@_entry
def render_sphere(brdf: _Any, light_angle_deg: float = 45.0, *, size: int = 256) -> _np.ndarray:
    """The metrics' sphere image: a (size, size, 3) float32 linear radiance image.

    A table (array or path) is looked up at the nearest bin; a :class:`Model` is
    evaluated continuously (``ModelEvaluator::eval``).  View along -z, one light
    at ``light_angle_deg`` from the view direction (see ``cbrdf/metrics.h``).
    """
    light = _real("render_sphere", "light_angle_deg", light_angle_deg)
    size = _size("render_sphere", size)
    if isinstance(brdf, _cbrdf._Model):
        return brdf._render(light, size)
    return _cbrdf._render_table(_metric_table("render_sphere", "brdf", brdf)(), light, size)


@_entry
def nearest_bin(wi: _Any, wo: _Any) -> tuple:
    """The MERL bins of direction pairs: ``(theta_h, theta_d, phi_d)`` int64 index arrays.

    The reference MERL reader's nearest-bin lookup (``cbrdf::nearest_bin``), so
    ``table[:, h, d, p].T`` is the table's value at the pairs.
    """
    return _cbrdf.nearest_bin(wi, wo)


@_entry
def bin_directions(theta_h: _Any, theta_d: _Any, phi_d: _Any) -> tuple:
    """The direction pairs ``(wi, wo)`` at MERL bins' grid angles (phi_h = 0).

    Arguments are integer indices (arrays broadcast together); the results have
    their shape plus a trailing 3.  theta_h = (i/90)^2 * 90 deg, theta_d = j deg,
    phi_d = k deg: where ``Model.eval`` equals ``Model.bin_value`` up to rounding.
    """
    return _cbrdf.bin_directions(theta_h, theta_d, phi_d)


@_entry
def set_thread_limit(n: int) -> None:
    """Cap the threads every parallel loop uses (fitting, eval, metrics): 1 to 256; 0 = one per
    hardware thread (the default)."""
    _cbrdf.set_thread_limit(_int("set_thread_limit", "n", n, 0, 256))


@_entry
def thread_limit() -> int:
    """The thread limit in force."""
    return _cbrdf.thread_limit()
