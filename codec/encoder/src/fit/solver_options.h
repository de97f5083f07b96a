// SPDX-License-Identifier: MIT
// The Ceres settings every per-slice fit uses: problems with a handful of parameters and a few
// compressed residuals, solved silently on the calling thread (fits run in parallel across slices,
// and one thread per solve keeps results identical for any thread count).
#pragma once

#include <ceres/ceres.h>

#include "encode_watch.h"

namespace cbrdf::internal {

// Ends a solve once the encode is cancelled (the encode then returns kCancelled, so the unfinished
// result is never used). Stateless: one instance serves every solve on every thread.
class CancelSolve final : public ceres::IterationCallback {
 public:
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return cancel_requested() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }
};
inline CancelSolve g_cancel_solve;

inline ceres::Solver::Options small_problem_options() {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  options.max_num_iterations = 50;
  options.function_tolerance = 1e-10;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-10;
  options.num_threads = 1;
  options.callbacks.push_back(&g_cancel_solve);
  return options;
}

}  // namespace cbrdf::internal
