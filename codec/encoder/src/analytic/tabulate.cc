// SPDX-License-Identifier: MIT
// tabulate(): an analytic BRDF sampled at the MERL grid.
#include "cbrdf/samples.h"
#include "grid_table.h"

namespace cbrdf {

Expected<BrdfTable> tabulate(const AnalyticBrdf& brdf) {
  CBRDF_RETURN_IF_ERROR(brdf.validate());
  return internal::tabulate_grid(
      [&brdf](const HalfDiff& hd, double rgb[3]) {
        Vec3 wi, wo;
        from_half_diff(hd, &wi, &wo);
        brdf.eval(wi, wo, rgb);
      },
      "analytic BRDF");
}

}  // namespace cbrdf
