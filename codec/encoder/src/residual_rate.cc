// SPDX-License-Identifier: MIT
// Rate control over the whole ladder: the copula model alone at the low end (encode_to_target),
// the model plus the residual layer above it, with the residual's bound E found by a secant search
// on log E.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "bitstream/chunks.h"
#include "cbrdf/encoder.h"
#include "cbrdf/noise.h"
#include "cbrdf/rate_control.h"
#include "encode_watch.h"
#include "metrics.h"
#include "rate/model_search.h"
#include "rate/secant.h"
#include "residual_encode.h"

namespace cbrdf {
namespace {

// The residual's bounds searched: from about the base model's error to near-lossless (up to a noisy
// table's floor where that is larger).
constexpr double kLargestError = 1.0;
constexpr double kSmallestError = 1e-5;
// Tried once when a finer bound cannot be written on the table (ResidualSearch::attempt): the
// format's largest, which needs the fewest bins stored exactly.
constexpr double kCoarsestError = kMaxResidualError;
// A try (write, decode, check and measure a file) costs about 1.5 default encodes, so the bound is
// not bisected (10 tries) but found by the secant on the curve of PSNR or bytes against log E,
// which is smooth: about 3 tries.
constexpr int kMaxTries = 6;
// The first PSNR try: near the bound that 45 to 50 dB need on the real materials.
constexpr double kFirstError = 0.03;
// PSNR against log E where only one point is known: quantization noise alone would give
// 20 log10(e) = 8.7 dB per e-fold; the real materials gave 5 to 9.
constexpr double kDbPerLogError = 7.0;
// Close enough: a try that meets the PSNR by at most this, or fills the budget to this share. A
// closer bound saves about 1% of the bytes per 0.1 dB, but below about 0.2 dB the PSNR against E
// is no longer smooth and the search spends tries (each about two encodes) for little.
constexpr double kPsnrTolerance = 0.3;
constexpr double kBudgetTolerance = 0.02;
// On a noisy table a residual is kept only when it brings its file this much closer to the
// smoothed table than the model alone (ResidualSearch::adds_signal).
constexpr double kSignalGainDb = 1.0;

// The residual on a noisy table (noise.h): what it codes and how close. Inactive on a smooth table,
// where the ladder is what it was before noise was measured.
struct NoiseFloor {
  bool active = false;
  double smallest_error = 0;  // no bound below this: it would code what is left of the noise
  double sigma = 0;           // the estimate's largest channel sigma
  double ceiling = 0;         // the estimate's tone-mapped PSNR ceiling (dB); NaN: not measurable
};

NoiseFloor noise_floor(const BrdfTable& table, const EncoderSettings& settings) {
  NoiseOptions o;
  o.threads = settings.fit.threads;
  const NoiseEstimate e = estimate_noise(table, o);
  NoiseFloor f;
  if (!e.noisy()) return f;
  f.active = true;
  // At most 16 (noise_floor_error): noise of many decades per bin (a table log-uniform over
  // 1e-30..1e30: 0.5 sigma = 21) would put it past what a file holds. Above kLargestError the
  // searches take the floor as their largest bound.
  f.smallest_error = noise_floor_error(e);
  f.sigma = e.max_sigma();
  f.ceiling = e.psnr_ceiling_tonemapped;
  return f;
}

// The base file with a residual at bound e, measured: the writer's own check decodes it, and that
// table is scored.
Expected<RateCandidate> try_error(const BrdfTable& source, const SphereScorer& scorer,
                                  const BrdfTable& base_table, const EncoderSettings& base_settings,
                                  const RateResult& base, double e, EncodeResult* out,
                                  const SphereScorer* signal = nullptr,
                                  double* signal_psnr = nullptr) {
  EncoderSettings st = base_settings;
  st.residual = target_residual_settings(e);
  st.container.bits = base.chosen.bits;
  *out = base.encoded;
  BrdfTable decoded;
  CBRDF_RETURN_IF_ERROR(internal::add_residual(source, st, out, &base_table, &decoded));
  RateCandidate c = base.chosen;
  c.bytes = double(out->bytes.size());
  c.max_error = e;
  CBRDF_RETURN_IF_ERROR(internal::check_cancel());
  const ImageMetrics im = scorer.score(decoded);
  c.psnr_tonemapped = im.psnr_tonemapped;
  c.psnr_linear = im.psnr_linear;
  if (signal) *signal_psnr = signal->score(decoded).psnr_tonemapped;
  return c;
}

// The residual's search: tries of bound E on the chosen model, and the best that met the target.
class ResidualSearch {
 public:
  ResidualSearch(const BrdfTable& table, const EncoderSettings& settings, const RateTarget& target,
                 RateResult* model, const NoiseFloor& floor)
      : table_(table),
        scorer_(table),
        settings_(settings),
        target_(target),
        model_(*model),
        floor_(floor) {}

  // A try at E: kept when it meets the target and beats the best so far. At a budget a try is
  // listed in `tried` only once chosen (encode_to_target_ladder). None: the layer cannot hold E on
  // this table, nor any finer bound, nor (tried at once) the coarsest, kCoarsestError.
  Expected<std::optional<RateCandidate>> attempt(double e) {
    auto c = attempt_once(e);
    if (!c.ok() || *c || coarsest_tried_ || uncodable_from_ >= kCoarsestError) return c;
    coarsest_tried_ = true;
    return attempt_once(kCoarsestError);
  }
  // Whether the layer could not be written even at the coarsest bound.
  bool uncodable() const { return uncodable_from_ >= kCoarsestError; }
  // Whether some bound tried could not be written (coarser ones may have been).
  bool some_uncodable() const { return uncodable_from_ > 0; }

 private:
  Expected<std::optional<RateCandidate>> attempt_once(double e) {
    CBRDF_RETURN_IF_ERROR(internal::check_cancel());
    // Progress: the searches end after about 3 tries, at most kMaxTries plus the coarsest.
    constexpr double kMostTries = kMaxTries + 2;
    const internal::ProgressPart part("residual", std::min(tries_ / kMostTries, 1.0),
                                      std::min((tries_ + 1) / kMostTries, 1.0));
    ++tries_;
    const bool by_bytes = target_.max_bytes > 0;
    if (e <= uncodable_from_) return std::optional<RateCandidate>();
    EncodeResult encoded;
    if (!base_table_) {
      // The base is the same for every try: decoded once.
      CBRDF_ASSIGN_OR_RETURN(Model base, decode_model(model_.encoded.bytes));
      base_table_ = base.table();
      CBRDF_RETURN_IF_ERROR(internal::check_cancel());
      // A noisy table: the residual codes the model times the smoothed ratio of the table to it,
      // the signal the model misses without the noise (the scorer still measures the input).
      if (floor_.active) {
        source_ = noise_floor_source(table_, *base_table_);
        signal_.emplace(*source_);
        base_signal_psnr_ = signal_->score(*base_table_).psnr_tonemapped;
      }
    }
    double signal_psnr = 0;
    e = std::max(e, floor_.active ? floor_.smallest_error : 0.0);
    auto c = try_error(source_ ? *source_ : table_, scorer_, *base_table_, settings_, model_, e,
                       &encoded, signal_ ? &*signal_ : nullptr, &signal_psnr);
    if (!c.ok()) {
      // kNumeric: more bins than RESD's escapes allow lie beyond the residual's range (values
      // tens of e-folds from the model, as on a table log-uniform over 1e-30..1e30). A finer
      // bound only adds such bins: no residual at or below E (attempt() tries the coarsest).
      if (c.status().code() != ErrorCode::kNumeric) return c.status();
      uncodable_from_ = std::max(uncodable_from_, e);
      return std::optional<RateCandidate>();
    }
    signal_psnr_.emplace_back(c->max_error, signal_psnr);
    if (!by_bytes) model_.tried.push_back(*c);
    if (meets(*c) && (!best_ || better(*c, best_->chosen))) {
      best_ = RateResult{std::move(encoded), *c, {}, true, model_.fits, model_.hals_sweeps, {}};
    } else if (!by_bytes && !best_ &&
               (!closest_ || c->psnr_tonemapped > closest_->chosen.psnr_tonemapped)) {
      closest_ = RateResult{std::move(encoded), *c, {}, false, model_.fits, model_.hals_sweeps, {}};
    }
    return std::optional<RateCandidate>(*c);
  }

 public:
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
  // On a noisy table: whether the file with residual bound e is closer than its base model alone
  // to the smoothed table, the best estimate of the noise-free signal there is. Where the model
  // alone already matches the signal, the residual only adds its quantization error (a 3% noisy
  // ward sample: 0.0 to 0.4 dB against the truth, for 30 KB). Always true on a smooth table.
  bool adds_signal(double e) const {
    if (!floor_.active) return true;
    for (const auto& [error, psnr] : signal_psnr_) {
      if (error == e) return psnr > base_signal_psnr_ + kSignalGainDb;
    }
    return false;
  }

 private:
  const BrdfTable& table_;
  const SphereScorer scorer_;            // the table's renders, made once for every try
  std::optional<BrdfTable> base_table_;  // the base file's decoded table, after the first try
  std::optional<BrdfTable> source_;      // the residual's smoothed source when the table is noisy
  std::optional<SphereScorer> signal_;   // source_'s renders
  double base_signal_psnr_ = 0;          // the base model's PSNR against source_
  std::vector<std::pair<double, double>> signal_psnr_;  // (E, PSNR against source_) per try
  const EncoderSettings& settings_;
  const RateTarget& target_;
  RateResult& model_;
  const NoiseFloor& floor_;
  std::optional<RateResult> best_, closest_;
  double uncodable_from_ = 0;  // the largest bound the layer could not hold (0: none)
  bool coarsest_tried_ = false;
  int tries_ = 0;  // for progress
};

// The largest E reaching the PSNR: PSNR falls as log E grows.
Status search_psnr(ResidualSearch* search, const RateTarget& target, double smallest_error) {
  internal::Secant secant(std::log(smallest_error),
                          std::log(std::max(kLargestError, smallest_error)), -kDbPerLogError);
  // Aim a little above the target, so that a try on the curve's estimate meets it.
  const double aim = target.min_psnr + 0.5 * kPsnrTolerance;
  double x = std::log(std::max(kFirstError, smallest_error));
  for (int k = 0; k < kMaxTries; ++k) {
    CBRDF_ASSIGN_OR_RETURN(auto tried, search->attempt(std::exp(x)));
    // No residual at or below this bound (and the coarsest tried instead): nothing finer either.
    if (!tried || search->some_uncodable()) break;
    const RateCandidate& c = *tried;
    const bool met = search->meets(c);
    if (met && c.psnr_tonemapped - target.min_psnr <= kPsnrTolerance) break;
    secant.add(x, c.psnr_tonemapped, met);
    const std::optional<double> next = secant.next(aim);
    if (!next) break;
    x = *next;
  }
  return ok_status();
}

// The smallest E within the budget: the residual's bytes fall as log E grows, about as a power
// of E, so the secant works on log(residual bytes).
Status search_bytes(ResidualSearch* search, const RateTarget& target, const RateCandidate& cheapest,
                    double smallest_error) {
  const double base_bytes = search->model().chosen.bytes;
  const auto value = [&](double bytes) { return std::log(std::max(bytes - base_bytes, 1.0)); };
  const double aim = value(target.max_bytes * (1 - 0.5 * kBudgetTolerance));
  // The residual's bytes against E on the real materials: about E^-0.7.
  internal::Secant secant(std::log(smallest_error), std::log(cheapest.max_error), -0.7);
  secant.add(std::log(cheapest.max_error), value(cheapest.bytes), true);
  for (int k = 0; k < kMaxTries; ++k) {
    const std::optional<double> next = secant.next(aim);
    if (!next) break;
    CBRDF_ASSIGN_OR_RETURN(auto tried, search->attempt(std::exp(*next)));
    if (!tried || search->some_uncodable()) break;  // as in search_psnr
    const RateCandidate& c = *tried;
    const bool met = search->meets(c);
    if (met && c.bytes >= target.max_bytes * (1 - kBudgetTolerance)) break;
    secant.add(*next, value(c.bytes), met);
  }
  return ok_status();
}

// The residual's base at a byte budget: the one-component model a default encode writes at the
// settings' slices and bits (as the PSNR ladder's choose_residual_base), not the best model within
// the budget, which leaves no bytes for a residual: a cheap base and a residual reach a higher PSNR
// in fewer bytes.
Expected<RateResult> cheap_base(const BrdfTable& table, const EncoderSettings& base) {
  EncoderSettings st = base;
  st.fit.components = 1;
  st.fit.auto_components = false;
  st.residual = ResidualSettings{};
  CBRDF_ASSIGN_OR_RETURN(EncodeResult e, encode_table(table, st));
  RateResult r;
  r.chosen.slices = int(e.model.slices.size());
  r.chosen.components = 1;
  r.chosen.bits = e.bits;
  r.chosen.bytes = double(e.bytes.size());
  r.encoded = std::move(e);
  r.fits = 1;
  return r;
}

// At a budget: a residual on the cheap base, within the budget, when it beats `model_only` (the
// best model alone); else model_only. *uncodable: no bound, not even the coarsest, could be
// written.
Expected<RateResult> residual_within_budget(const BrdfTable& table, const EncoderSettings& base,
                                            const RateTarget& target, RateResult model_only,
                                            const NoiseFloor& floor, bool* uncodable) {
  CBRDF_ASSIGN_OR_RETURN(RateResult cheap, cheap_base(table, base));
  model_only.fits += cheap.fits;
  if (cheap.chosen.bytes >= target.max_bytes) return model_only;
  ResidualSearch search(table, base, target, &cheap, floor);
  // The cheapest residual must fit, or no residual will; the smallest bound within the budget
  // (the best PSNR) is then found and weighed against the model alone.
  CBRDF_ASSIGN_OR_RETURN(auto c, search.attempt(kLargestError));
  *uncodable = search.uncodable();
  if (!c || !search.best()) return model_only;
  model_only.tried.push_back(search.best()->chosen);
  // A budget that holds the noise floor's file ends the search there (the first try, when the
  // floor is the largest bound).
  bool at_floor = floor.active && floor.smallest_error >= kLargestError;
  if (floor.active && !at_floor) {
    CBRDF_ASSIGN_OR_RETURN(auto f, search.attempt(floor.smallest_error));
    at_floor = f && search.meets(*f);
  }
  if (!at_floor) {
    CBRDF_RETURN_IF_ERROR(
        search_bytes(&search, target, *c, floor.active ? floor.smallest_error : kSmallestError));
  }
  *uncodable = search.uncodable();
  RateResult best = *search.best();
  if (best.chosen.max_error != (*c).max_error) model_only.tried.push_back(best.chosen);
  // On a noisy table the PSNR against the input does not tell signal from noise: the smoothed
  // residual is kept (closer to the truth than the model alone,
  // tests/encoder/noise_ladder_test.cc).
  if (floor.active ? !search.adds_signal(best.chosen.max_error)
                   : best.chosen.psnr_tonemapped <= model_only.chosen.psnr_tonemapped) {
    return model_only;
  }
  best.tried = std::move(model_only.tried);
  best.fits = model_only.fits;
  best.hals_sweeps = model_only.hals_sweeps;
  return best;
}

}  // namespace

namespace {

// The note on the chosen file: why it stopped at the noise floor, or why the model alone.
// `uncodable`: the residual layer could not be written at any bound tried.
void add_note(RateResult& r, const NoiseFloor& floor, bool uncodable, bool by_bytes) {
  // Why the model alone, when the layer could not be written at all.
  constexpr const char* kUncodable =
      "no residual layer can be written on this table, even at the largest bound 16 (more bins "
      "lie beyond its range from the model than it stores exactly: values tens of e-folds from "
      "any smooth BRDF); the model alone is the closest file";
  const bool model_alone = r.chosen.max_error == 0;
  // (Not when the model alone is already exact at the metric's cap: nothing was lost.)
  const bool say_uncodable = uncodable && model_alone && r.chosen.psnr_tonemapped < kPsnrCapDb;
  if (!floor.active) {
    if (say_uncodable) r.note = kUncodable;
    return;
  }
  r.residual_of_smoothed_input = r.encoded.model.residual.present();
  char text[512];
  // Per cent per bin: "3" for 3%, "4225" (not "4.2e+03") for noise of many decades.
  char sigma[32];
  if (100 * floor.sigma < 100) {
    std::snprintf(sigma, sizeof sigma, "%.2g", 100 * floor.sigma);
  } else {
    std::snprintf(sigma, sizeof sigma, "%.0f", 100 * floor.sigma);
  }
  if (r.chosen.max_error > 0 && r.chosen.max_error <= floor.smallest_error) {
    char beyond[96] = "";
    if (std::isfinite(floor.ceiling)) {
      std::snprintf(beyond, sizeof beyond, "beyond about %.1f dB ", floor.ceiling);
    }
    std::snprintf(text, sizeof text,
                  "the input is noisy (about %s%% per bin, see cbrdf info): stopped at its "
                  "noise floor (residual bound %.3g); PSNR against the input %swould be bought "
                  "by coding noise",
                  sigma, floor.smallest_error, beyond);
    r.note = text;
  } else if (say_uncodable) {
    std::snprintf(text, sizeof text, "the input is noisy (about %s%% per bin, see cbrdf info); %s",
                  sigma, kUncodable);
    r.note = text;
  } else if (model_alone && !by_bytes) {
    std::snprintf(text, sizeof text,
                  "the input is noisy (about %s%% per bin, see cbrdf info): the model alone is "
                  "as close to its signal as a residual layer gets; more bytes would code noise",
                  sigma);
    r.note = text;
  }
}

// encode_to_target_ladder's work, on the encode's watch (encode_watch.h).
Expected<RateResult> ladder(const BrdfTable& table, const EncoderSettings& base,
                            const RateTarget& target) {
  // Progress: shares of the time of --target-psnr 60 on real materials.
  Expected<RateResult> rc = [&] {
    const internal::ProgressPart part("target", 0, 0.45);
    return internal::search_model(table, base, target, true);
  }();
  if (!rc.ok()) return rc;
  const bool by_bytes = target.max_bytes > 0;
  // The model alone reaches the PSNR, or leaves no room in the budget for a better file.
  if (!by_bytes && rc->met) return rc;
  const NoiseFloor floor = [&] {
    const internal::ProgressPart part("residual", 0.45, 0.5);
    return noise_floor(table, base);
  }();
  CBRDF_RETURN_IF_ERROR(internal::check_cancel());
  const internal::ProgressPart residual_part("residual", 0.5, 1);
  bool uncodable = false;  // the residual layer could not be written at any bound tried
  const auto with_note = [&](Expected<RateResult> r) -> Expected<RateResult> {
    if (r.ok()) add_note(*r, floor, uncodable, by_bytes);
    return r;
  };
  RateResult result = std::move(rc).value();
  if (by_bytes) {
    return with_note(
        residual_within_budget(table, base, target, std::move(result), floor, &uncodable));
  }
  ResidualSearch search(table, base, target, &result, floor);
  if (floor.active && target.min_psnr >= floor.ceiling) {
    // Beyond the ceiling only noise is left to code: the noise floor's file, without a search.
    CBRDF_RETURN_IF_ERROR(search.attempt(floor.smallest_error).status());
  } else {
    CBRDF_RETURN_IF_ERROR(
        search_psnr(&search, target, floor.active ? floor.smallest_error : kSmallestError));
  }
  uncodable = search.uncodable();
  if (!search.best()) {
    // Nothing met the PSNR: the closest file, with the residual or without.
    const auto& closest = search.closest();
    // (On a noisy table the residual's file is kept: its PSNR against the input misses the
    // target because it does not reproduce the noise.)
    if (!closest ||
        (floor.active ? !search.adds_signal(closest->chosen.max_error)
                      : closest->chosen.psnr_tonemapped <= result.chosen.psnr_tonemapped)) {
      return with_note(std::move(result));
    }
    RateResult best = *closest;
    best.tried = std::move(result.tried);
    return with_note(std::move(best));
  }
  if (!search.adds_signal(search.best()->chosen.max_error)) return with_note(std::move(result));
  RateResult best = *search.best();
  best.tried = std::move(result.tried);
  return with_note(std::move(best));
}

}  // namespace

Expected<RateResult> encode_to_target_ladder(const BrdfTable& table, const EncoderSettings& base,
                                             const RateTarget& target) {
  return internal::watched<RateResult>(base.progress, [&] { return ladder(table, base, target); });
}

}  // namespace cbrdf
