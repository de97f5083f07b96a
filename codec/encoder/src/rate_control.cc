// SPDX-License-Identifier: MIT
#include "cbrdf/rate_control.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "cbrdf/metrics.h"

namespace cbrdf {
namespace {

constexpr int kMinBits = 6, kMaxBits = 16;

// The search's state: every setting measured, and the best so far.
class Search {
 public:
  Search(const BrdfTable& table, const EncoderSettings& base, const RateTarget& target)
      : table_(table), base_(base), target_(target), by_bytes_(target.max_bytes > 0) {}

  bool met(const RateCandidate& c) const {
    return by_bytes_ ? c.bytes <= target_.max_bytes : c.psnr_tonemapped >= target_.min_psnr;
  }

  // Encodes, decodes and measures one setting of a fitted model and keeps it when it is the best.
  Expected<RateCandidate> measure(const Model& model, const FitReport& report, int slices,
                                  int components, int bits) {
    ContainerSettings cs = base_.container;
    cs.bits = bits;
    auto bytes = encode_model(model, cs);
    if (!bytes.ok()) return bytes.status();
    auto decoded = decode_model(*bytes);
    if (!decoded.ok()) return decoded.status();
    const ImageMetrics im = sphere_psnr(table_, decoded->table());
    RateCandidate c{slices,        bits, components, double(bytes->size()), im.psnr_tonemapped,
                    im.psnr_linear};
    result_.tried.push_back(c);
    const bool c_met = met(c);
    if (!have_ || better(c, c_met, result_.chosen, result_.met)) {
      result_.chosen = c;
      result_.met = c_met;
      result_.encoded.bytes = std::move(bytes).value();
      result_.encoded.model = model;
      result_.encoded.report = report;
      result_.encoded.bits = bits;
      have_ = true;
    }
    return c;
  }

  // Bytes only (no decode, no PSNR): the bound the pruning needs.
  Expected<double> bytes_at(const Model& model, int bits) const {
    ContainerSettings cs = base_.container;
    cs.bits = bits;
    auto bytes = encode_model(model, cs);
    if (!bytes.ok()) return bytes.status();
    return double(bytes->size());
  }

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

  const BrdfTable& table_;
  const EncoderSettings& base_;
  const RateTarget& target_;
  const bool by_bytes_;
  RateResult result_;
  bool have_ = false;
};

// One row (a fitted slice and component count) at a byte budget: the most bits within it, by
// bisection (bytes grow with bits). Sets *over_at_fewest when even 6 bits exceed the budget.
Status search_bits_for_bytes(Search* search, const Model& model, const FitReport& report,
                             int slices, int components, bool* over_at_fewest) {
  auto lo_c = search->measure(model, report, slices, components, kMinBits);
  if (!lo_c.ok()) return lo_c.status();
  *over_at_fewest = !search->met(*lo_c);
  if (*over_at_fewest) return ok_status();
  auto hi_c = search->measure(model, report, slices, components, kMaxBits);
  if (!hi_c.ok()) return hi_c.status();
  if (search->met(*hi_c)) return ok_status();
  int lo = kMinBits, hi = kMaxBits;  // lo within the budget, hi over it
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    auto c = search->measure(model, report, slices, components, mid);
    if (!c.ok()) return c.status();
    (search->met(*c) ? lo : hi) = mid;
  }
  return ok_status();
}

// One row at a PSNR target: the fewest bits reaching it, by bisection (PSNR grows with bits);
// only 16 bits when even they do not reach it (the row's closest).
Status search_bits_for_psnr(Search* search, const Model& model, const FitReport& report, int slices,
                            int components) {
  auto hi_c = search->measure(model, report, slices, components, kMaxBits);
  if (!hi_c.ok()) return hi_c.status();
  if (!search->met(*hi_c)) return ok_status();
  int lo = kMinBits - 1, hi = kMaxBits;  // lo short of the target (or below the range), hi met
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    auto c = search->measure(model, report, slices, components, mid);
    if (!c.ok()) return c.status();
    (search->met(*c) ? hi : lo) = mid;
  }
  return ok_status();
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
    auto c = search->measure(model, report, start.slices, start.components, bits);
    if (!c.ok()) return c.status();
    if (c->psnr_tonemapped < search->chosen().psnr_tonemapped - kSaturatedDb) break;
  }
  return ok_status();
}

}  // namespace

Expected<RateResult> encode_to_target(const BrdfTable& table, const EncoderSettings& base,
                                      const RateTarget& target) {
  const bool by_bytes = target.max_bytes > 0, by_psnr = target.min_psnr > 0;
  if (by_bytes == by_psnr) {
    return error(ErrorCode::kInvalidArgument,
                 "give exactly one target: a byte budget or a PSNR to reach");
  }
  if (target.max_components < 1 || target.max_components > kMaxComponents) {
    return error(ErrorCode::kInvalidArgument,
                 "max_components " + std::to_string(target.max_components) + " is outside 1 to " +
                     std::to_string(kMaxComponents));
  }
  if (target.slice_counts.empty()) {
    return error(ErrorCode::kInvalidArgument, "no slice counts to search");
  }
  Search search(table, base, target);
  // Bytes grow with slices, components and bits (more marginal values to store). A slice count
  // whose one-component fit at 6 bits already costs `bytes_floor` bytes bounds every larger one:
  // past the budget (bytes target) or at least the bytes of a setting already reaching the PSNR
  // (PSNR target), larger slice counts cannot win and are not fitted.
  double slice_floor_bytes = -1;
  int slice_floor_count = 0;
  for (int slices : target.slice_counts) {
    if (slice_floor_bytes >= 0 && slices >= slice_floor_count) {
      const bool prune = by_bytes ? slice_floor_bytes > target.max_bytes
                                  : search.have_met() && slice_floor_bytes >= search.chosen().bytes;
      if (prune) continue;
    }
    FitSettings fs = base.fit;
    set_counts({slices, false}, {1, false}, &fs);
    // Components are fitted in increasing count, each continuing the factorization of the one
    // before (fit.h, FitLadder).
    FitLadder ladder(table, fs);
    for (int components = 1; components <= target.max_components; ++components) {
      FitReport report;
      auto model = ladder.fit(components, &report);
      if (!model.ok()) return model.status();
      if (by_bytes) {
        bool over_at_fewest = false;
        if (Status s =
                search_bits_for_bytes(&search, *model, report, slices, components, &over_at_fewest);
            !s.ok()) {
          return s;
        }
        if (over_at_fewest) {
          // More components only add bytes too.
          if (components == 1 && (slice_floor_bytes < 0 || slices < slice_floor_count)) {
            slice_floor_bytes = target.max_bytes + 1;
            slice_floor_count = slices;
          }
          break;
        }
        continue;
      }
      if (Status s = search_bits_for_psnr(&search, *model, report, slices, components); !s.ok()) {
        return s;
      }
      // Every setting with more components costs at least this row's bytes at 6 bits.
      if (search.have_met()) {
        auto floor = search.bytes_at(*model, kMinBits);
        if (!floor.ok()) return floor.status();
        if (components == 1 && (slice_floor_bytes < 0 || slices < slice_floor_count)) {
          slice_floor_bytes = *floor;
          slice_floor_count = slices;
        }
        if (*floor >= search.chosen().bytes) break;
      }
    }
    search.result().fits += ladder.fits();
    search.result().hals_sweeps += ladder.hals_sweeps();
  }
  if (by_psnr && !search.have_met()) {
    if (Status s = refine_closest(&search); !s.ok()) return s;
  }
  return std::move(search.result());
}

}  // namespace cbrdf
