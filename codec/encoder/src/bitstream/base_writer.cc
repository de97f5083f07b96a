// SPDX-License-Identifier: MIT
// BASE's writer (spec 4.8, container version 1.3): MODL and MARG in one chunk, the parameters as
// binary32 (K as binary64 where binary32 would lose it) and the marginal tables' codes chosen
// (rate-distortion rounding), predicted and range coded.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "bitstream/base_marginals.h"
#include "bitstream/chunk_writers.h"
#include "bitstream/mass_quantizer.h"
#include "bitstream/range_encoder.h"
#include "byte_writer.h"

namespace cbrdf {
namespace {

using base_marginals::clamp_code;
using base_marginals::first_prediction;
using base_marginals::for_each_component;
using base_marginals::kPredictors;
using base_marginals::kPredictPrevious;
using base_marginals::kPredictRefStep;
using base_marginals::MarginalContexts;
using base_marginals::predict;
using base_marginals::Reference;
using base_marginals::residual_class;

template <class Sink>
void put_predictor(Sink& s, std::array<internal::Prob, 3>& p, int mode) {
  s.bit(p[0], mode >> 1);
  s.bit(p[1 + (mode >> 1)], mode & 1);
}

// The codes of one table with one predictor, into any sink (encoder or cost meter).
template <class Sink>
void put_codes(Sink& s, std::array<internal::SIntContexts, 3>& ctx, int mode,
               const std::vector<std::uint32_t>& q, const Reference& ref, std::uint32_t span,
               std::int64_t first, std::int64_t top) {
  int cls = 2;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const std::int64_t e =
        std::int64_t(q[i]) - clamp_code(predict(mode, q, i, ref, span, first), top);
    internal::put_sint(s, ctx[std::size_t(cls)], std::int32_t(e));
    cls = residual_class(e);
  }
}

// The cost of coding one signed value from contexts, without adapting them: within one value
// each probability is used at most once, so this is exactly what an Encoder would spend.
struct PeekMeter {
  double bits = 0;
  void bit(const internal::Prob& prob, int b) {
    const double p0 = double(prob.p) / double(internal::kProbOne);
    bits -= std::log2(b == 0 ? p0 : 1.0 - p0);
  }
};
struct PeekSink {
  PeekMeter* m;
  void bit(internal::Prob& prob, int b) { m->bit(prob, b); }
};

}  // namespace

// Binary32 of a parameter inside the format's range: the nearest, or its neighbour towards the
// inside when the nearest falls outside (Frank's upper end ln 2 is not a binary32).
std::optional<float> parameter_f32(std::uint8_t family, double theta, double scale) {
  const double k = base_scale(scale, !scale_fits_f32(scale));
  const float f = float(theta);
  for (float g : {f, std::nextafter(f, -std::numeric_limits<float>::infinity()),
                  std::nextafter(f, std::numeric_limits<float>::infinity())}) {
    if (std::isfinite(g) && check_channel_params(family, double(g), k).ok()) return g;
  }
  return std::nullopt;
}

bool scale_fits_f32(double k) {
  return k == 0.0 || std::isnormal(float(k));
}

bool base_wide_scales(const Model& model) {
  bool wide = false;
  for_each_component(model.slices, [&](std::size_t s, int c, int k) {
    wide = wide || !scale_fits_f32(model.slices[s].channel[std::size_t(c)].component(k).scale);
  });
  return wide;
}

double base_scale(double k, bool wide) {
  return wide ? k : double(float(k));
}

namespace base_codes {

Positions positions(std::span<const double> masses, int bits) {
  Positions p;
  p.position.assign(masses.size(), 0.0);
  p.weight.assign(masses.size(), 0.0);
  // Scaled to sum 1, as the decoder renormalizes: every log mass at or below 0.
  const std::optional<double> total = log_mass_sum(masses);
  if (!total) return p;
  const double log_sum = *total;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double m : masses) {
    if (m > 0.0) {
      lo = std::min(lo, std::log(m) - log_sum);
      hi = std::max(hi, std::log(m) - log_sum);
    }
  }
  lo = std::max(lo, kMinLogMass);
  hi = std::max(hi, kMinLogMass);
  // The smallest grid span that holds every log mass (at least one unit, unless all are equal).
  const double units = std::ceil((hi - lo) * kRangeGridUnits);
  const std::uint32_t smallest = std::uint32_t(std::clamp(units, 0.0, double(kMaxGridUnits)));
  const double top = double(max_code(bits));
  const double peak = std::exp(hi + log_sum);
  auto fill = [&](std::uint32_t d, Positions* out) {
    out->span_units = d;
    const double span = double(d) / kRangeGridUnits;
    for (std::size_t i = 0; i < masses.size(); ++i) {
      if (!(masses[i] > 0.0)) continue;
      const double x = std::log(masses[i]) - log_sum - hi;  // <= 0
      out->position[i] = span > 0.0 ? std::clamp(top + x / span * (top - 1.0), 1.0, top) : top;
      out->weight[i] = std::pow(std::min(masses[i] / peak, 1.0), kWeightPower);
    }
  };
  fill(smallest, &p);
  if (smallest == 0) return p;
  // A slightly wider span moves every code's lattice point: take the one whose plain rounding
  // errs least where a linear image looks (log error weighted by the mass squared: the highlight
  // bins). A specular table's peak neighbours otherwise fall wherever the grid puts them.
  auto linear_error = [&](const Positions& c) {
    const double step = double(c.span_units) / kRangeGridUnits / (top - 1.0);
    double e2 = 0;
    for (std::size_t i = 0; i < masses.size(); ++i) {
      if (!(masses[i] > 0.0)) continue;
      const double r = masses[i] / peak;
      const double e = (std::nearbyint(c.position[i]) - c.position[i]) * step;
      e2 += r * r * e * e;
    }
    return e2;
  };
  double best = linear_error(p);
  Positions trial = p;
  for (std::uint32_t d = smallest + 1; d <= std::min(smallest + kSpanSearch, kMaxGridUnits); ++d) {
    fill(d, &trial);
    const double e = linear_error(trial);
    if (e < best) best = e, p = trial;
  }
  return p;
}

std::vector<std::uint32_t> rounded(const Positions& p) {
  std::vector<std::uint32_t> q(p.position.size(), 0);
  for (std::size_t i = 0; i < q.size(); ++i) {
    q[i] = p.position[i] > 0.0 ? std::uint32_t(std::nearbyint(p.position[i])) : 0;
  }
  return q;
}

namespace {
std::int64_t predicted(const Predicting& how, const std::vector<std::uint32_t>& q, std::size_t i,
                       std::uint32_t span) {
  const Reference ref{how.ref_codes, how.ref_span};
  return clamp_code(predict(how.mode, q, i, ref, span, how.first), how.top);
}
}  // namespace

double rd_cost(const Positions& p, const std::vector<std::uint32_t>& codes, const Predicting& how,
               std::array<internal::SIntContexts, 3> contexts, double lambda) {
  double distortion = 0;
  for (std::size_t i = 0; i < codes.size(); ++i) {
    const double e = double(codes[i]) - p.position[i];
    distortion += p.weight[i] * e * e;
  }
  internal::CostMeter meter;
  put_codes(meter, contexts, how.mode, codes, Reference{how.ref_codes, how.ref_span}, p.span_units,
            how.first, how.top);
  return distortion + lambda * meter.bits();
}

std::vector<std::uint32_t> rd_rounded(const Positions& p, const Predicting& how,
                                      const std::array<internal::SIntContexts, 3>& contexts,
                                      double lambda) {
  std::vector<std::uint32_t> plain = rounded(p);
  if (!(lambda > 0.0)) return plain;
  std::array<internal::SIntContexts, 3> ctx = contexts;
  std::vector<std::uint32_t> q(p.position.size(), 0);
  int cls = 2;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const std::int64_t pred = predicted(how, q, i, p.span_units);
    // A zero mass stays code 0 (an exact zero); others take a neighbour of their position.
    std::int64_t best = 0;
    if (p.position[i] > 0.0) {
      double best_cost = std::numeric_limits<double>::infinity();
      const double lo = std::floor(p.position[i]), hi = std::ceil(p.position[i]);
      for (double c : {lo, hi}) {
        if (c < 1.0 || c > double(how.top)) continue;
        PeekMeter meter;
        PeekSink sink{&meter};
        internal::put_sint(sink, ctx[std::size_t(cls)], std::int32_t(std::int64_t(c) - pred));
        const double e = c - p.position[i];
        const double cost = p.weight[i] * e * e + lambda * meter.bits;
        if (cost < best_cost) best_cost = cost, best = std::int64_t(c);
      }
    }
    q[i] = std::uint32_t(best);
    internal::CostMeter adapt;
    internal::put_sint(adapt, ctx[std::size_t(cls)], std::int32_t(best - pred));
    cls = residual_class(best - pred);
  }
  return rd_cost(p, q, how, contexts, lambda) <= rd_cost(p, plain, how, contexts, lambda) ? q
                                                                                          : plain;
}

double writer_lambda() {
  return kWriterLambda;
}

}  // namespace base_codes

std::optional<std::vector<std::uint8_t>> encode_base_chunk(const Model& model, int bits) {
  ByteWriter w;
  w.u8(std::uint8_t(bits));
  const bool mixtures = has_mixtures(model);
  const bool wide = base_wide_scales(model);
  w.u8(std::uint8_t((mixtures ? kBaseFlagComponents : 0) | (wide ? kBaseFlagWideScales : 0)));
  for (const Slice& s : model.slices) w.u8(std::uint8_t(s.theta_d_end));
  if (mixtures) {
    for (const Slice& s : model.slices) {
      for (const ChannelSlice& c : s.channel) w.u8(std::uint8_t(c.extra.size()));
    }
  }
  bool representable = true;
  for_each_component(model.slices, [&](std::size_t s, int c, int k) {
    const Component& comp = model.slices[s].channel[std::size_t(c)].component(k);
    const std::optional<float> theta =
        parameter_f32(std::uint8_t(comp.family), comp.theta, comp.scale);
    if (!theta) {
      representable = false;
      return;
    }
    w.u8(std::uint8_t(comp.family));
    w.f32(*theta);
    if (wide) {
      w.f64(comp.scale);
    } else {
      w.f32(float(comp.scale));
    }
  });
  if (!representable) return std::nullopt;

  MarginalContexts ctx;
  internal::Encoder enc;
  const std::int64_t top = max_code(bits);
  const double lambda_log = base_codes::writer_lambda();
  std::array<std::vector<std::uint32_t>, 3> last_codes;
  std::array<GridRange, 3> last_range{};
  std::array<bool, 3> have_last{};
  for_each_component(model.slices, [&](std::size_t s, int c, int k) {
    const Component& comp = model.slices[s].channel[std::size_t(c)].component(k);
    const std::vector<double>* tables[3] = {&comp.pdf_h, &comp.pdf_d, &comp.pdf_p};
    for (std::size_t a = 0; a < 3; ++a) {
      const base_codes::Positions pos = base_codes::positions(*tables[a], bits);
      // Only D shapes the decoded ratios (the decoder renormalizes): H costs nothing as the
      // previous table's, moved only as far as the range must stay inside [-746, 0].
      GridRange range;
      range.span_units = pos.span_units;
      range.hi_units = std::min(last_range[a].hi_units, kMaxGridUnits - pos.span_units);
      internal::put_sint(enc, ctx.hi[a],
                         std::int32_t(std::int64_t(range.hi_units) - last_range[a].hi_units));
      internal::put_sint(enc, ctx.span[a],
                         std::int32_t(std::int64_t(range.span_units) - last_range[a].span_units));
      Reference ref;
      if (have_last[a] && last_codes[a].size() == pos.position.size()) {
        ref = {&last_codes[a], last_range[a].span_units};
      }
      const std::int64_t first = first_prediction(have_last[a] ? &last_codes[a] : nullptr, top);
      // The predictor, and codes for it, that cost least (distortion + lambda x bits) from the
      // current state; lambda 0 is plain rounding and the fewest bits.
      int best = kPredictPrevious;
      double best_cost = std::numeric_limits<double>::infinity();
      QuantizedTable t;
      // lambda is per squared log mass: in squared code steps of this table it grows as the
      // step shrinks, so that fine codes are rounded towards cheap ones and coarse codes are not.
      const double step = double(pos.span_units) / kRangeGridUnits / double(top - 1);
      const double lambda = step > 0.0 ? lambda_log / (step * step) : 0.0;
      for (int mode = 0; mode < kPredictors; ++mode) {
        if (mode >= kPredictRefStep && ref.codes == nullptr) continue;
        const base_codes::Predicting how{mode, ref.codes, ref.span, first, top};
        std::vector<std::uint32_t> codes =
            base_codes::rd_rounded(pos, how, ctx.residual[a], lambda);
        internal::CostMeter meter;
        std::array<internal::Prob, 3> p = ctx.predictor[a];
        std::array<internal::SIntContexts, 3> r = ctx.residual[a];
        put_predictor(meter, p, mode);
        put_codes(meter, r, mode, codes, ref, range.span_units, first, top);
        // lambda 0: the fewest bits, as before (every mode then has the same codes).
        const double key =
            lambda > 0.0
                ? base_codes::rd_cost(pos, codes, how, ctx.residual[a], 0.0) + lambda * meter.bits()
                : meter.bits();
        if (key < best_cost) {
          best_cost = key;
          best = mode;
          t.codes = std::move(codes);
        }
      }
      put_predictor(enc, ctx.predictor[a], best);
      put_codes(enc, ctx.residual[a], best, t.codes, ref, range.span_units, first, top);
      last_codes[a] = t.codes;
      last_range[a] = range;
      have_last[a] = true;
    }
  });
  const std::vector<std::uint8_t> coded = enc.finish();
  std::vector<std::uint8_t> out = w.take();
  out.insert(out.end(), coded.begin(), coded.end());
  return out;
}

}  // namespace cbrdf
