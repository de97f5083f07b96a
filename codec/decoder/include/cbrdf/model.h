// SPDX-License-Identifier: MIT
/// @file
/// The copula BRDF model (Ozturk, Kurt, Bilgili 2010): per theta_d slice and colour channel, the
/// BRDF is K * c(F1(theta_h), F2(theta_d), F3(phi_d); theta) * f1(theta_h) f2(theta_d) f3(phi_d),
/// with empirical marginals f (probability mass per MERL bin), their CDFs F, an Archimedean copula
/// density c with one parameter, and the slice's normalization K. Beyond the paper, a slice may be
/// a mixture: a sum of such terms, each with its own marginals, parameter and K.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/coords.h"
#include "cbrdf/copula_family.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// One product-copula term: K c(F1(theta_h), F2(theta_d), F3(phi_d); theta) f1 f2 f3.
struct Component {
  CopulaFamily family = CopulaFamily::kFrank;  ///< the copula
  double theta = 0.0;  ///< the family's parameter, in its own convention (copula_family.h)
  double scale =
      0.0;  ///< K: the term's sum over the slice's bins (physical units; measured + imputed)
  /// Probability mass per bin, each summing to 1 (all zero when scale == 0):
  std::vector<double> pdf_h;  ///< 90 theta_h bins
  std::vector<double> pdf_d;  ///< the slice's theta_d bins
  std::vector<double> pdf_p;  ///< 180 phi_d bins
};

/// One slice of one colour channel. The paper's model is the single component held inline; a
/// mixture (container version 1.1) adds further components in `extra`, and the slice's value is the
/// sum of all of them. Each component has its own marginals, copula and weight K.
struct ChannelSlice : Component {
  std::vector<Component> extra;  ///< components 2.. of a mixture
  /// The number of components, at least 1.
  int components() const { return 1 + int(extra.size()); }
  /** Component r (0: the inline one), 0 <= r < components(). */
  ///@{
  const Component& component(int r) const { return r == 0 ? *this : extra[std::size_t(r - 1)]; }
  Component& component(int r) { return r == 0 ? *this : extra[std::size_t(r - 1)]; }
  ///@}
};

/// A run of theta_d bins sharing one model per channel.
struct Slice {
  int theta_d_begin = 0;                                     ///< first theta_d bin
  int theta_d_end = 0;                                       ///< one past the last
  std::array<ChannelSlice, kChannels> channel;               ///< R, G, B
  int width() const { return theta_d_end - theta_d_begin; }  ///< theta_d bins
};

/// Which bins the source did not measure, and the exact stored values it had there.
struct NotMeasured {
  /// Bit (c * kBinsPerChannel + i) set when channel c's bin i was not measured.
  std::vector<std::uint64_t> bits =
      std::vector<std::uint64_t>((kChannels * kBinsPerChannel + 63) / 64, 0);
  /// One value for all (the usual case) or one per set bit, in bit order.
  std::vector<double> values = {-1.0};

  /// Whether channel's MERL bin index is marked not measured.
  bool test(int channel, std::size_t index) const {
    const std::size_t b = std::size_t(channel) * kBinsPerChannel + index;
    return (bits[b >> 6] >> (b & 63)) & 1u;
  }
  /// Marks channel's MERL bin index not measured.
  void set(int channel, std::size_t index) {
    const std::size_t b = std::size_t(channel) * kBinsPerChannel + index;
    bits[b >> 6] |= std::uint64_t{1} << (b & 63);
  }
  std::size_t count() const;  ///< set bits
  /// Captures the mask and values of a table.
  static NotMeasured from_table(const BrdfTable& table);
};

/// The error-bounded residual layer (container 1.2, chunk 'RESD', spec/container.md 4.6): per
/// measured bin, the decoded value is k expm1(log1p(base / k) + code * step) in stored (MERL
/// file) units, with base the copula model's value (Model::table() without the residual) and k
/// the knee, so that |log1p(decoded / k) - log1p(source / k)| <= max_error on every measured bin:
/// a relative bound above the knee, an absolute one (about max_error k) below.
struct ResidualEscape {
  std::uint32_t bin = 0;  ///< c * kBinsPerChannel + i
  double stored = 0.0;    ///< the bin's decoded (stored-unit) value, exactly
};
/// The lossless mode (RESD mode 1) holds the exact table instead: the decoded table is it, bit for
/// bit, and continuous evaluation interpolates it.
struct Residual {
  double max_error = 0.0;                  ///< mode 0's bound; 0 with neither mode
  double step = 0.0;                       ///< quantizer step, at most 2 max_error
  double knee = 0.0;                       ///< k, stored units (1e-12 to 1e12)
  std::vector<std::int32_t> codes;         ///< kChannels * kBinsPerChannel; 0 at not-measured bins
  std::vector<ResidualEscape> escapes;     ///< bins whose value is stored exactly, increasing
  std::shared_ptr<const BrdfTable> exact;  ///< mode 1: the source table itself
  /// Mode 2: per row r = 90 theta_h + theta_d (kThetaHBins * kThetaDBins entries), the row's step
  /// and bound are step and max_error times 2^row_shift[r]; empty: one step for every bin.
  std::vector<std::uint8_t> row_shift;
  /// Mode 3 (interpolated): codes are the errors of a prediction that interpolates, level by level,
  /// the residual already rebuilt at coarser bins (spec 4.6). 0: modes 0 and 2; 1..4: the coarsest
  /// level's bins are every 2^levels-th theta_d and phi_d bin of each (channel, theta_h) slab.
  std::uint8_t levels = 0;
  /// Mode 3: the finest level's step and bound (bins with an odd theta_d or phi_d index) are its
  /// row's times this, 1..64.
  std::uint8_t fine_multiplier = 1;
  /// Mode 4 (version 1.3): the same for the levels between the finest and the coarsest: level l
  /// (1..levels - 1, level_of) has middle_multipliers[l - 1], 1..64. All 1 in mode 3 (and unused
  /// beyond levels - 1).
  std::array<std::uint8_t, 3> middle_multipliers{1, 1, 1};
  /// Mode 3, derived from the codes by the reader and the writer (not stored): the residual of
  /// every bin in log1p units, channel-major MERL order.
  std::vector<double> values;
  /// Whether the model has a residual layer.
  bool present() const { return max_error > 0.0 || exact != nullptr; }
  bool interpolated() const { return levels > 0; }  ///< Mode 3.
  /** The largest and smallest row shift (0 without row steps): the bound over every bin is
      max_error x 2^max_row_shift(), the finest row's max_error x 2^min_row_shift(). */
  ///@{
  int max_row_shift() const;
  int min_row_shift() const;
  ///@}
  /// The step of MERL index i (any channel).
  double step_at(std::size_t i) const {
    return row_shift.empty() ? step : std::ldexp(step, row_shift[i / std::size_t{kPhiDBins}]);
  }
  /// The bound at MERL index i (any channel): max_error x 2^row shift, times the multiplier of
  /// the bin's level in modes 3 and 4 (level_multiplier).
  double bound_at(std::size_t i) const {
    const double b = row_shift.empty()
                         ? max_error
                         : std::ldexp(max_error, row_shift[i / std::size_t{kPhiDBins}]);
    return interpolated() ? b * double(level_multiplier(i)) : b;
  }
  /// The bound every measured bin meets, the largest bound_at: max_error x 2^max_row_shift(), times
  /// the largest level multiplier in modes 3 and 4 (0 in mode 1 and without a residual). What the
  /// encoder prints, `cbrdf info`, the C API and Python show.
  double bound() const {
    if (exact || !present()) return 0.0;
    const double b = std::ldexp(max_error, max_row_shift());
    return interpolated() ? b * double(max_multiplier()) : b;
  }
  /// Mode 3's finest level at MERL index i: an odd theta_d or phi_d.
  static bool finest_level(std::size_t i) { return ((i % kPhiDBins) | (i / kPhiDBins)) & 1; }
  /// The level of MERL index i (any channel) in modes 3 and 4: min(tz(theta_d), tz(phi_d), levels)
  /// with tz the trailing zero bits (tz(0) = levels): 0 the finest, `levels` the coarsest nodes.
  int level_of(std::size_t i) const {
    const std::size_t both = (i % kPhiDBins) | ((i / kPhiDBins) % kThetaDBins);
    int l = 0;
    while (l < levels && ((both >> l) & 1u) == 0) ++l;
    return l;
  }
  /// The step and bound multiplier of a level: fine_multiplier at 0, middle_multipliers[l - 1]
  /// between, 1 at the coarsest nodes.
  int multiplier_of_level(int l) const {
    return l == 0 ? fine_multiplier : l >= levels ? 1 : middle_multipliers[std::size_t(l - 1)];
  }
  /// The multiplier of the level of MERL index i (any channel).
  int level_multiplier(std::size_t i) const { return multiplier_of_level(level_of(i)); }
  /// The largest multiplier of any level (1 without levels).
  int max_multiplier() const {
    int m = 1;
    for (int l = 0; l < levels; ++l) m = std::max(m, multiplier_of_level(l));
    return m;
  }
  /// Mode 4: a level between the finest and the coarsest has a multiplier other than 1.
  bool middle_steps() const {
    for (int l = 1; l < levels; ++l) {
      if (middle_multipliers[std::size_t(l - 1)] != 1) return true;
    }
    return false;
  }
  /// The residual of bin b = c x kBinsPerChannel + i in log1p units: code x step (modes 0, 2) or
  /// the interpolated reconstruction (mode 3).
  double value_at(std::size_t b) const {
    return interpolated() ? values[b] : double(codes[b]) * step_at(b % kBinsPerChannel);
  }
};

/// Pure data: what a .cbrdf file holds. Evaluate it through a ModelEvaluator.
struct Model {
  std::vector<Slice> slices;  ///< contiguous, covering theta_d bins [0, 90)
  NotMeasured not_measured;   ///< the source's mask and values
  Residual residual;          ///< absent (max_error 0) in files of version 1.0 and 1.1

  /// Index of the slice holding theta_d bin j.
  int slice_of(int theta_d_bin) const;
  /// The full table: model values at measured bins, the source's stored values at the others.
  BrdfTable table() const;
};

/// Whether a container can hold `model`: 1 to 90 slices, contiguous from theta_d bin 0 to 90; at
/// most 8 components per slice and channel, each with a family's parameter inside its range and K
/// finite and >= 0; marginal tables of the grid's sizes holding finite masses >= 0; a mask of
/// kChannels x kBinsPerChannel bits with one negative value or one per set bit; and a residual
/// layer within RESD's limits (spec/container.md section 4). kInvalidArgument with a message naming
/// the first rule broken (slice, channel, component, table, bin). encode_model refuses exactly
/// these models (its message prefixed "cannot encode: "); every model decode_model returns passes.
Status validate_model(const Model& model);

namespace internal {
class GridCopula;
}
namespace internal {
class InterpTables;
class ResidualEval;
}  // namespace internal

/// Directions. Evaluation and sampling take unit vectors (local frame, z the normal). One whose
/// squared length is within kDirectionTolerance of 1 is scaled to unit length before use; it is
/// used as given when that is within 1e-12 of 1 (float: 1e-6), so that a vector normalized by
/// the caller keeps its bits and its value. Any other direction, a non-finite component included,
/// is invalid: returns false (w unchanged).
inline constexpr double kDirectionTolerance = 1e-3;
template <class T>
/// Below this deviation of |w|^2 from 1 a direction is used as given.
constexpr T kDirectionAsGiven = sizeof(T) < sizeof(double) ? T(1e-6) : T(1e-12);
template <class T>
/// Checks and normalizes a direction as described above; false (unchanged) when invalid.
inline bool unit_direction(T& x, T& y, T& z) {
  const T n2 = x * x + y * y + z * z, dev = n2 - T(1);
  // NaN fails both comparisons.
  if (!(dev >= -T(kDirectionTolerance) && dev <= T(kDirectionTolerance))) return false;
  if (dev < -kDirectionAsGiven<T> || dev > kDirectionAsGiven<T>) {
    const T len = std::sqrt(n2);
    x /= len;
    y /= len;
    z /= len;
  }
  return true;
}
/// The same for a Vec3.
inline bool unit_direction(Vec3& w) {
  return unit_direction(w.x, w.y, w.z);
}

namespace internal {
/// Whether a direction is exactly (0, 0, 0) (either sign of zero): the wi of a rejected draw
/// (sampling.h), which evaluation and densities take as below the horizon (0), not as invalid.
template <class T>
constexpr bool zero_direction(T x, T y, T z) {
  return (x == T(0)) & (y == T(0)) & (z == T(0));
}
inline bool zero_direction(const Vec3& w) {
  return zero_direction(w.x, w.y, w.z);
}
}  // namespace internal

/// A model prepared for evaluation: per slice and channel, CDFs and the copula's per-axis terms.
/// Building one costs about a millisecond (the interpolation tables); keep it for as long as the
/// model is evaluated. The evaluator owns (or shares) the model it reads, so it stays valid
/// whatever happens to the caller's copy.
/// Copying and moving. What an evaluator prepared is immutable and shared: a copy costs a few
/// allocations and shares the tables, so copies may be evaluated concurrently. Moving transfers
/// them and leaves the moved-from evaluator empty (assign to it or destroy it; nothing else). A
/// sampler or BrdfFn made from an evaluator (sampling.h) holds its own copy, so moving or
/// destroying the evaluator afterwards is safe.
/// Invalid input: eval and eval_f32 of a direction that is not a finite unit vector (within
/// kDirectionTolerance; see unit_direction) give NaN in every channel, never a BRDF value; so do
/// the batch forms for that pair. (The C API refuses such a call with an error instead.) The one
/// exception is exactly (0, 0, 0), the wi of a rejected draw (sampling.h): it gives 0, as below
/// the horizon, so that drawn directions may be evaluated unchecked.
class ModelEvaluator {
 public:
  /// Takes the model (move it in to avoid a copy).
  explicit ModelEvaluator(Model model);
  /// Shares a model with the caller; it lives as long as either holds it.
  explicit ModelEvaluator(std::shared_ptr<const Model> model);
  ~ModelEvaluator();
  /** Copies share the prepared tables; moves leave the source empty (see above). */
  ///@{
  ModelEvaluator(const ModelEvaluator&);
  ModelEvaluator& operator=(const ModelEvaluator&);
  ModelEvaluator(ModelEvaluator&&) noexcept;
  ModelEvaluator& operator=(ModelEvaluator&&) noexcept;
  ///@}

  /// Model value (physical, 1/sr) of a channel at a MERL bin, ignoring the not-measured mask.
  double bin_value(int channel, int theta_h, int theta_d, int phi_d) const;
  /// RGB physical value at a direction pair (unit vectors, z = normal); continuous in angle and
  /// equal to bin_value at bin positions (up to rounding). 0 when wi or wo is at or below the
  /// horizon. Reciprocal: swapping wi and wo maps phi_d to phi_d + pi, the same bin. Between bins,
  /// the marginals' and the copula's per-axis terms are linear in MERL bin position (phi_d
  /// periodic; linear in theta_d across a slice boundary) and the density is evaluated once per
  /// channel and component at the interpolated terms (the paper's Algorithm 4); the separable part
  /// is exactly trilinear between the 8 surrounding bins. Families without a product form
  /// (Clayton, Gumbel, Joe) are trilinear between the 8 surrounding bins' values.
  void eval(const Vec3& wi, const Vec3& wo, double rgb[3]) const;
  /// The same in single precision, for renderers: from tables rounded to float and float angle
  /// arithmetic. Its relative error against eval is tested (tests/encoder/model_eval_test.cc).
  void eval_f32(const float wi[3], const float wo[3], float rgb[3]) const;
  /// n direction pairs at once, in structure-of-arrays form: pair k is wi = (wi_x[k], wi_y[k],
  /// wi_z[k]), wo likewise, and its value goes to (r[k], g[k], b[k]). Equal bit for bit to eval per
  /// pair (tests/encoder/model_eval_test.cc). Per pair on one core, one-component models run about
  /// 5 times faster than eval in a loop (20 real materials, tools/scripts/bench-20.sh), mixtures
  /// about 3 times (tests/bench, BM_EvalBatch*): blocks of 32 pairs go through one vectorized
  /// position loop; one-component models then through a whole-block path (8 pairs per vector),
  /// others through each pair's interpolation and copula ratios across its slots; chunks of 2048
  /// pairs through the library's thread pool (cbrdf/parallel.h) on at most `threads` threads (<= 0:
  /// the thread limit). Inputs and outputs must not overlap. Thread-safe.
  void eval_batch(std::size_t n, const double* wi_x, const double* wi_y, const double* wi_z,
                  const double* wo_x, const double* wo_y, const double* wo_z, double* r, double* g,
                  double* b, int threads = 0) const;
  /// The same with interleaved (x, y, z) triples: wi, wo and rgb hold 3n values.
  void eval_batch(std::size_t n, const double* wi, const double* wo, double* rgb,
                  int threads = 0) const;
  /// The batch form of eval_f32, equal to it bit for bit.
  void eval_batch_f32(std::size_t n, const float* wi_x, const float* wi_y, const float* wi_z,
                      const float* wo_x, const float* wo_y, const float* wo_z, float* r, float* g,
                      float* b, int threads = 0) const;
  /// The same with interleaved (x, y, z) float triples: wi, wo and rgb hold 3n values.
  void eval_batch_f32(std::size_t n, const float* wi, const float* wo, float* rgb,
                      int threads = 0) const;
  /// The directional albedo at elevation cos_theta_o: integral over the hemisphere of
  /// f(wi, wo) cos(theta_i) dwi per channel, for wo = (sqrt(1 - cos^2), 0, cos) (the model is
  /// isotropic); 0 for cos_theta_o <= 0, NaN for a NaN or one above 1 + kDirectionTolerance. A
  /// quadrature over half vectors h (wi = reflect(wo, h), dwi = 4 |wo.h| dh): 180 theta_h cells
  /// with the MERL spacing by 720 phi_h cells, 129,600 evaluations through eval_batch on at most
  /// `threads` threads (<= 0: the thread limit). Within 0.5% of a brute-force integration.
  void albedo(double cos_theta_o, double rgb[3], int threads = 0) const;
  /// Bytes this evaluator holds beyond its Model: the per-axis interpolation tables (float64 and
  /// float32), the copula grids behind bin_value and table(), the bookkeeping, and the bin values
  /// of Clayton, Gumbel and Joe components that eval has computed so far (kept: 24 bytes per bin
  /// of a slice evaluated, at most 35 MB). Not the Model itself (its masses and not-measured
  /// mask).
  std::size_t footprint_bytes() const;
  /// The full table (see Model::table()).
  BrdfTable table() const;
  /// The model's part of table() at some phi_d rows only: for rows[r] = theta_h * 90 + theta_d
  /// (each below 90 * 90), out[(r * 3 + channel) * 180 + phi_d] gets the value table() stores
  /// there, bit for bit, wherever the bin is measured and the model has no residual layer (the
  /// residual and the not-measured values are not applied). For measuring a model through a few
  /// rows (metrics.h, SphereScorer) without its 35 MB table.
  void table_rows(std::span<const std::uint32_t> rows, double* out) const;
  /// The model evaluated.
  const Model& model() const { return *model_; }
  /// The model evaluated, shared.
  const std::shared_ptr<const Model>& shared_model() const { return model_; }

 private:
  struct Part;
  /// table()'s values of one channel in the phi_d row (theta_h i, theta_d j) of slice s; c:
  /// kPhiDBins of scratch.
  void model_row(int channel, std::size_t s, int i, int j, double* row, double* c) const;
  std::shared_ptr<const Model> model_;
  std::vector<int> slice_of_bin_;  ///< theta_d bin -> slice
  /// Immutable once built, shared by copies.
  std::vector<std::array<std::shared_ptr<const Part>, kChannels>> parts_;
  std::shared_ptr<const internal::InterpTables> interp_;  ///< eval's tables
  std::shared_ptr<const internal::ResidualEval>
      residual_;  ///< the residual stage; null without one
};

}  // namespace cbrdf
