// SPDX-License-Identifier: MIT
// BrdfSampler: per-theta_o tables over half-vector cells (the design is in sampling.h).
#include "cbrdf/sampling.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>
#include <utility>

#include "cbrdf/parallel_for.h"

namespace cbrdf {
namespace {

constexpr double kPi = std::numbers::pi;

// wo's azimuthal frame: x along wo's projection on the surface, y = z cross x. At normal
// incidence any frame will do; this one is fixed so that sample() and pdf() agree.
struct AzimuthFrame {
  double xx = 1, xy = 0;  // x axis (xx, xy, 0); y axis (-xy, xx, 0)
};

AzimuthFrame azimuth_frame(const Vec3& wo) {
  const double r = std::hypot(wo.x, wo.y);
  if (r < 1e-12) return {};
  return {wo.x / r, wo.y / r};
}

// Upper bound search in a normalized CDF of n + 1 entries: the bin i with cdf[i] <= u < cdf[i+1]
// and u remapped to [0, 1) within it. Empty bins are never chosen.
int pick(const double* cdf, int n, double* u) {
  // std::upper_bound's own steps (libstdc++'s), its probes and result the same, with selects for
  // its branches: u is random, so they mispredict half the time.
  const double* it = cdf;
  std::size_t len = std::size_t(n) + 1;
  while (len > 0) {
    const std::size_t half = len >> 1;
    const bool right = !(*u < it[half]);
    it = right ? it + half + 1 : it;
    len = right ? len - half - 1 : half;
  }
  const int i = std::clamp(int(it - cdf) - 1, 0, n - 1);
  const double w = cdf[i + 1] - cdf[i];
  *u = w > 0 ? std::clamp((*u - cdf[i]) / w, 0.0, std::nextafter(1.0, 0.0)) : 0.5;
  return i;
}

}  // namespace

struct BrdfSampler::Table {
  std::once_flag once;
  bool empty = true;             // the BRDF reflects nothing at this theta_o
  std::vector<double> row_cdf;   // theta_h_cells + 1
  std::vector<double> cell_cdf;  // per theta_h row, phi_h_cells + 1 (conditional)
  std::vector<double> cell_p;    // probability of each cell, row-major
};

BrdfSampler::BrdfSampler(BrdfFn f, const SamplerSettings& settings)
    : f_(std::move(f)), settings_(settings) {
  settings_.theta_o_bins = std::clamp(settings_.theta_o_bins, 1, 1024);
  settings_.theta_h_cells = std::clamp(settings_.theta_h_cells, 1, 4096);
  settings_.phi_h_cells = std::clamp(settings_.phi_h_cells, 1, 4096);
  settings_.supersample = std::clamp(settings_.supersample, 1, 16);
  settings_.cosine_fraction = std::isfinite(settings_.cosine_fraction)
                                  ? std::clamp(settings_.cosine_fraction, 0.0, 1.0)
                                  : 0.1;
  const int n = settings_.theta_h_cells;
  cos_edges_.resize(std::size_t(n) + 1);
  for (int a = 0; a <= n; ++a) {
    const double t = double(a) / n;
    cos_edges_[a] = std::cos(t * t * kPi / 2);
  }
  cos_edges_[n] = 0.0;  // exactly the horizon, not cos(pi/2) ~ 6e-17
  tables_ = std::make_unique<Table[]>(std::size_t(settings_.theta_o_bins));
}

BrdfSampler::~BrdfSampler() = default;
BrdfSampler::BrdfSampler(BrdfSampler&&) noexcept = default;
BrdfSampler& BrdfSampler::operator=(BrdfSampler&&) noexcept = default;

const BrdfSampler::Table& BrdfSampler::table_for(double cos_theta_o) const {
  const int bins = settings_.theta_o_bins;
  const double theta_o = std::acos(std::clamp(cos_theta_o, 0.0, 1.0));
  const int k = std::clamp(int(theta_o / (kPi / 2) * bins), 0, bins - 1);
  Table& t = tables_[std::size_t(k)];
  std::call_once(t.once, [&] {
    const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells, ss = settings_.supersample;
    const double dphi = 2 * kPi / np;
    const double to = (k + 0.5) / bins * (kPi / 2);
    const Vec3 wo{std::sin(to), 0.0, std::cos(to)};
    t.cell_p.assign(std::size_t(nh) * np, 0.0);
    double total = 0.0;
    for (int a = 0; a < nh; ++a) {
      const double c0 = cos_edges_[a], c1 = cos_edges_[a + 1];
      for (int b = 0; b < np; ++b) {
        double sum = 0.0;
        for (int i = 0; i < ss; ++i) {
          const double ct = c0 + (i + 0.5) / ss * (c1 - c0);
          const double st = std::sqrt(std::max(0.0, 1 - ct * ct));
          for (int j = 0; j < ss; ++j) {
            const double phi = (b + (j + 0.5) / ss) * dphi;
            const Vec3 h{st * std::cos(phi), st * std::sin(phi), ct};
            const double d = dot(wo, h);
            if (!(d > 0)) continue;
            const Vec3 wi{2 * d * h.x - wo.x, 2 * d * h.y - wo.y, 2 * d * h.z - wo.z};
            if (!(wi.z > 0)) continue;
            double rgb[3] = {0, 0, 0};
            f_(wi, wo, rgb);
            const double m = (rgb[0] + rgb[1] + rgb[2]) / 3;
            if (std::isfinite(m) && m > 0) sum += m * wi.z * 4 * d;
          }
        }
        const double mass = sum / (ss * ss) * (c0 - c1) * dphi;
        t.cell_p[std::size_t(a) * np + b] = mass;
        total += mass;
      }
    }
    if (!(total > 0) || !std::isfinite(total)) return;  // stays empty: cosine sampling only
    t.empty = false;
    t.row_cdf.assign(std::size_t(nh) + 1, 0.0);
    t.cell_cdf.assign(std::size_t(nh) * (np + 1), 0.0);
    double run = 0.0;
    for (int a = 0; a < nh; ++a) {
      double* cdf = &t.cell_cdf[std::size_t(a) * (np + 1)];
      double* p = &t.cell_p[std::size_t(a) * np];
      double row = 0.0;
      for (int b = 0; b < np; ++b) {
        p[b] /= total;
        row += p[b];
        cdf[b + 1] = row;
      }
      for (int b = 1; b <= np; ++b) cdf[b] = row > 0 ? cdf[b] / row : double(b) / np;
      cdf[np] = 1.0;
      run += row;
      t.row_cdf[a + 1] = run;
    }
    for (double& v : t.row_cdf) v /= run;
    t.row_cdf[nh] = 1.0;
  });
  return t;
}

double BrdfSampler::table_pdf(const Table& t, const Vec3& wo, const Vec3& wi) const {
  Vec3 h{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
  const double len = std::sqrt(dot(h, h));
  if (!(len > 0)) return 0.0;
  h = {h.x / len, h.y / len, h.z / len};
  const double d = dot(wo, h);
  if (!(d > 0) || !(h.z > 0)) return 0.0;
  const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells;
  const double theta_h = std::acos(std::min(h.z, 1.0));
  const int a = std::clamp(int(std::sqrt(theta_h / (kPi / 2)) * nh), 0, nh - 1);
  const AzimuthFrame f = azimuth_frame(wo);
  double phi = std::atan2(-f.xy * h.x + f.xx * h.y, f.xx * h.x + f.xy * h.y);
  if (phi < 0) phi += 2 * kPi;
  const double dphi = 2 * kPi / np;
  const int b = std::clamp(int(phi / dphi), 0, np - 1);
  const double p = t.cell_p[std::size_t(a) * np + b];
  if (p == 0.0) return 0.0;
  return p / ((cos_edges_[a] - cos_edges_[a + 1]) * dphi) / (4 * d);
}

double BrdfSampler::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!(wo.z > 0) || !(wi.z > 0)) return 0.0;
  return pdf_in(table_for(wo.z), wo, wi);
}

double BrdfSampler::pdf_in(const Table& t, const Vec3& wo, const Vec3& wi) const {
  const double c = t.empty ? 1.0 : settings_.cosine_fraction;
  double p = c * wi.z / kPi;
  if (c < 1.0) p += (1 - c) * table_pdf(t, wo, wi);
  return p;
}

BrdfSample BrdfSampler::sample(const Vec3& wo, double u1, double u2) const {
  if (!(wo.z > 0)) return BrdfSample{};
  return sample_in(table_for(wo.z), wo, u1, u2);
}

BrdfSample BrdfSampler::sample_in(const Table& t, const Vec3& wo, double u1, double u2) const {
  BrdfSample s;
  // A NaN draw passes std::clamp unchanged and every comparison: refuse it (valid = false)
  // rather than search a table with it.
  if (std::isnan(u1) || std::isnan(u2)) return s;
  const double c = t.empty ? 1.0 : settings_.cosine_fraction;
  const double below_one = std::nextafter(1.0, 0.0);
  u1 = std::clamp(u1, 0.0, below_one);
  u2 = std::clamp(u2, 0.0, below_one);
  if (u1 < c || t.empty) {
    s.wi = sample_cosine_hemisphere(std::min(u1 / c, below_one), u2);
  } else {
    double v1 = std::min((u1 - c) / (1 - c), below_one), v2 = u2;
    const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells;
    const int a = pick(t.row_cdf.data(), nh, &v1);
    const int b = pick(&t.cell_cdf[std::size_t(a) * (np + 1)], np, &v2);
    const double ct = cos_edges_[a] + v1 * (cos_edges_[a + 1] - cos_edges_[a]);
    const double st = std::sqrt(std::max(0.0, 1 - ct * ct));
    const double phi = (b + v2) * (2 * kPi / np);
    const double hx = st * std::cos(phi), hy = st * std::sin(phi);
    const AzimuthFrame f = azimuth_frame(wo);
    const Vec3 h{f.xx * hx - f.xy * hy, f.xy * hx + f.xx * hy, ct};
    const double d = dot(wo, h);
    s.wi = {2 * d * h.x - wo.x, 2 * d * h.y - wo.y, 2 * d * h.z - wo.z};
  }
  if (!(s.wi.z > 0)) return s;
  s.pdf = pdf_in(t, wo, s.wi);  // pdf(wo, s.wi): wo.z > 0 and wi.z > 0 here
  s.valid = s.pdf > 0;
  if (!s.valid) s.pdf = 0;
  return s;
}

// The arrays of a batch, each read or written at index k * its stride (1: structure of arrays,
// 3 or 2: interleaved).
struct BrdfSampler::BatchIo {
  const double* wo[3] = {};
  std::size_t wo_stride = 1;
  const double* u[2] = {};
  std::size_t u_stride = 1;
  double* wi[3] = {};
  std::size_t wi_stride = 1;
  double* pdf = nullptr;
  double* weight[3] = {};
  std::size_t weight_stride = 1;
};

const BrdfSampler::Table* BrdfSampler::prefetch_rows(double wo_z, double u1) const {
  if (!(wo_z > 0)) return nullptr;
  const Table& t = table_for(wo_z);
  const double c = t.empty ? 1.0 : settings_.cosine_fraction;
  const double below_one = std::nextafter(1.0, 0.0);
  u1 = std::clamp(u1, 0.0, below_one);
  if (!(u1 >= c) || t.empty) return &t;  // no table rows to search (NaN: sample_in refuses it)
  double v1 = std::min((u1 - c) / (1 - c), below_one);
  const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells;
  const int a = pick(t.row_cdf.data(), nh, &v1);
  const double* cdf = &t.cell_cdf[std::size_t(a) * (np + 1)];
  const double* p = &t.cell_p[std::size_t(a) * np];
  constexpr int kLine = 64 / sizeof(double);
  for (int i = 0; i <= np; i += kLine) __builtin_prefetch(cdf + i);
  __builtin_prefetch(cdf + np);
  for (int i = 0; i < np; i += kLine) __builtin_prefetch(p + i);
  __builtin_prefetch(p + np - 1);
  return &t;
}

void BrdfSampler::sample_chunk(const BatchIo& io, std::size_t begin, std::size_t end) const {
  // Blocks: the table rows the draws will search brought into the cache together (their misses
  // overlap, where one draw after another waits for each in turn), the draws (scalar: binary
  // searches in the tables), then the block's BRDF values through the evaluator's batch path (or
  // f per draw), then the weights.
  constexpr std::size_t kBlock = 256;
  double v[6][kBlock], f[3][kBlock], p[kBlock];
  const Table* tables[kBlock];
  for (std::size_t base = begin; base < end; base += kBlock) {
    const std::size_t m = std::min(kBlock, end - base);
    for (std::size_t l = 0; l < m; ++l) {
      const std::size_t k = base + l;
      tables[l] = prefetch_rows(io.wo[2][k * io.wo_stride], io.u[0][k * io.u_stride]);
    }
    for (std::size_t l = 0; l < m; ++l) {
      const std::size_t k = base + l;
      const Vec3 o{io.wo[0][k * io.wo_stride], io.wo[1][k * io.wo_stride],
                   io.wo[2][k * io.wo_stride]};
      // sample(): its table is tables[l] (null where wo is at or below the horizon).
      const BrdfSample s = tables[l] == nullptr ? BrdfSample{}
                                                : sample_in(*tables[l], o, io.u[0][k * io.u_stride],
                                                            io.u[1][k * io.u_stride]);
      const bool ok = s.valid && s.pdf > 0;
      v[0][l] = ok ? s.wi.x : 0.0;
      v[1][l] = ok ? s.wi.y : 0.0;
      v[2][l] = ok ? s.wi.z : 0.0;
      v[3][l] = o.x;
      v[4][l] = o.y;
      v[5][l] = o.z;
      p[l] = ok ? s.pdf : 0.0;
    }
    if (evaluator_ != nullptr) {
      evaluator_->eval_batch(m, v[0], v[1], v[2], v[3], v[4], v[5], f[0], f[1], f[2], 1);
    } else {
      for (std::size_t l = 0; l < m; ++l) {
        double rgb[3] = {0, 0, 0};
        if (p[l] > 0) f_(Vec3{v[0][l], v[1][l], v[2][l]}, Vec3{v[3][l], v[4][l], v[5][l]}, rgb);
        for (int c = 0; c < 3; ++c) f[c][l] = rgb[c];
      }
    }
    for (std::size_t l = 0; l < m; ++l) {
      const std::size_t k = base + l;
      for (int c = 0; c < 3; ++c) io.wi[c][k * io.wi_stride] = v[c][l];
      io.pdf[k] = p[l];
      for (int c = 0; c < 3; ++c) {
        io.weight[c][k * io.weight_stride] = p[l] > 0 ? f[c][l] * v[2][l] / p[l] : 0.0;
      }
    }
  }
}

// Chunks of draws handed to the pool (smaller than the evaluator's: a draw costs more).
constexpr std::size_t kSampleChunk = 1024;

void BrdfSampler::sample_batch(std::size_t n, const double* wo_x, const double* wo_y,
                               const double* wo_z, const double* u1, const double* u2, double* wi_x,
                               double* wi_y, double* wi_z, double* pdf, double* weight_r,
                               double* weight_g, double* weight_b, int threads) const {
  BatchIo io;
  io.wo[0] = wo_x;
  io.wo[1] = wo_y;
  io.wo[2] = wo_z;
  io.u[0] = u1;
  io.u[1] = u2;
  io.wi[0] = wi_x;
  io.wi[1] = wi_y;
  io.wi[2] = wi_z;
  io.pdf = pdf;
  io.weight[0] = weight_r;
  io.weight[1] = weight_g;
  io.weight[2] = weight_b;
  internal::parallel_chunks(n, kSampleChunk, threads,
                            [&](std::size_t b, std::size_t e) { sample_chunk(io, b, e); });
}

void BrdfSampler::sample_batch(std::size_t n, const double* wo, const double* u, double* wi,
                               double* pdf, double* weight, int threads) const {
  if (n == 0) return;
  BatchIo io;
  for (int c = 0; c < 3; ++c) {
    io.wo[c] = wo + c;
    io.wi[c] = wi + c;
    io.weight[c] = weight + c;
  }
  io.u[0] = u;
  io.u[1] = u + 1;
  io.wo_stride = io.wi_stride = io.weight_stride = 3;
  io.u_stride = 2;
  io.pdf = pdf;
  internal::parallel_chunks(n, kSampleChunk, threads,
                            [&](std::size_t b, std::size_t e) { sample_chunk(io, b, e); });
}

Vec3 sample_cosine_hemisphere(double u1, double u2) {
  const double r = std::sqrt(u1), phi = 2 * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u1))};
}

BrdfFn model_brdf_fn(const ModelEvaluator& evaluator) {
  const ModelEvaluator* e = &evaluator;
  return [e](const Vec3& wi, const Vec3& wo, double rgb[3]) { e->eval(wi, wo, rgb); };
}

BrdfFn model_brdf_fn(std::shared_ptr<const ModelEvaluator> evaluator) {
  return [e = std::move(evaluator)](const Vec3& wi, const Vec3& wo, double rgb[3]) {
    e->eval(wi, wo, rgb);
  };
}

BrdfSampler make_model_sampler(const ModelEvaluator& evaluator, const SamplerSettings& settings) {
  BrdfSampler s(model_brdf_fn(evaluator), settings);
  s.evaluator_ = &evaluator;
  return s;
}

BrdfSampler make_model_sampler(std::shared_ptr<const ModelEvaluator> evaluator,
                               const SamplerSettings& settings) {
  const ModelEvaluator* e = evaluator.get();  // kept alive by the function's copy
  BrdfSampler s(model_brdf_fn(std::move(evaluator)), settings);
  s.evaluator_ = e;
  return s;
}

}  // namespace cbrdf
