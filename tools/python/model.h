// SPDX-License-Identifier: MIT
// cbrdf._Model: a decoded .cbrdf model held for Python (the base of cbrdf.Model), with its
// evaluator and, made on first use, its importance sampler. Internal to the extension.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <memory>
#include <mutex>

#include "cbrdf/codec.h"
#include "cbrdf/model.h"
#include "cbrdf/sampling.h"
#include "errors.h"
#include "tables.h"

namespace cbrdf::python {

namespace py = pybind11;

struct PyModel : ZeroedUntilConstructed {
  std::shared_ptr<const ModelEvaluator> evaluator;
  // The file's description, from the same validating pass that decoded the model.
  ContainerInfo info_;
  std::size_t file_bytes = 0;
  py::object file = py::none();
  std::mutex sampler_mutex;
  std::shared_ptr<const BrdfSampler> sampler;

  const ContainerInfo& info() const {
    check("cbrdf.Model");
    return info_;
  }
  // The evaluator; cbrdf.Error once the model is closed.
  std::shared_ptr<const ModelEvaluator> ev() const {
    check("cbrdf.Model");
    if (!evaluator) raise_invalid("the model is closed");
    return evaluator;
  }
  std::shared_ptr<const BrdfSampler> get_sampler() {
    auto e = ev();
    std::lock_guard<std::mutex> lock(sampler_mutex);
    if (!sampler) sampler = std::make_shared<const BrdfSampler>(make_model_sampler(e));
    return sampler;
  }
};

// Model._render: the metrics' sphere image of the model (metrics.cc).
py::array_t<float> render_model(PyModel& m, double light, int size);

}  // namespace cbrdf::python
