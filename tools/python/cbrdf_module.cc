// SPDX-License-Identifier: MIT
// The `cbrdf._cbrdf` Python extension: MERL tables as NumPy arrays, encode/decode, the model's
// evaluation and sampling (vectorized, GIL released, threaded), the report's metrics. The public
// Python API is tools/python/cbrdf/__init__.py; this file holds the C++ half and raises
// cbrdf.Error (set by __init__.py through _set_error_class) for every Status the library returns.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/coords.h"
#include "cbrdf/encoder.h"
#include "cbrdf/file_io.h"
#include "cbrdf/fit.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/model.h"
#include "cbrdf/noise.h"
#include "cbrdf/parallel.h"
#include "cbrdf/rate_control.h"
#include "cbrdf/samples.h"
#include "cbrdf/sampling.h"
#include "cbrdf/version.h"
#include "encoder_options.h"
#include "info_json.h"
#include "metrics.h"
#include "parallel_for.h"

namespace py = pybind11;

namespace cbrdf::python {
namespace {

// ---- Errors ---------------------------------------------------------------------------------

// cbrdf.Error (a ValueError subclass defined in __init__.py); ValueError until it is set.
py::object& error_class() {
  static py::object* cls = new py::object(py::reinterpret_borrow<py::object>(PyExc_ValueError));
  return *cls;
}

// cbrdf.ArgumentTypeError (cbrdf.Error and TypeError) for an argument of the wrong type.
py::object& type_error_class() {
  static py::object* cls = new py::object(py::reinterpret_borrow<py::object>(PyExc_TypeError));
  return *cls;
}

// Message text: a path's bytes need not be UTF-8, and a message must still become a str.
py::str text(const std::string& s) {
  return py::reinterpret_steal<py::str>(
      PyUnicode_DecodeUTF8(s.data(), py::ssize_t(s.size()), "backslashreplace"));
}

[[noreturn]] void raise_as(const py::object& cls, const Status& s, int exit_code) {
  py::object inst;
  if (cls.ptr() == PyExc_ValueError || cls.ptr() == PyExc_TypeError) {
    inst = cls(text(s.message()));
  } else {
    inst = cls(text(s.message()), int(s.code()), error_code_name(s.code()), exit_code);
  }
  PyErr_SetObject(cls.ptr(), inst.ptr());
  throw py::error_already_set();
}

// Raises cbrdf.Error(message, code, code_name, exit_code): exit_code is what `cbrdf` would exit
// with (1 bad data, 2 bad usage).
[[noreturn]] void raise_status(const Status& s, int exit_code = 1) {
  raise_as(error_class(), s, exit_code);
}

[[noreturn]] void raise_invalid(const std::string& message, int exit_code = 1) {
  raise_status(error(ErrorCode::kInvalidArgument, message), exit_code);
}

// An argument of the wrong type (None, a list, a str for a number): bad usage, exit code 2.
[[noreturn]] void raise_type(const std::string& message) {
  raise_as(type_error_class(), error(ErrorCode::kInvalidArgument, message), 2);
}

// The repr of a Python value, for messages (at most about 80 characters).
std::string repr_text(const py::handle& v) {
  std::string r = py::reinterpret_steal<py::str>(PyObject_ASCII(v.ptr())).cast<std::string>();
  return r.size() > 80 ? r.substr(0, 77) + "..." : r;
}

template <typename T>
T take(Expected<T>&& e, const std::string& context = {}) {
  if (!e.ok()) raise_status(context.empty() ? e.status() : e.status().with_context(context));
  return std::move(e).value();
}

std::vector<std::uint8_t> bytes_of(const py::handle& b) {
  // Any buffer, in its logical (C) order: a strided view (memoryview(x)[::-1], [::2]) is copied
  // element by element as bytes(view) does, never read as if it were contiguous.
  Py_buffer view;
  if (PyObject_GetBuffer(b.ptr(), &view, PyBUF_FULL_RO) != 0) {
    PyErr_Clear();
    raise_type("data must be bytes-like (bytes, bytearray, memoryview), not " + repr_text(b));
  }
  std::vector<std::uint8_t> out(std::size_t(view.len));
  const int rc = PyBuffer_ToContiguous(out.data(), &view, view.len, 'C');
  PyBuffer_Release(&view);
  if (rc != 0) throw py::error_already_set();
  return out;
}

// A path from Python: an embedded NUL would cut it short at the system call, so refuse it as
// Python's open() does.
const std::string& checked_path(const std::string& path) {
  if (path.find('\0') != std::string::npos) raise_invalid("path must not hold a NUL byte", 2);
  return path;
}

// A path argument (str, bytes or os.PathLike) as the bytes the system call gets: os.fsencode, so
// a name os.listdir gave with undecodable bytes (surrogate-escaped) names that same file.
std::string path_arg(const py::handle& v, const char* name = "path") {
  PyObject* p = PyOS_FSPath(v.ptr());
  if (p == nullptr) {
    PyErr_Clear();
    raise_type(std::string(name) + " must be a str, bytes or os.PathLike, not " + repr_text(v));
  }
  py::object fs = py::reinterpret_steal<py::object>(p);
  if (py::isinstance<py::str>(fs)) {
    PyObject* b = PyUnicode_EncodeFSDefault(fs.ptr());
    if (b == nullptr) {
      PyErr_Clear();
      raise_invalid(std::string(name) + " " + repr_text(fs) +
                        " cannot be a file name (a lone surrogate no encoding can write)",
                    2);
    }
    fs = py::reinterpret_steal<py::object>(b);
  }
  std::string path = fs.cast<std::string>();
  if (path.find('\0') != std::string::npos) {
    raise_invalid(std::string(name) + " must not hold a NUL byte, not " + repr_text(v), 2);
  }
  return path;
}

// An int argument in lo..hi: a Python int or a NumPy integer (not a bool, not a float), any size.
long long int_arg(const py::handle& v, const char* name, long long lo, long long hi,
                  int exit_code = 2) {
  const std::string range = std::to_string(lo) + " to " + std::to_string(hi);
  if (py::isinstance<py::bool_>(v) || !PyIndex_Check(v.ptr()) || py::isinstance<py::float_>(v)) {
    raise_type(std::string(name) + " must be an int from " + range + ", not " + repr_text(v));
  }
  py::object i = py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()));
  if (!i) throw py::error_already_set();
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow != 0 || x < lo || x > hi) {
    raise_invalid(std::string(name) + " must be " + range + ", not " + repr_text(v), exit_code);
  }
  return x;
}

// A str argument (not None, not a number), text UTF-8 can hold (no lone surrogate).
std::string str_arg(const py::handle& v, const char* name, int exit_code = 2) {
  if (!py::isinstance<py::str>(v)) {
    raise_type(std::string(name) + " must be a str, not " + repr_text(v));
  }
  py::ssize_t size = 0;
  const char* utf8 = PyUnicode_AsUTF8AndSize(v.ptr(), &size);
  if (utf8 == nullptr) {
    PyErr_Clear();
    raise_invalid(std::string(name) + " must be text UTF-8 can hold, not " + repr_text(v) +
                      " (a lone surrogate)",
                  exit_code);
  }
  return std::string(utf8, std::size_t(size));
}

// The `threads` argument of the batch methods: 0 (the library's limit) to 256, as --threads.
int threads_arg(const py::handle& v) {
  return int(int_arg(v, "threads", 0, 256, 2));
}

// ---- Tables <-> arrays ----------------------------------------------------------------------

constexpr std::size_t kTableValues = std::size_t(kChannels) * kBinsPerChannel;

using F64Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using F32Array = py::array_t<float, py::array::c_style | py::array::forcecast>;
using BoolArray = py::array_t<bool, py::array::c_style | py::array::forcecast>;

F64Array new_table_array() {
  return F64Array(std::vector<py::ssize_t>{kChannels, kThetaHBins, kThetaDBins, kPhiDBins});
}

void check_table_shape(const py::array& a, const char* what) {
  const bool ok = a.ndim() == 4 && a.shape(0) == kChannels && a.shape(1) == kThetaHBins &&
                  a.shape(2) == kThetaDBins && a.shape(3) == kPhiDBins;
  if (!ok) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) {
      shape += (i ? ", " : "") + std::to_string(a.shape(i));
    }
    shape += a.ndim() == 1 ? ",)" : ")";
    raise_invalid(std::string(what) + " must have the shape (3, 90, 90, 180) (channel, theta_h, " +
                  "theta_d, phi_d), not " + shape);
  }
}

std::string bin_name(std::size_t flat) {
  const int c = int(flat / kBinsPerChannel);
  const BinIndex b = merl_bin(flat % kBinsPerChannel);
  return "[" + std::to_string(c) + ", " + std::to_string(b.theta_h) + ", " +
         std::to_string(b.theta_d) + ", " + std::to_string(b.phi_d) + "]";
}

void check_not_measured_value(double v) {
  if (!(v < 0.0) && !std::isnan(v)) {
    raise_invalid(
        "not_measured_value must be negative or NaN (what MERL files store for bins "
        "that were not measured), not " +
        std::to_string(v));
  }
}

// The physical array (NaN where not measured) and the stored one (the file's values, bit for bit).
std::pair<F64Array, F64Array> table_arrays(const BrdfTable& t) {
  F64Array physical = new_table_array();
  F64Array stored = new_table_array();
  double* p = physical.mutable_data();
  double* s = stored.mutable_data();
  const double* src = t.stored_values().data();
  std::memcpy(s, src, kTableValues * sizeof(double));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int c = 0; c < kChannels; ++c) {
    const double scale = kMerlScale[std::size_t(c)];
    const std::size_t o = std::size_t(c) * kBinsPerChannel;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const double v = src[o + i];
      p[o + i] = v >= 0.0 ? v * scale : nan;
    }
  }
  return {std::move(physical), std::move(stored)};
}

// Physical values (NaN or mask = not measured) back to a table. `companion` holds stored values
// the array came from (cbrdf.MerlArray.stored): a bin whose physical value is still exactly
// companion * scale gets the companion's bits back, so an unmodified array is written byte for
// byte; other bins get value / scale, as BrdfTable::set_physical computes it.
BrdfTable table_from_physical(const F64Array& physical, const std::optional<BoolArray>& mask,
                              const std::optional<F64Array>& companion, double not_measured_value) {
  check_table_shape(physical, "the table");
  if (mask) check_table_shape(*mask, "the mask");
  if (companion) check_table_shape(*companion, "the stored companion");
  check_not_measured_value(not_measured_value);
  BrdfTable t;
  double* out = t.stored_values().data();
  const double* p = physical.data();
  const bool* m = mask ? mask->data() : nullptr;
  const double* comp = companion ? companion->data() : nullptr;
  for (int c = 0; c < kChannels; ++c) {
    const double scale = kMerlScale[std::size_t(c)];
    const std::size_t o = std::size_t(c) * kBinsPerChannel;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const std::size_t k = o + i;
      const double v = p[k];
      const bool not_measured = m ? m[k] : std::isnan(v);
      if (not_measured) {
        out[k] = comp && !(comp[k] >= 0.0) ? comp[k] : not_measured_value;
        continue;
      }
      if (std::isnan(v) || std::isinf(v) || v < 0.0) {
        raise_status(error(ErrorCode::kNumeric,
                           "the table holds " + std::to_string(v) + " at " + bin_name(k) +
                               " (a measured value must be finite and >= 0; mark bins that were "
                               "not measured with NaN or the mask)"));
      }
      if (comp && comp[k] >= 0.0 && comp[k] * scale == v &&
          std::signbit(comp[k]) == std::signbit(v)) {
        out[k] = comp[k];
      } else {
        out[k] = v / scale;
      }
    }
  }
  return t;
}

// Stored values as a file holds them (negative or NaN = not measured), mask bins set to
// not_measured_value.
BrdfTable table_from_stored(const F64Array& stored, const std::optional<BoolArray>& mask,
                            double not_measured_value) {
  check_table_shape(stored, "the table");
  if (mask) check_table_shape(*mask, "the mask");
  check_not_measured_value(not_measured_value);
  BrdfTable t;
  double* out = t.stored_values().data();
  const double* s = stored.data();
  const bool* m = mask ? mask->data() : nullptr;
  for (std::size_t k = 0; k < kTableValues; ++k) {
    if (m && m[k]) {
      out[k] = not_measured_value;
      continue;
    }
    if (std::isinf(s[k]) && s[k] > 0) {
      raise_status(error(ErrorCode::kNumeric, "the table holds +inf at " + bin_name(k) +
                                                  " (refused, as read_merl refuses it)"));
    }
    out[k] = s[k];
  }
  return t;
}

// pybind11 gives a Python instance whose __init__ never ran (cbrdf.Model.__new__(cbrdf.Model))
// uninitialized C++ memory; with this class-specific operator new that memory is zero, so
// `constructed` is false there and every method refuses such an object instead of reading it.
struct ZeroedUntilConstructed {
  bool constructed = true;
  static void* operator new(std::size_t n) {
    void* p = ::operator new(n);
    std::memset(p, 0, n);
    return p;
  }
  static void operator delete(void* p) { ::operator delete(p); }
  void check(const char* what) const {
    if (!constructed) {
      raise_invalid(std::string("this ") + what +
                    " was made by __new__ without __init__ and holds nothing; make one with " +
                    (std::string(what) == "cbrdf.Model" ? "cbrdf.decode()" : "cbrdf.read_merl()"));
    }
  }
};

// An opaque table for the Python layer (cbrdf._Table): what encode, the metrics and write_merl
// take, made from arrays, a file or a built-in sample.
struct PyTable : ZeroedUntilConstructed {
  BrdfTable table;
  std::string source_name;  // the file name `cbrdf encode` records, when read from a file
  std::string name;         // the path as given, prefixed to encode's errors as the command does
  bool folded_from_360 = false;  // read from a 90x90x360 file (its two phi_d halves averaged)
  const PyTable& ok() const {
    check("cbrdf._Table");
    return *this;
  }
};

PyTable read_table(const std::string& path) {
  PyTable t;
  MerlInfo mi;
  t.table = take(read_merl(checked_path(path), {}, &mi));
  t.folded_from_360 = mi.folded_from_360;
  t.source_name = std::filesystem::path(path).filename().string();
  t.name = path;
  return t;
}

// ---- Info dictionaries (exactly `cbrdf info --json`: the command's own builder) -------------

// `j` as a Python dict through its JSON text, with "file" set.
py::dict info_dict(const nlohmann::json& j, const py::object& file) {
  py::dict d = py::module_::import("json").attr("loads")(cli::dump_json(j, -1));
  d["file"] = file;
  return d;
}

bool is_container(const std::vector<std::uint8_t>& bytes) {
  return bytes.size() >= kContainerSignature.size() &&
         std::equal(kContainerSignature.begin(), kContainerSignature.end(), bytes.begin());
}

// `cbrdf info --json` for the bytes of a .cbrdf or a .binary; `name` prefixes error messages.
py::dict info_of_bytes(const std::vector<std::uint8_t>& bytes, const std::string& name,
                       const py::object& file) {
  if (is_container(bytes)) {
    ContainerInfo info;
    auto model = take(decode_model(bytes, &info), name);
    const std::size_t evaluator_bytes = ModelEvaluator(std::move(model)).footprint_bytes();
    return info_dict(cli::container_info_json(info, evaluator_bytes), file);
  }
  MerlInfo mi;
  auto table = take(parse_merl(bytes, name, {}, &mi));
  return info_dict(cli::merl_info_json(table, mi), file);
}

// ---- Directions -----------------------------------------------------------------------------

// How far a direction's squared length may be from 1 (as the C API: float directions pass).
constexpr double kUnitTolerance = 1e-3;

// A batch of 3-vectors: (N, 3) or a single (3,) broadcast to every row.
template <typename T>
struct Dirs {
  py::array_t<T, py::array::c_style | py::array::forcecast> array;
  const T* data = nullptr;
  std::size_t n = 0;
  bool single = false;
  std::size_t width = 3;  // values per row: 3 for directions, 2 for u pairs
  const T* at(std::size_t k) const { return single ? data : data + width * k; }
};

template <typename T>
Dirs<T> dirs_of(const py::handle& obj, const char* name, std::size_t width = 3) {
  Dirs<T> d;
  // Real numbers only: a cast would drop a complex value's imaginary part and read bools,
  // strings and datetimes as numbers.
  py::array given;
  try {
    given = py::module_::import("numpy").attr("asarray")(obj);
  } catch (py::error_already_set&) {
    raise_type(std::string(name) + " must be an array of numbers, not " + repr_text(obj));
  }
  const char kind = given.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    raise_type(std::string(name) + " must hold real numbers (float or int), not dtype " +
               std::string(py::str(given.dtype())) + " (" + repr_text(obj) + ")");
  }
  d.array = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(given);
  if (!d.array) {
    PyErr_Clear();
    raise_type(std::string(name) + " must be an array of numbers");
  }
  const py::ssize_t w = py::ssize_t(width);
  d.width = width;
  if (d.array.ndim() == 1 && d.array.shape(0) == w) {
    d.single = true;
    d.n = 1;
  } else if (d.array.ndim() == 2 && d.array.shape(1) == w) {
    d.n = std::size_t(d.array.shape(0));
  } else {
    raise_invalid(std::string(name) + " must have the shape (N, " + std::to_string(width) +
                  ") or (" + std::to_string(width) + ",)");
  }
  d.data = d.array.data();
  return d;
}

// The number of rows of a batch of arguments: equal, or 1 for broadcast singles.
std::size_t batch_rows(std::initializer_list<std::pair<std::size_t, bool>> parts,
                       const char* what) {
  std::size_t n = 0;
  bool any = false;
  for (const auto& [rows, single] : parts) {
    if (single) continue;
    if (any && rows != n) {
      raise_invalid(std::string(what) + ": the arrays have different lengths (" +
                    std::to_string(n) + " and " + std::to_string(rows) + ")");
    }
    n = rows;
    any = true;
  }
  return any ? n : 1;
}

template <typename T>
void check_directions(const Dirs<T>& d, std::size_t n, const char* name) {
  const std::size_t rows = d.single ? 1 : n;
  for (std::size_t k = 0; k < rows; ++k) {
    const T* w = d.at(k);
    const double x = double(w[0]), y = double(w[1]), z = double(w[2]);
    const bool finite = std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
    if (finite && std::fabs(x * x + y * y + z * z - 1.0) <= kUnitTolerance) continue;
    char buf[128];
    std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", x, y, z);
    const std::string what =
        d.single ? std::string(name) : std::string(name) + "[" + std::to_string(k) + "]";
    raise_invalid(what + " must be a finite unit vector, not " + buf);
  }
}

// body(begin, end) over [0, n) in blocks on the library's threads (inline for small n).
template <typename Fn>
void for_blocks(std::size_t n, int max_threads, const Fn& body) {
  constexpr std::size_t kBlock = 4096;
  if (n <= 2 * kBlock || max_threads == 1) {
    body(std::size_t{0}, n);
    return;
  }
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  internal::parallel_for(int(std::min<std::size_t>(blocks, std::size_t(INT32_MAX))), max_threads,
                         [&](int b) {
                           const std::size_t begin = std::size_t(b) * kBlock;
                           body(begin, std::min(n, begin + kBlock));
                         });
}

// body(begin, end) over [0, n) in chunks run with the GIL released; between chunks, with the GIL
// held, pending signals are handled, so Ctrl-C raises KeyboardInterrupt within one chunk's time
// (about 30 ms for eval at 2^17 pairs on one core) instead of after the whole batch.
template <typename Fn>
void interruptible(std::size_t n, const Fn& body) {
  constexpr std::size_t kChunk = std::size_t{1} << 17;
  for (std::size_t begin = 0; begin < n; begin += kChunk) {
    const std::size_t end = std::min(n, begin + kChunk);
    {
      py::gil_scoped_release release;
      body(begin, end);
    }
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
}

Vec3 vec3(const double* w) {
  return Vec3{w[0], w[1], w[2]};
}

// The MERL bins of direction pairs (the reference reader's nearest-bin lookup).
py::tuple nearest_bins(const py::handle& wi_obj, const py::handle& wo_obj) {
  const Dirs<double> wi = dirs_of<double>(wi_obj, "wi");
  const Dirs<double> wo = dirs_of<double>(wo_obj, "wo");
  const std::size_t n = batch_rows({{wi.n, wi.single}, {wo.n, wo.single}}, "nearest_bin");
  check_directions(wi, n, "wi");
  check_directions(wo, n, "wo");
  const bool single = wi.single && wo.single;
  const std::vector<py::ssize_t> shape =
      single ? std::vector<py::ssize_t>{} : std::vector<py::ssize_t>{py::ssize_t(n)};
  py::array_t<std::int64_t> h(shape), d(shape), p(shape);
  std::int64_t* hp = h.mutable_data();
  std::int64_t* dp = d.mutable_data();
  std::int64_t* pp = p.mutable_data();
  for (std::size_t k = 0; k < n; ++k) {
    const BinIndex b = merl_bin(nearest_bin(vec3(wi.at(k)), vec3(wo.at(k))));
    hp[k] = b.theta_h;
    dp[k] = b.theta_d;
    pp[k] = b.phi_d;
  }
  return py::make_tuple(h, d, p);
}

py::array_t<std::int64_t> index_array(const py::object& v, const char* name);

// The direction pair (wi, wo) at bins' grid angles (phi_h = 0), as the metrics and the table use.
py::tuple bin_directions(const py::object& theta_h, const py::object& theta_d,
                         const py::object& phi_d) {
  py::module_ np = py::module_::import("numpy");
  py::tuple b;
  const auto h_in = index_array(theta_h, "theta_h"), d_in = index_array(theta_d, "theta_d"),
             p_in = index_array(phi_d, "phi_d");
  try {
    b = np.attr("broadcast_arrays")(h_in, d_in, p_in);
  } catch (py::error_already_set&) {
    raise_invalid(
        "theta_h, theta_d and phi_d must broadcast together, not shapes " +
        repr_text(py::make_tuple(h_in.attr("shape"), d_in.attr("shape"), p_in.attr("shape"))));
  }
  using I64 = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
  const I64 h = I64::ensure(b[0]), d = I64::ensure(b[1]), p = I64::ensure(b[2]);
  std::vector<py::ssize_t> shape(h.shape(), h.shape() + h.ndim());
  shape.push_back(3);
  py::array_t<double> wi(shape), wo(shape);
  double* wip = wi.mutable_data();
  double* wop = wo.mutable_data();
  const auto n = std::size_t(h.size());
  for (std::size_t k = 0; k < n; ++k) {
    const std::int64_t hh = h.data()[k], dd = d.data()[k], pp = p.data()[k];
    if (hh < 0 || hh >= kThetaHBins || dd < 0 || dd >= kThetaDBins || pp < 0 || pp >= kPhiDBins) {
      raise_invalid("bin (theta_h, theta_d, phi_d) = (" + std::to_string(hh) + ", " +
                    std::to_string(dd) + ", " + std::to_string(pp) +
                    ") is outside the MERL grid (90, 90, 180)");
    }
    HalfDiff hd;
    hd.theta_h = theta_h_of(double(hh));
    hd.theta_d = theta_d_of(double(dd));
    hd.phi_d = phi_d_of(double(pp));
    Vec3 a, c;
    from_half_diff(hd, &a, &c);
    wip[3 * k] = a.x;
    wip[3 * k + 1] = a.y;
    wip[3 * k + 2] = a.z;
    wop[3 * k] = c.x;
    wop[3 * k + 1] = c.y;
    wop[3 * k + 2] = c.z;
  }
  return py::make_tuple(wi, wo);
}

// ---- Model ----------------------------------------------------------------------------------

struct PyModel : ZeroedUntilConstructed {
  std::shared_ptr<const ModelEvaluator> evaluator;
  // The file's description, from the same validating pass that decoded the model.
  ContainerInfo info_;
  std::size_t file_bytes = 0;
  py::object file = py::none();
  std::mutex sampler_mutex;
  std::shared_ptr<const BrdfSampler> sampler;

  const ContainerInfo& info() const {
    check("cbrdf.Model");
    return info_;
  }
  std::shared_ptr<const ModelEvaluator> ev() const {
    check("cbrdf.Model");
    if (!evaluator) raise_invalid("the model is closed");
    return evaluator;
  }
  std::shared_ptr<const BrdfSampler> get_sampler() {
    auto e = ev();
    std::lock_guard<std::mutex> lock(sampler_mutex);
    if (!sampler) sampler = std::make_shared<const BrdfSampler>(make_model_sampler(e));
    return sampler;
  }
};

std::unique_ptr<PyModel> model_from_bytes(const std::vector<std::uint8_t>& bytes,
                                          const std::string& name, py::object file) {
  auto m = std::make_unique<PyModel>();
  Expected<Model> model = Model{};
  {
    py::gil_scoped_release release;
    model = decode_model(bytes, &m->info_);
  }
  m->evaluator = std::make_shared<const ModelEvaluator>(take(std::move(model), name));
  m->file_bytes = bytes.size();
  m->file = std::move(file);
  return m;
}

// `file` is the path as the caller gave it (Model.file), `path` its bytes.
std::unique_ptr<PyModel> model_from_path(const std::string& path, py::object file) {
  auto bytes = take(read_file(checked_path(path), kMaxContainerBytes));
  return model_from_bytes(bytes, path, std::move(file));
}

template <typename T>
py::array eval_batch(const ModelEvaluator& ev, const py::handle& wi_obj, const py::handle& wo_obj,
                     int threads) {
  const Dirs<T> wi = dirs_of<T>(wi_obj, "wi");
  const Dirs<T> wo = dirs_of<T>(wo_obj, "wo");
  const std::size_t n = batch_rows({{wi.n, wi.single}, {wo.n, wo.single}}, "eval");
  check_directions(wi, n, "wi");
  check_directions(wo, n, "wo");
  py::array_t<T> out = wi.single && wo.single
                           ? py::array_t<T>(std::vector<py::ssize_t>{3})
                           : py::array_t<T>(std::vector<py::ssize_t>{py::ssize_t(n), 3});
  T* rgb = out.mutable_data();
  interruptible(n, [&](std::size_t first, std::size_t last) {
    // Two (N, 3) float64 batches: the evaluator's batch path (vectorized stages, its own
    // threads), equal to eval per pair bit for bit. (No Python object is touched here.)
    if constexpr (std::is_same_v<T, double>) {
      if (!wi.single && !wo.single) {
        ev.eval_batch(last - first, wi.data + 3 * first, wo.data + 3 * first, rgb + 3 * first,
                      threads);
        return;
      }
    }
    for_blocks(last - first, threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = first + begin; k < first + end; ++k) {
        if constexpr (std::is_same_v<T, float>) {
          ev.eval_f32(wi.at(k), wo.at(k), rgb + 3 * k);
        } else {
          ev.eval(vec3(wi.at(k)), vec3(wo.at(k)), rgb + 3 * k);
        }
      }
    });
  });
  return out;
}

bool is_float32(const py::handle& obj) {
  if (!py::isinstance<py::array>(obj)) return false;
  return py::reinterpret_borrow<py::array>(obj).dtype().is(py::dtype::of<float>());
}

py::array model_eval(PyModel& m, const py::handle& wi, const py::handle& wo,
                     const py::object& threads_obj) {
  auto ev = m.ev();
  const int threads = threads_arg(threads_obj);
  if (is_float32(wi) && is_float32(wo)) return eval_batch<float>(*ev, wi, wo, threads);
  return eval_batch<double>(*ev, wi, wo, threads);
}

py::tuple model_sample(PyModel& m, const py::handle& wo_obj, const py::handle& u_obj,
                       const py::object& threads_obj) {
  auto ev = m.ev();
  const int threads = threads_arg(threads_obj);
  const Dirs<double> wo = dirs_of<double>(wo_obj, "wo");
  const Dirs<double> u = dirs_of<double>(u_obj, "u", 2);
  const std::size_t n = batch_rows({{wo.n, wo.single}, {u.n, u.single}}, "sample");
  check_directions(wo, n, "wo");
  for (std::size_t k = 0; k < (u.single ? 1 : n); ++k) {
    const double* uk = u.at(k);
    if (!std::isfinite(uk[0]) || !std::isfinite(uk[1])) {
      raise_invalid("u[" + std::to_string(k) + "] must be two finite numbers in [0, 1)");
    }
  }
  auto sampler = m.get_sampler();
  const bool single = wo.single && u.single;
  py::array_t<double> wi_out =
      single ? py::array_t<double>(std::vector<py::ssize_t>{3})
             : py::array_t<double>(std::vector<py::ssize_t>{py::ssize_t(n), 3});
  py::array_t<double> pdf_out = single
                                    ? py::array_t<double>(std::vector<py::ssize_t>{})
                                    : py::array_t<double>(std::vector<py::ssize_t>{py::ssize_t(n)});
  py::array_t<double> w_out =
      single ? py::array_t<double>(std::vector<py::ssize_t>{3})
             : py::array_t<double>(std::vector<py::ssize_t>{py::ssize_t(n), 3});
  double* wi_p = wi_out.mutable_data();
  double* pdf_p = pdf_out.mutable_data();
  double* w_p = w_out.mutable_data();
  // As cbrdf_model_sample_batch: u clamped into [0, 1); a rejected sample is all zeros.
  const double below_one = std::nextafter(1.0, 0.0);
  interruptible(n, [&](std::size_t first, std::size_t last) {
    for_blocks(last - first, threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = first + begin; k < first + end; ++k) {
        const Vec3 o = vec3(wo.at(k));
        const double u1 = std::clamp(u.at(k)[0], 0.0, below_one);
        const double u2 = std::clamp(u.at(k)[1], 0.0, below_one);
        const BrdfSample s = sampler->sample(o, u1, u2);
        double* i = wi_p + 3 * k;
        double* w = w_p + 3 * k;
        double f[3] = {0, 0, 0};
        if (s.valid) ev->eval(s.wi, o, f);
        if (!s.valid || !(s.pdf > 0)) {
          i[0] = i[1] = i[2] = 0.0;
          pdf_p[k] = 0.0;
          w[0] = w[1] = w[2] = 0.0;
          continue;
        }
        i[0] = s.wi.x;
        i[1] = s.wi.y;
        i[2] = s.wi.z;
        pdf_p[k] = s.pdf;
        for (int c = 0; c < 3; ++c) w[c] = f[c] * s.wi.z / s.pdf;
      }
    });
  });
  return py::make_tuple(wi_out, pdf_out, w_out);
}

py::array model_pdf(PyModel& m, const py::handle& wo_obj, const py::handle& wi_obj,
                    const py::object& threads_obj) {
  m.ev();
  const int threads = threads_arg(threads_obj);
  const Dirs<double> wo = dirs_of<double>(wo_obj, "wo");
  const Dirs<double> wi = dirs_of<double>(wi_obj, "wi");
  const std::size_t n = batch_rows({{wo.n, wo.single}, {wi.n, wi.single}}, "pdf");
  check_directions(wo, n, "wo");
  check_directions(wi, n, "wi");
  auto sampler = m.get_sampler();
  const bool single = wo.single && wi.single;
  py::array_t<double> out = single ? py::array_t<double>(std::vector<py::ssize_t>{})
                                   : py::array_t<double>(std::vector<py::ssize_t>{py::ssize_t(n)});
  double* p = out.mutable_data();
  interruptible(n, [&](std::size_t first, std::size_t last) {
    for_blocks(last - first, threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = first + begin; k < first + end; ++k) {
        p[k] = sampler->pdf(vec3(wo.at(k)), vec3(wi.at(k)));
      }
    });
  });
  return out;
}

// Bin indices: ints or integer arrays, never truncated floats, bools, strings or objects.
py::array_t<std::int64_t> index_array(const py::object& v, const char* name) {
  if (py::isinstance<py::int_>(v) && !py::isinstance<py::bool_>(v)) {
    int overflow = 0;
    const long long x = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
    if (overflow != 0) raise_invalid(std::string(name) + " is out of range: " + repr_text(v));
    return py::array_t<std::int64_t>::ensure(py::int_(x));
  }
  py::array a;
  try {
    a = py::module_::import("numpy").attr("asarray")(v);
  } catch (py::error_already_set&) {
    raise_type(std::string(name) + " must be an int or an integer array, not " + repr_text(v));
  }
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u') {
    raise_type(std::string(name) + " must be an int or an integer array, not " + repr_text(v));
  }
  if (kind == 'u' && a.size() > 0 &&
      a.attr("max")().cast<std::uint64_t>() > std::uint64_t(INT64_MAX)) {
    raise_invalid(std::string(name) + " is out of range: " + repr_text(v));
  }
  return py::array_t<std::int64_t>::ensure(a);
}

py::object model_bin_value(PyModel& m, const py::object& channel, const py::object& theta_h,
                           const py::object& theta_d, const py::object& phi_d) {
  auto ev = m.ev();
  auto f = [ev](std::int64_t c, std::int64_t h, std::int64_t d, std::int64_t p) -> double {
    auto range = [](const char* name, std::int64_t v, int hi) {
      if (v < 0 || v >= hi) {
        raise_invalid(std::string(name) + " must be 0 to " + std::to_string(hi - 1) + ", not " +
                      std::to_string(v));
      }
    };
    range("channel", c, kChannels);
    range("theta_h", h, kThetaHBins);
    range("theta_d", d, kThetaDBins);
    range("phi_d", p, kPhiDBins);
    return ev->bin_value(int(c), int(h), int(d), int(p));
  };
  auto c = index_array(channel, "channel"), h = index_array(theta_h, "theta_h"),
       d = index_array(theta_d, "theta_d"), p = index_array(phi_d, "phi_d");
  try {
    py::module_::import("numpy").attr("broadcast_shapes")(c.attr("shape"), h.attr("shape"),
                                                          d.attr("shape"), p.attr("shape"));
  } catch (py::error_already_set&) {
    raise_invalid("channel, theta_h, theta_d and phi_d must broadcast together, not shapes " +
                  repr_text(py::make_tuple(c.attr("shape"), h.attr("shape"), d.attr("shape"),
                                           p.attr("shape"))));
  }
  return py::vectorize(f)(c, h, d, p);
}

py::array_t<double> to_array(const std::vector<double>& v) {
  py::array_t<double> a(py::ssize_t(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// Slices as plain Python objects (types.SimpleNamespace-like dicts are built in __init__.py).
py::list model_slices(PyModel& m) {
  auto ev = m.ev();
  py::list out;
  for (const Slice& s : ev->model().slices) {
    py::list channels;
    for (const ChannelSlice& cs : s.channel) {
      py::list comps;
      for (int r = 0; r < cs.components(); ++r) {
        const Component& c = cs.component(r);
        py::dict d;
        d["family"] = std::string(family_name(c.family));
        d["theta"] = c.theta;
        d["scale"] = c.scale;
        d["pdf_h"] = to_array(c.pdf_h);
        d["pdf_d"] = to_array(c.pdf_d);
        d["pdf_p"] = to_array(c.pdf_p);
        comps.append(d);
      }
      channels.append(comps);
    }
    py::dict d;
    d["theta_d_begin"] = s.theta_d_begin;
    d["theta_d_end"] = s.theta_d_end;
    d["channels"] = channels;
    out.append(d);
  }
  return out;
}

// ---- Encoding -------------------------------------------------------------------------------

// Jobs abandoned by Ctrl-C that are still running, and what a normal exit waits for: the fit has
// no cancellation point, so such a job finishes on its own thread and its result is dropped.
std::mutex g_abandoned_mutex;
std::condition_variable g_abandoned_done;
int g_abandoned = 0;

void wait_for_abandoned_jobs() {
  std::unique_lock<std::mutex> lock(g_abandoned_mutex);
  g_abandoned_done.wait(lock, [] { return g_abandoned == 0; });
}

// Runs job() on a thread of its own while this thread, with the GIL, handles signals every 20 ms:
// Ctrl-C raises KeyboardInterrupt within that time instead of when the job returns (an encode can
// take tens of seconds). An interrupted job is left to finish in the background (see above).
template <typename Job>
Expected<std::vector<std::uint8_t>> interruptible_job(Job job) {
  struct State {
    std::mutex mutex;
    std::condition_variable done_cv;
    bool done = false, abandoned = false;
    Expected<std::vector<std::uint8_t>> result = std::vector<std::uint8_t>{};
  };
  auto state = std::make_shared<State>();
  std::thread worker([state, job = std::move(job)]() mutable {
    Expected<std::vector<std::uint8_t>> r = std::vector<std::uint8_t>{};
    try {
      r = job();
    } catch (const std::exception& e) {
      r = error(ErrorCode::kInternal, std::string("encoding failed: ") + e.what());
    }
    std::lock_guard<std::mutex> lock(state->mutex);
    state->result = std::move(r);
    state->done = true;
    state->done_cv.notify_all();
    if (state->abandoned) {
      std::lock_guard<std::mutex> g(g_abandoned_mutex);
      --g_abandoned;
      g_abandoned_done.notify_all();
    }
  });
  for (;;) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(state->mutex);
      if (state->done_cv.wait_for(lock, std::chrono::milliseconds(20),
                                  [&] { return state->done; })) {
        break;
      }
    }
    if (PyErr_CheckSignals() != 0) {
      std::lock_guard<std::mutex> lock(state->mutex);
      if (state->done) break;  // finished meanwhile: joined below, the signal still raised
      state->abandoned = true;
      {
        std::lock_guard<std::mutex> g(g_abandoned_mutex);
        if (g_abandoned++ == 0) {
          // Registered after the library's thread pool exists, so it runs before the pool's
          // destructor: a normal exit never destroys what the abandoned job still uses.
          static const bool registered = (std::atexit(wait_for_abandoned_jobs), true);
          (void)registered;
        }
      }
      worker.detach();
      throw py::error_already_set();
    }
  }
  worker.join();
  if (PyErr_Occurred()) throw py::error_already_set();
  return std::move(state->result);
}

// A count (an int from lo to hi) or "auto", as the text the command's option parser takes.
std::string count_text(const py::object& v, const char* name, int lo, int hi) {
  if (py::isinstance<py::bool_>(v)) {
    raise_type(std::string(name) + " must be an int or 'auto', not a bool");
  }
  if (PyIndex_Check(v.ptr()) && !py::isinstance<py::float_>(v)) {
    // Any size: a value beyond long long is out of range, not an internal cast failure.
    py::object i = py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()));
    if (!i) throw py::error_already_set();
    int overflow = 0;
    const long long x = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
    if (overflow != 0) {
      raise_invalid(std::string(name) + " is out of range (an int or 'auto'), not " + repr_text(v),
                    2);
    }
    return std::to_string(x);
  }
  if (py::isinstance<py::str>(v)) {
    // "auto" only: a count is an int, as the stubs say ("3" would be an easy slip to accept).
    if (str_arg(v, name) != "auto") {
      raise_invalid(std::string(name) + " must be " + std::to_string(lo) + " to " +
                        std::to_string(hi) + " or 'auto', not " + repr_text(v),
                    2);
    }
    return "auto";
  }
  raise_type(std::string(name) + " must be an int or 'auto', not " + repr_text(v));
}

// A real number (int, float or a NumPy real scalar such as np.float32; not a bool, str or
// complex), or nullopt; an int too large for a double is infinite (refused as out of range).
std::optional<double> real_value(const py::object& v) {
  if (py::isinstance<py::bool_>(v) || py::isinstance<py::str>(v)) return std::nullopt;
  static py::object* real = new py::object(py::module_::import("numbers").attr("Real"));
  if (!py::isinstance(v, *real) || py::isinstance(v, py::module_::import("numpy").attr("bool_"))) {
    return std::nullopt;
  }
  const double x = PyFloat_AsDouble(v.ptr());
  if (x == -1.0 && PyErr_Occurred()) {
    if (!PyErr_ExceptionMatches(PyExc_OverflowError)) throw py::error_already_set();
    PyErr_Clear();
    return std::numeric_limits<double>::infinity();
  }
  return x;
}

// As `cbrdf encode --target-bytes/--target-psnr`: a positive finite number up to max.
double target_value(const py::object& v, const char* name, double max, const char* max_text,
                    double min = 0.0, const char* min_text = nullptr) {
  const std::optional<double> x = real_value(v);
  if (!x) {
    raise_type(std::string(name) + " must be a number (an int or a float), not " + repr_text(v));
  }
  const bool ok = std::isfinite(*x) && (min_text ? *x >= min : *x > 0) && *x <= max;
  if (!ok) {
    raise_invalid(std::string(name) + " must be a number " +
                      (min_text ? std::string("from ") + min_text + " to "
                                : std::string("above 0 and at most ")) +
                      max_text + ", not " + repr_text(v),
                  2);
  }
  return *x;
}

// The encoder's usage messages name the command's options; Python callers know the keywords.
std::string keyword_names(std::string message) {
  static const std::pair<const char*, const char*> kNames[] = {
      {"--target-bytes", "target_bytes"},
      {"--target-psnr", "target_psnr"},
      {"--max-error", "max_error"},
      {"--residual-steps", "residual_steps"},
      {"--lossless", "lossless"},
      {"--mixture-copulas", "mixture_copulas"},
      {"--format-version", "format_version"},
      {"--metadata", "metadata"},
      {"--slice-placement", "placement"},
      {"--naive-marginals", "naive_marginals"},
      {"--components", "components"},
      {"--slices", "slices"},
      {"--family", "family"},
      {"--threads", "threads"},
      {"--level", "level"},
      {"--loss", "loss"},
      {"--bits", "bits"},
  };
  for (const auto& [flag, keyword] : kNames) {
    for (std::size_t at = message.find(flag); at != std::string::npos;
         at = message.find(flag, at)) {
      message.replace(at, std::strlen(flag), keyword);
    }
  }
  return message;
}

// `make_table()` gives the cbrdf._Table, called once every option has been checked: reading or
// converting a table takes a while, and a bad option is refused at once.
py::bytes encode(const py::object& make_table, const py::object& bits, const py::object& components,
                 const py::object& slices, const py::object& family, const py::object& loss,
                 const py::object& level, const py::object& placement, bool naive_marginals,
                 const py::object& threads, const py::object& target_bytes,
                 const py::object& target_psnr, const py::object& max_error, bool lossless,
                 const py::object& source_name, const py::object& mixture_copulas,
                 const py::object& format_version, const py::object& metadata,
                 const py::object& residual_steps) {
  EncoderOptions o;
  if (!mixture_copulas.is_none()) o.mixture_copulas = str_arg(mixture_copulas, "mixture_copulas");
  o.format_version = str_arg(format_version, "format_version");
  o.metadata = str_arg(metadata, "metadata");
  o.slices = count_text(slices, "slices", 1, kThetaDBins);
  o.components = count_text(components, "components", 1, kMaxComponents);
  o.family = str_arg(family, "family");
  o.loss = str_arg(loss, "loss");
  const std::string bits_text = count_text(bits, "bits", 6, 16);
  const auto bits_value = parse_count_or_auto(bits_text, 6, 16, true);
  if (!bits_value) raise_invalid("bits must be 6 to 16 or 'auto', not '" + bits_text + "'", 2);
  o.bits = bits_value->is_auto ? kAutoBits : bits_value->count;
  o.level = int(int_arg(level, "level", 1, 22));
  o.placement = str_arg(placement, "placement");
  o.naive_marginals = naive_marginals;
  o.threads = int(int_arg(threads, "threads", 0, 256));
  if (!source_name.is_none()) o.source_name = str_arg(source_name, "source_name");
  if (!max_error.is_none()) {
    o.max_error = target_value(max_error, "max_error", 16.0, "16", 1e-6, "1e-06");
  }
  o.lossless = lossless;
  RateTarget target;
  if (!target_bytes.is_none() && !target_psnr.is_none()) {
    raise_invalid("give target_bytes or target_psnr, not both", 2);
  }
  if (!target_bytes.is_none()) {
    target.max_bytes =
        target_value(target_bytes, "target_bytes", double(kMaxContainerBytes), "67108864 (64 MiB)");
  }
  if (!target_psnr.is_none()) {
    target.min_psnr = target_value(target_psnr, "target_psnr", 1000.0, "1000");
  }
  const bool targeted = target.max_bytes > 0 || target.min_psnr > 0;
  if (!residual_steps.is_none()) o.residual_steps = str_arg(residual_steps, "residual_steps");
  if (auto conflict = residual_option_conflict(
          {targeted, !max_error.is_none(), lossless, !residual_steps.is_none()})) {
    raise_invalid(keyword_names(*conflict), 2);
  }
  const py::object table_obj = make_table();
  const PyTable& t = table_obj.cast<const PyTable&>();
  t.ok();
  if (source_name.is_none()) o.source_name = t.source_name;
  if (lossless && t.folded_from_360) {
    raise_invalid(t.name +
                      ": lossless cannot keep a 90x90x360 file exactly (it is read as 180 phi_d "
                      "bins, each the mean of phi_d and phi_d + 180); convert it with "
                      "cbrdf.write_merl first if that table is what you want",
                  2);
  }
  if (targeted && o.slices == "auto") {
    raise_invalid(
        "slices='auto' and a target (target_bytes, target_psnr) both choose the slice "
        "count; give one of them",
        2);
  }
  auto st = encoder_settings(o);
  if (!st.ok()) {
    raise_status(error(st.status().code(), keyword_names(st.status().message())), 2);
  }
  // Given explicitly, mixture_copulas applies to the search too (as --mixture-copulas).
  if (!mixture_copulas.is_none()) target.mixture_copulas = st->fit.mixture_copulas;
  // An explicit components=K > 1 caps the search, as in `cbrdf encode`.
  if (targeted && !st->fit.auto_components && st->fit.components > 1) {
    target.max_components = st->fit.components;
  }
  // The job owns copies of its inputs: after Ctrl-C it may outlive this call.
  auto b = take(interruptible_job([table = t.table, settings = *st, target, targeted] {
                  if (!targeted) {
                    auto r = encode_table(table, settings);
                    return r.ok() ? Expected<std::vector<std::uint8_t>>(std::move(r->bytes))
                                  : Expected<std::vector<std::uint8_t>>(r.status());
                  }
                  // The whole ladder, as `cbrdf encode --target-*`: the model, then model +
                  // residual.
                  auto r = encode_to_target_ladder(table, settings, target);
                  return r.ok() ? Expected<std::vector<std::uint8_t>>(std::move(r->encoded.bytes))
                                : Expected<std::vector<std::uint8_t>>(r.status());
                }),
                t.name);
  return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
}

// ---- Metrics --------------------------------------------------------------------------------

SphereSetup sphere_setup(int size, const std::vector<double>& lights) {
  if (size < 1 || size > kMaxSphereSize) {
    raise_invalid("size must be 1 to " + std::to_string(kMaxSphereSize) + ", not " +
                  std::to_string(size));
  }
  if (lights.empty()) raise_invalid("light_angles must name at least one angle");
  for (double a : lights) {
    if (!std::isfinite(a)) raise_invalid("light_angles must be finite numbers");
  }
  SphereSetup s;
  s.size = size;
  s.light_angles_deg = lights;
  return s;
}

py::dict image_metrics_dict(const ImageMetrics& im) {
  py::dict d;
  d["psnr_linear"] = im.psnr_linear;
  d["psnr_tonemapped"] = im.psnr_tonemapped;
  py::list lights;
  for (const LightMetrics& l : im.per_light) {
    py::dict ld;
    ld["light_angle_deg"] = l.light_angle_deg;
    ld["psnr_linear"] = py::make_tuple(l.psnr_linear[0], l.psnr_linear[1], l.psnr_linear[2]);
    ld["psnr_tonemapped"] =
        py::make_tuple(l.psnr_tonemapped[0], l.psnr_tonemapped[1], l.psnr_tonemapped[2]);
    ld["exposure"] = l.exposure;
    lights.append(ld);
  }
  d["per_light"] = lights;
  return d;
}

py::dict sphere_metrics(const PyTable& ref, const PyTable& test, int size,
                        const std::vector<double>& lights) {
  ref.ok();
  test.ok();
  const SphereSetup setup = sphere_setup(size, lights);
  ImageMetrics im;
  {
    py::gil_scoped_release release;
    im = sphere_psnr(ref.table, test.table, setup);
  }
  return image_metrics_dict(im);
}

py::dict brdf_metrics_dict(const PyTable& ref, const PyTable& test) {
  ref.ok();
  test.ok();
  BrdfMetrics m;
  {
    py::gil_scoped_release release;
    m = brdf_metrics(ref.table, test.table);
  }
  auto t3 = [](const std::array<double, 3>& a) { return py::make_tuple(a[0], a[1], a[2]); };
  py::dict d;
  d["rel_rmse"] = m.rel_rmse_mean;
  d["log_rmse"] = m.log_rmse_mean;
  d["cos_rmse"] = m.cos_rmse_mean;
  d["rel_rmse_rgb"] = t3(m.rel_rmse);
  d["log_rmse_rgb"] = t3(m.log_rmse);
  d["cos_rmse_rgb"] = t3(m.cos_rmse);
  d["bins"] = py::make_tuple(m.bins[0], m.bins[1], m.bins[2]);
  return d;
}

py::array_t<float> image_array(const Image& im) {
  py::array_t<float> a(std::vector<py::ssize_t>{im.height, im.width, 3});
  std::copy(im.data.begin(), im.data.end(), a.mutable_data());
  return a;
}

py::array_t<float> render_table(const PyTable& t, double light, int size) {
  t.ok();
  sphere_setup(size, {light});
  Image im;
  {
    py::gil_scoped_release release;
    im = render_sphere(t.table, light, size);
  }
  return image_array(im);
}

py::array_t<float> render_model(PyModel& m, double light, int size) {
  sphere_setup(size, {light});
  auto ev = m.ev();
  Image im;
  {
    py::gil_scoped_release release;
    im = render_sphere(model_brdf_fn(ev), light, size);
  }
  return image_array(im);
}

}  // namespace
}  // namespace cbrdf::python

PYBIND11_MODULE(_cbrdf, m) {
  using namespace cbrdf;
  using namespace cbrdf::python;
  m.doc() = "The C++ half of the cbrdf module (use `import cbrdf`).";

  m.def(
      "_set_error_class",
      [](py::object cls, py::object type_cls) {
        error_class() = std::move(cls);
        type_error_class() = std::move(type_cls);
      },
      "Sets the exception classes raised for library errors (cbrdf.Error) and arguments of the "
      "wrong type (cbrdf.ArgumentTypeError).");
  m.attr("__version__") = version_string();
  m.attr("CONTAINER_VERSION") =
      py::make_tuple(kContainerMajorVersion, kContainerMinorVersion);  // the newest it writes
  m.attr("MERL_SCALE") = py::make_tuple(kMerlScale[0], kMerlScale[1], kMerlScale[2]);
  m.attr("MERL_FILE_BYTES") = kMerlFileBytes;
  m.attr("MAX_CONTAINER_BYTES") = kMaxContainerBytes;
  {
    py::list families;  // the library's family table, in the order the command lists them
    for (CopulaFamily f : listed_families()) families.append(std::string(family_name(f)));
    m.attr("COPULA_FAMILIES") = py::tuple(families);
  }
  {
    py::dict codes;
    for (int c = 0; c <= int(ErrorCode::kInternal); ++c) {
      codes[py::int_(c)] = error_code_name(ErrorCode(c));
    }
    m.attr("ERROR_CODES") = codes;
  }

  py::class_<PyTable>(m, "_Table", "A MERL table held in C++ (internal).")
      .def_static(
          "read", [](const py::object& path) { return read_table(path_arg(path)); },
          py::arg("path"))
      .def_static(
          "parse",
          [](const py::buffer& b, const std::string& name) {
            PyTable t;
            t.table = take(parse_merl(bytes_of(b), name));
            return t;
          },
          py::arg("data"), py::arg("name"))
      .def_static(
          "from_physical",
          [](const F64Array& a, std::optional<BoolArray> mask, std::optional<F64Array> companion,
             double nmv) {
            PyTable t;
            t.table = table_from_physical(a, mask, companion, nmv);
            return t;
          },
          py::arg("array"), py::arg("mask") = py::none(), py::arg("companion") = py::none(),
          py::arg("not_measured_value") = -1.0)
      .def_static(
          "from_stored",
          [](const F64Array& a, std::optional<BoolArray> mask, double nmv) {
            PyTable t;
            t.table = table_from_stored(a, mask, nmv);
            return t;
          },
          py::arg("array"), py::arg("mask") = py::none(), py::arg("not_measured_value") = -1.0)
      .def_static(
          "sample",
          [](const std::string& name) {
            PyTable t;
            t.table = take(make_sample(name));
            t.source_name = name;
            return t;
          },
          py::arg("name"))
      .def("arrays", [](const PyTable& t) { return table_arrays(t.ok().table); })
      .def("write",
           [](const PyTable& t, const py::object& path_obj) {
             t.ok();
             const std::string path = path_arg(path_obj);
             Status s;
             {
               py::gil_scoped_release release;
               s = write_merl(path, t.table);
             }
             if (!s.ok()) raise_status(s);
           })
      .def("serialize",
           [](const PyTable& t) {
             const auto b = serialize_merl(t.ok().table);
             return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
           })
      .def_property(
          "source_name", [](const PyTable& t) { return t.ok().source_name; },
          [](PyTable& t, const py::object& v) {
            t.ok();
            t.source_name = str_arg(v, "source_name");
          });

  m.def(
      "samples",
      [] {
        py::list out;
        for (const SampleInfo& s : sample_materials()) {
          out.append(py::make_tuple(std::string(s.name), std::string(sample_kind_name(s.kind)),
                                    std::string(s.description)));
        }
        return out;
      },
      "The built-in sample materials as (name, kind, description), kind 'measured' or "
      "'analytic'.");

  m.def(
      "_info_path",
      [](const py::object& file) {
        const std::string path = path_arg(file);
        auto bytes =
            take(read_file(path, std::max<std::uint64_t>(kMaxContainerBytes, 2 * kMerlFileBytes)));
        return info_of_bytes(bytes, path, file);
      },
      py::arg("path"));
  m.def(
      "_info_bytes",
      [](const py::buffer& b) { return info_of_bytes(bytes_of(b), "<bytes>", py::none()); },
      py::arg("data"));

  m.def("_encode", &encode, py::arg("table"), py::arg("bits"), py::arg("components"),
        py::arg("slices"), py::arg("family"), py::arg("loss"), py::arg("level"),
        py::arg("placement"), py::arg("naive_marginals"), py::arg("threads"),
        py::arg("target_bytes"), py::arg("target_psnr"), py::arg("max_error"), py::arg("lossless"),
        py::arg("source_name"), py::arg("mixture_copulas"), py::arg("format_version"),
        py::arg("metadata"), py::arg("residual_steps"));

  m.def("_sphere_metrics", &sphere_metrics, py::arg("reference"), py::arg("test"), py::arg("size"),
        py::arg("light_angles"));
  m.def("_brdf_metrics", &brdf_metrics_dict, py::arg("reference"), py::arg("test"));
  m.def(
      "_estimate_noise",
      [](const PyTable& t) {
        t.ok();
        NoiseEstimate e;
        {
          py::gil_scoped_release release;
          e = estimate_noise(t.table);
        }
        return info_dict(cli::noise_json(e), py::none());
      },
      py::arg("table"));
  m.def("_render_table", &render_table, py::arg("table"), py::arg("light_angle_deg"),
        py::arg("size"));

  m.def("nearest_bin", &nearest_bins, py::arg("wi"), py::arg("wo"),
        "The MERL bins (theta_h, theta_d, phi_d index arrays) of direction pairs: the reference "
        "reader's nearest-bin lookup.");
  m.def("bin_directions", &bin_directions, py::arg("theta_h"), py::arg("theta_d"), py::arg("phi_d"),
        "The direction pairs (wi, wo), arrays (..., 3), at MERL bins' grid angles (phi_h = 0).");
  m.def(
      "set_thread_limit",
      [](const py::object& n) { set_thread_limit(int(int_arg(n, "n", 0, kMaxThreadLimit))); },
      py::arg("n"),
      "Caps the threads every parallel loop of the library uses (0: one per hardware thread).");
  m.def("thread_limit", &thread_limit, "The thread limit in force.");

  py::class_<PyModel>(m, "_Model", "A decoded .cbrdf model (internal base of cbrdf.Model).")
      .def(py::init([](const py::object& source) {
             if (py::isinstance<py::bytes>(source) || py::isinstance<py::bytearray>(source) ||
                 py::isinstance<py::memoryview>(source)) {
               return model_from_bytes(bytes_of(source), "<bytes>", py::none());
             }
             // A path: Model.file is the str the caller gave (os.fspath's, os.fsdecode'd).
             const std::string path = path_arg(source, "source");
             py::object fspath = py::module_::import("os").attr("fspath")(source);
             if (!py::isinstance<py::str>(fspath)) {
               fspath = py::module_::import("os").attr("fsdecode")(fspath);
             }
             return model_from_path(path, fspath);
           }),
           py::arg("source"))
      .def_property_readonly("info",
                             [](PyModel& self) {
                               auto ev = self.ev();
                               return info_dict(
                                   cli::container_info_json(self.info(), ev->footprint_bytes()),
                                   self.file);
                             })
      .def_property_readonly(
          "file", [](const PyModel& self) { return self.constructed ? self.file : py::none(); })
      .def_property_readonly(
          "closed", [](const PyModel& self) { return !self.constructed || !self.evaluator; })
      .def_property_readonly("bits", [](PyModel& self) { return self.info().bits; })
      .def_property_readonly("version",
                             [](PyModel& self) {
                               return py::make_tuple(self.info().layout.major,
                                                     self.info().layout.minor);
                             })
      .def_property_readonly("nbytes",
                             [](const PyModel& self) {
                               self.check("cbrdf.Model");
                               return self.file_bytes;
                             })
      .def_property_readonly("not_measured_bins",
                             [](PyModel& self) { return self.info().not_measured_bins; })
      .def_property_readonly("footprint_bytes",
                             [](PyModel& self) { return self.ev()->footprint_bytes(); })
      .def_property_readonly("_slices", &model_slices)
      .def("close",
           [](PyModel& self) {
             if (!self.constructed) return;
             std::lock_guard<std::mutex> lock(self.sampler_mutex);
             self.sampler.reset();
             self.evaluator.reset();
           })
      .def("_table_arrays",
           [](PyModel& self) {
             auto ev = self.ev();
             BrdfTable t;
             {
               py::gil_scoped_release release;
               t = ev->table();
             }
             return table_arrays(t);
           })
      .def("_table",
           [](PyModel& self) {
             auto ev = self.ev();
             PyTable t;
             py::gil_scoped_release release;
             t.table = ev->table();
             return t;
           })
      .def(
          "write_merl",
          [](PyModel& self, const py::object& path_obj) {
            auto ev = self.ev();
            const std::string path = path_arg(path_obj);
            Status s;
            {
              py::gil_scoped_release release;
              s = write_merl(path, ev->table());
            }
            if (!s.ok()) raise_status(s);
          },
          py::arg("path"))
      .def("eval", &model_eval, py::arg("wi"), py::arg("wo"), py::arg("threads") = 0)
      .def(
          "eval_pair",
          [](PyModel& self, const py::object& wi_obj, const py::object& wo_obj) {
            auto ev = self.ev();
            const Dirs<double> a = dirs_of<double>(wi_obj, "wi");
            const Dirs<double> b = dirs_of<double>(wo_obj, "wo");
            if (!a.single) raise_invalid("wi must be one direction, shape (3,)");
            if (!b.single) raise_invalid("wo must be one direction, shape (3,)");
            check_directions(a, 1, "wi");
            check_directions(b, 1, "wo");
            double rgb[3];
            ev->eval(vec3(a.data), vec3(b.data), rgb);
            return py::make_tuple(rgb[0], rgb[1], rgb[2]);
          },
          py::arg("wi"), py::arg("wo"))
      .def("sample", &model_sample, py::arg("wo"), py::arg("u"), py::arg("threads") = 0)
      .def("pdf", &model_pdf, py::arg("wo"), py::arg("wi"), py::arg("threads") = 0)
      .def("bin_value", &model_bin_value, py::arg("channel"), py::arg("theta_h"),
           py::arg("theta_d"), py::arg("phi_d"))
      .def("_render", &render_model, py::arg("light_angle_deg"), py::arg("size"));
}
