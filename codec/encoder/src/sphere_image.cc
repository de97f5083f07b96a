// SPDX-License-Identifier: MIT
// Sphere renders and their PSNR (metrics.h documents the scene exactly).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <utility>

#include "metrics.h"
#include "parallel_for.h"

namespace cbrdf {
namespace {

// What a pixel inside the sphere needs for any light: its local frame and the view direction in it.
struct PixelGeometry {
  int x = 0;
  Vec3 t, b, n;  // world-space tangent, bitangent, normal
  Vec3 wo;       // the view direction (0, 0, 1) in the local frame
};

struct SphereGeometry {
  int size = 0;
  std::vector<PixelGeometry> pixels;   // row by row
  std::vector<std::size_t> row_begin;  // size + 1 offsets into pixels
  std::vector<std::uint8_t> mask;
};

double pixel_centre(int i, int size) {
  return (i + 0.5) / size * 2 - 1;
}

// Duff et al. 2017: a continuous-enough, branch-light orthonormal basis around n.
void basis(const Vec3& n, Vec3* t, Vec3* b) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double c = n.x * n.y * a;
  *t = {1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x};
  *b = {c, sign + n.y * n.y * a, -n.y};
}

Vec3 light_direction(double light_angle_deg) {
  const double a = light_angle_deg * std::numbers::pi / 180.0;
  return {std::sin(a), 0.0, std::cos(a)};
}

// The light in a pixel's local frame; false when it is at or below that pixel's horizon.
bool local_light(const PixelGeometry& p, const Vec3& light, Vec3* wi, double* cos_i) {
  *cos_i = dot(light, p.n);
  if (!(*cos_i > 0.0)) return false;
  *wi = {dot(light, p.t), dot(light, p.b), *cos_i};
  return true;
}

std::shared_ptr<const SphereGeometry> build_geometry(int size) {
  auto g = std::make_shared<SphereGeometry>();
  g->size = size;
  g->mask.assign(std::size_t(size) * std::size_t(size), 0);
  g->row_begin.reserve(std::size_t(size) + 1);
  for (int y = 0; y < size; ++y) {
    g->row_begin.push_back(g->pixels.size());
    const double v = -pixel_centre(y, size);
    for (int x = 0; x < size; ++x) {
      const double u = pixel_centre(x, size);
      const double r2 = u * u + v * v;
      if (!(r2 < 1.0)) continue;
      PixelGeometry p;
      p.x = x;
      p.n = {u, v, std::sqrt(1.0 - r2)};
      basis(p.n, &p.t, &p.b);
      p.wo = {p.t.z, p.b.z, p.n.z};
      g->pixels.push_back(p);
      g->mask[std::size_t(y) * std::size_t(size) + std::size_t(x)] = 1;
    }
  }
  g->row_begin.push_back(g->pixels.size());
  return g;
}

// Reports render the same few sizes over and over: build each once. Large sizes (128 bytes per
// pixel) are built per call instead of being kept forever.
std::shared_ptr<const SphereGeometry> geometry(int size) {
  constexpr int kMaxCachedSize = 1024;
  if (size > kMaxCachedSize) return build_geometry(size);
  static std::mutex mutex;
  static std::map<int, std::shared_ptr<const SphereGeometry>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[size];
  if (!slot) slot = build_geometry(size);
  return slot;
}

// For tables: the MERL bin and cos(theta_i) of every lit pixel under one light.
struct LitPixel {
  std::uint32_t pixel = 0;  // y * size + x
  std::uint32_t bin = 0;    // nearest_bin(wi, wo)
  double cos_i = 0.0;
};

std::vector<LitPixel> build_bins(const SphereGeometry& g, double light_angle_deg, int threads) {
  std::vector<std::vector<LitPixel>> rows(std::size_t(g.size));
  const Vec3 light = light_direction(light_angle_deg);
  internal::parallel_rows(g.size, threads, [&](int y_begin, int y_end) {
    for (int y = y_begin; y < y_end; ++y) {
      for (std::size_t i = g.row_begin[std::size_t(y)]; i < g.row_begin[std::size_t(y) + 1]; ++i) {
        const PixelGeometry& p = g.pixels[i];
        Vec3 wi;
        double cos_i = 0;
        if (!local_light(p, light, &wi, &cos_i)) continue;
        rows[std::size_t(y)].push_back(
            {std::uint32_t(y * g.size + p.x), std::uint32_t(nearest_bin(wi, p.wo)), cos_i});
      }
    }
  });
  std::vector<LitPixel> out;
  for (const auto& r : rows) out.insert(out.end(), r.begin(), r.end());
  return out;
}

// Keyed by size and the angle's exact value; cleared when it grows past kMaxCachedLights, which
// only a caller sweeping many angles reaches.
std::shared_ptr<const std::vector<LitPixel>> cached_bins(int size, double light_angle_deg,
                                                         int threads) {
  constexpr std::size_t kMaxCachedLights = 64;
  static std::mutex mutex;
  static std::map<std::pair<int, double>, std::shared_ptr<const std::vector<LitPixel>>> cache;
  const std::shared_ptr<const SphereGeometry> g = geometry(size);
  // NaN would break the map's ordering, and nothing is lit by it anyway.
  if (!std::isfinite(light_angle_deg)) return std::make_shared<const std::vector<LitPixel>>();
  std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_pair(size, light_angle_deg);
  if (const auto it = cache.find(key); it != cache.end()) return it->second;
  if (cache.size() >= kMaxCachedLights) cache.clear();
  auto bins =
      std::make_shared<const std::vector<LitPixel>>(build_bins(*g, light_angle_deg, threads));
  cache[key] = bins;
  return bins;
}

// Renders one light with the BRDF's values times `scale` (a power of two) and, when peak is not
// null, stores there the largest radiance it rendered, in double.
using Renderer = std::function<Image(double light_angle_deg, double scale, double* peak)>;

// Images are float: a BRDF beyond about 1e38 would render as inf (inf - inf is NaN, which read as
// a perfect match) and one below about 1e-38 as 0 (a perfect match with anything as small).
// Both renders are therefore scaled by the power of two that brings the reference's peak to
// [1, 2) when the peak is outside [2^-60, 2^60]; PSNR does not depend on a common scale, and
// ordinary materials (scale 1) render exactly as before.
double render_scale(double peak) {
  if (!(peak > 0) || !std::isfinite(peak) || (peak >= 0x1p-60 && peak <= 0x1p60)) return 1.0;
  return std::ldexp(1.0, -std::ilogb(peak));
}

void atomic_max(std::atomic<double>* m, double v) {
  double cur = m->load(std::memory_order_relaxed);
  while (v > cur && !m->compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
  }
}

Renderer fn_renderer(const BrdfFn& f, const SphereSetup& setup) {
  return [&f, &setup](double angle, double scale, double* peak) {
    std::atomic<double> largest{0.0};
    const BrdfFn scaled = [&](const Vec3& wi, const Vec3& wo, double rgb[3]) {
      f(wi, wo, rgb);
      for (int c = 0; c < 3; ++c) {
        rgb[c] *= scale;
        if (peak) atomic_max(&largest, rgb[c]);
      }
    };
    Image img = render_sphere(scale == 1.0 && !peak ? f : scaled, angle, setup.size, setup.threads);
    if (peak) *peak = largest.load();
    return img;
  };
}

Renderer table_renderer(const BrdfTable& table, const SphereSetup& setup) {
  return [&table, &setup](double angle, double scale, double* peak) {
    if (scale == 1.0 && !peak) return render_sphere(table, angle, setup.size, setup.threads);
    if (setup.size <= 0 || setup.size > kMaxSphereSize) return Image{};
    const std::shared_ptr<const std::vector<LitPixel>> bins =
        cached_bins(setup.size, angle, setup.threads);
    Image img(setup.size, setup.size);
    double largest = 0;
    for (const LitPixel& p : *bins) {
      for (int c = 0; c < kChannels; ++c) {
        const double v = table.measured(c, p.bin) ? table.physical(c, p.bin) * scale : 0.0;
        largest = std::max(largest, v);
        img.data[std::size_t(p.pixel) * 3 + std::size_t(c)] = float(v * p.cos_i);
      }
    }
    if (peak) *peak = largest;
    return img;
  };
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / double(v.size());
}

// What one light's comparison needs of the reference, made once per reference.
struct ReferenceLight {
  double angle = 0, scale = 1.0;
  Image image, tonemapped;
  double exposure = 1.0;
  std::array<double, 3> peak{};  // per channel, over the sphere's pixels
};

ReferenceLight reference_light(const Renderer& render_reference, double angle,
                               const std::vector<std::uint8_t>& mask) {
  ReferenceLight r;
  r.angle = angle;
  double ref_peak = 0;
  r.image = render_reference(angle, 1.0, &ref_peak);
  r.scale = render_scale(ref_peak);
  if (r.scale != 1.0) r.image = render_reference(angle, r.scale, nullptr);
  r.exposure = tonemap_exposure(r.image, &mask);
  r.tonemapped = tonemap(r.image, r.exposure);
  for (int c = 0; c < 3; ++c) {
    double peak = 0;
    for (std::size_t i = 0; i < r.image.pixel_count(); ++i) {
      if (mask[i]) peak = std::max(peak, double(r.image.data[i * 3 + std::size_t(c)]));
    }
    r.peak[std::size_t(c)] = peak;
  }
  return r;
}

LightMetrics score_light(const ReferenceLight& r, const Image& tst,
                         const std::vector<std::uint8_t>& mask) {
  LightMetrics lm;
  lm.light_angle_deg = r.angle;
  lm.exposure = r.exposure;
  const Image tst_tm = tonemap(tst, r.exposure);
  for (int c = 0; c < 3; ++c) {
    lm.psnr_linear[std::size_t(c)] = psnr(r.image, tst, c, r.peak[std::size_t(c)], &mask);
    lm.psnr_tonemapped[std::size_t(c)] = psnr(r.tonemapped, tst_tm, c, 1.0, &mask);
  }
  return lm;
}

// The summary over lights: means of the dB values over lights and channels.
ImageMetrics summarize(std::vector<LightMetrics> per_light) {
  ImageMetrics m;
  std::vector<double> linear, tonemapped;
  for (const LightMetrics& lm : per_light) {
    for (int c = 0; c < 3; ++c) {
      linear.push_back(lm.psnr_linear[std::size_t(c)]);
      tonemapped.push_back(lm.psnr_tonemapped[std::size_t(c)]);
    }
  }
  m.per_light = std::move(per_light);
  m.psnr_linear = mean(linear);
  m.psnr_tonemapped = mean(tonemapped);
  return m;
}

ImageMetrics compare(const Renderer& render_reference, const Renderer& render_test,
                     const SphereSetup& setup) {
  const std::vector<std::uint8_t> mask = sphere_mask(setup.size);
  std::vector<LightMetrics> per_light;
  for (double angle : setup.light_angles_deg) {
    const ReferenceLight r = reference_light(render_reference, angle, mask);
    per_light.push_back(score_light(r, render_test(angle, r.scale, nullptr), mask));
  }
  return summarize(std::move(per_light));
}

}  // namespace

std::vector<std::uint8_t> sphere_mask(int size) {
  if (size <= 0 || size > kMaxSphereSize) return {};
  return geometry(size)->mask;
}

Image render_sphere(const BrdfFn& f, double light_angle_deg, int size, int threads) {
  if (size <= 0 || size > kMaxSphereSize) return {};
  const std::shared_ptr<const SphereGeometry> g = geometry(size);
  const Vec3 light = light_direction(light_angle_deg);
  Image img(size, size);
  internal::parallel_rows(size, threads, [&](int y_begin, int y_end) {
    for (int y = y_begin; y < y_end; ++y) {
      for (std::size_t i = g->row_begin[std::size_t(y)]; i < g->row_begin[std::size_t(y) + 1];
           ++i) {
        const PixelGeometry& p = g->pixels[i];
        Vec3 wi;
        double cos_i = 0;
        if (!local_light(p, light, &wi, &cos_i)) continue;
        double rgb[3] = {0, 0, 0};
        f(wi, p.wo, rgb);
        for (int c = 0; c < 3; ++c) img.at(p.x, y, c) = float(rgb[c] * cos_i);
      }
    }
  });
  return img;
}

Image render_sphere(const BrdfTable& table, double light_angle_deg, int size, int threads) {
  if (size <= 0 || size > kMaxSphereSize) return {};
  const std::shared_ptr<const std::vector<LitPixel>> bins =
      cached_bins(size, light_angle_deg, threads);
  Image img(size, size);
  for (const LitPixel& p : *bins) {
    for (int c = 0; c < kChannels; ++c) {
      // The arithmetic of lookup_nearest followed by render_sphere's product, so images match.
      const double v = table.measured(c, p.bin) ? table.physical(c, p.bin) : 0.0;
      img.data[std::size_t(p.pixel) * 3 + std::size_t(c)] = float(v * p.cos_i);
    }
  }
  return img;
}

ImageMetrics sphere_psnr(const BrdfFn& reference, const BrdfFn& test, const SphereSetup& setup) {
  return compare(fn_renderer(reference, setup), fn_renderer(test, setup), setup);
}

ImageMetrics sphere_psnr(const BrdfTable& reference, const BrdfTable& test,
                         const SphereSetup& setup) {
  return compare(table_renderer(reference, setup), table_renderer(test, setup), setup);
}

ImageMetrics sphere_psnr(const BrdfTable& reference, const BrdfFn& test, const SphereSetup& setup) {
  return compare(table_renderer(reference, setup), fn_renderer(test, setup), setup);
}

struct SphereScorer::Impl {
  const BrdfTable* reference = nullptr;
  SphereSetup setup;
  std::vector<std::uint8_t> mask;
  std::vector<ReferenceLight> lights;
  std::vector<std::shared_ptr<const std::vector<LitPixel>>> bins;  // per light
  std::vector<std::uint32_t> rows;  // the phi_d rows (theta_h * 90 + theta_d) the lights read
  std::vector<std::int32_t> slot;   // row -> its index in rows, -1 when not read
};

SphereScorer::SphereScorer(const BrdfTable& reference, SphereSetup setup)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.reference = &reference;
  m.setup = std::move(setup);
  m.mask = sphere_mask(m.setup.size);
  if (m.mask.empty()) return;  // no sphere: score() measures as sphere_psnr does
  const Renderer render = table_renderer(reference, m.setup);
  m.slot.assign(std::size_t(kThetaHBins) * kThetaDBins, -1);
  for (double angle : m.setup.light_angles_deg) {
    m.lights.push_back(reference_light(render, angle, m.mask));
    m.bins.push_back(cached_bins(m.setup.size, angle, m.setup.threads));
    for (const LitPixel& p : *m.bins.back()) m.slot[p.bin / kPhiDBins] = 0;
  }
  for (std::size_t row = 0; row < m.slot.size(); ++row) {
    if (m.slot[row] == 0) {
      m.slot[row] = std::int32_t(m.rows.size());
      m.rows.push_back(std::uint32_t(row));
    }
  }
}

SphereScorer::~SphereScorer() = default;
SphereScorer::SphereScorer(SphereScorer&&) noexcept = default;
SphereScorer& SphereScorer::operator=(SphereScorer&&) noexcept = default;

ImageMetrics SphereScorer::score(const BrdfTable& test) const {
  const Impl& m = *impl_;
  if (m.mask.empty()) return sphere_psnr(*m.reference, test, m.setup);
  const Renderer render = table_renderer(test, m.setup);
  std::vector<LightMetrics> per_light;
  for (const ReferenceLight& r : m.lights) {
    per_light.push_back(score_light(r, render(r.angle, r.scale, nullptr), m.mask));
  }
  return summarize(std::move(per_light));
}

ImageMetrics SphereScorer::score(const Model& test) const {
  const Impl& m = *impl_;
  if (m.mask.empty() || test.residual.present()) return score(test.table());
  // table_renderer's arithmetic on the values table() would store at the rows read: the model's
  // value where measured, 0 where not.
  const ModelEvaluator ev(std::shared_ptr<const Model>(std::shared_ptr<const Model>(), &test));
  std::vector<double> values(m.rows.size() * kChannels * kPhiDBins);
  ev.table_rows(m.rows, values.data());
  std::vector<LightMetrics> per_light;
  for (std::size_t l = 0; l < m.lights.size(); ++l) {
    const ReferenceLight& r = m.lights[l];
    Image img(m.setup.size, m.setup.size);
    for (const LitPixel& p : *m.bins[l]) {
      const std::size_t at = std::size_t(m.slot[p.bin / kPhiDBins]) * kChannels,
                        k = p.bin % kPhiDBins;
      for (int c = 0; c < kChannels; ++c) {
        const double stored =
            test.not_measured.test(c, p.bin) ? -1.0 : values[(at + std::size_t(c)) * kPhiDBins + k];
        const double v = stored >= 0.0 ? stored * kMerlScale[std::size_t(c)] * r.scale : 0.0;
        img.data[std::size_t(p.pixel) * 3 + std::size_t(c)] = float(v * p.cos_i);
      }
    }
    per_light.push_back(score_light(r, img, m.mask));
  }
  return summarize(std::move(per_light));
}

}  // namespace cbrdf
