// SPDX-License-Identifier: MIT
// Rate control over the whole ladder: the copula model alone at the low end (encode_to_target),
// the model plus the residual layer above it, with the residual's bound E found by a secant search
// on log E.
#include <algorithm>
#include <cmath>
#include <optional>

#include "cbrdf/encoder.h"
#include "cbrdf/metrics.h"
#include "cbrdf/rate_control.h"
#include "rate/model_search.h"
#include "rate/secant.h"
#include "residual_encode.h"

namespace cbrdf {
namespace {

// The residual's bounds searched: from about the base model's error to near-lossless.
constexpr double kLargestError = 1.0;
constexpr double kSmallestError = 1e-5;
// A try (write, decode, check and measure a file) costs about 1.5 default encodes, so the bound is
// not bisected (10 tries) but found by the secant on the curve of PSNR or bytes against log E,
// which is smooth: about 3 tries.
constexpr int kMaxTries = 6;
// The first PSNR try: near the bound that 45 to 50 dB need on the real materials.
constexpr double kFirstError = 0.03;
// PSNR against log E where only one point is known: quantization noise alone would give
// 20 log10(e) = 8.7 dB per e-fold; the real materials gave 5 to 9.
constexpr double kDbPerLogError = 7.0;
// Close enough: a try that meets the PSNR by at most this, or fills the budget to this share. The
// bytes that a closer bound would save are about 1% per 0.1 dB, but below about 0.2 dB the PSNR
// against E is no longer smooth (green-latex: E 0.0147 gave 50.15 dB, 0.0148 50.07; beige-fabric:
// 0.014 gave 50.16 and the four tries after it, at 0.0142 to 0.0205, all missed 50). At 0.15 dB
// the search spent up to four more tries, each about two default encodes, that saved at most 1.1%
// of the bytes; at 0.3 dB the files of four real materials at 45 and 50 dB were 0.3% to 2.5%
// larger and their searches 1.1x to 3x faster.
constexpr double kPsnrTolerance = 0.3;
constexpr double kBudgetTolerance = 0.02;

// The base file with a residual at bound e, measured: the writer's own check decodes it, and that
// table is scored.
Expected<RateCandidate> try_error(const BrdfTable& table, const SphereScorer& scorer,
                                  const BrdfTable& base_table, const EncoderSettings& base_settings,
                                  const RateResult& base, double e, EncodeResult* out) {
  EncoderSettings st = base_settings;
  st.residual = target_residual_settings(e);
  st.container.bits = base.chosen.bits;
  *out = base.encoded;
  BrdfTable decoded;
  CBRDF_RETURN_IF_ERROR(internal::add_residual(table, st, out, &base_table, &decoded));
  RateCandidate c = base.chosen;
  c.bytes = double(out->bytes.size());
  c.max_error = e;
  const ImageMetrics im = scorer.score(decoded);
  c.psnr_tonemapped = im.psnr_tonemapped;
  c.psnr_linear = im.psnr_linear;
  return c;
}

// The residual's search: tries of bound E on the chosen model, and the best that met the target.
class ResidualSearch {
 public:
  ResidualSearch(const BrdfTable& table, const EncoderSettings& settings, const RateTarget& target,
                 RateResult* model)
      : table_(table), scorer_(table), settings_(settings), target_(target), model_(*model) {}

  // A try at E: kept when it meets the target and beats the best so far. At a budget a try is
  // listed in `tried` only once chosen (encode_to_target_ladder).
  Expected<RateCandidate> attempt(double e) {
    const bool by_bytes = target_.max_bytes > 0;
    EncodeResult encoded;
    if (!base_table_) {
      // The base is the same for every try: decoded once.
      Expected<Model> base = decode_model(model_.encoded.bytes);
      if (!base.ok()) return base.status();
      base_table_ = base->table();
    }
    auto c = try_error(table_, scorer_, *base_table_, settings_, model_, e, &encoded);
    if (!c.ok()) return c;
    if (!by_bytes) model_.tried.push_back(*c);
    if (meets(*c) && (!best_ || better(*c, best_->chosen))) {
      best_ = RateResult{std::move(encoded), *c, {}, true, model_.fits, model_.hals_sweeps};
    } else if (!by_bytes && !best_ &&
               (!closest_ || c->psnr_tonemapped > closest_->chosen.psnr_tonemapped)) {
      closest_ = RateResult{std::move(encoded), *c, {}, false, model_.fits, model_.hals_sweeps};
    }
    return c;
  }
  // A PSNR missed even by the smallest bound tried: that try.
  const std::optional<RateResult>& closest() const { return closest_; }
  bool meets(const RateCandidate& c) const {
    return target_.max_bytes > 0 ? c.bytes <= target_.max_bytes
                                 : c.psnr_tonemapped >= target_.min_psnr;
  }
  // By PSNR the fewest bytes; by bytes the largest E is the cheapest, the smallest the best.
  bool better(const RateCandidate& a, const RateCandidate& b) const {
    return target_.max_bytes > 0 ? a.max_error < b.max_error : a.bytes < b.bytes;
  }
  const std::optional<RateResult>& best() const { return best_; }
  RateResult& model() { return model_; }

 private:
  const BrdfTable& table_;
  const SphereScorer scorer_;            // the table's renders, made once for every try
  std::optional<BrdfTable> base_table_;  // the base file's decoded table, after the first try
  const EncoderSettings& settings_;
  const RateTarget& target_;
  RateResult& model_;
  std::optional<RateResult> best_, closest_;
};

// The largest E reaching the PSNR: PSNR falls as log E grows.
Status search_psnr(ResidualSearch* search, const RateTarget& target) {
  rate::Secant secant(std::log(kSmallestError), std::log(kLargestError), -kDbPerLogError);
  // Aim a little above the target, so that a try on the curve's estimate meets it.
  const double aim = target.min_psnr + 0.5 * kPsnrTolerance;
  double x = std::log(kFirstError);
  for (int k = 0; k < kMaxTries; ++k) {
    auto c = search->attempt(std::exp(x));
    if (!c.ok()) return c.status();
    const bool met = search->meets(*c);
    if (met && c->psnr_tonemapped - target.min_psnr <= kPsnrTolerance) break;
    secant.add(x, c->psnr_tonemapped, met);
    const std::optional<double> next = secant.next(aim);
    if (!next) break;
    x = *next;
  }
  return ok_status();
}

// The smallest E within the budget: the residual's bytes fall as log E grows, about as a power
// of E, so the secant works on log(residual bytes).
Status search_bytes(ResidualSearch* search, const RateTarget& target,
                    const RateCandidate& cheapest) {
  const double base_bytes = search->model().chosen.bytes;
  const auto value = [&](double bytes) { return std::log(std::max(bytes - base_bytes, 1.0)); };
  const double aim = value(target.max_bytes * (1 - 0.5 * kBudgetTolerance));
  // The residual's bytes against E on the real materials: about E^-0.7.
  rate::Secant secant(std::log(kSmallestError), std::log(kLargestError), -0.7);
  secant.add(std::log(kLargestError), value(cheapest.bytes), true);
  for (int k = 0; k < kMaxTries; ++k) {
    const std::optional<double> next = secant.next(aim);
    if (!next) break;
    auto c = search->attempt(std::exp(*next));
    if (!c.ok()) return c.status();
    const bool met = search->meets(*c);
    if (met && c->bytes >= target.max_bytes * (1 - kBudgetTolerance)) break;
    secant.add(*next, value(c->bytes), met);
  }
  return ok_status();
}

// The residual's base at a byte budget: the one-component model a default encode writes at the
// settings' slices and bits (as the PSNR ladder's choose_residual_base), not the best model within
// the budget, which leaves no bytes for a residual. Measured on aluminium at 100,000 bytes: the
// model alone gave 89.7 KB at 49.0 dB, a residual on this base reaches 60 dB in 62.7 KB.
Expected<RateResult> cheap_base(const BrdfTable& table, const EncoderSettings& base) {
  EncoderSettings st = base;
  st.fit.components = 1;
  st.fit.auto_components = false;
  st.residual = ResidualSettings{};
  Expected<EncodeResult> e = encode_table(table, st);
  if (!e.ok()) return e.status();
  RateResult r;
  r.chosen.slices = int(e->model.slices.size());
  r.chosen.components = 1;
  r.chosen.bits = e->bits;
  r.chosen.bytes = double(e->bytes.size());
  r.encoded = std::move(e).value();
  r.fits = 1;
  return r;
}

// At a budget: a residual on the cheap base, within the budget, when it beats `model_only` (the
// best model alone); else model_only.
Expected<RateResult> residual_within_budget(const BrdfTable& table, const EncoderSettings& base,
                                            const RateTarget& target, RateResult model_only) {
  Expected<RateResult> cheap = cheap_base(table, base);
  if (!cheap.ok()) return cheap.status();
  model_only.fits += cheap->fits;
  if (cheap->chosen.bytes >= target.max_bytes) return model_only;
  ResidualSearch search(table, base, target, &*cheap);
  // The cheapest residual must fit, or no residual will; the smallest bound within the budget
  // (the best PSNR) is then found and weighed against the model alone.
  auto c = search.attempt(kLargestError);
  if (!c.ok()) return c.status();
  if (!search.best()) return model_only;
  model_only.tried.push_back(search.best()->chosen);
  CBRDF_RETURN_IF_ERROR(search_bytes(&search, target, *c));
  RateResult best = *search.best();
  if (best.chosen.max_error != kLargestError) model_only.tried.push_back(best.chosen);
  if (best.chosen.psnr_tonemapped <= model_only.chosen.psnr_tonemapped) return model_only;
  best.tried = std::move(model_only.tried);
  best.fits = model_only.fits;
  best.hals_sweeps = model_only.hals_sweeps;
  return best;
}

}  // namespace

Expected<RateResult> encode_to_target_ladder(const BrdfTable& table, const EncoderSettings& base,
                                             const RateTarget& target) {
  Expected<RateResult> rc = rate::search_model(table, base, target, true);
  if (!rc.ok()) return rc;
  const bool by_bytes = target.max_bytes > 0;
  // The model alone reaches the PSNR, or leaves no room in the budget for a better file.
  if (!by_bytes && rc->met) return rc;
  RateResult result = std::move(rc).value();
  if (by_bytes) return residual_within_budget(table, base, target, std::move(result));
  ResidualSearch search(table, base, target, &result);
  CBRDF_RETURN_IF_ERROR(search_psnr(&search, target));
  if (!search.best()) {
    // Nothing met the PSNR: the closest file, with the residual or without.
    const auto& closest = search.closest();
    if (!closest || closest->chosen.psnr_tonemapped <= result.chosen.psnr_tonemapped) {
      return result;
    }
    RateResult best = *closest;
    best.tried = std::move(result.tried);
    return best;
  }
  RateResult best = *search.best();
  best.tried = std::move(result.tried);
  return best;
}

}  // namespace cbrdf
