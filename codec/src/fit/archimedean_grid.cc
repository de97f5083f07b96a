// GridCopula for the families without a closed product form (Clayton, Gumbel, Joe), through the
// Archimedean fast path of copula.h: log c = log|psi'''(s)| + sum_i log|phi'(u_i)|, s = sum_i
// phi(u_i). Per-axis terms are prepared once per parameter, so a bin costs two adds, one log/exp
// and the family's third derivative. Where the fast path is not finite (phi over- or underflows at
// large parameters) the bin falls back to the general log_density. The derivative in the parameter
// is a one-sided difference with a second prepared grid (the fitter only needs it to steer: Ceres's
// cost, and so its acceptance of steps, is exact).
#include <cmath>
#include <limits>
#include <numbers>

#include "cbrdf/copula.h"
#include "fit/grid_copula.h"

namespace cbrdf::fit {
namespace {

struct AxisTerms {
  std::vector<double> psi, log_dpsi, u;
};

class PreparedGrid {
 public:
  void prepare(const Copula& c, double theta, const std::vector<double>* u[3]) {
    copula_ = &c;
    theta_ = theta;
    path_ = c.prepare_fast_path(theta);
    for (int a = 0; a < 3; ++a) {
      AxisTerms& t = axes_[a];
      t.u = *u[a];
      t.psi.resize(t.u.size());
      t.log_dpsi.resize(t.u.size());
      for (std::size_t i = 0; i < t.u.size(); ++i) {
        const Copula::AxisTerm term = c.axis_term(t.u[i], theta);
        t.psi[i] = term.psi;
        t.log_dpsi[i] = term.log_abs_dpsi;
      }
    }
  }
  double density(int i, int j, int k) const {
    const double s = axes_[0].psi[i] + axes_[1].psi[j] + axes_[2].psi[k];
    const double l = axes_[0].log_dpsi[i] + axes_[1].log_dpsi[j] + axes_[2].log_dpsi[k];
    double log_c = copula_->log_abs_inverse_third_derivative(s, path_) + l;
    if (!std::isfinite(log_c) && !(log_c == -std::numeric_limits<double>::infinity())) {
      log_c = copula_->log_density(axes_[0].u[i], axes_[1].u[j], axes_[2].u[k], theta_);
    }
    const double c = std::exp(log_c);
    return std::isfinite(c) ? c : 0.0;
  }

 private:
  const Copula* copula_ = nullptr;
  double theta_ = 0;
  Copula::FastPath path_;
  AxisTerms axes_[3];
};

class ArchimedeanGrid final : public GridCopula {
 public:
  ArchimedeanGrid(CopulaFamily family, double fit_lo, double fit_hi)
      : copula_(copula_for(family)), lo_(fit_lo), hi_(fit_hi) {}
  double fit_lo() const override { return lo_; }
  double fit_hi() const override { return hi_; }
  double independence() const override { return copula_.domain().independence; }

  void prepare(double theta, const std::vector<double>& u1, const std::vector<double>& u2,
               const std::vector<double>& u3) override {
    const std::vector<double>* u[3] = {&u1, &u2, &u3};
    n3_ = int(u3.size());
    grid_.prepare(copula_, theta, u);
    // Forward inside the domain, backward at its upper end.
    const double step = 1e-6 * std::max(1.0, std::abs(theta));
    other_theta_ = theta + step <= hi_ ? theta + step : theta - step;
    other_.prepare(copula_, other_theta_, u);
    span_ = other_theta_ - theta;
  }
  double density(int i, int j, int k) const override { return grid_.density(i, j, k); }
  double density_and_derivative(int i, int j, int k, double* d) const override {
    const double c = grid_.density(i, j, k);
    *d = (other_.density(i, j, k) - c) / span_;
    return c;
  }
  void row(int i, int j, double* c, double* dc) const override {
    for (int k = 0; k < n3_; ++k) {
      c[k] = grid_.density(i, j, k);
      if (dc) dc[k] = (other_.density(i, j, k) - c[k]) / span_;
    }
  }

 private:
  const Copula& copula_;
  double lo_, hi_;
  int n3_ = 0;
  double other_theta_ = 0, span_ = 1;
  PreparedGrid grid_, other_;
};

}  // namespace

// Fit ranges: beyond these the dependence is so strong that the three marginals are nearly
// comonotone, which no BRDF slice in the MERL data approaches (the fitted Frank parameters stay
// within |alpha| < 10); the file format accepts the whole domain.
std::unique_ptr<GridCopula> make_archimedean_grid(CopulaFamily family) {
  switch (family) {
    case CopulaFamily::kFrank:  // not fitted through this grid: its range is the whole domain
      return std::make_unique<ArchimedeanGrid>(family, -std::numeric_limits<double>::max(),
                                               std::numbers::ln2);
    case CopulaFamily::kClayton:
      return std::make_unique<ArchimedeanGrid>(family, 0.0, 50.0);
    case CopulaFamily::kGumbel:
      return std::make_unique<ArchimedeanGrid>(family, 1.0, 20.0);
    case CopulaFamily::kJoe:
      return std::make_unique<ArchimedeanGrid>(family, 1.0, 20.0);
    default:
      return nullptr;
  }
}

}  // namespace cbrdf::fit
