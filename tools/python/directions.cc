// SPDX-License-Identifier: MIT
#include "directions.h"

#include <vector>

#include "bindings.h"
#include "cbrdf/brdf_table.h"
#include "errors.h"

namespace cbrdf::python {

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

namespace {

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

}  // namespace

void bind_directions(py::module_& m) {
  m.def("nearest_bin", &nearest_bins, py::arg("wi"), py::arg("wo"),
        "The MERL bins (theta_h, theta_d, phi_d index arrays) of direction pairs: the reference "
        "reader's nearest-bin lookup.");
  m.def("bin_directions", &bin_directions, py::arg("theta_h"), py::arg("theta_d"), py::arg("phi_d"),
        "The direction pairs (wi, wo), arrays (..., 3), at MERL bins' grid angles (phi_h = 0).");
}

}  // namespace cbrdf::python
