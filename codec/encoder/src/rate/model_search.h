// SPDX-License-Identifier: MIT
// The model's rate control (rate_control.cc) as the whole ladder (residual_rate.cc) uses it.
#pragma once

#include "cbrdf/rate_control.h"

namespace cbrdf::internal {

// encode_to_target; with for_ladder, a PSNR target that the one-component rows leave more than any
// mixture gains out of reach ends the search there: no mixture is fitted, met is false, and the
// chosen file is the base for the residual layer (the one-component model at the settings' slice
// count and the bits --bits auto chooses), not the closest model.
Expected<RateResult> search_model(const BrdfTable& table, const EncoderSettings& base,
                                  const RateTarget& target, bool for_ladder);

}  // namespace cbrdf::internal
