// SPDX-License-Identifier: MIT
// tabulate_like(): an analytic BRDF on the MERL grid with a reference table's not-measured bins.
#include <atomic>
#include <cmath>
#include <string>

#include "cbrdf/analytic_fit.h"
#include "cbrdf/coords.h"
#include "parallel_for.h"

namespace cbrdf {

Expected<BrdfTable> tabulate_like(const AnalyticBrdf& brdf, const BrdfTable& reference) {
  CBRDF_RETURN_IF_ERROR(brdf.validate());
  BrdfTable table = reference;  // keeps the not-measured values bit for bit
  std::atomic<bool> finite{true};
  internal::parallel_rows(kThetaHBins, 0, [&](int h_begin, int h_end) {
    for (int h = h_begin; h < h_end; ++h) {
      for (int d = 0; d < kThetaDBins; ++d) {
        for (int p = 0; p < kPhiDBins; ++p) {
          const std::size_t idx = merl_index(h, d, p);
          Vec3 wi, wo;
          from_half_diff({theta_h_of(h), 0.0, theta_d_of(d), phi_d_of(p)}, &wi, &wo);
          double rgb[3];
          brdf.eval(wi, wo, rgb);
          for (int c = 0; c < kChannels; ++c) {
            if (!reference.measured(c, idx)) continue;
            if (!std::isfinite(rgb[c])) finite = false;
            table.set_physical(c, idx, rgb[c]);
          }
        }
      }
    }
  });
  if (!finite) {
    return error(ErrorCode::kNumeric, "analytic BRDF is not finite at some measured bin");
  }
  return table;
}

}  // namespace cbrdf
