// SPDX-License-Identifier: MIT
#include "cbrdf/rate_control.h"

#include <cmath>
#include <string>

#include "cbrdf/metrics.h"

namespace cbrdf {

Expected<RateResult> encode_to_target(const BrdfTable& table, const EncoderSettings& base,
                                      const RateTarget& target) {
  const bool by_bytes = target.max_bytes > 0, by_psnr = target.min_psnr > 0;
  if (by_bytes == by_psnr) {
    return error(ErrorCode::kInvalidArgument,
                 "give exactly one target: a byte budget or a PSNR to reach");
  }
  RateResult best;
  bool have = false;
  // Better than: meets the target and beats the other on the objective; when neither meets it,
  // the closer to the target.
  auto better = [&](const RateCandidate& a, bool a_met, const RateCandidate& b, bool b_met) {
    if (a_met != b_met) return a_met;
    if (by_bytes) return a_met ? a.psnr_tonemapped > b.psnr_tonemapped : a.bytes < b.bytes;
    return a_met ? a.bytes < b.bytes : a.psnr_tonemapped > b.psnr_tonemapped;
  };
  if (target.max_components < 1 || target.max_components > kMaxComponents) {
    return error(ErrorCode::kInvalidArgument,
                 "max_components " + std::to_string(target.max_components) + " is outside 1 to " +
                     std::to_string(kMaxComponents));
  }
  if (target.slice_counts.empty()) {
    return error(ErrorCode::kInvalidArgument, "no slice counts to search");
  }
  for (int slices : target.slice_counts) {
    for (int components = 1; components <= target.max_components; ++components) {
      EncoderSettings st = base;
      set_counts({slices, false}, {components, false}, &st.fit);
      FitReport report;
      auto model = fit_model(table, st.fit, &report);
      if (!model.ok()) return model.status();
      bool over_budget_at_fewest_bits = false;
      for (int bits = 6; bits <= 16; ++bits) {
        st.container.bits = bits;
        auto bytes = encode_model(*model, st.container);
        if (!bytes.ok()) return bytes.status();
        auto decoded = decode_model(*bytes);
        if (!decoded.ok()) return decoded.status();
        const ImageMetrics im = sphere_psnr(table, decoded->table());
        RateCandidate c{slices,        bits, components, double(bytes->size()), im.psnr_tonemapped,
                        im.psnr_linear};
        best.tried.push_back(c);
        const bool met =
            by_bytes ? c.bytes <= target.max_bytes : c.psnr_tonemapped >= target.min_psnr;
        if (!have || better(c, met, best.chosen, best.met)) {
          best.chosen = c;
          best.met = met;
          best.encoded.bytes = std::move(bytes).value();
          best.encoded.model = *model;
          best.encoded.report = report;
          have = true;
        }
        // More bits only add bytes: past the budget, or once the PSNR is reached, stop this row.
        if (by_bytes && c.bytes > target.max_bytes) {
          over_budget_at_fewest_bits = bits == 6;
          break;
        }
        if (by_psnr && met) break;
      }
      // More components only add bytes too.
      if (over_budget_at_fewest_bits) break;
    }
  }
  return best;
}

}  // namespace cbrdf
