// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "cbrdf/fit.h"
#include "cbrdf/parallel_for.h"
#include "density/grid_copula.h"
#include "fit/fit_parameter.h"
#include "fit/marginals.h"
#include "fit/mixture.h"
#include "fit/slice_data.h"

namespace cbrdf {
namespace {

constexpr CopulaFamily kAutoFamilies[] = {CopulaFamily::kFrank, CopulaFamily::kClayton,
                                          CopulaFamily::kGumbel, CopulaFamily::kJoe};

struct SliceFitResult {
  ChannelSlice cs;
  ChannelSliceFit report;
};

// Marginals (imputed or naive) and parameter for one family.
SliceFitResult fit_family(const fit::SliceData& s, CopulaFamily family, const FitSettings& st) {
  SliceFitResult r;
  auto copula = fit::make_grid_copula(family);
  fit::Marginals m = fit::naive_marginals(s);
  auto independence = fit::make_grid_copula(CopulaFamily::kIndependence);
  if (st.impute_missing) {
    r.report.impute_rounds +=
        fit::impute_marginals(s, *independence, 0.0, st.impute_iterations, st.impute_tolerance, &m);
  }
  fit::ParameterFit p = fit::fit_parameter(s, m, *copula, st.loss);
  r.report.solver_iterations += p.iterations;
  // The marginals were imputed under independence: once the parameter is known, impute under the
  // fitted copula and refit (one more round gains nothing measurable).
  if (st.impute_missing && st.impute_with_copula && p.theta != copula->independence()) {
    fit::Marginals m2 = m;
    r.report.impute_rounds +=
        fit::impute_marginals(s, *copula, p.theta, st.impute_iterations, st.impute_tolerance, &m2);
    fit::ParameterFit p2 = fit::fit_parameter(s, m2, *copula, st.loss);
    r.report.solver_iterations += p2.iterations;
    if (p2.objective <= p.objective) {
      m = std::move(m2);
      p = p2;
    }
  }
  r.cs.family = family;
  r.cs.theta = p.theta;
  r.cs.scale = p.scale;
  r.cs.pdf_h = m.pdf_h;
  r.cs.pdf_d = m.pdf_d;
  r.cs.pdf_p = m.pdf_p;
  r.report.objective = p.objective;
  r.report.objective_independence = p.objective_independence;
  r.report.measured_bins = int(s.measured_count());
  return r;
}

// An RMS residual of 0.1% of the slice's mean value (the objective is in units of the mean
// squared).
constexpr double kAutoObjectiveFloor = 1e-6;

// Grows the fit into a mixture (fit/mixture.h). A fixed count is fitted in one call, which adds
// components one at a time; `auto_components` adds them one call at a time and keeps a component
// only when it lowers the objective by the factor auto_component_gain, and stops early once the
// residual is negligible.
void add_components(const fit::SliceData& s, const FitSettings& st, SliceFitResult* r) {
  const CopulaFamily family = st.auto_family ? CopulaFamily::kFrank : st.family;
  if (!st.auto_components) {
    fit::MixtureFit m = fit::fit_mixture(s, r->cs, st.components, family, st.loss);
    if (m.objective < r->report.objective) {
      r->cs = std::move(m.cs);
      r->report.objective = m.objective;
    }
    r->report.hals_sweeps += m.sweeps;
    r->report.hals_unconverged += m.unconverged;
    r->report.solver_iterations += m.solver_iterations;
    return;
  }
  for (int k = r->cs.components() + 1; k <= st.components; ++k) {
    // Already within kAutoObjectiveFloor: nothing visible left to gain.
    if (r->report.objective < kAutoObjectiveFloor) break;
    fit::MixtureFit m = fit::fit_mixture(s, r->cs, k, family, st.loss);
    r->report.hals_sweeps += m.sweeps;
    r->report.hals_unconverged += m.unconverged;
    r->report.solver_iterations += m.solver_iterations;
    if (m.cs.components() < k || !(m.objective < st.auto_component_gain * r->report.objective)) {
      break;
    }
    r->cs = std::move(m.cs);
    r->report.objective = m.objective;
  }
}

SliceFitResult fit_slice_channel(const BrdfTable& table, int channel, int begin, int end,
                                 const FitSettings& st) {
  fit::SliceData s = fit::extract_slice(table, channel, begin, end, st.loss == FitLoss::kCosine);
  fit::normalize_slice(&s);  // the fit in units of s.unit; K back to physical units at the end
  double sum = 0;
  for (double v : s.mv) sum += v;
  if (!(sum > 0)) {
    // Nothing measured, or all zero: the model is 0 here. Uniform marginals keep CDFs defined.
    SliceFitResult r;
    r.cs.family = CopulaFamily::kIndependence;
    r.cs.theta = 0;
    r.cs.scale = 0;
    r.cs.pdf_h.assign(s.nh, 1.0 / s.nh);
    r.cs.pdf_d.assign(s.nd, 1.0 / s.nd);
    r.cs.pdf_p.assign(s.np, 1.0 / s.np);
    r.report.measured_bins = int(s.measured_count());
    return r;
  }
  SliceFitResult best;
  if (!st.auto_family) {
    best = fit_family(s, st.family, st);
  } else {
    bool have = false;
    for (CopulaFamily f : kAutoFamilies) {
      if (!fit::make_grid_copula(f)) continue;
      SliceFitResult r = fit_family(s, f, st);
      if (!have || r.report.objective < best.report.objective) {
        best = std::move(r);
        have = true;
      }
    }
  }
  if (st.components > 1 && best.cs.scale > 0) add_components(s, st, &best);
  best.cs.scale *= s.unit;  // a power of two: exact
  for (Component& c : best.cs.extra) c.scale *= s.unit;
  return best;
}

}  // namespace

Expected<std::vector<int>> slice_bounds(const FitSettings& st) {
  std::vector<int> b = st.slice_bounds;
  if (b.empty()) {
    if (st.slices < 1 || st.slices > kThetaDBins) {
      return error(ErrorCode::kInvalidArgument,
                   "slice count " + std::to_string(st.slices) + " is outside 1 to 90");
    }
    for (int s = 0; s <= st.slices; ++s) b.push_back(s * kThetaDBins / st.slices);
    return b;
  }
  if (b.size() < 2 || b.front() != 0 || b.back() != kThetaDBins) {
    return error(ErrorCode::kInvalidArgument,
                 "slice boundaries must start at 0 and end at 90 (theta_d bins)");
  }
  for (std::size_t i = 1; i < b.size(); ++i) {
    if (b[i] <= b[i - 1]) {
      return error(ErrorCode::kInvalidArgument, "slice boundaries must increase strictly");
    }
  }
  return b;
}

namespace {

// The supported value range (fit.h).
Status check_value_range(const BrdfTable& table) {
  for (int c = 0; c < kChannels; ++c) {
    const double* data = table.channel_data(c);
    double largest = 0;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (data[i] >= 0.0) largest = std::max(largest, data[i]);  // inf is measured and largest
    }
    if (largest == 0.0 || (largest >= kMinPeakMeasuredValue && largest <= kMaxMeasuredValue)) {
      continue;
    }
    char text[160];
    std::snprintf(text, sizeof text,
                  "channel %c: the largest measured value, %.3g, is outside the supported range "
                  "(%.0e to %.0e, or a channel of zeros)",
                  "RGB"[c], largest, kMinPeakMeasuredValue, kMaxMeasuredValue);
    return error(ErrorCode::kNumeric, text);
  }
  return ok_status();
}

}  // namespace

Expected<Model> fit_model(const BrdfTable& table, const FitSettings& settings, FitReport* report) {
  if (Status s = check_value_range(table); !s.ok()) return s;
  FitSettings st = settings;
  if (st.slice_bounds.empty() && (st.adaptive_slices || st.auto_slices)) {
    if (st.auto_slices) {
      Expected<int> n =
          choose_slice_count(table, kDefaultSliceTolerance, kDefaultMaxAutoSlices, st.slicing);
      if (!n.ok()) return n.status();
      st.slices = *n;
    }
    Expected<std::vector<int>> b = adaptive_slice_bounds(table, st.slices, st.slicing);
    if (!b.ok()) return b.status();
    st.slice_bounds = std::move(b).value();
  }
  auto bounds = slice_bounds(st);
  if (!bounds.ok()) return bounds.status();
  if (!fit::make_grid_copula(st.family)) {
    return error(ErrorCode::kInvalidArgument,
                 "copula family '" + std::string(family_name(st.family)) + "' cannot be fitted");
  }
  if (st.threads < 1) return error(ErrorCode::kInvalidArgument, "threads must be at least 1");
  if (st.components < 1 || st.components > kMaxComponents) {
    return error(ErrorCode::kInvalidArgument, "component count " + std::to_string(st.components) +
                                                  " is outside 1 to " +
                                                  std::to_string(kMaxComponents));
  }
  if (!(st.auto_component_gain > 0 && st.auto_component_gain <= 1)) {
    return error(ErrorCode::kInvalidArgument, "auto_component_gain must lie in (0, 1]");
  }
  const int slices = int(bounds->size()) - 1;
  Model model;
  model.slices.resize(slices);
  model.not_measured = NotMeasured::from_table(table);
  if (report) report->slices.assign(slices, {});
  // Jobs are independent (slice, channel) pairs; each writes only its own result, so the output
  // does not depend on the thread count.
  const int jobs = slices * kChannels;
  internal::parallel_for(jobs, st.threads, [&](int job) {
    const int s = job / kChannels, c = job % kChannels;
    SliceFitResult r = fit_slice_channel(table, c, (*bounds)[s], (*bounds)[s + 1], st);
    model.slices[s].channel[c] = std::move(r.cs);
    if (report) report->slices[s][c] = r.report;
  });
  for (int s = 0; s < slices; ++s) {
    model.slices[s].theta_d_begin = (*bounds)[s];
    model.slices[s].theta_d_end = (*bounds)[s + 1];
  }
  return model;
}

}  // namespace cbrdf
