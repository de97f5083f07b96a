// SPDX-License-Identifier: MIT
// A copula density evaluated over the tensor grid of a slice's CDF values: per-axis terms are
// prepared once per parameter value, so a bin costs a few multiply-adds.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "cbrdf/copula_family.h"

namespace cbrdf {
struct CopulaFamilyRow;
}  // namespace cbrdf

namespace cbrdf::internal {

class GridCopula {
 public:
  explicit GridCopula(const CopulaFamilyRow& row) : row_(&row) {}
  virtual ~GridCopula() = default;
  CopulaFamily family() const;
  // The parameter range the fitter searches (the family's row), and the parameter of
  // independence.
  double search_lo() const;
  double search_hi() const;
  double independence() const;
  virtual void prepare(double theta, const std::vector<double>& u1, const std::vector<double>& u2,
                       const std::vector<double>& u3) = 0;
  // prepare for density() and row(i, j, c, nullptr) only, as an evaluator needs: a grid may then
  // skip what the derivative in theta takes (the Archimedean grid's second prepared grid), and its
  // derivatives are NaN.
  virtual void prepare_density(double theta, const std::vector<double>& u1,
                               const std::vector<double>& u2, const std::vector<double>& u3) {
    prepare(theta, u1, u2, u3);
  }
  virtual double density(int i, int j, int k) const = 0;
  virtual double density_and_derivative(int i, int j, int k, double* dc_dtheta) const = 0;
  // A whole phi_d row at (i, j): densities into c, derivatives into dc unless it is null.
  virtual void row(int i, int j, double* c, double* dc) const = 0;

 private:
  const CopulaFamilyRow* row_;
};

// The family's grid (its row's); null for an unknown family.
std::unique_ptr<GridCopula> make_grid_copula(CopulaFamily family);
// The general grid of the Archimedean fast path (log domain, log_density where it is not finite,
// a non-finite density read as 0) for every family with a parameter; null for independence.
std::unique_ptr<GridCopula> make_archimedean_grid(CopulaFamily family);
// The grid that evaluates theta accurately: the family's own, or the general grid below its row's
// grid_lo (Frank below kFrankGridMinAlpha, where FrankGrid's terms underflow and its density
// turns NaN), since a Model may hold any parameter of the domain.
std::unique_ptr<GridCopula> make_evaluation_grid(CopulaFamily family, double theta);

// Bins of the calling thread that the Archimedean grid evaluated off its fast path, for tests
// that bound the decoder's work (spec/container.md, "Resource bounds"): log_sum_paths formed log s
// by a log-sum-exp (a few exp and a log more than the fast path), general_paths fell back to the
// general Copula::log_density (about ten times the fast path). Reset them by assignment.
// densities counts every density the Archimedean grid evaluated (tests that bound the evaluator's
// work per pair: eval/interp_tables.h keeps a generic bin once computed).
struct GridWorkCounters {
  std::uint64_t log_sum_paths = 0;
  std::uint64_t general_paths = 0;
  std::uint64_t densities = 0;
};
GridWorkCounters& grid_work_counters();

class FrankGrid;
// The Frank grid inside a GridCopula made for kFrank (null for other families), so that hot loops
// can call its inline density directly.
const FrankGrid* frank_grid_of(const GridCopula& copula);

// Midpoint CDF of bin masses: U_i = sum_{k<i} f_k + f_i / 2 (the decoder's and the fit's).
void midpoint_cdf(const std::vector<double>& f, std::vector<double>* u);

}  // namespace cbrdf::internal
