// SPDX-License-Identifier: MIT
// Batches of directions (and sample pairs) from NumPy arrays, checked, and the loops that run
// over them: in blocks on the library's threads, in chunks that let Ctrl-C through. Internal to
// the extension.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <utility>

#include "cbrdf/coords.h"
#include "cbrdf/parallel.h"
#include "errors.h"

namespace cbrdf::python {

namespace py = pybind11;

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
std::size_t batch_rows(std::initializer_list<std::pair<std::size_t, bool>> parts, const char* what);

// Whether a batch of directions may hold (0, 0, 0): the wi of a rejected draw, which eval, pdf
// and sample_pdf take as below the horizon (0), so that drawn directions pass on unchecked.
enum class ZeroRows { kRefused, kAllowed };

template <typename T>
void check_directions(const Dirs<T>& d, std::size_t n, const char* name,
                      ZeroRows zero = ZeroRows::kRefused) {
  const std::size_t rows = d.single ? 1 : n;
  for (std::size_t k = 0; k < rows; ++k) {
    const T* w = d.at(k);
    const double x = double(w[0]), y = double(w[1]), z = double(w[2]);
    const bool finite = std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
    if (finite && std::fabs(x * x + y * y + z * z - 1.0) <= kUnitTolerance) continue;
    const bool is_zero = x == 0 && y == 0 && z == 0;
    if (is_zero && zero == ZeroRows::kAllowed) continue;
    char buf[128];
    std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", x, y, z);
    const std::string what =
        d.single ? std::string(name) : std::string(name) + "[" + std::to_string(k) + "]";
    raise_invalid(what + " must be a finite unit vector" +
                  (zero == ZeroRows::kAllowed ? " or (0, 0, 0) (a rejected draw)" : "") + ", not " +
                  buf);
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
  parallel_for(int(std::min<std::size_t>(blocks, std::size_t(INT32_MAX))), max_threads, [&](int b) {
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

inline Vec3 vec3(const double* w) {
  return Vec3{w[0], w[1], w[2]};
}

// Bin indices: ints or integer arrays, never truncated floats, bools, strings or objects.
py::array_t<std::int64_t> index_array(const py::object& v, const char* name);

}  // namespace cbrdf::python
