// SPDX-License-Identifier: MIT
// MERL tables between C++ and NumPy: the opaque cbrdf._Table the Python layer passes to encode,
// the metrics and write_merl, and the conversions between a table and (3, 90, 90, 180) arrays.
// Internal to the extension.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <optional>
#include <string>
#include <utility>

#include "cbrdf/merl_io.h"

namespace cbrdf::python {

namespace py = pybind11;

using F64Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using BoolArray = py::array_t<bool, py::array::c_style | py::array::forcecast>;

// pybind11 gives a Python instance whose __init__ never ran (cbrdf.Model.__new__(cbrdf.Model))
// uninitialized C++ memory; with this class-specific operator new that memory is zero, so
// `constructed` is false there and every method refuses such an object instead of reading it.
struct ZeroedUntilConstructed {
  bool constructed = true;
  static void* operator new(std::size_t n);
  static void operator delete(void* p);
  // Raises cbrdf.Error for an object made by __new__ alone; `what` is its Python name.
  void check(const char* what) const;
};

// cbrdf._Table: a table made from arrays, a file or a built-in sample.
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

// The physical array (NaN where not measured) and the stored one (the file's values, bit for bit).
std::pair<F64Array, F64Array> table_arrays(const BrdfTable& t);

}  // namespace cbrdf::python
