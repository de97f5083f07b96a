// SPDX-License-Identifier: MIT
#include "fit/mixture.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <numeric>

#include "density/grid_copula.h"
#include "encode_watch.h"
#include "fit/fit_families.h"
#include "fit/loss.h"
#include "fit/marginals.h"
#include "fit/solver_options.h"

namespace cbrdf::internal {
namespace {

// Stop when a sweep lowers the measured objective by less than this fraction: a tighter bound
// buys hundredths of a dB for many more sweeps, a looser one loses tenths.
constexpr double kSweepTolerance = 3e-3;

// Extrapolated HALS (Ang and Gillis, "Accelerating nonnegative matrix factorization algorithms
// using extrapolation", Neural Computation 2019): after each sweep the factors move on along
// their last step, x + beta (x - x_prev) clipped at 0; a step that raises the objective is undone
// and beta shrinks (and its cap with it), a step that lowers it lets beta grow. A start of 0.5
// reaches a lower objective than plain HALS in fewer sweeps; a bolder start ends higher.
constexpr double kExtrapolationStart = 0.5;
constexpr double kExtrapolationGrowth = 1.1, kExtrapolationCapGrowth = 1.05;
constexpr double kExtrapolationShrink = 1.5;

// Stage 2's relative cost change at which Ceres stops (see solve_copulas_and_weights).
constexpr double kStage2Tolerance = 1e-5;

// The factorization's passes over a slice (fill_and_measure, add_residual_component, hals_sweep)
// are compiled for AVX2 and for the baseline and chosen at load time (GCC on x86-64, not under
// the sanitizers). Their loops are element-wise or keep explicit partial sums, and AVX2 alone
// does not contract multiply-adds, so both versions give the same results bit for bit.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define CBRDF_FIT_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CBRDF_FIT_CLONES
#endif

// Nonnegative rank-K factors of a slice, one per marginal axis (theta_h, theta_d, phi_d), not
// normalized: value(i, j, k) ~ sum_r pdf_h[r][i] pdf_d[r][j] pdf_p[r][k].
struct Factors {
  std::vector<std::vector<double>> pdf_h, pdf_d, pdf_p;
  int rank() const { return int(pdf_h.size()); }
};

void add(Factors* f, const Component& comp) {
  std::vector<double> pdf_h(comp.pdf_h);
  for (double& x : pdf_h) x *= comp.scale;
  f->pdf_h.push_back(std::move(pdf_h));
  f->pdf_d.push_back(comp.pdf_d);
  f->pdf_p.push_back(comp.pdf_p);
}

double dot(const std::vector<double>& x, const std::vector<double>& y) {
  return std::inner_product(x.begin(), x.end(), y.begin(), 0.0);
}

// Four doubles (GCC/Clang vector types: AVX2 in the AVX2 clone, two SSE2 halves in the other).
// Loaded through pointers, not returned: GCC warns (-Wpsabi) about returning a 32-byte vector where
// AVX is not enabled, in the baseline clone.
using Vec4 = double __attribute__((vector_size(32)));

// Four partial sums, so that the compiler can vectorize without reassociating on its own.
[[gnu::always_inline]] inline double dot_row(const double* x, const double* y, int n) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    s0 += x[k] * y[k];
    s1 += x[k + 1] * y[k + 1];
    s2 += x[k + 2] * y[k + 2];
    s3 += x[k + 3] * y[k + 3];
  }
  for (; k < n; ++k) s0 += x[k] * y[k];
  return (s0 + s1) + (s2 + s3);
}

// The model's phi_d row at (i, j). Inlined, so that it is compiled with its callers' clone.
[[gnu::always_inline]] inline void model_row(const Factors& f, int i, int j, int np, double* row) {
  std::fill(row, row + np, 0.0);
  for (int r = 0; r < f.rank(); ++r) {
    const double w =
        f.pdf_h[std::size_t(r)][std::size_t(i)] * f.pdf_d[std::size_t(r)][std::size_t(j)];
    if (w == 0.0) continue;
    const double* pdf_p = f.pdf_p[std::size_t(r)].data();
    for (int k = 0; k < np; ++k) row[k] += w * pdf_p[k];
  }
}

// t[(i * nd + j) * n + r] = <y(i, j, .), pdf_p_r>, one row: what a sweep's theta_h and theta_d
// updates read.
[[gnu::always_inline]] inline void project_row(const double* yr, const Factors& f, int np,
                                               double* t) {
  for (std::size_t r = 0; r < std::size_t(f.rank()); ++r) t[r] = dot_row(yr, f.pdf_p[r].data(), np);
}

CBRDF_FIT_CLONES void project_rows(const SliceData& s, const std::vector<double>& y,
                                   const Factors& f, std::vector<double>* t) {
  const std::size_t rows = std::size_t(s.nh) * std::size_t(s.nd), n = std::size_t(f.rank());
  t->resize(rows * n);
  for (std::size_t row = 0; row < rows; ++row) {
    project_row(y.data() + row * std::size_t(s.np), f, s.np, t->data() + row * n);
  }
}

// The slice's values with kNotMeasured where a bin is not measured (measured values are >= 0): one
// array that the fill reads with a compare and a blend, where a separate byte mask made the
// compiler branch per bin on an irregular pattern.
constexpr double kNotMeasured = -1.0;

std::vector<double> values_or_sentinel(const SliceData& s) {
  std::vector<double> v(s.value);
  for (std::size_t q = 0; q < v.size(); ++q) {
    if (!s.measured[q]) v[q] = kNotMeasured;
  }
  return v;
}

// Fills y's not-measured bins with the model's values and returns the sum of squared residuals
// over measured bins (vs: values_or_sentinel). With t, also the projections of the filled rows for
// the next sweep (project_rows), taken while each row is in cache: one pass over the slice instead
// of two. Written with vectors of four (the sum in four lanes): GCC kept a branch per bin on its
// own, and this pass was the factorization's bottleneck.
CBRDF_FIT_CLONES double fill_and_measure(const SliceData& s, const std::vector<double>& vs,
                                         const Factors& f, std::vector<double>* y,
                                         std::vector<double>* t) {
  std::vector<double> row(std::size_t(s.np));
  const std::size_t n = std::size_t(f.rank());
  if (t != nullptr) t->resize(std::size_t(s.nh) * std::size_t(s.nd) * n);
  Vec4 lanes{};
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      model_row(f, i, j, s.np, row.data());
      const std::size_t base = s.at(i, j, 0);
      const double* value = vs.data() + base;
      const double* model = row.data();
      double* yr = y->data() + base;
      int k = 0;
      for (; k + 4 <= s.np; k += 4) {
        Vec4 v, m;
        std::memcpy(&v, value + k, sizeof v);
        std::memcpy(&m, model + k, sizeof m);
        const auto measured = v >= 0.0;
        const Vec4 d = measured ? v - m : Vec4{};
        lanes += d * d;
        const Vec4 filled = measured ? v : m;
        std::memcpy(yr + k, &filled, sizeof filled);
      }
      for (; k < s.np; ++k) {
        const double v = value[k], m = model[k];
        const double d = v >= 0.0 ? v - m : 0.0;
        lanes[0] += d * d;
        yr[k] = v >= 0.0 ? v : m;
      }
      if (t != nullptr) {
        project_row(yr, f, s.np,
                    t->data() + (std::size_t(i) * std::size_t(s.nd) + std::size_t(j)) * n);
      }
    }
  }
  return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
}

// A new component from the positive part of the residual y - model: the product of its sums over
// each pair of axes, scaled to the residual's total (the rank-1 moment estimate). Refining it
// toward the residual's best rank-1 least-squares fit (10 alternating passes) was tried: it
// recovered an exact two-lobe table better (0.2% vs 0.6% RMS) but cost 2 dB tone-mapped on
// blue-metallic-paint, because least squares chases the specular peak while the sums keep the broad
// shape.
CBRDF_FIT_CLONES void add_residual_component(const SliceData& s, const std::vector<double>& y,
                                             Factors* f) {
  std::vector<double> pdf_h(std::size_t(s.nh), 0.0), pdf_d(std::size_t(s.nd), 0.0),
      pdf_p(std::size_t(s.np), 0.0), row(std::size_t(s.np));
  double total = 0;
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      model_row(*f, i, j, s.np, row.data());
      const double* yr = y.data() + s.at(i, j, 0);
      for (int k = 0; k < s.np; ++k) {
        const double r = std::max(0.0, yr[k] - row[std::size_t(k)]);
        pdf_h[std::size_t(i)] += r;
        pdf_d[std::size_t(j)] += r;
        pdf_p[std::size_t(k)] += r;
        total += r;
      }
    }
  }
  if (!(total > 0)) return;
  for (double& x : pdf_h) x /= total * total;
  f->pdf_h.push_back(std::move(pdf_h));
  f->pdf_d.push_back(std::move(pdf_d));
  f->pdf_p.push_back(std::move(pdf_p));
}

// Gram matrix G[q][r] = <x_q, x_r>.
std::vector<double> gram(const std::vector<std::vector<double>>& x) {
  const std::size_t n = x.size();
  std::vector<double> g(n * n);
  for (std::size_t q = 0; q < n; ++q) {
    for (std::size_t r = q; r < n; ++r) g[q * n + r] = g[r * n + q] = dot(x[q], x[r]);
  }
  return g;
}

// One HALS update of factor x given M = <y, products of the other two factors> (m[i * n + r]) and
// the other two factors' Gram matrices: each column in turn is the nonnegative least-squares
// optimum with every other column fixed. (Repeating the column updates with the same M, Gillis
// and Glineur's accelerated HALS, was tried: 18% fewer sweeps on blue-metallic-paint at 4
// components but no less time, and 0.28 dB less on nickel.)
void hals_update(const std::vector<double>& m, const std::vector<double>& g1,
                 const std::vector<double>& g2, std::vector<std::vector<double>>* x) {
  const std::size_t n = x->size(), len = (*x)[0].size();
  for (std::size_t r = 0; r < n; ++r) {
    const double denom = g1[r * n + r] * g2[r * n + r];
    std::vector<double>& col = (*x)[r];
    if (!(denom > 0)) {
      std::fill(col.begin(), col.end(), 0.0);
      continue;
    }
    for (std::size_t i = 0; i < len; ++i) {
      double num = m[i * n + r];
      for (std::size_t q = 0; q < n; ++q) {
        if (q != r) num -= (*x)[q][i] * g1[q * n + r] * g2[q * n + r];
      }
      col[i] = std::max(0.0, num / denom);
    }
  }
}

// One sweep over the three factors, y holding the measured values and the filled-in model values
// and t its rows' projections on pdf_p (project_rows).
CBRDF_FIT_CLONES void hals_sweep(const SliceData& s, const std::vector<double>& y,
                                 const std::vector<double>& t, Factors* f) {
  const std::size_t n = std::size_t(f->rank());
  std::vector<double> m(std::size_t(s.nh) * n, 0.0);
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      for (std::size_t r = 0; r < n; ++r) {
        m[std::size_t(i) * n + r] +=
            t[(std::size_t(i) * std::size_t(s.nd) + std::size_t(j)) * n + r] *
            f->pdf_d[r][std::size_t(j)];
      }
    }
  }
  hals_update(m, gram(f->pdf_d), gram(f->pdf_p), &f->pdf_h);

  m.assign(std::size_t(s.nd) * n, 0.0);
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      for (std::size_t r = 0; r < n; ++r) {
        m[std::size_t(j) * n + r] +=
            t[(std::size_t(i) * std::size_t(s.nd) + std::size_t(j)) * n + r] *
            f->pdf_h[r][std::size_t(i)];
      }
    }
  }
  hals_update(m, gram(f->pdf_h), gram(f->pdf_p), &f->pdf_d);

  // mc[r * np + k] = sum_ij y(i, j, k) pdf_h_r(i) pdf_d_r(j), accumulated row by row (vectorizes).
  std::vector<double> mc(n * std::size_t(s.np), 0.0);
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      const double* yr = y.data() + s.at(i, j, 0);
      for (std::size_t r = 0; r < n; ++r) {
        const double w = f->pdf_h[r][std::size_t(i)] * f->pdf_d[r][std::size_t(j)];
        if (w == 0.0) continue;
        double* out = mc.data() + r * std::size_t(s.np);
        for (int k = 0; k < s.np; ++k) out[k] += yr[k] * w;
      }
    }
  }
  m.assign(std::size_t(s.np) * n, 0.0);
  for (std::size_t r = 0; r < n; ++r) {
    for (int k = 0; k < s.np; ++k)
      m[std::size_t(k) * n + r] = mc[r * std::size_t(s.np) + std::size_t(k)];
  }
  hals_update(m, gram(f->pdf_h), gram(f->pdf_d), &f->pdf_p);

  // Equal norms across a component's three factors keep the sweeps well scaled.
  for (std::size_t r = 0; r < n; ++r) {
    const double norm_h = std::sqrt(dot(f->pdf_h[r], f->pdf_h[r])),
                 norm_d = std::sqrt(dot(f->pdf_d[r], f->pdf_d[r])),
                 norm_p = std::sqrt(dot(f->pdf_p[r], f->pdf_p[r]));
    if (!(norm_h > 0 && norm_d > 0 && norm_p > 0)) continue;
    const double g = std::cbrt(norm_h * norm_d * norm_p);
    for (double& x : f->pdf_h[r]) x *= g / norm_h;
    for (double& x : f->pdf_d[r]) x *= g / norm_d;
    for (double& x : f->pdf_p[r]) x *= g / norm_p;
  }
}

// Components with an all-zero factor contribute nothing: drop them.
void drop_vanished(Factors* f) {
  for (int r = f->rank() - 1; r >= 0; --r) {
    const auto nonzero = [](const std::vector<double>& v) {
      return std::any_of(v.begin(), v.end(), [](double x) { return x > 0; });
    };
    const std::size_t u = std::size_t(r);
    if (nonzero(f->pdf_h[u]) && nonzero(f->pdf_d[u]) && nonzero(f->pdf_p[u])) continue;
    f->pdf_h.erase(f->pdf_h.begin() + r);
    f->pdf_d.erase(f->pdf_d.begin() + r);
    f->pdf_p.erase(f->pdf_p.begin() + r);
  }
}

// A component's marginals (masses and midpoint CDFs) and weight, from its factors.
struct Term {
  std::vector<double> pdf_h, pdf_d, pdf_p, cdf_h, cdf_d, cdf_p;
  double weight = 0;  // in units of the mean measured value
  std::unique_ptr<GridCopula> copula;
};

std::vector<double> normalized(const std::vector<double>& x, double* sum) {
  *sum = std::accumulate(x.begin(), x.end(), 0.0);
  std::vector<double> out(x);
  for (double& v : out) v /= *sum;
  return out;
}

// Stage 2: r_q = loss residual of v_q against sum_r w_r c_r f_r, parameters (log w_r, theta_r)
// for every component, passed to Ceres compressed exactly as in fit_parameter.cc: with
// J^T J = V L V^T, the P + 1 residuals (L^{-1/2} V^T J^T r, sqrt(|r|^2 - |that|^2)) with Jacobian
// [L^{1/2} V^T; 0] have the same cost, J^T J and J^T r as the n residuals at every point.
class MixtureCost final : public ceres::CostFunction {
 public:
  MixtureCost(const SliceData& s, std::vector<Term>& terms, double vbar, FitLoss loss)
      : s_(s), terms_(terms), vbar_(vbar), loss_(loss), p_(2 * int(terms.size())) {
    set_num_residuals(p_ + 1);
    mutable_parameter_block_sizes()->push_back(p_);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return evaluate(parameters[0], residuals, jacobians != nullptr ? jacobians[0] : nullptr);
  }

 private:
  // The residuals and, with jac (row-major (P + 1) x P), the Jacobian at x.
  CBRDF_FIT_CLONES bool evaluate(const double* x, double* residuals, double* jac) const {
    const std::size_t n = terms_.size();
    std::vector<double> w(n);
    for (std::size_t r = 0; r < n; ++r) {
      w[r] = std::exp(x[2 * r]);
      terms_[r].copula->prepare(x[2 * r + 1], terms_[r].cdf_h, terms_[r].cdf_d, terms_[r].cdf_p);
    }
    const bool want_jacobian = jac != nullptr;
    std::vector<std::vector<double>> c(n, std::vector<double>(std::size_t(s_.np))),
        dc(n, std::vector<double>(std::size_t(s_.np)));
    // J^T J and J^T r are accumulated from blocks of bins' gradients g (kBlock rows of gb): each
    // element gets the same products added in the same bin order as the rank-1 update per bin
    // did (jtj(b, a) += g[a] g[b], jtr[a] += g[a] res), so results are unchanged, but the sums
    // read gradients written long before instead of a vector load of values just stored one by
    // one (a store-forwarding stall per bin that cost more than the arithmetic), and without
    // Eigen's dynamic-size overhead at 2 to 16 parameters.
    constexpr int kBlock = 64;
    const std::size_t p = std::size_t(p_);
    Eigen::MatrixXd jtj = Eigen::MatrixXd::Zero(p_, p_);
    Eigen::VectorXd jtr = Eigen::VectorXd::Zero(p_);
    std::vector<double> gb(std::size_t(kBlock) * p), rb(kBlock), hd(n), wf(n);
    int nb = 0;
    const auto flush = [&] {
      // Bin by bin, each element's sum in bin order as before, but the inner loops run along
      // contiguous gradients (they vectorize) instead of down strided columns.
      double* jtj_data = jtj.data();
      double* jtr_data = jtr.data();
      for (int q = 0; q < nb; ++q) {
        const double* g = gb.data() + std::size_t(q) * p;
        for (std::size_t a = 0; a < p; ++a) {
          double* out = jtj_data + a * p;
          const double ga = g[a];
          for (std::size_t b = a; b < p; ++b) out[b] += ga * g[b];
        }
        const double res = rb[std::size_t(q)];
        for (std::size_t a = 0; a < p; ++a) jtr_data[a] += g[a] * res;
      }
      nb = 0;
    };
    double rr = 0;
    const double inv_vbar = 1.0 / vbar_;
    for (int i = 0; i < s_.nh; ++i) {
      for (int j = 0; j < s_.nd; ++j) {
        const std::size_t row = std::size_t(i) * std::size_t(s_.nd) + std::size_t(j);
        const std::uint32_t begin = s_.row_begin[row], end = s_.row_begin[row + 1];
        if (begin == end) continue;
        for (std::size_t r = 0; r < n; ++r) {
          terms_[r].copula->row(i, j, c[r].data(), want_jacobian ? dc[r].data() : nullptr);
          hd[r] = terms_[r].pdf_h[std::size_t(i)] * terms_[r].pdf_d[std::size_t(j)];
        }
        for (std::uint32_t q = begin; q < end; ++q) {
          const std::size_t l = s_.mk[q];
          double model = 0;
          for (std::size_t r = 0; r < n; ++r) {
            const double f = hd[r] * terms_[r].pdf_p[l];
            wf[r] = w[r] * f;
            model += wf[r] * c[r][l];
          }
          const auto [res, dr_dm] = loss_residual(loss_, s_, q, model, inv_vbar, vbar_ * s_.unit);
          rr += res * res;
          if (!want_jacobian) continue;
          double* g = gb.data() + std::size_t(nb) * p;
          for (std::size_t r = 0; r < n; ++r) {
            const double g0 = wf[r] * c[r][l], g1 = wf[r] * dc[r][l];  // rounded, then scaled
            g[2 * r] = g0 * dr_dm;
            g[2 * r + 1] = g1 * dr_dm;
          }
          rb[std::size_t(nb)] = res;
          if (++nb == kBlock) flush();
        }
      }
    }
    if (nb > 0) flush();
    if (!std::isfinite(rr)) return false;
    std::fill(residuals, residuals + p_ + 1, 0.0);
    if (!want_jacobian) {
      residuals[0] = std::sqrt(rr);
      return true;
    }
    jtj = jtj.selfadjointView<Eigen::Lower>();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jtj);
    const Eigen::VectorXd& lambda = eig.eigenvalues();
    const Eigen::MatrixXd& v = eig.eigenvectors();
    const double floor = 1e-14 * std::max(lambda.maxCoeff(), 0.0);
    Eigen::MatrixXd rmat = Eigen::MatrixXd::Zero(p_, p_);
    double explained = 0;
    for (int e = 0; e < p_; ++e) {
      if (!(lambda[e] > floor) || !(lambda[e] > 0)) continue;
      const double sq = std::sqrt(lambda[e]);
      rmat.row(e) = sq * v.col(e).transpose();
      residuals[e] = v.col(e).dot(jtr) / sq;
      explained += residuals[e] * residuals[e];
    }
    residuals[p_] = std::sqrt(std::max(0.0, rr - explained));
    for (int e = 0; e < p_; ++e) {
      for (int k = 0; k < p_; ++k) jac[e * p_ + k] = rmat(e, k);
    }
    for (int k = 0; k < p_; ++k) jac[p_ * p_ + k] = 0.0;
    return std::isfinite(explained);
  }

  const SliceData& s_;
  std::vector<Term>& terms_;
  double vbar_;
  FitLoss loss_;
  int p_;
};

// Mean loss per measured bin with the terms' copulas at the given parameters.
double objective_at(const SliceData& s, std::vector<Term>& terms, double vbar, FitLoss loss,
                    const std::vector<double>& x) {
  MixtureCost cost(s, terms, vbar, loss);
  std::vector<double> res(x.size() + 1);
  const double* params[] = {x.data()};
  if (!cost.Evaluate(params, res.data(), nullptr)) return HUGE_VAL;
  return res[0] * res[0] / double(s.measured_count());
}

// x + beta (x - x_prev), clipped at 0, into out (shaped as x).
void extrapolate(const Factors& x, const Factors& x_prev, double beta, Factors* out) {
  const auto step = [beta](const std::vector<std::vector<double>>& a,
                           const std::vector<std::vector<double>>& b,
                           std::vector<std::vector<double>>* o) {
    for (std::size_t r = 0; r < a.size(); ++r) {
      for (std::size_t i = 0; i < a[r].size(); ++i) {
        (*o)[r][i] = std::max(0.0, a[r][i] + beta * (a[r][i] - b[r][i]));
      }
    }
  };
  step(x.pdf_h, x_prev.pdf_h, &out->pdf_h);
  step(x.pdf_d, x_prev.pdf_d, &out->pdf_d);
  step(x.pdf_p, x_prev.pdf_p, &out->pdf_p);
}

// Extrapolated HALS sweeps (kExtrapolationStart) until a sweep lowers the objective by less than
// kSweepTolerance or kMaxSweeps: f, y (filled), t (its projections) and sse (of f) are updated in
// place and sweeps counted. Returns whether it converged. A sweep whose extrapolated point raised
// the objective costs one more fill, at the sweep's own point.
bool converge(const SliceData& s, const std::vector<double>& vs, Factors* f, std::vector<double>* y,
              std::vector<double>* t, double* sse, int* sweeps) {
  double beta = kExtrapolationStart, beta_cap = 1.0;
  Factors x_prev = *f, x;
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    if (cancel_requested()) return false;  // the encode returns kCancelled: f need not be good
    hals_sweep(s, *y, *t, f);
    x = *f;  // the sweep's own point
    extrapolate(x, x_prev, beta, f);
    double next = fill_and_measure(s, vs, *f, y, t);
    if (!(next <= *sse)) {
      *f = x;
      next = fill_and_measure(s, vs, *f, y, t);
      beta_cap = beta;
      beta /= kExtrapolationShrink;
    } else {
      beta = std::min(beta_cap, beta * kExtrapolationGrowth);
      beta_cap = std::min(1.0, beta_cap * kExtrapolationCapGrowth);
    }
    std::swap(x_prev, x);
    ++*sweeps;
    const bool converged = *sse - next <= kSweepTolerance * *sse;
    *sse = next;
    if (converged) return true;
  }
  return false;
}

// Stage 1: the factorization, each added component started from the residual of the fit before.
// Counts HALS sweeps and unconverged factorizations in `out`. With a started `state`, continues
// from its factors instead of `start`'s: y, the measured values with the model's filled in, is a
// function of the factors (the last sweep's fill, and dropping a vanished component changes no
// model value), so recomputing it here gives the very y and sse the earlier call ended with.
Factors factorize(const SliceData& s, const ChannelSlice& start, int components, MixtureFit* out,
                  MixtureState* state) {
  Factors f;
  bool exhausted = false;
  if (state != nullptr && state->started) {
    f.pdf_h = state->pdf_h;
    f.pdf_d = state->pdf_d;
    f.pdf_p = state->pdf_p;
    out->sweeps = state->sweeps;
    out->unconverged = state->unconverged;
    exhausted = state->exhausted;
  } else {
    for (int r = 0; r < start.components(); ++r) {
      if (start.component(r).scale > 0) add(&f, start.component(r));
    }
  }
  std::vector<double> y = s.value;
  const std::vector<double> vs = values_or_sentinel(s);
  std::vector<double> t;
  double sse = fill_and_measure(s, vs, f, &y, nullptr);
  while (!exhausted && f.rank() < components && !cancel_requested()) {
    const int before = f.rank();
    add_residual_component(s, y, &f);
    if (f.rank() == before) {
      exhausted = true;  // nothing positive left to explain
      break;
    }
    project_rows(s, y, f, &t);
    if (!converge(s, vs, &f, &y, &t, &sse, &out->sweeps)) ++out->unconverged;
    drop_vanished(&f);
  }
  if (state != nullptr) {
    state->pdf_h = f.pdf_h;
    state->pdf_d = f.pdf_d;
    state->pdf_p = f.pdf_p;
    state->started = true;
    state->exhausted = exhausted;
    state->sweeps = out->sweeps;
    state->unconverged = out->unconverged;
  }
  return f;
}

// Each component's normalized marginals and weight (in units of vbar), with its copula at
// independence; `x` gets the starting parameters (log weight, theta) per component.
std::vector<Term> terms_at_independence(const Factors& f, double vbar, CopulaFamily family,
                                        std::vector<double>* x) {
  std::vector<Term> terms(std::size_t(f.rank()));
  for (std::size_t r = 0; r < terms.size(); ++r) {
    Term& t = terms[r];
    double sum_h = 0, sum_d = 0, sum_p = 0;
    t.pdf_h = normalized(f.pdf_h[r], &sum_h);
    t.pdf_d = normalized(f.pdf_d[r], &sum_d);
    t.pdf_p = normalized(f.pdf_p[r], &sum_p);
    midpoint_cdf(t.pdf_h, &t.cdf_h);
    midpoint_cdf(t.pdf_d, &t.cdf_d);
    midpoint_cdf(t.pdf_p, &t.cdf_p);
    t.weight = sum_h * sum_d * sum_p / vbar;
    t.copula = make_grid_copula(family);
    x->push_back(std::log(t.weight));
    x->push_back(t.copula->independence());
  }
  return terms;
}

// Stage 2: the copula parameters and weights, jointly, from x (the factorization's start). Sets
// out's objectives and solver iterations; x is left at the solution, or at the start when the
// solver did not improve on it.
void solve_copulas_and_weights(const SliceData& s, std::vector<Term>& terms, double vbar,
                               FitLoss loss, const GridCopula& probe, std::vector<double>* x,
                               MixtureFit* out) {
  const std::vector<double> x0 = *x;
  const double start_objective = objective_at(s, terms, vbar, loss, x0);
  out->objective_factorization = start_objective;
  double best_objective = start_objective;
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddResidualBlock(new MixtureCost(s, terms, vbar, loss), nullptr, x->data());
  for (std::size_t r = 0; r < terms.size(); ++r) {
    problem.SetParameterLowerBound(x->data(), int(2 * r + 1), probe.search_lo());
    problem.SetParameterUpperBound(x->data(), int(2 * r + 1), probe.search_hi());
  }
  ceres::Solver::Options options = small_problem_options();
  // The fit's last digits are below what quantization keeps: stopping at a relative change of
  // kStage2Tolerance instead of 1e-10 saves most late iterations.
  options.function_tolerance = kStage2Tolerance;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  out->solver_iterations = int(summary.iterations.size());
  const double solved = 2.0 * summary.final_cost / double(s.measured_count());
  // The solver only ever improves on its start; keep the start if rounding says otherwise.
  if (solved <= start_objective &&
      std::all_of(x->begin(), x->end(), [](double v) { return std::isfinite(v); })) {
    best_objective = solved;
  } else {
    *x = x0;
  }
  out->objective = best_objective;
}

// The components as a ChannelSlice, largest first; ties keep the factorization's order.
ChannelSlice largest_first(std::vector<Term>& terms, const std::vector<double>& x, double vbar,
                           CopulaFamily family, const GridCopula& probe) {
  std::vector<std::size_t> order(terms.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t p, std::size_t q) { return x[2 * p] > x[2 * q]; });
  ChannelSlice cs;
  for (std::size_t o = 0; o < order.size(); ++o) {
    const std::size_t r = order[o];
    Component comp;
    comp.family = family;
    comp.theta = std::clamp(x[2 * r + 1], probe.search_lo(), probe.search_hi());
    comp.scale = std::exp(x[2 * r]) * vbar;
    comp.pdf_h = std::move(terms[r].pdf_h);
    comp.pdf_d = std::move(terms[r].pdf_d);
    comp.pdf_p = std::move(terms[r].pdf_p);
    if (o == 0) {
      static_cast<Component&>(cs) = std::move(comp);
    } else {
      cs.extra.push_back(std::move(comp));
    }
  }
  return cs;
}

}  // namespace

MixtureFit fit_mixture(const SliceData& s, const ChannelSlice& start, int components,
                       CopulaFamily family, FitLoss loss, bool fit_copulas) {
  return fit_mixture_continued(s, start, components, family, loss, nullptr, fit_copulas);
}

MixtureFit fit_mixture_continued(const SliceData& s, const ChannelSlice& start, int components,
                                 CopulaFamily family, FitLoss loss, MixtureState* state,
                                 bool fit_copulas) {
  MixtureFit out;
  out.cs = start;
  if (s.mv.empty()) return out;
  const double vbar = std::accumulate(s.mv.begin(), s.mv.end(), 0.0) / double(s.mv.size());
  if (!(vbar > 0)) return out;

  const Factors f = factorize(s, start, components, &out, state);
  if (f.rank() == 0) return out;

  auto probe = make_grid_copula(family);
  if (!probe) family = kAutoMixtureFamily, probe = make_grid_copula(family);
  std::vector<double> x;
  std::vector<Term> terms = terms_at_independence(f, vbar, family, &x);
  if (fit_copulas) {
    solve_copulas_and_weights(s, terms, vbar, loss, *probe, &x, &out);
  } else {
    out.objective_factorization = objective_at(s, terms, vbar, loss, x);
    out.objective = out.objective_factorization;
  }
  out.cs = largest_first(terms, x, vbar, family, *probe);
  return out;
}

}  // namespace cbrdf::internal
