// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "cbrdf/fit.h"
#include "density/grid_copula.h"
#include "encode_watch.h"
#include "fit/fit_families.h"
#include "fit/fit_parameter.h"
#include "fit/marginals.h"
#include "fit/mixture.h"
#include "fit/slice_data.h"
#include "parallel_for.h"

namespace cbrdf {
namespace {

struct SliceFitResult {
  ChannelSlice cs;
  ChannelSliceFit report;
};

// Marginals (imputed or naive) and parameter for one family.
SliceFitResult fit_family(const internal::SliceData& s, CopulaFamily family,
                          const FitSettings& st) {
  SliceFitResult r;
  auto copula = internal::make_grid_copula(family);
  internal::Marginals m = internal::naive_marginals(s);
  auto independence = internal::make_grid_copula(CopulaFamily::kIndependence);
  if (st.impute_missing) {
    r.report.impute_rounds += internal::impute_marginals(
        s, *independence, 0.0, st.impute_iterations, st.impute_tolerance, &m);
  }
  internal::ParameterFit p = internal::fit_parameter(s, m, *copula, st.loss);
  r.report.solver_iterations += p.iterations;
  // The marginals were imputed under independence: once the parameter is known, impute under the
  // fitted copula and refit (one more round gains nothing measurable).
  if (st.impute_missing && st.impute_with_copula && p.theta != copula->independence() &&
      !internal::cancel_requested()) {
    internal::Marginals m2 = m;
    r.report.impute_rounds += internal::impute_marginals(s, *copula, p.theta, st.impute_iterations,
                                                         st.impute_tolerance, &m2);
    internal::ParameterFit p2 = internal::fit_parameter(s, m2, *copula, st.loss);
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

// A mixture fit's effort, added to its slice's report.
void count_effort(const internal::MixtureFit& m, SliceFitResult* r) {
  r->report.hals_sweeps += m.sweeps;
  r->report.hals_unconverged += m.unconverged;
  r->report.solver_iterations += m.solver_iterations;
}

// Keeps a mixture fit where it lowers its slice's objective, and counts its effort either way.
void keep_if_better(internal::MixtureFit m, SliceFitResult* r) {
  if (m.objective < r->report.objective) {
    r->cs = std::move(m.cs);
    r->report.objective = m.objective;
  }
  count_effort(m, r);
}

// Grows the fit into a mixture (fit/mixture.h). A fixed count is fitted in one call, which adds
// components one at a time; `auto_components` adds them one call at a time and keeps a component
// only when it lowers the objective by the factor auto_component_gain, and stops early once the
// residual is negligible.
void add_components(const internal::SliceData& s, const FitSettings& st, SliceFitResult* r) {
  const CopulaFamily family = st.auto_family ? internal::kAutoMixtureFamily : st.family;
  if (!st.auto_components) {
    keep_if_better(
        internal::fit_mixture(s, r->cs, st.components, family, st.loss, st.mixture_copulas), r);
    return;
  }
  for (int k = r->cs.components() + 1; k <= st.components; ++k) {
    // Already within kAutoObjectiveFloor: nothing visible left to gain.
    if (r->report.objective < kAutoObjectiveFloor) break;
    internal::MixtureFit m =
        internal::fit_mixture(s, r->cs, k, family, st.loss, st.mixture_copulas);
    count_effort(m, r);
    if (m.cs.components() < k || !(m.objective < st.auto_component_gain * r->report.objective)) {
      break;
    }
    r->cs = std::move(m.cs);
    r->report.objective = m.objective;
  }
}

internal::SliceData slice_for_fit(const BrdfTable& table, int channel, int begin, int end,
                                  const FitSettings& st) {
  internal::SliceData s =
      internal::extract_slice(table, channel, begin, end, st.loss == FitLoss::kCosine);
  internal::normalize_slice(&s);  // the fit in units of s.unit; K back to physical units at the end
  return s;
}

// K from the fit's units (s.unit) back to physical ones.
void to_physical(double unit, SliceFitResult* r) {
  r->cs.scale *= unit;  // a power of two: exact
  for (Component& c : r->cs.extra) c.scale *= unit;
}

// The one-component fit of a slice (in units of s.unit); `zero` is set when nothing is measured
// or all is zero, and the result is then final (the model is 0 there).
SliceFitResult fit_single(const internal::SliceData& s, const FitSettings& st, bool* zero) {
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
    *zero = true;
    return r;
  }
  *zero = false;
  SliceFitResult best;
  if (!st.auto_family) {
    best = fit_family(s, st.family, st);
  } else {
    bool have = false;
    for (const internal::FitFamilyRow& row : internal::kFitFamilies) {
      if (!row.in_auto) continue;
      SliceFitResult r = fit_family(s, row.id, st);
      if (!have || r.report.objective < best.report.objective) {
        best = std::move(r);
        have = true;
      }
    }
  }
  return best;
}

SliceFitResult fit_slice_channel(const BrdfTable& table, int channel, int begin, int end,
                                 const FitSettings& st) {
  const internal::SliceData s = slice_for_fit(table, channel, begin, end, st);
  bool zero = false;
  SliceFitResult best = fit_single(s, st, &zero);
  if (zero) return best;
  if (st.components > 1 && best.cs.scale > 0) add_components(s, st, &best);
  to_physical(s.unit, &best);
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

// The settings checked, with the slicing resolved into `bounds`.
Expected<FitSettings> resolve(const BrdfTable& table, const FitSettings& settings,
                              std::vector<int>* bounds_out) {
  if (Status s = check_value_range(table); !s.ok()) return s;
  FitSettings st = settings;
  if (st.slice_bounds.empty() && (st.adaptive_slices || st.auto_slices)) {
    if (st.auto_slices) {
      CBRDF_ASSIGN_OR_RETURN(int n, choose_slice_count(table, kDefaultSliceTolerance,
                                                       kDefaultMaxAutoSlices, st.slicing));
      st.slices = n;
    }
    CBRDF_ASSIGN_OR_RETURN(st.slice_bounds, adaptive_slice_bounds(table, st.slices, st.slicing));
  }
  CBRDF_ASSIGN_OR_RETURN(auto bounds, slice_bounds(st));
  if (!internal::make_grid_copula(st.family)) {
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
  *bounds_out = std::move(bounds);
  return st;
}

}  // namespace

Expected<Model> fit_model(const BrdfTable& table, const FitSettings& settings, FitReport* report) {
  std::vector<int> b;
  CBRDF_ASSIGN_OR_RETURN(FitSettings resolved, resolve(table, settings, &b));
  const FitSettings& st = resolved;
  const std::vector<int>* bounds = &b;
  const int slices = int(bounds->size()) - 1;
  Model model;
  model.slices.resize(slices);
  model.not_measured = NotMeasured::from_table(table);
  if (report) report->slices.assign(slices, {});
  // Jobs are independent (slice, channel) pairs; each writes only its own result, so the output
  // does not depend on the thread count.
  const int jobs = slices * kChannels;
  internal::watched_parallel_for(jobs, st.threads, [&](int job) {
    const int s = job / kChannels, c = job % kChannels;
    SliceFitResult r = fit_slice_channel(table, c, (*bounds)[s], (*bounds)[s + 1], st);
    model.slices[s].channel[c] = std::move(r.cs);
    if (report) report->slices[s][c] = r.report;
  });
  CBRDF_RETURN_IF_ERROR(internal::check_cancel());
  for (int s = 0; s < slices; ++s) {
    model.slices[s].theta_d_begin = (*bounds)[s];
    model.slices[s].theta_d_end = (*bounds)[s + 1];
  }
  return model;
}

struct FitLadder::State {
  const BrdfTable* table = nullptr;
  FitSettings settings;  // as given
  bool prepared = false;
  Status failure = ok_status();  // the settings' error, once prepared
  FitSettings st;                // resolved, one component
  std::vector<int> bounds;
  NotMeasured not_measured;
  // Per (slice, channel) job: the one-component fit in the fit's units, its unit, whether the
  // slice is all zero, and the factorization as the last count left it.
  std::vector<SliceFitResult> single;
  std::vector<double> unit;
  std::vector<char> zero;
  std::vector<internal::MixtureState> mixture;
  int top = 0;  // the highest count whose factorization `mixture` holds
  std::map<int, std::pair<Model, FitReport>> done;
  int fits = 0;
  long long sweeps = 0;

  Model assemble(const std::vector<SliceFitResult>& results, FitReport* report) const {
    const int slices = int(bounds.size()) - 1;
    Model model;
    model.slices.resize(std::size_t(slices));
    model.not_measured = not_measured;
    if (report) report->slices.assign(std::size_t(slices), {});
    for (int s = 0; s < slices; ++s) {
      model.slices[std::size_t(s)].theta_d_begin = bounds[std::size_t(s)];
      model.slices[std::size_t(s)].theta_d_end = bounds[std::size_t(s) + 1];
      for (int c = 0; c < kChannels; ++c) {
        const SliceFitResult& r = results[std::size_t(s * kChannels + c)];
        model.slices[std::size_t(s)].channel[std::size_t(c)] = r.cs;
        if (report) report->slices[std::size_t(s)][std::size_t(c)] = r.report;
      }
    }
    return model;
  }

  internal::SliceData slice(int job) const {
    const int s = job / kChannels, c = job % kChannels;
    return slice_for_fit(*table, c, bounds[std::size_t(s)], bounds[std::size_t(s) + 1], st);
  }

  // Resolves the settings once, for one component; an error is kept for every call.
  void prepare() {
    prepared = true;
    FitSettings one = settings;
    one.components = 1;
    one.auto_components = false;
    Expected<FitSettings> r = resolve(*table, one, &bounds);
    if (!r.ok()) {
      failure = r.status();
    } else {
      st = *r;
      not_measured = NotMeasured::from_table(*table);
    }
  }

  // The one-component fit of every job, which every larger count starts from.
  Status fit_single_components(int jobs) {
    single.assign(std::size_t(jobs), {});
    unit.assign(std::size_t(jobs), 1.0);
    zero.assign(std::size_t(jobs), 0);
    mixture.assign(std::size_t(jobs), {});
    internal::watched_parallel_for(jobs, st.threads, [&](int job) {
      const internal::SliceData s = slice(job);
      bool all_zero = false;
      single[std::size_t(job)] = fit_single(s, st, &all_zero);
      unit[std::size_t(job)] = s.unit;
      zero[std::size_t(job)] = all_zero;
    });
    // A cancelled loop leaves fits undone: nothing of it may be kept for a later call.
    if (internal::cancel_requested()) {
      top = 0;
      return internal::cancelled_status();
    }
    top = 1;
    ++fits;
    return ok_status();
  }

  // add_components at a fixed count, with each job's factorization continued from `top`.
  Status continue_mixtures(int components, int jobs, std::vector<SliceFitResult>* results) {
    const CopulaFamily family = st.auto_family ? internal::kAutoMixtureFamily : st.family;
    std::vector<long long> job_sweeps(std::size_t(jobs), 0);
    internal::watched_parallel_for(jobs, st.threads, [&](int job) {
      SliceFitResult* r = &(*results)[std::size_t(job)];
      if (zero[std::size_t(job)] || !(r->cs.scale > 0)) return;
      const internal::SliceData s = slice(job);
      internal::MixtureState& state = mixture[std::size_t(job)];
      const int before = state.sweeps;
      internal::MixtureFit m = internal::fit_mixture_continued(s, r->cs, components, family,
                                                               st.loss, &state, st.mixture_copulas);
      job_sweeps[std::size_t(job)] = state.started ? state.sweeps - before : 0;
      keep_if_better(std::move(m), r);
    });
    if (internal::cancel_requested()) {
      top = 0;  // the factorizations are left part-way: start again on a later call
      mixture.assign(std::size_t(jobs), {});
      return internal::cancelled_status();
    }
    for (long long n : job_sweeps) sweeps += n;
    top = components;
    ++fits;
    return ok_status();
  }
};

FitLadder::FitLadder(const BrdfTable& table, const FitSettings& settings)
    : state_(std::make_unique<State>()) {
  state_->table = &table;
  state_->settings = settings;
}
FitLadder::~FitLadder() = default;
FitLadder::FitLadder(FitLadder&&) noexcept = default;
FitLadder& FitLadder::operator=(FitLadder&&) noexcept = default;

int FitLadder::fits() const {
  return state_->fits;
}

long long FitLadder::hals_sweeps() const {
  return state_->sweeps;
}

Expected<Model> FitLadder::fit(int components, FitReport* report) {
  State& L = *state_;
  if (!L.prepared) L.prepare();
  if (!L.failure.ok()) return L.failure;
  if (components < 1 || components > kMaxComponents) {
    return error(ErrorCode::kInvalidArgument, "component count " + std::to_string(components) +
                                                  " is outside 1 to " +
                                                  std::to_string(kMaxComponents));
  }
  if (const auto it = L.done.find(components); it != L.done.end()) {
    if (report) *report = it->second.second;
    return it->second.first;
  }
  if (components < L.top) {
    // Past this count already: fit it on its own (never happens in an increasing search).
    FitSettings st = L.st;
    st.components = components;
    st.slice_bounds = L.bounds;
    return fit_model(*L.table, st, report);
  }
  const int jobs = int(L.bounds.size() - 1) * kChannels;
  if (L.top == 0) CBRDF_RETURN_IF_ERROR(L.fit_single_components(jobs));
  std::vector<SliceFitResult> results(L.single);
  if (components > 1) CBRDF_RETURN_IF_ERROR(L.continue_mixtures(components, jobs, &results));
  for (int job = 0; job < jobs; ++job) {
    if (!L.zero[std::size_t(job)])
      to_physical(L.unit[std::size_t(job)], &results[std::size_t(job)]);
  }
  FitReport rep;
  Model model = L.assemble(results, &rep);
  L.done[components] = {model, rep};
  if (report) *report = std::move(rep);
  return model;
}

}  // namespace cbrdf
