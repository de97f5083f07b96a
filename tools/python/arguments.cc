// SPDX-License-Identifier: MIT
#include "arguments.h"

#include <limits>

#include "errors.h"

namespace cbrdf::python {

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
std::string path_arg(const py::handle& v, const char* name) {
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
                  int exit_code) {
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
std::string str_arg(const py::handle& v, const char* name, int exit_code) {
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

}  // namespace cbrdf::python
