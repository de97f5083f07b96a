// SPDX-License-Identifier: MIT
#include "cbrdf/model.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "copula/registry.h"
#include "density/frank_grid.h"
#include "density/grid_copula.h"
#include "eval/interp_tables.h"
#include "eval/residual_eval.h"
#include "parallel_for.h"

namespace cbrdf {
namespace {

// Model values are finite. A file may hold any K and parameter of the domain, and their product
// with a density near a singular corner can exceed the double range: it saturates at the largest
// double, so that a table reconstructed from any valid file can be written and read back. A NaN
// here can only be an overflowed factor times an exact zero (a zero mass), which is 0.
inline double saturate(double v) {
  constexpr double kMax = std::numeric_limits<double>::max();
  return v < kMax ? v : (v == v ? kMax : 0.0);
}

// Parameters are evaluated clamped to [-1e300, 1e300]: beyond, 1/|theta| is subnormal and the
// families' terms go through libm's slow subnormal paths (Frank at -DBL_MAX cost 8x the time per
// bin of Frank at -1e300), while the densities on a grid of midpoint CDFs are already those of the
// limit copula (0 off the diagonal). spec/container.md, "Resource bounds", states the rule.
constexpr double kMaxEvaluatedParameter = 1e300;

}  // namespace

int Residual::max_row_shift() const {
  return row_shift.empty() ? 0 : *std::max_element(row_shift.begin(), row_shift.end());
}

int Residual::min_row_shift() const {
  return row_shift.empty() ? 0 : *std::min_element(row_shift.begin(), row_shift.end());
}

std::size_t NotMeasured::count() const {
  std::size_t n = 0;
  for (std::uint64_t w : bits) n += std::size_t(__builtin_popcountll(w));
  return n;
}

NotMeasured NotMeasured::from_table(const BrdfTable& table) {
  NotMeasured nm;
  nm.values.clear();
  bool uniform = true;
  for (int c = 0; c < kChannels; ++c) {
    const double* data = table.channel_data(c);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (data[i] >= 0.0) continue;
      nm.set(c, i);
      // Bit-exact comparison: -1.0 and a NaN-free negative value compare by their bits.
      if (uniform && !nm.values.empty() &&
          std::memcmp(&nm.values.front(), &data[i], sizeof(double)) != 0) {
        uniform = false;
      }
      nm.values.push_back(data[i]);
    }
  }
  if (uniform) {
    const double v = nm.values.empty() ? -1.0 : nm.values.front();
    nm.values.assign(1, v);
  }
  return nm;
}

int Model::slice_of(int theta_d_bin) const {
  for (std::size_t s = 0; s < slices.size(); ++s) {
    if (theta_d_bin < slices[s].theta_d_end) return int(s);
  }
  return int(slices.size()) - 1;
}

BrdfTable Model::table() const {
  // A non-owning pointer: the evaluator lives only inside this call, so no copy is needed.
  return ModelEvaluator(std::shared_ptr<const Model>(std::shared_ptr<const Model>(), this)).table();
}

namespace {

// One component prepared for evaluation.
struct Term {
  const Component* cs = nullptr;
  std::unique_ptr<internal::GridCopula> copula;
  const internal::FrankGrid* frank =
      nullptr;  // the copula's grid when Frank: evaluated without a virtual call

  explicit Term(const Component& c) : cs(&c) {
    // A family's own grid may be accurate only within the fitter's bounds (FrankGrid down to
    // kFrankGridMinAlpha); a Model may hold any parameter of the domain, which the general grid
    // evaluates in the log domain.
    const double theta = std::clamp(c.theta, -kMaxEvaluatedParameter, kMaxEvaluatedParameter);
    copula = internal::make_evaluation_grid(c.family, theta);
    std::vector<double> u1, u2, u3;
    internal::midpoint_cdf(c.pdf_h, &u1);
    internal::midpoint_cdf(c.pdf_d, &u2);
    internal::midpoint_cdf(c.pdf_p, &u3);
    copula->prepare_density(theta, u1, u2, u3);  // values only: no derivative grid
    frank = internal::frank_grid_of(*copula);
  }

  // j is the theta_d bin inside the slice.
  double value(int i, int j, int k) const {
    const double f = cs->pdf_h[i] * cs->pdf_d[j] * cs->pdf_p[k];
    if (f == 0.0 || cs->scale == 0.0) return 0.0;
    const double c = frank ? frank->density(i, j, k) : copula->density(i, j, k);
    return saturate(cs->scale * c * f);
  }
};

}  // namespace

struct ModelEvaluator::Part {
  std::vector<Term> terms;  // one per component
  int theta_d_begin = 0;

  double value(int i, int j, int k) const {
    double v = 0.0;
    for (const Term& t : terms) v += t.value(i, j - theta_d_begin, k);
    return saturate(v);
  }
};

ModelEvaluator::ModelEvaluator(Model model)
    : ModelEvaluator(std::make_shared<const Model>(std::move(model))) {}

ModelEvaluator::ModelEvaluator(std::shared_ptr<const Model> shared) : model_(std::move(shared)) {
  const Model& model = *model_;
  slice_of_bin_.resize(kThetaDBins);
  for (int j = 0; j < kThetaDBins; ++j) slice_of_bin_[j] = model.slice_of(j);
  parts_.resize(model.slices.size());
  for (std::size_t s = 0; s < model.slices.size(); ++s) {
    for (int c = 0; c < kChannels; ++c) {
      auto part = std::make_shared<Part>();
      const ChannelSlice& cs = model.slices[s].channel[c];
      part->terms.reserve(std::size_t(cs.components()));
      for (int r = 0; r < cs.components(); ++r) part->terms.emplace_back(cs.component(r));
      part->theta_d_begin = model.slices[s].theta_d_begin;
      parts_[s][c] = std::move(part);
    }
  }
  interp_ = std::make_shared<const internal::InterpTables>(model);
  if (model.residual.present()) residual_ = std::make_shared<const internal::ResidualEval>(model);
}

ModelEvaluator::~ModelEvaluator() = default;
ModelEvaluator::ModelEvaluator(const ModelEvaluator&) = default;
ModelEvaluator& ModelEvaluator::operator=(const ModelEvaluator&) = default;
ModelEvaluator::ModelEvaluator(ModelEvaluator&&) noexcept = default;
ModelEvaluator& ModelEvaluator::operator=(ModelEvaluator&&) noexcept = default;

double ModelEvaluator::bin_value(int channel, int theta_h, int theta_d, int phi_d) const {
  const double v = parts_[slice_of_bin_[theta_d]][channel]->value(theta_h, theta_d, phi_d);
  if (!residual_) return v;
  return residual_->at_bin(channel, merl_index(theta_h, theta_d, phi_d), v);
}

namespace {

// Whether a direction is used as given (unit_direction leaves it unchanged). NaN and infinities
// fail the comparison.
template <class T>
bool deviation_ok(T x, T y, T z) {
  return std::fabs(x * x + y * y + z * z - T(1)) <= kDirectionAsGiven<T>;
}

// unit_direction, but exactly (0, 0, 0), a rejected draw's wi, is kept as it is: every path
// evaluates it as below the horizon (0), the batch kernels as they do their zero padding. Checked
// only where deviation_ok fails, so that the usual unit input pays nothing for it.
template <class T>
bool usable_direction(T& x, T& y, T& z) {
  return internal::zero_direction(x, y, z) || unit_direction(x, y, z);
}

// eval of a pair with a direction to rescale or to refuse, out of eval's usual path.
[[gnu::noinline]] void eval_rescaled(const internal::InterpTables& interp,
                                     const internal::ResidualEval* residual, const Vec3& wi_in,
                                     const Vec3& wo_in, double rgb[3]) {
  Vec3 wi = wi_in, wo = wo_in;
  if (!usable_direction(wi.x, wi.y, wi.z) || !usable_direction(wo.x, wo.y, wo.z)) {
    rgb[0] = rgb[1] = rgb[2] = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  interp.eval(wi, wo, rgb);
  if (residual) residual->apply(wi, wo, rgb);
}

}  // namespace

void ModelEvaluator::eval(const Vec3& wi, const Vec3& wo, double rgb[3]) const {
  // One predictable branch for the usual unit input; rescaling and refusing out of line.
  // `&` of the two as ints: both checks are cheap, so one branch beats a short-circuit's two.
  if (int(deviation_ok(wi.x, wi.y, wi.z)) & int(deviation_ok(wo.x, wo.y, wo.z))) [[likely]] {
    interp_->eval(wi, wo, rgb);
    if (residual_) residual_->apply(wi, wo, rgb);
    return;
  }
  eval_rescaled(*interp_, residual_.get(), wi, wo, rgb);
}

void ModelEvaluator::eval_f32(const float wi_in[3], const float wo_in[3], float rgb[3]) const {
  if (int(deviation_ok(wi_in[0], wi_in[1], wi_in[2])) &
      int(deviation_ok(wo_in[0], wo_in[1], wo_in[2]))) [[likely]] {
    interp_->eval(wi_in, wo_in, rgb);
    if (residual_) residual_->apply(wi_in, wo_in, rgb);
    return;
  }
  float wi[3] = {wi_in[0], wi_in[1], wi_in[2]}, wo[3] = {wo_in[0], wo_in[1], wo_in[2]};
  if (!usable_direction(wi[0], wi[1], wi[2]) || !usable_direction(wo[0], wo[1], wo[2])) {
    rgb[0] = rgb[1] = rgb[2] = std::numeric_limits<float>::quiet_NaN();
    return;
  }
  interp_->eval(wi, wo, rgb);
  if (residual_) residual_->apply(wi, wo, rgb);
}

namespace {

// The batch kernel's arguments for structure-of-arrays inputs and outputs.
template <typename T>
internal::BatchArgs<T> soa_args(const T* wi_x, const T* wi_y, const T* wi_z, const T* wo_x,
                                const T* wo_y, const T* wo_z, T* r, T* g, T* b) {
  internal::BatchArgs<T> a;
  a.in[0] = wi_x;
  a.in[1] = wi_y;
  a.in[2] = wi_z;
  a.in[3] = wo_x;
  a.in[4] = wo_y;
  a.in[5] = wo_z;
  a.out[0] = r;
  a.out[1] = g;
  a.out[2] = b;
  return a;
}

// The residual stage over a batch the base has evaluated: pair k's coordinates at index
// k * stride of each array, as in BatchArgs.
template <class T>
void apply_residual_batch(const internal::ResidualEval& stage, std::size_t n,
                          const internal::BatchArgs<T>& a, int threads) {
  internal::parallel_chunks(n, 2048, threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t i = k * a.in_stride, o = k * a.out_stride;
      T rgb[3] = {a.out[0][o], a.out[1][o], a.out[2][o]};
      if constexpr (std::is_same_v<T, double>) {
        stage.apply(Vec3{a.in[0][i], a.in[1][i], a.in[2][i]},
                    Vec3{a.in[3][i], a.in[4][i], a.in[5][i]}, rgb);
      } else {
        const float wi[3] = {a.in[0][i], a.in[1][i], a.in[2][i]};
        const float wo[3] = {a.in[3][i], a.in[4][i], a.in[5][i]};
        stage.apply(wi, wo, rgb);
      }
      for (int c = 0; c < 3; ++c) a.out[c][o] = rgb[c];
    }
  });
}

// The check's loop over n directions in separate coordinate arrays, compiled for AVX-512, AVX2
// and the baseline where GCC can choose at load time (as the batch kernels are); plain C++
// elsewhere. Comparisons only: any instruction set gives the same answer.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define CBRDF_CHECK_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define CBRDF_CHECK_CLONES
#endif

template <class T>
unsigned count_not_as_given(const T* x, const T* y, const T* z, std::size_t n, std::size_t s) {
  unsigned bad = 0;
  for (std::size_t k = 0; k < n; ++k) bad |= !deviation_ok(x[k * s], y[k * s], z[k * s]);
  return bad;
}

CBRDF_CHECK_CLONES unsigned soa_not_as_given(const double* x, const double* y, const double* z,
                                             std::size_t n) {
  unsigned bad = 0;
  for (std::size_t k = 0; k < n; ++k) bad |= !deviation_ok(x[k], y[k], z[k]);
  return bad;
}

CBRDF_CHECK_CLONES unsigned soa_not_as_given(const float* x, const float* y, const float* z,
                                             std::size_t n) {
  unsigned bad = 0;
  for (std::size_t k = 0; k < n; ++k) bad |= !deviation_ok(x[k], y[k], z[k]);
  return bad;
}

// Whether every direction of a batch is used as given: the usual case, checked chunk by chunk
// just before the kernel reads the same pairs (a separate pass over the whole batch cost 8%).
template <class T>
bool batch_as_given(std::size_t n, const internal::BatchArgs<T>& a) {
  unsigned bad = 0;
  for (int d = 0; d < 6; d += 3) {
    bad |= a.in_stride == 1 ? soa_not_as_given(a.in[d], a.in[d + 1], a.in[d + 2], n)
                            : count_not_as_given(a.in[d], a.in[d + 1], a.in[d + 2], n, a.in_stride);
  }
  if (bad == 0) return true;
  // A second pass only for a chunk that failed: rejected draws' (0, 0, 0) among directions used
  // as given go to the kernel too (see usable_direction), not through the copy of the checked path.
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = k * a.in_stride;
    for (int d = 0; d < 6; d += 3) {
      const T x = a.in[d][i], y = a.in[d + 1][i], z = a.in[d + 2][i];
      if (!deviation_ok(x, y, z) && !internal::zero_direction(x, y, z)) return false;
    }
  }
  return true;
}

// The kernel and the residual stage over a batch whose directions are used as given.
template <class T>
void eval_batch_valid(const internal::InterpTables& interp, const internal::ResidualEval* residual,
                      std::size_t n, const internal::BatchArgs<T>& a, int threads) {
  interp.eval_batch(n, a, threads);
  if (residual) apply_residual_batch(*residual, n, a, threads);
}

// A batch with directions to rescale or to refuse: its directions as unit_direction leaves them,
// copied (structure of arrays; a refused pair evaluated at the normal), and NaN for refused pairs.
template <class T>
void eval_batch_checked(const internal::InterpTables& interp,
                        const internal::ResidualEval* residual, std::size_t n,
                        const internal::BatchArgs<T>& a, int threads) {
  std::vector<T> dirs(6 * n);
  std::vector<unsigned char> refused(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = k * a.in_stride;
    for (int d = 0; d < 6; d += 3) {
      T x = a.in[d][i], y = a.in[d + 1][i], z = a.in[d + 2][i];
      if (!usable_direction(x, y, z)) {
        refused[k] = 1;
        x = 0, y = 0, z = 1;
      }
      dirs[std::size_t(d) * n + k] = x;
      dirs[std::size_t(d + 1) * n + k] = y;
      dirs[std::size_t(d + 2) * n + k] = z;
    }
  }
  internal::BatchArgs<T> c = a;
  for (int d = 0; d < 6; ++d) c.in[d] = dirs.data() + std::size_t(d) * n;
  c.in_stride = 1;
  eval_batch_valid(interp, residual, n, c, threads);
  for (std::size_t k = 0; k < n; ++k) {
    if (!refused[k]) continue;
    for (int ch = 0; ch < 3; ++ch)
      a.out[ch][k * a.out_stride] = std::numeric_limits<T>::quiet_NaN();
  }
}

// A batch through the pool in chunks of the kernel's size (2048 pairs), each checked and then
// evaluated on its thread (results per pair do not depend on the chunks).
template <class T>
void eval_batch_any(const internal::InterpTables& interp, const internal::ResidualEval* residual,
                    std::size_t n, const internal::BatchArgs<T>& a, int threads) {
  internal::parallel_chunks(n, 2048, threads, [&](std::size_t b, std::size_t e) {
    internal::BatchArgs<T> c = a;
    for (int d = 0; d < 6; ++d) c.in[d] += b * a.in_stride;
    for (int ch = 0; ch < 3; ++ch) c.out[ch] += b * a.out_stride;
    if (batch_as_given(e - b, c)) {
      eval_batch_valid(interp, residual, e - b, c, 1);
    } else {
      eval_batch_checked(interp, residual, e - b, c, 1);
    }
  });
}

// The batch kernel's arguments for interleaved (x, y, z) triples.
template <typename T>
internal::BatchArgs<T> interleaved_args(const T* wi, const T* wo, T* rgb) {
  internal::BatchArgs<T> a;
  for (int i = 0; i < 3; ++i) {
    a.in[i] = wi + i;
    a.in[3 + i] = wo + i;
    a.out[i] = rgb + i;
  }
  a.in_stride = a.out_stride = 3;
  return a;
}

}  // namespace

void ModelEvaluator::eval_batch(std::size_t n, const double* wi_x, const double* wi_y,
                                const double* wi_z, const double* wo_x, const double* wo_y,
                                const double* wo_z, double* r, double* g, double* b,
                                int threads) const {
  eval_batch_any(*interp_, residual_.get(), n,
                 soa_args(wi_x, wi_y, wi_z, wo_x, wo_y, wo_z, r, g, b), threads);
}

void ModelEvaluator::eval_batch(std::size_t n, const double* wi, const double* wo, double* rgb,
                                int threads) const {
  if (n == 0) return;
  eval_batch_any(*interp_, residual_.get(), n, interleaved_args(wi, wo, rgb), threads);
}

void ModelEvaluator::eval_batch_f32(std::size_t n, const float* wi_x, const float* wi_y,
                                    const float* wi_z, const float* wo_x, const float* wo_y,
                                    const float* wo_z, float* r, float* g, float* b,
                                    int threads) const {
  eval_batch_any(*interp_, residual_.get(), n,
                 soa_args(wi_x, wi_y, wi_z, wo_x, wo_y, wo_z, r, g, b), threads);
}

void ModelEvaluator::eval_batch_f32(std::size_t n, const float* wi, const float* wo, float* rgb,
                                    int threads) const {
  if (n == 0) return;
  eval_batch_any(*interp_, residual_.get(), n, interleaved_args(wi, wo, rgb), threads);
}

void ModelEvaluator::albedo(double cos_theta_o, double rgb[3], int threads) const {
  double x = 0, z = cos_theta_o;
  if (!(z <= 1 + kDirectionTolerance)) {  // NaN included
    rgb[0] = rgb[1] = rgb[2] = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  rgb[0] = rgb[1] = rgb[2] = 0.0;
  if (!(z > 0)) return;
  z = std::min(z, 1.0);
  x = std::sqrt(std::max(0.0, 1 - z * z));
  // Points over h: theta_h cells with the MERL spacing, edges (a / 180)^2 * 90 deg (fine near the
  // normal, where specular peaks are), phi_h uniform over [0, 2 pi) (a fitted model need not be
  // symmetric about wo's plane) in 720 cells (grazing lobes are narrow in phi_h: 256 cells were
  // 3% off at 75 deg), one midpoint per cell. The integrand is f cos(theta_i) 4 (wo.h) per unit
  // solid angle of h, a cell's solid angle (cos0 - cos1) dphi. Evaluated in blocks of rows.
  constexpr int kThetaCells = 180, kPhiCells = 720, kRowsPerBlock = 30;
  constexpr std::size_t kBlock = std::size_t(kRowsPerBlock) * kPhiCells;
  constexpr double kPi = 3.14159265358979323846;
  const double dphi = 2 * kPi / kPhiCells;
  std::vector<double> wi(3 * kBlock), wo(3 * kBlock), f(3 * kBlock), weight(kBlock);
  for (std::size_t k = 0; k < kBlock; ++k) {
    wo[3 * k] = x, wo[3 * k + 1] = 0, wo[3 * k + 2] = z;
  }
  for (int a0 = 0; a0 < kThetaCells; a0 += kRowsPerBlock) {
    for (int r = 0; r < kRowsPerBlock; ++r) {
      const int a = a0 + r;
      const double t0 = double(a) / kThetaCells, t1 = double(a + 1) / kThetaCells;
      const double c0 = std::cos(t0 * t0 * kPi / 2),
                   c1 = a + 1 == kThetaCells ? 0.0 : std::cos(t1 * t1 * kPi / 2);
      const double ct = 0.5 * (c0 + c1), st = std::sqrt(std::max(0.0, 1 - ct * ct));
      for (int b = 0; b < kPhiCells; ++b) {
        const double phi = (b + 0.5) * dphi;
        const double hx = st * std::cos(phi), hy = st * std::sin(phi), hz = ct;
        const double d = x * hx + z * hz;
        const std::size_t k = std::size_t(r) * kPhiCells + std::size_t(b);
        double* w = &wi[3 * k];
        w[0] = 2 * d * hx - x;
        w[1] = 2 * d * hy;
        w[2] = 2 * d * hz - z;
        weight[k] = d > 0 && w[2] > 0 ? w[2] * 4 * d * (c0 - c1) * dphi : 0.0;
        if (weight[k] == 0.0) w[0] = 0, w[1] = 0, w[2] = 1;  // a valid direction, weight 0
      }
    }
    eval_batch(kBlock, wi.data(), wo.data(), f.data(), threads);
    for (std::size_t k = 0; k < kBlock; ++k) {
      if (weight[k] == 0.0) continue;
      for (int ch = 0; ch < 3; ++ch) rgb[ch] += f[3 * k + std::size_t(ch)] * weight[k];
    }
  }
}

std::size_t ModelEvaluator::footprint_bytes() const {
  std::size_t n = sizeof(*this) + slice_of_bin_.capacity() * sizeof(int) +
                  parts_.capacity() * sizeof(parts_[0]) + interp_->footprint_bytes() +
                  (residual_ ? residual_->footprint_bytes() : 0);
  for (const auto& channels : parts_) {
    for (const auto& part : channels) {
      n += sizeof(Part) + part->terms.capacity() * sizeof(Term);
      for (const Term& t : part->terms) {
        // The grid's prepared per-axis arrays (density/): FrankGrid holds e, w, y, q and u per
        // axis, the Archimedean grid (values only) psi, log psi, log |psi'| and u.
        const std::size_t bins = t.cs->pdf_h.size() + t.cs->pdf_d.size() + t.cs->pdf_p.size();
        const CopulaFamilyRow* row = family_row(t.cs->family);
        const std::size_t arrays = t.frank ? 5 : row && row->has_parameter() ? 4 : 0;
        n += arrays * bins * sizeof(double) + 128;  // 128: the grid object itself, roughly
      }
    }
  }
  return n;
}

void ModelEvaluator::model_row(int ch, std::size_t s, int i, int j, double* row, double* c) const {
  const Slice& slice = model_->slices[s];
  const Part& p = *parts_[s][std::size_t(ch)];
  const double inv_scale = 1.0 / kMerlScale[std::size_t(ch)];
  std::fill(row, row + kPhiDBins, 0.0);
  for (const Term& term : p.terms) {
    const Component& cs = *term.cs;
    const double f12 = cs.scale * cs.pdf_h[std::size_t(i)] *
                       cs.pdf_d[std::size_t(j - slice.theta_d_begin)] * inv_scale;
    if (f12 == 0.0) continue;
    // A whole phi_d row at once: the copula's per-row factors are shared and it vectorizes.
    term.copula->row(i, j - slice.theta_d_begin, c, nullptr);
    for (int k = 0; k < kPhiDBins; ++k) row[k] += saturate(f12 * c[k] * cs.pdf_p[k]);
  }
  if (p.terms.size() > 1) {
    for (int k = 0; k < kPhiDBins; ++k) row[k] = saturate(row[k]);
  }
}

void ModelEvaluator::table_rows(std::span<const std::uint32_t> rows, double* out) const {
  std::vector<double> c(kPhiDBins);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const int i = int(rows[r] / kThetaDBins), j = int(rows[r] % kThetaDBins);
    const std::size_t s = std::size_t(slice_of_bin_[std::size_t(j)]);
    const bool covered = j >= model_->slices[s].theta_d_begin && j < model_->slices[s].theta_d_end;
    for (int ch = 0; ch < kChannels; ++ch) {
      double* row = out + (r * kChannels + std::size_t(ch)) * kPhiDBins;
      if (covered) {
        model_row(ch, s, i, j, row, c.data());
      } else {
        std::fill(row, row + kPhiDBins, 0.0);  // as table() leaves a row no slice covers
      }
    }
  }
}

BrdfTable ModelEvaluator::table() const {
  BrdfTable t;
  const NotMeasured& nm = model_->not_measured;
  std::vector<double> c(kPhiDBins);
  for (int ch = 0; ch < kChannels; ++ch) {
    double* out = t.channel_data(ch);
    for (std::size_t s = 0; s < model_->slices.size(); ++s) {
      const Slice& slice = model_->slices[s];
      for (int i = 0; i < kThetaHBins; ++i) {
        for (int j = slice.theta_d_begin; j < slice.theta_d_end; ++j) {
          model_row(ch, s, i, j, out + merl_index(i, j, 0), c.data());
        }
      }
    }
  }
  internal::apply_residual_to_table(*model_, &t);
  // The source's stored values where it measured nothing, bit for bit: walk the set bits of the
  // mask (bit c * kBinsPerChannel + i) word by word, in bit order, as the values list is.
  const bool uniform = nm.values.size() == 1;
  std::size_t next_value = 0;
  double* all = t.stored_values().data();
  for (std::size_t w = 0; w < nm.bits.size(); ++w) {
    for (std::uint64_t word = nm.bits[w]; word != 0; word &= word - 1) {
      const std::size_t bit = w * 64 + std::size_t(__builtin_ctzll(word));
      if (bit >= kChannels * kBinsPerChannel) break;
      all[bit] = uniform ? nm.values[0] : nm.values[next_value++];
    }
  }
  return t;
}

}  // namespace cbrdf
