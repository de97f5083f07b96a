// SPDX-License-Identifier: MIT
// The report's metrics for Python: sphere PSNR, per-bin errors and the sphere images they are
// measured on, for tables and decoded models.
#include "cbrdf/metrics.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "bindings.h"
#include "errors.h"
#include "model.h"
#include "tables.h"

namespace cbrdf::python {
namespace {

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
}  // namespace

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

void bind_metrics(py::module_& m) {
  m.def("_sphere_metrics", &sphere_metrics, py::arg("reference"), py::arg("test"), py::arg("size"),
        py::arg("light_angles"));
  m.def("_brdf_metrics", &brdf_metrics_dict, py::arg("reference"), py::arg("test"));
  m.def("_render_table", &render_table, py::arg("table"), py::arg("light_angle_deg"),
        py::arg("size"));
}

}  // namespace cbrdf::python
