// SPDX-License-Identifier: MIT
#include "density/grid_copula.h"

#include <algorithm>
#include <numbers>

#include "density/frank_grid.h"

namespace cbrdf::internal {
namespace {

class IndependenceGrid final : public GridCopula {
 public:
  double fit_lo() const override { return 0; }
  double fit_hi() const override { return 0; }
  double independence() const override { return 0; }
  double density(int, int, int) const override { return 1.0; }
  double density_and_derivative(int, int, int, double* d) const override {
    *d = 0;
    return 1.0;
  }
  void row(int, int, double* c, double* dc) const override {
    for (int k = 0; k < n3_; ++k) c[k] = 1.0;
    if (dc) std::fill(dc, dc + n3_, 0.0);
  }
  void prepare(double, const std::vector<double>&, const std::vector<double>&,
               const std::vector<double>& u3) override {
    n3_ = int(u3.size());
  }

 private:
  int n3_ = 0;
};

class FrankGridCopula final : public GridCopula {
 public:
  double fit_lo() const override { return kFrankGridMinAlpha; }
  double fit_hi() const override { return std::numbers::ln2; }
  double independence() const override { return 0; }
  void prepare(double theta, const std::vector<double>& u1, const std::vector<double>& u2,
               const std::vector<double>& u3) override {
    grid_.prepare(theta, u1, u2, u3);
  }
  double density(int i, int j, int k) const override { return grid_.density(i, j, k); }
  double density_and_derivative(int i, int j, int k, double* d) const override {
    return grid_.density_and_derivative(i, j, k, d);
  }
  void row(int i, int j, double* c, double* dc) const override { grid_.row(i, j, c, dc); }
  const FrankGrid& grid() const { return grid_; }

 private:
  FrankGrid grid_;
};

}  // namespace

std::unique_ptr<GridCopula> make_archimedean_grid(CopulaFamily family);

const FrankGrid* frank_grid_of(const GridCopula& copula) {
  const auto* f = dynamic_cast<const FrankGridCopula*>(&copula);
  return f ? &f->grid() : nullptr;
}

std::unique_ptr<GridCopula> make_grid_copula(CopulaFamily family) {
  switch (family) {
    case CopulaFamily::kFrank:
      return std::make_unique<FrankGridCopula>();
    case CopulaFamily::kIndependence:
      return std::make_unique<IndependenceGrid>();
    default:
      return make_archimedean_grid(family);
  }
}

void midpoint_cdf(const std::vector<double>& f, std::vector<double>* u) {
  u->resize(f.size());
  double acc = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    (*u)[i] = std::min(acc + 0.5 * f[i], 1.0);
    acc += f[i];
  }
}

}  // namespace cbrdf::internal
