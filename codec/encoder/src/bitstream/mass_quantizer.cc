// SPDX-License-Identifier: MIT
#include "bitstream/mass_quantizer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cbrdf {
namespace {

float round_down_to_float(double v) {
  float f = float(v);
  if (double(f) > v) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

float round_up_to_float(double v) {
  float f = float(v);
  if (double(f) < v) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

double step_of(const QuantizedTable& t, int bits) {
  return (double(t.hi) - double(t.lo)) / double(max_code(bits) - 1);
}

}  // namespace

std::optional<double> log_mass_sum(std::span<const double> masses) {
  double sum = 0.0, max = 0.0;
  for (double m : masses) {
    sum += m > 0.0 ? m : 0.0;
    max = m > max ? m : max;
  }
  if (!(sum > 0.0)) return std::nullopt;
  if (std::isfinite(sum)) return std::log(sum);  // as before, so that codes do not move
  double scaled = 0.0;
  for (double m : masses) scaled += m > 0.0 ? m / max : 0.0;
  return std::log(max) + std::log(scaled);
}

namespace {

// The shared quantizer; `round_range` turns the exact log range into the stored one (which must
// contain it, up to the -746 clamp).
template <class RoundRange>
QuantizedTable quantize_with(std::span<const double> masses, int bits, RoundRange round_range) {
  QuantizedTable t;
  t.codes.assign(masses.size(), 0);
  // The decoder renormalizes, so only ratios matter: quantize the table scaled to sum 1, which
  // also keeps every log mass at or below 0.
  const std::optional<double> total = log_mass_sum(masses);
  if (!total) return t;
  const double log_sum = *total;
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (double m : masses) {
    if (m > 0.0) {
      lo = std::min(lo, std::log(m) - log_sum);
      hi = std::max(hi, std::log(m) - log_sum);
    }
  }
  if (!(lo <= hi)) return t;  // all zero: the range is unused and stays (0, 0)
  // Ratios beyond e^746 cannot be represented after renormalization anyway.
  lo = std::max(lo, kMinLogMass);
  hi = std::max(hi, kMinLogMass);
  round_range(lo, hi, &t);
  const std::uint32_t top = max_code(bits);
  const double span = double(t.hi) - double(t.lo);
  for (std::size_t i = 0; i < masses.size(); ++i) {
    if (!(masses[i] > 0.0)) continue;
    if (span <= 0.0) {
      t.codes[i] = top;  // one distinct value: every nonzero mass is the same
      continue;
    }
    const double pos = (std::log(masses[i]) - log_sum - double(t.lo)) / span * double(top - 1);
    const double q = 1.0 + std::nearbyint(std::clamp(pos, 0.0, double(top - 1)));
    t.codes[i] = std::uint32_t(q);
  }
  return t;
}

}  // namespace

QuantizedTable quantize_masses(std::span<const double> masses, int bits) {
  return quantize_with(masses, bits, [](double lo, double hi, QuantizedTable* t) {
    t->lo = round_down_to_float(lo);
    t->hi = std::min(round_up_to_float(hi), 0.0f);  // a rounding excess above 1 maps to the top
    if (double(t->lo) > double(t->hi)) t->lo = t->hi;
  });
}

QuantizedTable quantize_masses_on_grid(std::span<const double> masses, int bits, GridRange* range) {
  *range = GridRange{};
  QuantizedTable t = quantize_with(masses, bits, [&](double lo, double hi, QuantizedTable* q) {
    // hi rounded up and lo down to the grid: every log mass stays inside.
    const double top = double(kMaxGridUnits);
    const double h = std::clamp(std::floor(-hi * kRangeGridUnits), 0.0, top);
    const double l = std::clamp(std::ceil(-lo * kRangeGridUnits), h, top);
    range->hi_units = std::uint32_t(h);
    range->span_units = std::uint32_t(l - h);
    const QuantizedTable g = grid_table(*range);
    q->lo = g.lo;
    q->hi = g.hi;
  });
  return t;
}

double relative_error_bound(const QuantizedTable& t, int bits) {
  return std::expm1(step_of(t, bits));
}

}  // namespace cbrdf
