// SPDX-License-Identifier: MIT
#include "cbrdf/rate_control.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "cbrdf/encoder_options.h"
#include "cbrdf/encoder_settings.h"
#include "encode_watch.h"
#include "metrics.h"
#include "rate/byte_predictor.h"
#include "rate/model_search.h"

namespace cbrdf {
namespace {

constexpr int kMinBits = 6, kMaxBits = 16;
constexpr double kNone = -std::numeric_limits<double>::infinity();
// A forecast of bytes (rate/byte_predictor.h) prunes a fit only when it misses the limit by more
// than this share: the forecasts were within 4% on the real materials, and a pruned fit that
// could have won costs quality, while a fit done for nothing only costs time.
constexpr double kForecastMargin = 0.06;

// The search's state: every setting measured, and the best so far.
class Search {
 public:
  Search(const BrdfTable& table, const EncoderSettings& base, const RateTarget& target)
      : base_(base), target_(target), by_bytes_(target.max_bytes > 0), scorer_(table) {}

  bool met(const RateCandidate& c) const {
    return by_bytes_ ? c.bytes <= target_.max_bytes : c.psnr_tonemapped >= target_.min_psnr;
  }

  // Encodes, decodes and measures one setting of a fitted model and keeps it when it is the best.
  Expected<RateCandidate> measure(const Model& model, const FitReport& report, int slices,
                                  int components, int bits) {
    CBRDF_RETURN_IF_ERROR(internal::check_cancel());
    ContainerSettings cs = base_.container;
    cs.bits = bits;
    CBRDF_ASSIGN_OR_RETURN(auto file, encode_and_score(model, cs, scorer_));
    RateCandidate c{slices,
                    bits,
                    components,
                    double(file.bytes.size()),
                    file.metrics.psnr_tonemapped,
                    file.metrics.psnr_linear};
    result_.tried.push_back(c);
    const bool c_met = met(c);
    if (!have_ || better(c, c_met, result_.chosen, result_.met)) {
      result_.chosen = c;
      result_.met = c_met;
      result_.encoded.bytes = std::move(file.bytes);
      result_.encoded.model = model;
      result_.encoded.report = report;
      result_.encoded.bits = bits;
      have_ = true;
    }
    return c;
  }

  // Bytes only (no decode, no PSNR): encoding is a small part of a measurement, so the bits of a
  // byte budget are searched this way and only the setting found is measured.
  Expected<double> bytes_at(const Model& model, int bits) const {
    CBRDF_RETURN_IF_ERROR(internal::check_cancel());
    ContainerSettings cs = base_.container;
    cs.bits = bits;
    CBRDF_ASSIGN_OR_RETURN(auto bytes, encode_model(model, cs));
    return double(bytes.size());
  }

  // Makes `model` at `bits` the chosen setting (measured), whatever was chosen before.
  Status choose(const Model& model, const FitReport& report, int slices, int components, int bits) {
    have_ = false;
    return measure(model, report, slices, components, bits).status();
  }

  bool have() const { return have_; }
  bool have_met() const { return have_ && result_.met; }
  const RateCandidate& chosen() const { return result_.chosen; }
  RateResult& result() { return result_; }

 private:
  // Better than: meets the target and beats the other on the objective; when neither meets it,
  // the closer to the target.
  bool better(const RateCandidate& a, bool a_met, const RateCandidate& b, bool b_met) const {
    if (a_met != b_met) return a_met;
    if (by_bytes_) return a_met ? a.psnr_tonemapped > b.psnr_tonemapped : a.bytes < b.bytes;
    return a_met ? a.bytes < b.bytes : a.psnr_tonemapped > b.psnr_tonemapped;
  }

  const EncoderSettings& base_;
  const RateTarget& target_;
  const bool by_bytes_;
  const SphereScorer scorer_;  // the table's sphere renders, made once for every measurement
  RateResult result_;
  bool have_ = false;
};

// What one row (a fitted slice and component count) gave.
struct Row {
  double bytes_at_fewest = 0;  // bytes at 6 bits: the least any setting of the row costs
  double psnr = kNone;         // bytes: the best PSNR within the budget; PSNR: at 16 bits
};

// One row at a byte budget: the most bits within it, found on bytes alone by bisection (bytes grow
// with bits), then measured once (PSNR grows with bits). A row over the budget even at 6 bits is
// measured there only while nothing met it (it may be the closest).
Expected<Row> row_for_bytes(Search* search, const Model& model, const FitReport& report, int slices,
                            int components, double budget) {
  Row row;
  CBRDF_ASSIGN_OR_RETURN(auto fewest, search->bytes_at(model, kMinBits));
  row.bytes_at_fewest = fewest;
  if (fewest > budget) {
    if (!search->have() || (!search->have_met() && fewest < search->chosen().bytes)) {
      CBRDF_RETURN_IF_ERROR(search->measure(model, report, slices, components, kMinBits).status());
    }
    return row;
  }
  int lo = kMinBits, hi = kMaxBits + 1;  // lo within the budget, hi over it (or past the range)
  CBRDF_ASSIGN_OR_RETURN(auto most, search->bytes_at(model, kMaxBits));
  if (most <= budget) lo = kMaxBits;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    CBRDF_ASSIGN_OR_RETURN(auto b, search->bytes_at(model, mid));
    (b <= budget ? lo : hi) = mid;
  }
  CBRDF_ASSIGN_OR_RETURN(auto c, search->measure(model, report, slices, components, lo));
  row.psnr = c.psnr_tonemapped;
  return row;
}

// One row at a PSNR target: the fewest bits reaching it, by bisection (PSNR grows with bits);
// only 16 bits when even they do not reach it (the row's closest).
Expected<Row> row_for_psnr(Search* search, const Model& model, const FitReport& report, int slices,
                           int components) {
  Row row;
  CBRDF_ASSIGN_OR_RETURN(auto fewest, search->bytes_at(model, kMinBits));
  row.bytes_at_fewest = fewest;
  CBRDF_ASSIGN_OR_RETURN(auto hi_c, search->measure(model, report, slices, components, kMaxBits));
  row.psnr = hi_c.psnr_tonemapped;
  if (!search->met(hi_c)) return row;
  int lo = kMinBits - 1, hi = kMaxBits;  // lo short of the target (or below the range), hi met
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    CBRDF_ASSIGN_OR_RETURN(auto c, search->measure(model, report, slices, components, mid));
    (search->met(c) ? hi : lo) = mid;
  }
  return row;
}

// Within a PSNR target's reach, the most bits need not be the best: quantization noise of a
// few bits less can score a hair higher once the PSNR has saturated (chrome-steel: 13 bits). When
// nothing reached the target, the chosen row (measured at 16 bits only) is walked down in bits
// while its PSNR stays within kSaturatedDb of the best, so the closest setting is the one the
// full enumeration of bits would choose there.
constexpr double kSaturatedDb = 0.05;

Status refine_closest(Search* search) {
  const RateCandidate start = search->chosen();
  const Model model = search->result().encoded.model;
  const FitReport report = search->result().encoded.report;
  for (int bits = start.bits - 1; bits >= kMinBits; --bits) {
    CBRDF_ASSIGN_OR_RETURN(auto c,
                           search->measure(model, report, start.slices, start.components, bits));
    if (c.psnr_tonemapped < search->chosen().psnr_tonemapped - kSaturatedDb) break;
  }
  return ok_status();
}

Status check_target(const RateTarget& target) {
  const bool by_bytes = target.max_bytes > 0, by_psnr = target.min_psnr > 0;
  if (by_bytes == by_psnr) {
    return error(ErrorCode::kInvalidArgument,
                 "give exactly one target: a byte budget or a PSNR to reach");
  }
  return ok_status();
}

}  // namespace

namespace {

// The search over slice and component counts: what it knows of the rows fitted so far, and the
// rules that keep it from fitting rows that cannot win.
class Grid {
 public:
  Grid(const BrdfTable& table, const EncoderSettings& base, const RateTarget& target,
       bool for_ladder)
      : table_(table),
        base_(base),
        target_(target),
        for_ladder_(for_ladder),
        search_(table, base, target) {}

  // First one component at each slice count (ascending) until slices stop paying, then one more
  // component at a time across the slice counts still open: each round learns what a component
  // gains before the next slice count decides whether to fit it.
  Status run() {
    double best_one = kNone;
    int misses = 0;
    for (int slices : target_.slice_counts) {
      // Bytes grow with slices: a smaller slice count's one-component file at 6 bits bounds this
      // one's, and so does a forecast (with its margin) through the smaller counts' files.
      if (floor_bytes_ >= 0 && slices >= floor_count_ && cannot_win(floor_bytes_)) continue;
      if (forecast_cannot_win(slices, 1)) continue;
      CBRDF_ASSIGN_OR_RETURN(auto row, fit_row(slices, 1));
      if (components_pay(row, kNone)) lanes_.at(slices).previous = row.psnr;
      // PSNR against slices rises to a few slices and then is flat or falls (the metric sees
      // three theta_d): the first slice count that does not beat the smaller ones ends the
      // search over slices.
      misses = row.psnr > best_one ? 0 : misses + 1;
      best_one = std::max(best_one, row.psnr);
      if (misses >= kSlicePatience) break;
    }
    if (for_ladder_ && !by_bytes() && best_one + kMixtureGainDb < target_.min_psnr) {
      return choose_residual_base();
    }
    for (int components = 2; components <= target_.max_components; ++components) {
      for (auto& [slices, lane] : lanes_) {
        if (!std::isfinite(lane.previous) || forecast_cannot_win(slices, components) ||
            gain_cannot_win(slices, components, lane.previous)) {
          lane.previous = kNone;  // closed: more components cannot win
          continue;
        }
        CBRDF_ASSIGN_OR_RETURN(auto row, fit_row(slices, components));
        lane.previous = components_pay(row, lane.previous) ? row.psnr : kNone;
      }
    }
    if (for_ladder_ && !by_bytes() && !search_.have_met()) return choose_residual_base();
    add_work();
    if (!by_bytes() && !search_.have_met()) return refine_closest(&search_);
    return ok_status();
  }

  RateResult& result() { return search_.result(); }

 private:
  static constexpr int kSlicePatience = 1;
  // The most mixtures added to the best one-component row's PSNR on the real materials measured
  // (gold-metallic-paint: 7.3 dB from 1 to 4 components at 9 slices; red-specular-plastic 6.0,
  // specular-black-phenolic 2.9), with a margin. Gains come in jumps (gold at 9 slices: +0.7,
  // +4.5, +2.1 dB), so a cheaper probe of fewer components does not tell them.
  static constexpr double kMixtureGainDb = 8.0;

  void add_work() {
    for (const auto& [slices, lane] : lanes_) {
      search_.result().fits += lane.ladder.fits();
      search_.result().hals_sweeps += lane.ladder.hals_sweeps();
    }
  }

  // A PSNR that no model reaches goes to the residual layer (encode_to_target_ladder), and there
  // the model under it is best cheap: a residual on the default one-component model takes well
  // under half the bytes of one on the closest model. So the base is the one-component row at the
  // settings' slice count (else the best one fitted) at the bits `--bits auto` chooses, as a
  // default encode would write it; when the one-component rows show the PSNR out of reach, no
  // mixture is fitted.
  Status choose_residual_base() {
    auto lane = lanes_.find(base_.fit.slices);
    if (lane == lanes_.end()) {
      double best = kNone;
      for (auto it = lanes_.begin(); it != lanes_.end(); ++it) {
        const double p = psnr_.at({it->first, 1});
        if (lane == lanes_.end() || p > best) lane = it, best = p;
      }
    }
    FitReport report;
    CBRDF_ASSIGN_OR_RETURN(auto model, lane->second.ladder.fit(1, &report));
    CBRDF_ASSIGN_OR_RETURN(auto bits, choose_bits(table_, model, base_.container, base_.auto_bits));
    add_work();
    return search_.choose(model, report, lane->first, 1, bits.bits);
  }

  static constexpr double kGainSlackDb = 1.0;

  bool by_bytes() const { return target_.max_bytes > 0; }
  // No setting costing `bytes` or more can beat the one chosen (or fit the budget).
  bool cannot_win(double bytes) const {
    return by_bytes() ? bytes > target_.max_bytes
                      : search_.have_met() && bytes >= search_.chosen().bytes;
  }
  bool forecast_cannot_win(int slices, int components) const {
    const auto b = predictor_.predict(slices, components);
    return b && cannot_win(*b * (1 - kForecastMargin));
  }

  // The most one more component can add to a row's PSNR: the gain from components - 1 to
  // components at any slice count fitted, else the gain of the component before at this one
  // (gains shrink with the count); none known: no bound.
  std::optional<double> gain_bound(int slices, int components) const {
    std::optional<double> gain;
    for (const auto& [sk, p] : psnr_) {
      if (sk.second != components) continue;
      const auto before = psnr_.find({sk.first, components - 1});
      if (before == psnr_.end() || !std::isfinite(p) || !std::isfinite(before->second)) continue;
      gain = std::max(gain.value_or(kNone), p - before->second);
    }
    if (gain) return gain;
    const auto a = psnr_.find({slices, components - 1}), b = psnr_.find({slices, components - 2});
    if (a != psnr_.end() && b != psnr_.end() && std::isfinite(a->second) &&
        std::isfinite(b->second)) {
      return a->second - b->second;
    }
    return std::nullopt;
  }
  // A component whose best possible gain (with kGainSlackDb to spare) leaves the row short of
  // the best setting within the budget, or of a PSNR target already met elsewhere.
  bool gain_cannot_win(int slices, int components, double previous) const {
    if (!std::isfinite(previous) || !search_.have_met()) return false;
    const auto gain = gain_bound(slices, components);
    if (!gain) return false;
    const double bound = previous + std::max(*gain, 0.0) + kGainSlackDb;
    return by_bytes() ? bound <= search_.chosen().psnr_tonemapped : bound < target_.min_psnr;
  }

  // More components may still win after this row: it does not cost the target's bytes already at
  // 6 bits (more components only add bytes), and its component raised the row's PSNR (at a
  // budget: the best within it; a component that does not is not followed by one that does).
  bool components_pay(const Row& row, double previous) const {
    return !cannot_win(row.bytes_at_fewest) && row.psnr > previous;
  }

  // One row: the slice count's ladder (fit.h, FitLadder: each component count continues the
  // factorization of the one before) fitted at `components`, and its bits searched.
  Expected<Row> fit_row(int slices, int components) {
    // Progress: each row an equal share of the most rows the search could fit (pruning ends it
    // early, so the fraction jumps at the end rather than run past 1).
    const double most = double(target_.slice_counts.size()) * target_.max_components;
    const internal::ProgressPart part("target", rows_ / most, std::min(1.0, (rows_ + 1) / most));
    ++rows_;
    auto lane = lanes_.find(slices);
    if (lane == lanes_.end()) {
      FitSettings fs = base_.fit;
      set_counts({slices, false}, {1, false}, &fs);
      fs.mixture_copulas = target_.mixture_copulas;
      lane = lanes_.emplace(slices, Lane{FitLadder(table_, fs), kNone}).first;
    }
    FitReport report;
    CBRDF_ASSIGN_OR_RETURN(auto model, lane->second.ladder.fit(components, &report));
    CBRDF_ASSIGN_OR_RETURN(
        auto row,
        by_bytes() ? row_for_bytes(&search_, model, report, slices, components, target_.max_bytes)
                   : row_for_psnr(&search_, model, report, slices, components));
    predictor_.add(slices, components, row.bytes_at_fewest);
    psnr_[{slices, components}] = row.psnr;
    if (components == 1 && (floor_bytes_ < 0 || slices < floor_count_)) {
      floor_bytes_ = row.bytes_at_fewest;
      floor_count_ = slices;
    }
    return row;
  }

  struct Lane {
    FitLadder ladder;
    double previous;  // the PSNR of its last row; -inf: closed to more components
  };

  const BrdfTable& table_;
  const EncoderSettings& base_;
  const RateTarget& target_;
  const bool for_ladder_;
  Search search_;
  internal::BytePredictor predictor_;
  std::map<std::pair<int, int>, double> psnr_;  // Row::psnr per (slices, components) fitted
  std::map<int, Lane> lanes_;                   // per slice count fitted
  double floor_bytes_ = -1;  // one component at 6 bits at the smallest slice count fitted
  int floor_count_ = 0;
  int rows_ = 0;  // rows fitted, for progress
};

}  // namespace

Expected<RateResult> encode_to_target(const BrdfTable& table, const EncoderSettings& base,
                                      const RateTarget& target) {
  return internal::watched<RateResult>(base.progress, [&] {
    const internal::ProgressPart part("target", 0, 1);
    return internal::search_model(table, base, target, false);
  });
}

namespace internal {

Expected<RateResult> search_model(const BrdfTable& table, const EncoderSettings& base,
                                  const RateTarget& target, bool for_ladder) {
  std::vector<SettingProblem> problems = validate(base);
  for (SettingProblem& p : validate(target)) problems.push_back(std::move(p));
  CBRDF_RETURN_IF_ERROR(settings_status(problems, cxx_spelling));
  if (Status s = check_target(target); !s.ok()) return s;
  Grid grid(table, base, target, for_ladder);
  if (Status s = grid.run(); !s.ok()) return s;
  return std::move(grid.result());
}

}  // namespace internal

}  // namespace cbrdf
