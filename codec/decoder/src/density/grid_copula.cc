// SPDX-License-Identifier: MIT
#include "density/grid_copula.h"

#include <algorithm>

#include "copula/registry.h"
#include "density/frank_grid.h"

namespace cbrdf::internal {
namespace {

class IndependenceGrid final : public GridCopula {
 public:
  using GridCopula::GridCopula;
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
  using GridCopula::GridCopula;
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

CopulaFamily GridCopula::family() const {
  return row_->id;
}
double GridCopula::search_lo() const {
  return row_->search_lo;
}
double GridCopula::search_hi() const {
  return row_->search_hi;
}
double GridCopula::independence() const {
  return row_->copula().domain().independence;
}

std::unique_ptr<GridCopula> make_independence_grid(const CopulaFamilyRow& row) {
  return std::make_unique<IndependenceGrid>(row);
}

std::unique_ptr<GridCopula> make_frank_grid(const CopulaFamilyRow& row) {
  return std::make_unique<FrankGridCopula>(row);
}

const FrankGrid* frank_grid_of(const GridCopula& copula) {
  const auto* f = dynamic_cast<const FrankGridCopula*>(&copula);
  return f ? &f->grid() : nullptr;
}

std::unique_ptr<GridCopula> make_grid_copula(CopulaFamily family) {
  const CopulaFamilyRow* row = family_row(family);
  if (!row) return nullptr;
  return row->grid ? row->grid(*row) : make_archimedean_grid(family);
}

std::unique_ptr<GridCopula> make_evaluation_grid(CopulaFamily family, double theta) {
  const CopulaFamilyRow* row = family_row(family);
  if (row && theta < row->grid_lo) return make_archimedean_grid(family);
  return make_grid_copula(family);
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
