// SPDX-License-Identifier: MIT
// The areas of the `cbrdf._cbrdf` extension, each adding its functions and classes to the
// module (module.cc calls them in this order). Internal to the extension.
#pragma once

#include <pybind11/pybind11.h>

namespace cbrdf::python {

namespace py = pybind11;

void bind_errors(py::module_& m);      // errors.cc: the exception classes, ERROR_CODES
void bind_tables(py::module_& m);      // tables.cc: cbrdf._Table, samples()
void bind_info(py::module_& m);        // info.cc: what `cbrdf info --json` prints
void bind_encode(py::module_& m);      // encode.cc: cbrdf.encode's options and progress
void bind_metrics(py::module_& m);     // metrics.cc: sphere PSNR, per-bin errors, images
void bind_noise(py::module_& m);       // noise.cc: the noise estimate
void bind_directions(py::module_& m);  // directions.cc: MERL bins <-> direction pairs
void bind_model(py::module_& m);       // model.cc: cbrdf._Model (decode, eval, sample, pdf)

}  // namespace cbrdf::python
