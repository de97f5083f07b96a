// SPDX-License-Identifier: MIT
// Rate control over the whole ladder: the copula model alone at the low end (encode_to_target),
// the model plus the residual layer above it, with the residual's bound E chosen by bisection.
#include <cmath>

#include "cbrdf/metrics.h"
#include "cbrdf/rate_control.h"
#include "residual_encode.h"

namespace cbrdf {
namespace {

// The residual's bounds searched: from about the base model's error to near-lossless.
constexpr double kLargestError = 1.0;
constexpr double kSmallestError = 1e-5;
constexpr int kBisections = 10;

// The base file with a residual at bound e, measured.
Expected<RateCandidate> try_error(const BrdfTable& table, const EncoderSettings& base_settings,
                                  const RateResult& base, double e, EncodeResult* out) {
  EncoderSettings st = base_settings;
  st.residual.max_error = e;
  st.residual.row_steps = true;  // a target in PSNR or bytes, not a bound: steps by visibility
  st.container.bits = base.chosen.bits;
  *out = base.encoded;
  CBRDF_RETURN_IF_ERROR(internal::add_residual(table, st, out));
  Expected<BrdfTable> decoded = decode_table(out->bytes);
  if (!decoded.ok()) return decoded.status();
  const ImageMetrics im = sphere_psnr(table, *decoded);
  RateCandidate c = base.chosen;
  c.bytes = double(out->bytes.size());
  c.psnr_tonemapped = im.psnr_tonemapped;
  c.psnr_linear = im.psnr_linear;
  c.max_error = e;
  return c;
}

}  // namespace

Expected<RateResult> encode_to_target_ladder(const BrdfTable& table, const EncoderSettings& base,
                                             const RateTarget& target) {
  Expected<RateResult> rc = encode_to_target(table, base, target);
  if (!rc.ok()) return rc;
  const bool by_bytes = target.max_bytes > 0;
  // The model alone reaches the PSNR, or leaves no room in the budget for a better file.
  if (!by_bytes && rc->met) return rc;
  RateResult result = std::move(rc).value();
  const auto meets = [&](const RateCandidate& c) {
    return by_bytes ? c.bytes <= target.max_bytes : c.psnr_tonemapped >= target.min_psnr;
  };
  // Bytes fall and PSNR falls as E grows: bisect log E for the largest E that meets the target
  // (fewest bytes reaching the PSNR), or the smallest E within the budget (best PSNR in it).
  double lo = std::log(kSmallestError), hi = std::log(kLargestError);
  bool any = false;
  RateResult best = result;
  if (by_bytes) {
    // The cheapest residual must fit and beat the model alone, or no residual will.
    EncodeResult encoded;
    Expected<RateCandidate> c = try_error(table, base, result, kLargestError, &encoded);
    if (!c.ok()) return c.status();
    result.tried.push_back(*c);
    if (!meets(*c) || c->psnr_tonemapped <= result.chosen.psnr_tonemapped) return result;
  }
  for (int k = 0; k < kBisections; ++k) {
    const double mid = 0.5 * (lo + hi);
    EncodeResult encoded;
    Expected<RateCandidate> c = try_error(table, base, result, std::exp(mid), &encoded);
    if (!c.ok()) return c.status();
    result.tried.push_back(*c);
    const bool ok = meets(*c);
    // A residual that does not beat the model alone within the budget is not worth its bytes.
    const bool better = by_bytes ? c->psnr_tonemapped > best.chosen.psnr_tonemapped : true;
    if (ok && better) {
      best.chosen = *c;
      best.encoded = std::move(encoded);
      best.met = true;
      any = true;
    }
    // Meeting the target at E: by PSNR, try a larger E (fewer bytes); by bytes, a smaller E.
    if (ok == by_bytes) {
      hi = mid;
    } else {
      lo = mid;
    }
  }
  if (!any) return result;  // the model alone is the closest
  best.tried = std::move(result.tried);
  return best;
}

}  // namespace cbrdf
