// SPDX-License-Identifier: MIT
// The `cbrdf._cbrdf` Python extension: MERL tables as NumPy arrays, encode/decode, the model's
// evaluation and sampling (vectorized, GIL released, threaded), the report's metrics. The public
// Python API is tools/python/cbrdf/__init__.py; the C++ half is split by area (bindings.h), and
// raises cbrdf.Error (set by __init__.py through _set_error_class) for every Status the library
// returns. It includes only the libraries' installed headers.
#include <pybind11/pybind11.h>

#include <string>

#include "arguments.h"
#include "bindings.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/copula_family.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/parallel.h"
#include "cbrdf/version.h"

namespace py = pybind11;

namespace {

// Version, format limits and the family table, as constants of the module.
void add_constants(py::module_& m) {
  using namespace cbrdf;
  m.attr("__version__") = version_string();
  m.attr("CONTAINER_VERSION") =
      py::make_tuple(kContainerMajorVersion, kContainerMinorVersion);  // the newest it writes
  m.attr("MERL_SCALE") = py::make_tuple(kMerlScale[0], kMerlScale[1], kMerlScale[2]);
  m.attr("MERL_FILE_BYTES") = kMerlFileBytes;
  m.attr("MAX_CONTAINER_BYTES") = kMaxContainerBytes;
  py::list families;  // the library's family table, in the order the command lists them
  for (CopulaFamily f : listed_families()) families.append(std::string(family_name(f)));
  m.attr("COPULA_FAMILIES") = py::tuple(families);
}

}  // namespace

PYBIND11_MODULE(_cbrdf, m) {
  using namespace cbrdf::python;
  m.doc() = "The C++ half of the cbrdf module (use `import cbrdf`).";
  add_constants(m);
  bind_errors(m);
  bind_tables(m);
  bind_info(m);
  bind_encode(m);
  bind_metrics(m);
  bind_noise(m);
  bind_directions(m);
  bind_model(m);
  m.def(
      "set_thread_limit",
      [](const py::object& n) {
        cbrdf::set_thread_limit(int(int_arg(n, "n", 0, cbrdf::kMaxThreadLimit)));
      },
      py::arg("n"),
      "Caps the threads every parallel loop of the library uses (0: one per hardware thread).");
  m.def("thread_limit", &cbrdf::thread_limit, "The thread limit in force.");
}
