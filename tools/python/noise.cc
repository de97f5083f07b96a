// SPDX-License-Identifier: MIT
// cbrdf.estimate_noise: the library's noise estimate of a table as a dict.
#include "cbrdf/noise.h"

#include <pybind11/pybind11.h>

#include "bindings.h"
#include "info.h"
#include "tables.h"

namespace cbrdf::python {

void bind_noise(py::module_& m) {
  m.def(
      "_estimate_noise",
      [](const PyTable& t) {
        t.ok();
        NoiseEstimate e;
        {
          py::gil_scoped_release release;
          e = estimate_noise(t.table);
        }
        return noise_dict(e);
      },
      py::arg("table"));
}

}  // namespace cbrdf::python
