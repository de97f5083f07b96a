// SPDX-License-Identifier: MIT
// The dicts cbrdf.info, Model.info and cbrdf.estimate_noise return: exactly what
// `cbrdf info --json` prints (tests/python/test_codec.py compares the two), built here from the
// library's public descriptions rather than by compiling the command's JSON writer into the
// extension. Internal to the extension.
#pragma once

#include <pybind11/pybind11.h>

#include <cstddef>

#include "cbrdf/codec.h"
#include "cbrdf/noise.h"

namespace cbrdf::python {

namespace py = pybind11;

// The container's chunks, header, slices, residual layer and metadata, what the evaluator holds
// in memory, and "file".
py::dict container_info_dict(const ContainerInfo& info, std::size_t evaluator_bytes,
                             const py::object& file);

// The noise estimate: "sigma" per channel, "bands" of theta_d, "grazing_growth", "noisy" and the
// two PSNR ceilings (dB, or "not measurable").
py::dict noise_dict(const NoiseEstimate& estimate);

// The dict with its keys in the order the command's JSON prints them (sorted, recursively).
py::object json_ordered(const py::handle& value);

}  // namespace cbrdf::python
