// SPDX-License-Identifier: MIT
#include "tables.h"

#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include "arguments.h"
#include "bindings.h"
#include "cbrdf/file_io.h"
#include "cbrdf/samples.h"
#include "errors.h"

namespace cbrdf::python {
namespace {

constexpr std::size_t kTableValues = std::size_t(kChannels) * kBinsPerChannel;

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

}  // namespace

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

namespace {

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
PyTable read_table(const std::string& path) {
  PyTable t;
  MerlInfo mi;
  t.table = take(read_merl(checked_path(path), {}, &mi));
  t.folded_from_360 = mi.folded_from_360;
  t.source_name = std::filesystem::path(path).filename().string();
  t.name = path;
  return t;
}

}  // namespace

void* ZeroedUntilConstructed::operator new(std::size_t n) {
  void* p = ::operator new(n);
  std::memset(p, 0, n);
  return p;
}

void ZeroedUntilConstructed::operator delete(void* p) {
  ::operator delete(p);
}

void ZeroedUntilConstructed::check(const char* what) const {
  if (!constructed) {
    raise_invalid(std::string("this ") + what +
                  " was made by __new__ without __init__ and holds nothing; make one with " +
                  (std::string(what) == "cbrdf.Model" ? "cbrdf.decode()" : "cbrdf.read_merl()"));
  }
}

void bind_tables(py::module_& m) {
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
}

}  // namespace cbrdf::python
