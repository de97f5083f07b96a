// SPDX-License-Identifier: MIT
/// @file
/// Importance sampling of an isotropic BRDF (the copula model, a measured table or an analytic
/// BRDF) for renderers: sample(wo, u) -> wi and the exact density sample_pdf(wi, wo) of what it
/// draws (arguments in the (wi, wo) order of eval; pdf(wo, wi), the other order, is deprecated).
///
/// Design. Conditioning the copula on wo has no closed form (the paper leaves it open), so the
/// sampler tabulates, per wo, the BRDF's own distribution over half vectors and reflects wo about
/// the drawn h:
///  - The BRDF is isotropic, so the distribution depends on wo only through theta_o. theta_o is cut
///    into `theta_o_bins` uniform bins; each bin gets one table, built on first use (thread-safe)
///    from the BRDF at the bin's central theta_o with phi_o = 0, and used for every wo in the bin
///    after rotating by phi_o. Which wo shares a table changes efficiency, never correctness:
///    sample_pdf() reads the same table sample() draws from.
///  - A table is a piecewise-constant density over half-vector cells (theta_h, phi_h relative to
///    wo's azimuth). theta_h edges follow the MERL grid, (a / n)^2 * 90 deg, fine near the normal
///    where specular peaks live; phi_h edges are uniform over [0, 2 pi). A cell's mass is the mean
///    of mean_rgb(f(wi, wo)) cos(theta_i) 4 (wo.h) over supersample x supersample points times the
///    cell's solid angle: the integrand f cos_i dwi written over dh (dwi = 4 |wo.h| dh).
///  - Within a cell h is uniform in solid angle (uniform in cos(theta_h) and phi_h), so
///    pdf_h = P / (delta cos * delta phi) exactly, P the cell's probability as the draws see it
///    (its row's step of the row CDF times its step of the row's cell CDF), and
///    wi = 2 (wo.h) h - wo has sample_pdf(wi, wo) = pdf_h(h) / (4 (wo.h)), h = normalize(wi + wo).
///  - A defensive share c of draws is cosine-weighted in wi, so the density is positive wherever
///    wi is above the horizon (the table may miss a thin feature or differ from the BRDF at other
///    theta_o in its bin). The full density is
///      pdf = c cos(theta_i) / pi + (1 - c) pdf_table(wi, wo).
///    c is chosen per table when it is built, from the points its masses were computed at: the
///    share in [cosine_fraction, 1] that minimises the predicted variance of f cos / pdf, or 1
///    (cosine-weighted only) where the table's predicted gain over cosine-weighted sampling is
///    below min_table_gain. Broad lobes near normal incidence (fabrics, matte paints) are where a
///    piecewise-constant table of a model does no better than the cosine it is mixed with.
///  - A drawn h whose reflection falls at or below the horizon is a rejected sample (valid =
///    false). sample_pdf() is 0 there, so it integrates over the upper hemisphere to 1 minus the
///    rejected probability, the mass of cells that reflect below the horizon.
/// Cost: building a table evaluates the BRDF theta_h_cells * phi_h_cells * supersample^2 times
/// (23,040 by default); a draw is two binary searches, a pdf none, and both a few square roots and
/// polynomial acos, sincos and atan2 (no libm calls). sample_batch takes the same steps for blocks
/// of draws, its searches one step for all draws at a time and its arithmetic in vector lanes
/// (AVX2 where available), so that its results equal sample()'s bit for bit.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "cbrdf/brdf_fn.h"
#include "cbrdf/coords.h"
#include "cbrdf/model.h"

namespace cbrdf {
namespace internal {
struct SamplerLanes;  ///< sampling.cc: a block of batch draws
}  // namespace internal

/// How a BrdfSampler tabulates the BRDF (the defaults suit MERL-like materials).
struct SamplerSettings {
  int theta_o_bins = 32;         ///< tables over theta_o in [0, 90 deg)
  int theta_h_cells = 90;        ///< MERL-spaced theta_h cells
  int phi_h_cells = 64;          ///< uniform phi_h cells
  int supersample = 2;           ///< points per cell per axis when building a table
  double cosine_fraction = 0.1;  ///< least cosine-weighted share of each table's draws, in [0, 1]
  /// A table is drawn from only where, on the BRDF it tabulates, it is predicted to give at least
  /// this many times less variance than cosine-weighted sampling (for f cos / pdf at the table's
  /// theta_o); elsewhere every draw is cosine-weighted. Its share of draws is then chosen in
  /// [cosine_fraction, 1] to minimise that predicted variance. 0 or less: the share is
  /// cosine_fraction wherever the table is not empty (the sampler of cbrdf 2.2).
  double min_table_gain = 2.0;
};

/// One draw of BrdfSampler::sample().
struct BrdfSample {
  Vec3 wi;             ///< the drawn direction (unit, local frame); see BrdfSampler::sample
  double pdf = 0.0;    ///< sample_pdf(wi, wo) per unit solid angle; 0 when !valid
  bool valid = false;  ///< false: rejected (wo below the horizon or wi reflected below it)
};

/// Importance sampling of wi given wo from tables of a BRDF (see the file's description).
class BrdfSampler {
 public:
  /// f is called from several threads (it must not mutate shared state) and must outlive the
  /// sampler. Settings are clamped to sensible ranges (at least 1 bin/cell, c in [0, 1]).
  explicit BrdfSampler(BrdfFn f, const SamplerSettings& settings = {});
  ~BrdfSampler();
  /** Move-only. */
  ///@{
  BrdfSampler(BrdfSampler&&) noexcept;
  BrdfSampler& operator=(BrdfSampler&&) noexcept;
  ///@}

  /// Draws wi for a unit wo (local frame, z = normal) from u1, u2 in [0, 1) (clamped into it; a
  /// NaN u1 or u2 gives a rejected sample, valid = false). wo is rescaled or refused as
  /// unit_direction (model.h) says: a wo that is not a finite unit vector gives a rejected sample.
  BrdfSample sample(const Vec3& wo, double u1, double u2) const;
  /// The same with the draw's weight f(wi, wo) cos(theta_i) / pdf in RGB, equal bit for bit to
  /// sample_batch's; a rejected draw has wi = (0, 0, 0), pdf 0 and weight 0 (as in sample_batch).
  /// That wi may be passed on unchecked: ModelEvaluator::eval (every form) and sample_pdf give 0
  /// for it, never NaN, e.g.
  ///     BrdfSample s = sampler.sample(wo, u1, u2, weight);  // s.wi = (0, 0, 0) if rejected
  ///     evaluator.eval(s.wi, wo, f);                         // f = 0 for a rejected draw
  ///     double p = sampler.sample_pdf(s.wi, wo);             // p = s.pdf (0 if rejected)
  BrdfSample sample(const Vec3& wo, double u1, double u2, double weight[3]) const;
  /// The density of sample() per unit solid angle of wi, given wo: the arguments in the (wi, wo)
  /// order of ModelEvaluator::eval and of the C API's cbrdf_model_sample_pdf. 0 when wo or wi is
  /// at or below the horizon, and 0 when either is exactly (0, 0, 0), a rejected draw's wi, so that
  /// drawn directions may be passed on unchecked; NaN when either is any other vector that is not
  /// a finite unit vector (within kDirectionTolerance; rescaled as sample() rescales wo).
  double sample_pdf(const Vec3& wi, const Vec3& wo) const;
  /// sample_pdf(wi, wo) with its arguments in the opposite order, kept for one release.
  [[deprecated("use sample_pdf(wi, wo): the arguments are in the other order")]] double pdf(
      const Vec3& wo, const Vec3& wi) const {
    return sample_pdf(wi, wo);
  }

  /// n draws at once, in structure-of-arrays form: for wo = (wo_x[k], wo_y[k], wo_z[k]) and
  /// (u1[k], u2[k]), the direction wi and pdf of sample() (equal to it bit for bit) and the weight
  /// f(wi, wo) cos(theta_i) / pdf in RGB. A rejected draw has wi = (0, 0, 0), pdf = 0 and weight
  /// 0. Chunks of draws go through the library's thread pool on at most `threads` threads (<= 0:
  /// the thread limit). For a sampler of make_model_sampler the weights' evaluations go through
  /// ModelEvaluator::eval_batch, else through f per draw. Outputs must not overlap the inputs.
  void sample_batch(std::size_t n, const double* wo_x, const double* wo_y, const double* wo_z,
                    const double* u1, const double* u2, double* wi_x, double* wi_y, double* wi_z,
                    double* pdf, double* weight_r, double* weight_g, double* weight_b,
                    int threads = 0) const;
  /// The same with interleaved arrays: wo, wi and weight hold n (x, y, z) / (r, g, b) triples, u
  /// n pairs (u1, u2).
  void sample_batch(std::size_t n, const double* wo, const double* u, double* wi, double* pdf,
                    double* weight, int threads = 0) const;

  const SamplerSettings& settings() const { return settings_; }  ///< As clamped.

 private:
  struct Table;
  struct Draw;
  struct BatchIo;
  friend BrdfSampler make_model_sampler(const ModelEvaluator&, const SamplerSettings&);
  friend BrdfSampler make_model_sampler(std::shared_ptr<const ModelEvaluator>,
                                        const SamplerSettings&);
  /// The table of theta_o bin k, built on first use (thread-safe).
  const Table& table_at(int k) const;
  void build_table(int k, Table& t) const;
  /// The share of t's mass whose reflection of a wo at theta_o falls below the horizon.
  double rejected_share(const Table& t, double theta_o) const;
  /// A draw's choices (sampling.cc): cosine-weighted or from t (true; d->v1 is then the row
  /// search's u), and in t its cell in a row.
  bool draw_choice(const Table& t, double u1, double u2, Draw* d) const;
  void draw_cell(const Table& t, int row, Draw* d) const;
  void sample_chunk(const BatchIo& io, std::size_t begin, std::size_t end) const;
  /// Draws [base, base + m) of a batch loaded into lanes, their tables and choices made; returns
  /// the lanes the lane loops run over (m rounded up to whole vector groups).
  int draw_lanes(const BatchIo& io, std::size_t base, int m, internal::SamplerLanes& l) const;

  BrdfFn f_;
  SamplerSettings settings_;
  std::vector<double> cos_edges_;  ///< cos of the theta_h cell edges, theta_h_cells + 1, decreasing
  std::unique_ptr<Table[]> tables_;
  const ModelEvaluator* evaluator_ = nullptr;  ///< f_'s evaluator (make_model_sampler), for batches
};

/** The model's eval() as a BrdfFn, and a sampler for the copula model through it. Each holds its
    own copy of the evaluator (the first forms copy it, sharing its tables; the shared forms keep
    the given one alive), so the caller's evaluator may be moved or destroyed afterwards. */
///@{
BrdfFn model_brdf_fn(const ModelEvaluator& evaluator);
BrdfFn model_brdf_fn(std::shared_ptr<const ModelEvaluator> evaluator);
BrdfSampler make_model_sampler(const ModelEvaluator& evaluator,
                               const SamplerSettings& settings = {});
BrdfSampler make_model_sampler(std::shared_ptr<const ModelEvaluator> evaluator,
                               const SamplerSettings& settings = {});
///@}

/// Cosine-weighted hemisphere sampling, the usual baseline: wi with pdf cos(theta_i) / pi.
Vec3 sample_cosine_hemisphere(double u1, double u2);

}  // namespace cbrdf
