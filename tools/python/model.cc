// SPDX-License-Identifier: MIT
#include "model.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "arguments.h"
#include "bindings.h"
#include "cbrdf/file_io.h"
#include "directions.h"
#include "info.h"

namespace cbrdf::python {
namespace {

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

// Rows per kernel call when an argument is one row broadcast to all (below 1 MB of copies).
constexpr std::size_t kBroadcastRun = std::size_t{1} << 15;

// A batch argument's rows as the kernels read them: the caller's C-contiguous array in place, or,
// for one row broadcast to every row, a block of copies of it, which serves every run of rows
// (they are all the same), so that a broadcast costs a block of memory, not a copy per row.
template <typename T>
class Rows {
 public:
  Rows(const Dirs<T>& d, std::size_t n) : d_(d) {
    if (!d.single) return;
    copies_.resize(d.width * std::max<std::size_t>(1, std::min(n, kBroadcastRun)));
    for (std::size_t at = 0; at < copies_.size(); at += d.width) {
      std::copy_n(d.data, d.width, copies_.data() + at);
    }
  }
  const T* from(std::size_t k) const { return d_.single ? copies_.data() : d_.data + d_.width * k; }

 private:
  const Dirs<T>& d_;
  std::vector<T> copies_;
};

// body(begin, end) over [first, last): at once, or in runs of kBroadcastRun rows when an argument
// is broadcast (its copies cover that many).
template <typename Fn>
void in_runs(std::size_t first, std::size_t last, bool broadcast, const Fn& body) {
  const std::size_t run = broadcast ? kBroadcastRun : std::max<std::size_t>(1, last - first);
  for (std::size_t b = first; b < last; b += run) body(b, std::min(last, b + run));
}

// Pairs through the evaluator's batch kernels (eval_batch, eval_batch_f32: equal to eval and
// eval_f32 per pair bit for bit, vectorized, on the library's threads), with the GIL released.
template <typename T>
py::array eval_batch(const ModelEvaluator& ev, const py::handle& wi_obj, const py::handle& wo_obj,
                     int threads) {
  const Dirs<T> wi = dirs_of<T>(wi_obj, "wi");
  const Dirs<T> wo = dirs_of<T>(wo_obj, "wo");
  const std::size_t n = batch_rows({{wi.n, wi.single}, {wo.n, wo.single}}, "eval");
  check_directions(wi, n, "wi", ZeroRows::kAllowed);
  check_directions(wo, n, "wo", ZeroRows::kAllowed);
  py::array_t<T> out = wi.single && wo.single
                           ? py::array_t<T>(std::vector<py::ssize_t>{3})
                           : py::array_t<T>(std::vector<py::ssize_t>{py::ssize_t(n), 3});
  T* rgb = out.mutable_data();
  const Rows<T> wi_rows(wi, n), wo_rows(wo, n);
  interruptible(n, [&](std::size_t first, std::size_t last) {
    in_runs(first, last, wi.single || wo.single, [&](std::size_t b, std::size_t e) {
      if constexpr (std::is_same_v<T, float>) {
        ev.eval_batch_f32(e - b, wi_rows.from(b), wo_rows.from(b), rgb + 3 * b, threads);
      } else {
        ev.eval_batch(e - b, wi_rows.from(b), wo_rows.from(b), rgb + 3 * b, threads);
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
  m.ev();  // a closed model is refused before the arguments
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
  const Rows<double> wo_rows(wo, n), u_rows(u, n);
  // BrdfSampler::sample_batch, as cbrdf_model_sample_batch: u clamped into [0, 1), a rejected
  // draw all zeros, equal to sample() with weights per draw bit for bit.
  interruptible(n, [&](std::size_t first, std::size_t last) {
    in_runs(first, last, wo.single || u.single, [&](std::size_t b, std::size_t e) {
      sampler->sample_batch(e - b, wo_rows.from(b), u_rows.from(b), wi_p + 3 * b, pdf_p + b,
                            w_p + 3 * b, threads);
    });
  });
  return py::make_tuple(wi_out, pdf_out, w_out);
}

// The sampler's density of wi given wo, in eval's (wi, wo) order (Model.pdf(wo, wi), deprecated,
// calls it with its arguments swapped).
py::array model_sample_pdf(PyModel& m, const py::handle& wi_obj, const py::handle& wo_obj,
                           const py::object& threads_obj) {
  m.ev();
  const int threads = threads_arg(threads_obj);
  const Dirs<double> wi = dirs_of<double>(wi_obj, "wi");
  const Dirs<double> wo = dirs_of<double>(wo_obj, "wo");
  const std::size_t n = batch_rows({{wi.n, wi.single}, {wo.n, wo.single}}, "sample_pdf");
  check_directions(wi, n, "wi", ZeroRows::kAllowed);
  check_directions(wo, n, "wo", ZeroRows::kAllowed);
  auto sampler = m.get_sampler();
  const bool single = wo.single && wi.single;
  py::array_t<double> out = single ? py::array_t<double>(std::vector<py::ssize_t>{})
                                   : py::array_t<double>(std::vector<py::ssize_t>{py::ssize_t(n)});
  double* p = out.mutable_data();
  interruptible(n, [&](std::size_t first, std::size_t last) {
    for_blocks(last - first, threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = first + begin; k < first + end; ++k) {
        p[k] = sampler->sample_pdf(vec3(wi.at(k)), vec3(wo.at(k)));
      }
    });
  });
  return out;
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

// Model.info, .file, .closed, .bits, .version, .nbytes, ...: what the file holds.
void def_properties(py::class_<PyModel>& c) {
  c.def_property_readonly("info",
                          [](PyModel& self) {
                            auto ev = self.ev();
                            return container_info_dict(self.info(), ev->footprint_bytes(),
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
      .def_property_readonly("_slices", &model_slices);
}

// eval, sample, pdf, bin_value, the table, close.
void def_methods(py::class_<PyModel>& c) {
  c.def("close",
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
            check_directions(a, 1, "wi", ZeroRows::kAllowed);
            check_directions(b, 1, "wo", ZeroRows::kAllowed);
            double rgb[3];
            ev->eval(vec3(a.data), vec3(b.data), rgb);
            return py::make_tuple(rgb[0], rgb[1], rgb[2]);
          },
          py::arg("wi"), py::arg("wo"))
      .def("sample", &model_sample, py::arg("wo"), py::arg("u"), py::arg("threads") = 0)
      .def("sample_pdf", &model_sample_pdf, py::arg("wi"), py::arg("wo"), py::arg("threads") = 0)
      .def("bin_value", &model_bin_value, py::arg("channel"), py::arg("theta_h"),
           py::arg("theta_d"), py::arg("phi_d"))
      .def("_render", &render_model, py::arg("light_angle_deg"), py::arg("size"));
}

}  // namespace

void bind_model(py::module_& m) {
  py::class_<PyModel> c =
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
               py::arg("source"));
  def_properties(c);
  def_methods(c);
}

}  // namespace cbrdf::python
