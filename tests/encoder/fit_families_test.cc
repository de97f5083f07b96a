// SPDX-License-Identifier: MIT
// The fitter's copula family table (fit/fit_families.h), row by row: for every family with a
// parameter, fit_parameter recovers the parameter of the codec's model and, near enough, of data
// the family's own sampler drew. The decoder's side of each row: copula_registry_test.
#include "fit/fit_families.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "density/grid_copula.h"
#include "fit/fit_parameter.h"
#include "fit/marginals.h"
#include "fit/slice_data.h"

namespace cbrdf {
namespace {

// An n x n x n slice, every bin measured, values 0.
internal::SliceData empty_slice(int n) {
  internal::SliceData s;
  s.nh = s.nd = s.np = n;
  s.value.assign(std::size_t(n) * n * n, 0.0);
  s.measured.assign(s.value.size(), 1);
  return s;
}

// Fills the measured-bin lists from the values.
void list_measured(internal::SliceData* s) {
  for (int i = 0; i < s->nh; ++i)
    for (int j = 0; j < s->nd; ++j) {
      s->row_begin.push_back(std::uint32_t(s->mv.size()));
      for (int k = 0; k < s->np; ++k) {
        s->mi.push_back(std::uint8_t(i));
        s->mj.push_back(std::uint8_t(j));
        s->mk.push_back(std::uint16_t(k));
        s->mv.push_back(s->value[s->at(i, j, k)]);
        s->mw.push_back(1.0);
      }
    }
  s->row_begin.push_back(std::uint32_t(s->mv.size()));
}

// The counts of `draws` points the copula's sampler draws (uniform marginals), in n^3 bins.
internal::SliceData histogram_slice(const Copula& c, double theta, int n, int draws) {
  internal::SliceData s = empty_slice(n);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  auto bin = [n](double u) { return std::min(n - 1, int(u * n)); };
  for (int d = 0; d < draws; ++d) {
    const double u1 = uniform(rng);
    const double u2 = c.conditional2_inverse(uniform(rng), u1, theta);
    const double u3 = c.conditional3_inverse(uniform(rng), u1, u2, theta);
    s.value[s.at(bin(u1), bin(u2), bin(u3))] += 1.0;
  }
  list_measured(&s);
  return s;
}

TEST(FitFamilies, EveryRowHasItsDecoderRow) {
  for (const internal::FitFamilyRow& row : internal::kFitFamilies) {
    const CopulaFamilyRow* decoder = family_row(row.id);
    ASSERT_NE(decoder, nullptr);
    SCOPED_TRACE(std::string(decoder->name));
    // Auto only tries families it can fit, and fits no family without a parameter.
    if (row.in_auto) {
      EXPECT_TRUE(decoder->has_parameter());
    }
    EXPECT_EQ(internal::fit_family_row(row.id), &row);
  }
  EXPECT_TRUE(internal::fit_family_row(internal::kAutoMixtureFamily)->in_auto);
}

// Twice the first scan start's distance from independence: a parameter the scan does not start
// at (Frank -10, Clayton 1, Gumbel and Joe 2).
double test_parameter(const internal::FitFamilyRow& row) {
  const CopulaFamilyRow& decoder = *family_row(row.id);
  const double ind = decoder.copula().domain().independence;
  return std::clamp(ind + 2.0 * (row.scan[0] - ind), decoder.search_lo, decoder.search_hi);
}

TEST(FitFamilies, FitterRecoversTheParameterOfTheModel) {
  // Data that is exactly the codec's model (K c(U) f1 f2 f3 at the midpoint CDFs U, as decoders
  // evaluate it), over uneven marginals.
  constexpr int n = 12;
  for (const internal::FitFamilyRow& row : internal::kFitFamilies) {
    const CopulaFamilyRow& decoder = *family_row(row.id);
    if (!decoder.has_parameter()) continue;
    const double truth = test_parameter(row);
    SCOPED_TRACE(std::string(decoder.name) + " theta " + std::to_string(truth));
    std::vector<double> f(n), u;
    double sum = 0;
    for (int i = 0; i < n; ++i) sum += f[i] = 1.0 + 0.5 * std::sin(i);
    for (double& v : f) v /= sum;
    internal::midpoint_cdf(f, &u);
    auto grid = internal::make_grid_copula(row.id);
    ASSERT_NE(grid, nullptr);
    grid->prepare(truth, u, u, u);
    internal::SliceData s = empty_slice(n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          s.value[s.at(i, j, k)] = 100.0 * grid->density(i, j, k) * f[i] * f[j] * f[k];
        }
    list_measured(&s);
    internal::Marginals m = internal::naive_marginals(s);
    // The model's marginals, not the sums (which differ slightly on a grid): the fit is then exact.
    m.pdf_h = m.pdf_d = m.pdf_p = f;
    m.cdf_h = m.cdf_d = m.cdf_p = u;
    const internal::ParameterFit p = internal::fit_parameter(s, m, *grid);
    EXPECT_NEAR(p.theta, truth, 1e-3 * std::abs(truth)) << "fitted " << p.theta;
    EXPECT_NEAR(p.scale, 100.0, 1e-3);
  }
}

TEST(FitFamilies, FitterRecoversTheParameterTheSamplerDrewWith) {
  for (const internal::FitFamilyRow& row : internal::kFitFamilies) {
    const CopulaFamilyRow& decoder = *family_row(row.id);
    if (!decoder.has_parameter()) continue;
    const Copula& c = decoder.copula();
    const double ind = c.domain().independence;
    const double truth = test_parameter(row);
    SCOPED_TRACE(std::string(decoder.name) + " theta " + std::to_string(truth));
    const internal::SliceData s = histogram_slice(c, truth, 10, 60000);
    const internal::Marginals m = internal::naive_marginals(s);
    auto grid = internal::make_grid_copula(row.id);
    ASSERT_NE(grid, nullptr);
    const internal::ParameterFit p = internal::fit_parameter(s, m, *grid);
    // A histogram's bins are integrals, the model's densities at the midpoint CDF: where a family
    // has tail dependence (Clayton's lower, Gumbel's and Joe's upper) the corner bin holds mass
    // the midpoint misses at any bin size, and the fit leans towards independence (Gumbel and Joe
    // 1.74 for 2). It is far better than independence all the same.
    EXPECT_NEAR(p.theta, truth, 0.3 * std::abs(truth - ind)) << "fitted " << p.theta;
    EXPECT_LT(p.objective, 0.5 * p.objective_independence);
  }
}

}  // namespace
}  // namespace cbrdf
