// SPDX-License-Identifier: MIT
// BrdfSampler: per-theta_o tables over half-vector cells (the design is in sampling.h).
// This file's functions set no errno (their square roots see non-negative values, or values whose
// results are discarded; CMakeLists.txt adds -fno-math-errno, which the pragma does not give sqrt),
// may evaluate both sides of a select and contract no multiply-adds: no value changes, and the
// batch's lane loops vectorize with each lane rounding as sample() does. Everything below is plain
// C++ with a scalar meaning; the pragmas and attributes only let GCC and clang vectorize it and
// must never change a result: each compiler is told not to contract a * b + c into a fused
// multiply-add, which rounds once where sample() rounds twice.
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("no-math-errno", "no-trapping-math", "fp-contract=off")
#elif defined(_MSC_VER)
#pragma fp_contract(off)
#else
#pragma STDC FP_CONTRACT OFF
#endif
#include "cbrdf/sampling.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <utility>

#include "parallel_for.h"
#include "sampling_math.h"
#include "sampling_share.h"

namespace cbrdf {
namespace {

using internal::kPi;
constexpr double kBelowOne = 0x1.fffffffffffffp-1;  // std::nextafter(1.0, 0.0)

// wo's azimuthal frame: x along wo's projection on the surface, y = z cross x. At normal
// incidence any frame will do; this one is fixed so that sample() and pdf() agree.
struct Frame {
  double xx = 1, xy = 0;  // x axis (xx, xy, 0); y axis (-xy, xx, 0)
};

inline Frame azimuth_frame(double x, double y) {
  const double r = std::sqrt(x * x + y * y);  // |x|, |y| <= 1: no overflow
  const bool normal = r < 1e-12;
  return {normal ? 1.0 : x / r, normal ? 0.0 : y / r};
}

// The table of cos(theta_o) (any value: NaN and values outside [0, 1] are clamped).
inline int theta_o_bin(double cos_theta_o, int bins) {
  const double theta_o = internal::acos01(cos_theta_o);
  return std::min(int(theta_o * (2 / kPi) * bins), bins - 1);
}

// The bin i of a non-decreasing CDF of n + 1 entries (cdf[0] = 0 <= u < 1 = cdf[n]) with
// cdf[i] <= u < cdf[i + 1], so never an empty bin, and u remapped to [0, 1) within it. It is
// std::upper_bound's bin, found in steps whose number depends on n only, with selects: u is
// random, so branches on it mispredict half the time. The steps keep cdf[base] <= u with the bin
// in [base, base + len).
inline const double* pick_step(const double* base, std::size_t half, double u) {
  return base[half] <= u ? base + half : base;
}

inline int pick_end(const double* cdf, const double* base, int n, double* u) {
  const int i = std::min(int(base - cdf), n - 1);
  const double w = cdf[i + 1] - cdf[i];
  *u = w > 0 ? std::clamp((*u - cdf[i]) / w, 0.0, kBelowOne) : 0.5;
  return i;
}

inline int pick(const double* cdf, int n, double* u) {
  const double* base = cdf;
  for (std::size_t len = std::size_t(n) + 1; len > 1; len -= len >> 1) {
    base = pick_step(base, len >> 1, *u);
  }
  return pick_end(cdf, base, n, u);
}

// The lane loops (and the searches' steps across lanes), compiled for AVX-512, AVX2 and the
// baseline and chosen at load time where the toolchain supports it (GCC on x86-64; not under the
// sanitizers, whose runtimes and ifunc resolvers do not mix). A draw takes about a dozen square
// roots and divisions, which AVX-512 does at twice AVX2's rate per lane where the CPU has
// full-width units. Every lane computes what sample() computes for its draw, with the same
// functions: vector lanes round as scalar instructions do (no multiply-add is contracted: the
// pragma above).
// Elsewhere (clang, MSVC, emscripten, other targets) the same loops are compiled once for the
// baseline instruction set, which the compiler may still vectorize.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define CBRDF_SAMPLING_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define CBRDF_SAMPLING_CLONES
#endif

// A hint to start loading the line of p (no effect on results).
#if defined(__GNUC__) || defined(__clang__)
#define CBRDF_SAMPLING_PREFETCH(p) __builtin_prefetch(p)
#else
#define CBRDF_SAMPLING_PREFETCH(p) ((void)(p))
#endif

constexpr int kLanes = 128;  // draws in a block of sample_batch, at most
// The lane loops run over the block's draws rounded up to a multiple of this (the widest vector,
// AVX-512's 8 doubles), so that a small batch costs what it holds and no loop has a scalar tail.
constexpr int kLaneGroup = 8;

// pick() for m <= kLanes CDFs of n + 1 entries at once (bin[k] of cdf[k] at u[k]), one step for
// all lanes at a time: the lanes' loads (cache misses, in large tables) are in flight together,
// and with AVX-512 a step is a vector loop of gathers.
CBRDF_SAMPLING_CLONES void pick_lanes(const double* const* cdf, int n, double* u, int* bin, int m) {
  const double* base[kLanes];
  for (int k = 0; k < m; ++k) base[k] = cdf[k];
  for (std::size_t len = std::size_t(n) + 1; len > 1; len -= len >> 1) {
    const std::size_t half = len >> 1;
    for (int k = 0; k < m; ++k) base[k] = pick_step(base[k], half, u[k]);
  }
  for (int k = 0; k < m; ++k) bin[k] = pick_end(cdf[k], base[k], n, &u[k]);
}

// Where lanes without a table row or cell search (cosine-weighted or refused draws) search.
constexpr double kNoCdf[4097] = {};

// A draw's first choice, u1 and u2 clamped into [0, 1): cosine-weighted with probability c (v1 =
// u1 / c, v2 = u2: the point of sample_cosine_hemisphere) or from the table (v1 is then the row
// search's u); c = 1 for an empty table. Selects only: a lane loop of it vectorizes.
struct Choice {
  double v1, v2;
  bool table;
};

inline Choice choose(double c, double u1, double u2) {
  u1 = std::clamp(u1, 0.0, kBelowOne);
  const bool cosine = u1 < c;
  const double v1 = cosine ? u1 / c : (u1 - c) / (1 - c);
  return {std::min(v1, kBelowOne), std::clamp(u2, 0.0, kBelowOne), !cosine};
}

struct Dir {
  double x, y, z;
};

// A draw's direction wi from its choices (BrdfSampler::Draw): for a table draw (b >= 0) h at
// cos(theta_h) = ce0 + v1 (ce1 - ce0) and phi_h = (b + v2) dphi in wo's frame, reflected about;
// for a cosine-weighted one (b < 0) sample_cosine_hemisphere(v1, v2). Both are computed.
inline Dir draw_direction(double ox, double oy, double oz, Frame f, double b, double v1, double v2,
                          double ce0, double ce1, double dphi) {
  const bool cosine = b < 0;
  const double ct = ce0 + v1 * (ce1 - ce0);
  const double st = std::sqrt(std::max(0.0, 1 - ct * ct));
  const double r = std::sqrt(v1), z = std::sqrt(std::max(0.0, 1 - v1));
  const internal::SinCos sc = internal::sincos_0_2pi(cosine ? 2 * kPi * v2 : (b + v2) * dphi);
  const double hx = st * sc.c, hy = st * sc.s;
  const double h_x = f.xx * hx - f.xy * hy, h_y = f.xy * hx + f.xx * hy;
  const double d = ox * h_x + oy * h_y + oz * ct;
  return {cosine ? r * sc.c : 2 * d * h_x - ox, cosine ? r * sc.s : 2 * d * h_y - oy,
          cosine ? z : 2 * d * ct - oz};
}

// The table cell (a, b) of wi's half vector h = normalize(wi + wo) and wo.h; ok is false where
// the table's density is 0 there (h or its reflection at or below the horizon).
struct Located {
  double d;
  int a, b;
  bool ok;
};

inline Located locate(double ox, double oy, double oz, Frame f, double wx, double wy, double wz,
                      int nh, int np, double dphi) {
  double hx = wx + ox, hy = wy + oy, hz = wz + oz;
  const double len = std::sqrt(hx * hx + hy * hy + hz * hz), inv_len = 1 / len;
  hx *= inv_len;
  hy *= inv_len;
  hz *= inv_len;
  const double d = ox * hx + oy * hy + oz * hz;
  const double theta_h = internal::acos01(hz);  // NaN (len 0) clamped: a valid, unused cell
  const int a = std::min(int(std::sqrt(theta_h * (2 / kPi)) * nh), nh - 1);
  const double phi = internal::atan2_0_2pi(-f.xy * hx + f.xx * hy, f.xx * hx + f.xy * hy);
  const int b = std::min(int(phi / dphi), np - 1);
  const bool ok = (len > 0) & (d > 0) & (hz > 0);  // & vectorizes where && does not
  return {d, a, b, ok};
}

// The table's probability of wi's cell as the draws see it, from the CDFs they search (0 where
// the table's density is 0; row_cdf is null for an empty table).
inline double cell_probability(const double* row_cdf, const double* cell_cdf, int np,
                               const Located& at) {
  if (!at.ok || row_cdf == nullptr) return 0.0;
  const std::size_t a = std::size_t(at.a), b = std::size_t(at.b);
  const double* cdf = cell_cdf + a * std::size_t(np + 1);
  return (row_cdf[a + 1] - row_cdf[a]) * (cdf[b + 1] - cdf[b]);
}

// The half vector at point (i, j) of the ss x ss points of cell (a, b) a table is built from,
// uniform in cos(theta_h) (c0 > c1, the row's edges) and phi_h, in wo's azimuth frame.
inline Vec3 cell_point(double c0, double c1, int b, int i, int j, int ss, double dphi) {
  const double ct = c0 + (i + 0.5) / ss * (c1 - c0);
  const double st = std::sqrt(std::max(0.0, 1 - ct * ct));
  const double phi = (b + (j + 0.5) / ss) * dphi;
  return {st * std::cos(phi), st * std::sin(phi), ct};
}

// pdf(wo, wi) from its cell's probability p and cos(theta_h) edges ce0 > ce1: the table's density
// of h (p over the cell's solid angle) over 4 wo.h, mixed with the cosine-weighted density.
inline double mix_pdf(double p, double ce0, double ce1, double d, double c, double wz,
                      double dphi) {
  const double table = p != 0.0 ? p / ((ce0 - ce1) * dphi) / (4 * d) : 0.0;
  return c * wz / kPi + (c < 1.0 ? (1 - c) * table : 0.0);
}

}  // namespace

// The lanes of a block of batch draws (structure of arrays): inputs, the draws' tables and
// choices (BrdfSampler::Draw's fields), their directions, pdf cells and pdfs. One object, so that
// its arrays provably do not alias. Flags are doubles (1 or 0): masks as wide as the values
// vectorize.
struct internal::SamplerLanes {
  alignas(64) double ox[kLanes], oy[kLanes], oz[kLanes], u1[kLanes], u2[kLanes], live[kLanes];
  alignas(64) double fxx[kLanes], fxy[kLanes];
  alignas(64) double c[kLanes], b[kLanes], v1[kLanes], v2[kLanes], ce0[kLanes], ce1[kLanes];
  alignas(64) double table_draw[kLanes];
  alignas(64) double wx[kLanes], wy[kLanes], wz[kLanes], d[kLanes], ok[kLanes];
  alignas(64) double p[kLanes], pce0[kLanes], pce1[kLanes], pdf[kLanes];
  alignas(64) double wi[3][kLanes];
  alignas(64) int bin[kLanes], cell_a[kLanes], cell_b[kLanes];
};

namespace {
using Lanes = internal::SamplerLanes;

// Each lane loop runs over the first m lanes (a multiple of kLaneGroup).
CBRDF_SAMPLING_CLONES void lanes_frames(Lanes& l, int bins, int m) {
  for (int k = 0; k < m; ++k) {
    const Frame f = azimuth_frame(l.ox[k], l.oy[k]);
    l.fxx[k] = f.xx;
    l.fxy[k] = f.xy;
    l.bin[k] = theta_o_bin(l.oz[k], bins);
  }
}

// choose() per lane (c set per lane); a refused lane (live 0) is no table draw.
CBRDF_SAMPLING_CLONES void lanes_choices(Lanes& l, int m) {
  for (int k = 0; k < m; ++k) {
    const Choice ch = choose(l.c[k], l.u1[k], l.u2[k]);
    l.v1[k] = ch.v1;
    l.v2[k] = ch.v2;
    l.b[k] = -1.0;
    l.ce0[k] = l.ce1[k] = 0.0;
    l.table_draw[k] = ((l.live[k] != 0.0) & ch.table) ? 1.0 : 0.0;
  }
}

CBRDF_SAMPLING_CLONES void lanes_directions(Lanes& l, int nh, int np, double dphi, int m) {
  for (int k = 0; k < m; ++k) {
    const Frame f{l.fxx[k], l.fxy[k]};
    const Dir w = draw_direction(l.ox[k], l.oy[k], l.oz[k], f, l.b[k], l.v1[k], l.v2[k], l.ce0[k],
                                 l.ce1[k], dphi);
    l.wx[k] = w.x;
    l.wy[k] = w.y;
    l.wz[k] = w.z;
    const Located at = locate(l.ox[k], l.oy[k], l.oz[k], f, w.x, w.y, w.z, nh, np, dphi);
    l.d[k] = at.d;
    l.cell_a[k] = at.a;
    l.cell_b[k] = at.b;
    l.ok[k] = at.ok ? 1.0 : 0.0;
  }
}

// sample()'s pdf and validity from the cells' probabilities (p, pce0, pce1); wi is 0 where
// rejected.
CBRDF_SAMPLING_CLONES void lanes_pdfs(Lanes& l, double dphi, int m) {
  for (int k = 0; k < m; ++k) {
    const double pdf = mix_pdf(l.p[k], l.pce0[k], l.pce1[k], l.d[k], l.c[k], l.wz[k], dphi);
    const bool valid = (l.live[k] != 0.0) & (l.wz[k] > 0) & (pdf > 0);
    l.pdf[k] = valid ? pdf : 0.0;
    l.wi[0][k] = valid ? l.wx[k] : 0.0;
    l.wi[1][k] = valid ? l.wy[k] : 0.0;
    l.wi[2][k] = valid ? l.wz[k] : 0.0;
  }
}

// A chunk's draws for the evaluator (whole chunks at once: its batch has a cost per call) and
// their weights: 13 arrays of the chunk's n draws in one buffer, on the stack for small chunks
// (a heap block of a whole chunk's size cost more than a few draws).
constexpr std::size_t kSampleChunk = 1024;  // draws per task of the pool
constexpr std::size_t kStackDraws = 64;
// Below this many draws a chunk's BRDF values are evaluated one by one (ModelEvaluator's batch
// works in blocks of 32 pairs).
constexpr std::size_t kEvalBatchMin = 32;
// Below this many draws a chunk is drawn one draw at a time (sample() with weights).
constexpr std::size_t kScalarDraws = 4;
struct ChunkDraws {
  double *wi[3], *wo[3], *pdf, *f[3], *weight[3];
  ChunkDraws(double* buffer, std::size_t n) {
    double* p = buffer;
    for (double** a : {&wi[0], &wi[1], &wi[2], &wo[0], &wo[1], &wo[2], &pdf, &f[0], &f[1], &f[2],
                       &weight[0], &weight[1], &weight[2]}) {
      *a = p;
      p += n;
    }
  }
};

// The weight f cos(theta_i) / pdf, as sample() with weights computes it per draw.
inline double draw_weight(double f, double wi_z, double pdf) {
  return pdf > 0 ? f * wi_z / pdf : 0.0;
}

CBRDF_SAMPLING_CLONES void chunk_weights(const ChunkDraws& c, std::size_t n) {
  for (int ch = 0; ch < 3; ++ch) {
    for (std::size_t k = 0; k < n; ++k)
      c.weight[ch][k] = draw_weight(c.f[ch][k], c.wi[2][k], c.pdf[k]);
  }
}

}  // namespace

struct BrdfSampler::Table {
  std::once_flag once;
  std::atomic<bool> ready{false};
  bool empty = true;             // the BRDF reflects nothing at this theta_o
  double c = 1.0;                // the cosine-weighted share of draws (1: the table is unused)
  std::vector<double> row_cdf;   // theta_h_cells + 1
  std::vector<double> cell_cdf;  // per theta_h row, phi_h_cells + 1 (conditional)
};

// A draw's choices before its direction: the cosine-weighted share c; for a table draw its
// cell's column b, its row's cos(theta_h) edges ce0 > ce1 and the fractions v1, v2 of the cell
// along cos(theta_h) and phi_h; for a cosine-weighted draw b = -1 and (v1, v2) the point of
// sample_cosine_hemisphere.
struct BrdfSampler::Draw {
  double c = 1, b = -1, v1 = 0, v2 = 0, ce0 = 0, ce1 = 0;
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
  if (std::isnan(settings_.min_table_gain))
    settings_.min_table_gain = SamplerSettings{}.min_table_gain;
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

const BrdfSampler::Table& BrdfSampler::table_at(int k) const {
  Table& t = tables_[std::size_t(k)];
  // The flag first: call_once sets up thread-local state on every call, even when done.
  if (!t.ready.load(std::memory_order_acquire)) {
    std::call_once(t.once, [&] {
      build_table(k, t);
      t.ready.store(true, std::memory_order_release);
    });
  }
  return t;
}

void BrdfSampler::build_table(int k, Table& t) const {
  const int bins = settings_.theta_o_bins;
  const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells, ss = settings_.supersample;
  const double dphi = 2 * kPi / np;
  const double to = (k + 0.5) / bins * (kPi / 2);
  const Vec3 wo{std::sin(to), 0.0, std::cos(to)};
  std::vector<double> cell_p(std::size_t(nh) * np, 0.0);
  std::vector<internal::QuadraturePoint> points;
  points.reserve(std::size_t(nh) * np * ss * ss);
  double total = 0.0;
  for (int a = 0; a < nh; ++a) {
    const double c0 = cos_edges_[a], c1 = cos_edges_[a + 1];
    for (int b = 0; b < np; ++b) {
      double sum = 0.0;
      for (int i = 0; i < ss; ++i) {
        for (int j = 0; j < ss; ++j) {
          const Vec3 h = cell_point(c0, c1, b, i, j, ss, dphi);
          const double d = dot(wo, h);
          if (!(d > 0)) continue;
          const Vec3 wi{2 * d * h.x - wo.x, 2 * d * h.y - wo.y, 2 * d * h.z - wo.z};
          if (!(wi.z > 0)) continue;
          double rgb[3] = {0, 0, 0};
          f_(wi, wo, rgb);
          const double m = (rgb[0] + rgb[1] + rgb[2]) / 3;
          const double g = std::isfinite(m) && m > 0 ? m * wi.z : 0.0;
          sum += g * 4 * d;
          points.push_back({g, wi.z, d, (c0 - c1) * dphi / (ss * ss), a * np + b});
        }
      }
      const double mass = sum / (ss * ss) * (c0 - c1) * dphi;
      cell_p[std::size_t(a) * np + b] = mass;
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
    double* p = &cell_p[std::size_t(a) * np];
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
  // Each point's table density per unit solid angle of wi, as pdf() reads it (no cosine share).
  std::vector<double> table_pdf(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const internal::QuadraturePoint& q = points[i];
    const Located at{q.d, q.cell / np, q.cell % np, true};
    const double p = cell_probability(t.row_cdf.data(), t.cell_cdf.data(), np, at);
    table_pdf[i] = mix_pdf(p, cos_edges_[std::size_t(at.a)], cos_edges_[std::size_t(at.a) + 1], q.d,
                           0.0, q.wi_z, dphi);
  }
  const double edges[2] = {rejected_share(t, double(k) / bins * (kPi / 2)),
                           rejected_share(t, double(k + 1) / bins * (kPi / 2))};
  t.c = internal::best_cosine_share(points, table_pdf, edges, settings_.cosine_fraction,
                                    settings_.min_table_gain);
}

double BrdfSampler::rejected_share(const Table& t, double theta_o) const {
  const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells, ss = settings_.supersample;
  const double dphi = 2 * kPi / np;
  const Vec3 wo{std::sin(theta_o), 0.0, std::cos(theta_o)};
  double rejected = 0.0;
  for (int a = 0; a < nh; ++a) {
    const double c0 = cos_edges_[a], c1 = cos_edges_[a + 1];
    for (int b = 0; b < np; ++b) {
      const double p =
          cell_probability(t.row_cdf.data(), t.cell_cdf.data(), np, Located{1.0, a, b, true});
      if (!(p > 0)) continue;
      int out = 0;
      for (int i = 0; i < ss; ++i) {
        for (int j = 0; j < ss; ++j) {
          const Vec3 h = cell_point(c0, c1, b, i, j, ss, dphi);
          const double d = dot(wo, h);
          out += !(d > 0) || !(2 * d * h.z - wo.z > 0);
        }
      }
      rejected += p * out / (ss * ss);
    }
  }
  return rejected;
}

inline bool BrdfSampler::draw_choice(const Table& t, double u1, double u2, Draw* d) const {
  d->c = t.c;
  const Choice ch = choose(d->c, u1, u2);
  d->v1 = ch.v1;
  d->v2 = ch.v2;
  return ch.table;
}

void BrdfSampler::draw_cell(const Table& t, int row, Draw* d) const {
  const int np = settings_.phi_h_cells;
  d->b = pick(&t.cell_cdf[std::size_t(row) * (np + 1)], np, &d->v2);
  d->ce0 = cos_edges_[std::size_t(row)];
  d->ce1 = cos_edges_[std::size_t(row) + 1];
}

double BrdfSampler::sample_pdf(const Vec3& wi_in, const Vec3& wo_in) const {
  if (internal::zero_direction(wi_in) || internal::zero_direction(wo_in)) return 0.0;
  Vec3 wo = wo_in, wi = wi_in;
  if (!unit_direction(wo) || !unit_direction(wi)) return std::numeric_limits<double>::quiet_NaN();
  if (!(wo.z > 0) || !(wi.z > 0)) return 0.0;
  const Table& t = table_at(theta_o_bin(wo.z, settings_.theta_o_bins));
  const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells;
  const double c = t.c;
  const Located at =
      locate(wo.x, wo.y, wo.z, azimuth_frame(wo.x, wo.y), wi.x, wi.y, wi.z, nh, np, 2 * kPi / np);
  const double p =
      cell_probability(t.empty ? nullptr : t.row_cdf.data(), t.cell_cdf.data(), np, at);
  return mix_pdf(p, cos_edges_[std::size_t(at.a)], cos_edges_[std::size_t(at.a) + 1], at.d, c, wi.z,
                 2 * kPi / np);
}

BrdfSample BrdfSampler::sample(const Vec3& wo_in, double u1, double u2) const {
  Vec3 wo = wo_in;
  if (!unit_direction(wo) || !(wo.z > 0)) return BrdfSample{};
  const Table& t = table_at(theta_o_bin(wo.z, settings_.theta_o_bins));
  // A NaN draw passes std::clamp unchanged and every comparison: refuse it (valid = false)
  // rather than search a table with it.
  if (std::isnan(u1) || std::isnan(u2)) return BrdfSample{};
  Draw d;
  if (draw_choice(t, u1, u2, &d)) {
    const int row = pick(t.row_cdf.data(), settings_.theta_h_cells, &d.v1);
    draw_cell(t, row, &d);
  }
  // The steps of sample_chunk's lanes, one draw at a time.
  const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells;
  const double dphi = 2 * kPi / np;
  const Frame f = azimuth_frame(wo.x, wo.y);
  const Dir w = draw_direction(wo.x, wo.y, wo.z, f, d.b, d.v1, d.v2, d.ce0, d.ce1, dphi);
  BrdfSample s;
  s.wi = {w.x, w.y, w.z};
  if (!(w.z > 0)) return s;
  const Located at = locate(wo.x, wo.y, wo.z, f, w.x, w.y, w.z, nh, np, dphi);
  const double p =
      cell_probability(t.empty ? nullptr : t.row_cdf.data(), t.cell_cdf.data(), np, at);
  s.pdf = mix_pdf(p, cos_edges_[std::size_t(at.a)], cos_edges_[std::size_t(at.a) + 1], at.d, d.c,
                  w.z, dphi);
  s.valid = s.pdf > 0;
  if (!s.valid) s.pdf = 0;
  return s;
}

BrdfSample BrdfSampler::sample(const Vec3& wo_in, double u1, double u2, double weight[3]) const {
  weight[0] = weight[1] = weight[2] = 0.0;
  BrdfSample s = sample(wo_in, u1, u2);
  if (!s.valid) {
    s.wi = Vec3{0, 0, 0};  // as sample_batch reports a rejected draw
    return s;
  }
  Vec3 wo = wo_in;
  unit_direction(wo);  // valid: sample() accepted it
  double f[3] = {0, 0, 0};
  f_(s.wi, wo, f);
  for (int ch = 0; ch < 3; ++ch) weight[ch] = draw_weight(f[ch], s.wi.z, s.pdf);
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

int BrdfSampler::draw_lanes(const BatchIo& io, std::size_t base, int m, Lanes& l) const {
  // Inputs; lanes from m up to the group's end hold a harmless draw (wo at the normal) whose
  // results are dropped, so that the lane loops run over whole groups. A wo that is not a unit
  // vector (within kDirectionTolerance) is rescaled as sample() does, or refused (oz = 0).
  const int lanes = (m + kLaneGroup - 1) / kLaneGroup * kLaneGroup;
  for (int k = 0; k < lanes; ++k) {
    const std::size_t i = base + std::size_t(k);
    const bool in = k < m;
    double x = in ? io.wo[0][i * io.wo_stride] : 0.0;
    double y = in ? io.wo[1][i * io.wo_stride] : 0.0;
    double z = in ? io.wo[2][i * io.wo_stride] : 1.0;
    if (!unit_direction(x, y, z)) x = y = z = 0.0;
    l.ox[k] = x;
    l.oy[k] = y;
    l.oz[k] = z;
    l.u1[k] = in ? io.u[0][i * io.u_stride] : 0.5;
    l.u2[k] = in ? io.u[1][i * io.u_stride] : 0.5;
  }
  m = lanes;
  lanes_frames(l, settings_.theta_o_bins, m);
  // sample()'s steps per lane: its table and choice, then its row and its cell, each search
  // across the lanes at once (lanes without one search kNoCdf, their results unused).
  const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells;
  const double* cdf[kLanes];
  double u[kLanes];
  int row[kLanes], cell[kLanes];
  for (int k = 0; k < m; ++k) {
    const bool live = l.oz[k] > 0 && !std::isnan(l.u1[k]) && !std::isnan(l.u2[k]);
    const Table* t = live ? &table_at(l.bin[k]) : nullptr;
    l.live[k] = live ? 1.0 : 0.0;
    l.c[k] = t != nullptr ? t->c : 1.0;  // as draw_choice
    cdf[k] = t != nullptr && !t->empty ? t->row_cdf.data() : kNoCdf;
  }
  lanes_choices(l, m);
  for (int k = 0; k < m; ++k) {
    cdf[k] = l.table_draw[k] != 0.0 ? cdf[k] : kNoCdf;
    u[k] = l.table_draw[k] != 0.0 ? l.v1[k] : 0.5;
  }
  pick_lanes(cdf, nh, u, row, m);
  for (int k = 0; k < m; ++k) {
    const bool table_draw = l.table_draw[k] != 0.0;
    if (table_draw) l.v1[k] = u[k];
    cdf[k] = table_draw ? &tables_[std::size_t(l.bin[k])].cell_cdf[std::size_t(row[k]) * (np + 1)]
                        : kNoCdf;
    u[k] = table_draw ? l.v2[k] : 0.5;
    // The lines of the search's first two probes (at a half, then a quarter or three quarters of
    // the row) requested at once, rather than its misses waited for one after another; fewer
    // requests than the row's every line, which cost more than the later probes' misses save.
    if (table_draw) {
      for (int i = 1; i < 4; ++i) {
        CBRDF_SAMPLING_PREFETCH(cdf[k] + std::size_t(i) * (np + 1) / 4);
      }
    }
  }
  pick_lanes(cdf, np, u, cell, m);
  for (int k = 0; k < m; ++k) {
    if (l.table_draw[k] == 0.0) continue;  // as draw_cell
    l.b[k] = cell[k];
    l.v2[k] = u[k];
    l.ce0[k] = cos_edges_[std::size_t(row[k])];
    l.ce1[k] = cos_edges_[std::size_t(row[k]) + 1];
  }
  return m;
}

void BrdfSampler::sample_chunk(const BatchIo& io, std::size_t begin, std::size_t end) const {
  // Blocks of lanes: the draws' tables, rows and cells (scalar searches), their directions and
  // pdf cells (lane loops), their cells' probabilities (loads) and pdfs (lane loop). Then the
  // chunk's BRDF values through the evaluator's batch path (or f per draw) and the weights.
  if (end - begin > kSampleChunk) {  // the pool's chunks are larger beyond 2^20 of them
    for (std::size_t b = begin; b < end; b += kSampleChunk) {
      sample_chunk(io, b, std::min(end, b + kSampleChunk));
    }
    return;
  }
  const std::size_t n = end - begin;
  if (n < kScalarDraws) {
    // A block of lanes for one to three draws costs more than sample() per draw, whose results
    // are the lanes' bit for bit.
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 wo{io.wo[0][i * io.wo_stride], io.wo[1][i * io.wo_stride],
                    io.wo[2][i * io.wo_stride]};
      double w[3];
      const BrdfSample s = sample(wo, io.u[0][i * io.u_stride], io.u[1][i * io.u_stride], w);
      io.wi[0][i * io.wi_stride] = s.wi.x;
      io.wi[1][i * io.wi_stride] = s.wi.y;
      io.wi[2][i * io.wi_stride] = s.wi.z;
      io.pdf[i] = s.pdf;
      for (int ch = 0; ch < 3; ++ch) io.weight[ch][i * io.weight_stride] = w[ch];
    }
    return;
  }
  Lanes l;
  // Not zeroed: every entry read is written.
  double stack_buffer[13 * kStackDraws];
  std::unique_ptr<double[]> heap_buffer;
  if (n > kStackDraws) heap_buffer.reset(new double[13 * n]);
  const ChunkDraws draws(n > kStackDraws ? heap_buffer.get() : stack_buffer, n);
  const ChunkDraws* c = &draws;
  const int nh = settings_.theta_h_cells, np = settings_.phi_h_cells;
  const double dphi = 2 * kPi / np;
  for (std::size_t base = 0; base < n; base += kLanes) {
    const int m = int(std::min<std::size_t>(kLanes, n - base));
    const int lanes = draw_lanes(io, begin + base, m, l);
    lanes_directions(l, nh, np, dphi, lanes);
    for (int k = 0; k < lanes; ++k) {
      // The cells' CDF entries requested together (a cosine-weighted draw's cell is anywhere).
      if (l.live[k] == 0.0 || l.ok[k] == 0.0) continue;
      const Table& t = tables_[std::size_t(l.bin[k])];
      if (!t.empty) {
        CBRDF_SAMPLING_PREFETCH(&t.cell_cdf[std::size_t(l.cell_a[k]) * (np + 1) + l.cell_b[k]]);
      }
    }
    for (int k = 0; k < lanes; ++k) {
      // Only a live lane's table is known to be built.
      const Located at{l.d[k], l.cell_a[k], l.cell_b[k], l.ok[k] != 0.0};
      const Table* t = l.live[k] != 0.0 ? &tables_[std::size_t(l.bin[k])] : nullptr;
      l.p[k] = t != nullptr && !t->empty
                   ? cell_probability(t->row_cdf.data(), t->cell_cdf.data(), np, at)
                   : 0.0;
      l.pce0[k] = cos_edges_[std::size_t(at.a)];
      l.pce1[k] = cos_edges_[std::size_t(at.a) + 1];
    }
    lanes_pdfs(l, dphi, lanes);
    for (int k = 0; k < m; ++k) {
      // A rejected draw (pdf 0, weight 0 whatever f is) goes to the evaluator as the pair (normal,
      // normal), so that its batch holds only valid directions (an invalid one costs it a
      // checking pass); its wi is output as (0, 0, 0) (lanes_pdfs' l.wi) all the same.
      const bool valid = l.pdf[k] > 0;
      const std::size_t j = base + std::size_t(k);
      c->wi[0][j] = l.wi[0][k];
      c->wi[1][j] = l.wi[1][k];
      c->wi[2][j] = valid ? l.wi[2][k] : 1.0;
      c->wo[0][j] = valid ? l.ox[k] : 0.0;
      c->wo[1][j] = valid ? l.oy[k] : 0.0;
      c->wo[2][j] = valid ? l.oz[k] : 1.0;
      c->pdf[j] = l.pdf[k];
    }
  }
  if (evaluator_ != nullptr && n < kEvalBatchMin) {
    // Few draws: eval per draw (equal to eval_batch bit for bit), as the batch evaluates whole
    // blocks of 32 pairs whatever n is.
    for (std::size_t k = 0; k < n; ++k) {
      double rgb[3] = {0, 0, 0};
      if (c->pdf[k] > 0) {
        evaluator_->eval(Vec3{c->wi[0][k], c->wi[1][k], c->wi[2][k]},
                         Vec3{c->wo[0][k], c->wo[1][k], c->wo[2][k]}, rgb);
      }
      for (int i = 0; i < 3; ++i) c->f[i][k] = rgb[i];
    }
  } else if (evaluator_ != nullptr) {
    evaluator_->eval_batch(n, c->wi[0], c->wi[1], c->wi[2], c->wo[0], c->wo[1], c->wo[2], c->f[0],
                           c->f[1], c->f[2], 1);
  } else {
    for (std::size_t k = 0; k < n; ++k) {
      double rgb[3] = {0, 0, 0};
      if (c->pdf[k] > 0) {
        f_(Vec3{c->wi[0][k], c->wi[1][k], c->wi[2][k]}, Vec3{c->wo[0][k], c->wo[1][k], c->wo[2][k]},
           rgb);
      }
      for (int i = 0; i < 3; ++i) c->f[i][k] = rgb[i];
    }
  }
  chunk_weights(*c, n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = begin + k;
    io.wi[0][i * io.wi_stride] = c->wi[0][k];
    io.wi[1][i * io.wi_stride] = c->wi[1][k];
    io.wi[2][i * io.wi_stride] = c->pdf[k] > 0 ? c->wi[2][k] : 0.0;  // (1 for the evaluator)
    io.pdf[i] = c->pdf[k];
    for (int ch = 0; ch < 3; ++ch) io.weight[ch][i * io.weight_stride] = c->weight[ch][k];
  }
}

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
  // The sampler's own sine and cosine (its cosine-weighted draws are this function's values)
  // inside its range, libm's outside it.
  const double z = std::sqrt(std::max(0.0, 1 - u1));
  if (!(phi >= 0 && phi <= 2 * kPi)) return {r * std::cos(phi), r * std::sin(phi), z};
  const internal::SinCos sc = internal::sincos_0_2pi(phi);
  return {r * sc.c, r * sc.s, z};
}

BrdfFn model_brdf_fn(const ModelEvaluator& evaluator) {
  // A copy (sharing the evaluator's tables): valid whatever happens to `evaluator` later.
  return model_brdf_fn(std::make_shared<const ModelEvaluator>(evaluator));
}

BrdfFn model_brdf_fn(std::shared_ptr<const ModelEvaluator> evaluator) {
  return [e = std::move(evaluator)](const Vec3& wi, const Vec3& wo, double rgb[3]) {
    e->eval(wi, wo, rgb);
  };
}

BrdfSampler make_model_sampler(const ModelEvaluator& evaluator, const SamplerSettings& settings) {
  // A copy (sharing the evaluator's tables), so that moving or destroying `evaluator` afterwards
  // leaves the sampler valid.
  return make_model_sampler(std::make_shared<const ModelEvaluator>(evaluator), settings);
}

BrdfSampler make_model_sampler(std::shared_ptr<const ModelEvaluator> evaluator,
                               const SamplerSettings& settings) {
  const ModelEvaluator* e = evaluator.get();  // kept alive by the function's copy
  BrdfSampler s(model_brdf_fn(std::move(evaluator)), settings);
  s.evaluator_ = e;
  return s;
}

}  // namespace cbrdf
