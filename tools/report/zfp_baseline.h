// SPDX-License-Identifier: MIT
// The error-bounded float baseline: ZFP (Debian's libzfp, fixed-accuracy mode) on log1p of the
// physical values, one 3D array per channel (phi_d fastest), plus the not-measured mask as a
// zstd-compressed bitmap and one stored value for those bins. Not-measured bins enter ZFP as the
// previous measured value of their row (a smooth fill costs ZFP the fewest bits), and decode back
// to the stored value. The tolerance bounds |log1p(decoded) - log1p(source)| per measured bin.
#pragma once

#include "cbrdf/brdf_table.h"
#include "cbrdf/status.h"
#include "report/lossless.h"

namespace cbrdf::report {

struct ZfpResult {
  Compressed compressed;  // times include log1p, expm1 and the mask
  BrdfTable decoded;
};

// tolerance > 0 (ZFP's absolute error bound in the log1p domain).
Expected<ZfpResult> zfp_log_round_trip(const BrdfTable& table, double tolerance);

}  // namespace cbrdf::report
