// SPDX-License-Identifier: MIT
// PSNR, percentile exposure, tone mapping and false-colour differences (metrics.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include "metrics.h"

namespace cbrdf {
namespace {

bool counted(const std::vector<std::uint8_t>* mask, std::size_t pixel) {
  return mask == nullptr || (pixel < mask->size() && (*mask)[pixel] != 0);
}

bool same_size(const Image& a, const Image& b) {
  return a.width == b.width && a.height == b.height && a.data.size() == b.data.size();
}

// matplotlib's viridis sampled at t = k / 9, k = 0..9 (#440154 ... #fde725).
constexpr float kViridis[10][3] = {
    {68, 1, 84},    {72, 40, 120},  {62, 73, 137},  {49, 104, 142}, {38, 130, 142},
    {31, 158, 137}, {53, 183, 121}, {110, 206, 88}, {181, 222, 43}, {253, 231, 37},
};

}  // namespace

double psnr(const Image& reference, const Image& test, int channel, double peak,
            const std::vector<std::uint8_t>* mask) {
  if (!same_size(reference, test) || channel < 0 || channel > 2) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < reference.pixel_count(); ++i) {
    if (!counted(mask, i)) continue;
    const double t = test.data[i * 3 + std::size_t(channel)];
    const double r = reference.data[i * 3 + std::size_t(channel)];
    // Equal values (infinities too) match; any other pair with an inf or NaN is an infinite
    // error, never a NaN that would compare as a perfect match.
    const double e = t == r ? 0.0 : t - r;
    sum += std::isnan(e) ? std::numeric_limits<double>::infinity() : e * e;
    ++n;
  }
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  const double mse = sum / double(n);
  if (mse == 0.0) return kPsnrCapDb;
  if (peak <= 0.0 || mse == std::numeric_limits<double>::infinity()) {
    return -std::numeric_limits<double>::infinity();
  }
  const double db = 10.0 * std::log10(peak * peak / mse);
  return std::isnan(db) ? db : std::min(kPsnrCapDb, db);
}

double percentile(const Image& image, double p, const std::vector<std::uint8_t>* mask) {
  std::vector<float> values;
  values.reserve(image.data.size());
  for (std::size_t i = 0; i < image.pixel_count(); ++i) {
    if (!counted(mask, i)) continue;
    for (std::size_t c = 0; c < 3; ++c) values.push_back(image.data[i * 3 + c]);
  }
  if (values.empty()) return 0.0;
  const double rank = std::clamp(p, 0.0, 100.0) / 100.0 * double(values.size() - 1);
  const std::size_t lo = std::size_t(rank);
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  // Two selections instead of a full sort: reports call this per render.
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(lo), values.end());
  const double v_lo = values[lo];
  const double v_hi =
      hi == lo ? v_lo
               : double(*std::min_element(values.begin() + std::ptrdiff_t(lo) + 1, values.end()));
  return v_lo + (rank - double(lo)) * (v_hi - v_lo);
}

double tonemap_exposure(const Image& reference, const std::vector<std::uint8_t>* mask) {
  const double p99 = percentile(reference, 99.0, mask);
  if (p99 > 0.0) return 1.0 / p99;
  const double max = percentile(reference, 100.0, mask);
  return max > 0.0 ? 1.0 / max : 1.0;
}

Image tonemap(const Image& image, double exposure, double gamma) {
  Image out = image;
  for (float& v : out.data) {
    const double x = double(v) * exposure;
    v = x > 0.0 ? float(std::pow(std::min(x, 1.0), 1.0 / gamma)) : 0.0f;  // NaN fails x > 0
  }
  return out;
}

std::array<float, 3> viridis(double t) {
  const double x = std::isnan(t) ? 0.0 : std::clamp(t, 0.0, 1.0) * 9.0;
  const int k = std::min(int(x), 8);
  const float f = float(x - k);
  std::array<float, 3> rgb;
  for (std::size_t c = 0; c < 3; ++c) {
    rgb[c] = ((1.0f - f) * kViridis[k][c] + f * kViridis[k + 1][c]) / 255.0f;
  }
  return rgb;
}

Image difference_image(const Image& a, const Image& b, double scale,
                       const std::vector<std::uint8_t>* mask) {
  if (!same_size(a, b) || !(scale > 0.0)) return {};
  Image out(a.width, a.height);
  for (std::size_t i = 0; i < a.pixel_count(); ++i) {
    if (!counted(mask, i)) continue;
    double d = 0;
    for (std::size_t c = 0; c < 3; ++c)
      d += std::abs(double(a.data[i * 3 + c]) - double(b.data[i * 3 + c]));
    const std::array<float, 3> rgb = viridis(d / 3.0 / scale);
    for (std::size_t c = 0; c < 3; ++c) out.data[i * 3 + c] = rgb[c];
  }
  return out;
}

}  // namespace cbrdf
