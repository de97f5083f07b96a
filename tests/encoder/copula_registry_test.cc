// SPDX-License-Identifier: MIT
// The copula family table (copula/registry.h), row by row: what a family added as one file plus
// one row must satisfy for the decoder. Names round-trip through parsing, ids through the
// container, the density integrates to 1, is the CDF's mixed derivative and stays finite at the
// range's edges, and the sampler (conditional inversion) draws the CDF's cell masses. The fitter's
// rows: fit_families_test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cbrdf/cbrdf_c.h"
#include "cbrdf/codec.h"
#include "cbrdf/container_writer.h"
#include "coding_1_2.h"
#include "copula/registry.h"
#include "density/grid_copula.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

double independence_of(const CopulaFamilyRow& row) {
  return row.copula().domain().independence;
}

// Parameters to check a row at: independence, and a weak and a strong dependence on the side of
// independence with more room in the search range (Frank -2 and -20, Clayton 0.5 and 5).
std::vector<double> parameters(const CopulaFamilyRow& row) {
  const double ind = independence_of(row);
  if (!row.has_parameter()) return {ind};
  const double far = row.search_hi - ind >= ind - row.search_lo ? row.search_hi : row.search_lo;
  return {ind, ind + 0.01 * (far - ind), ind + 0.1 * (far - ind)};
}

std::string label(const CopulaFamilyRow& row, double theta) {
  return std::string(row.name) + " theta " + std::to_string(theta);
}

// Probability of the box [a, b] under the copula, by integrating its density: a midpoint rule in
// t with u = a + (b - a)(1 - cos(pi t)) / 2 per axis, whose points crowd the box's faces, where
// Clayton, Gumbel and Joe have their tail singularities.
double box_mass(const Copula& c, double theta, const double a[3], const double b[3], int m) {
  std::vector<double> u[3], w[3];
  for (int axis = 0; axis < 3; ++axis) {
    for (int i = 0; i < m; ++i) {
      const double t = (i + 0.5) / m, h = b[axis] - a[axis];
      u[axis].push_back(a[axis] + h * 0.5 * (1 - std::cos(std::numbers::pi * t)));
      w[axis].push_back(h * 0.5 * std::numbers::pi * std::sin(std::numbers::pi * t) / m);
    }
  }
  double sum = 0;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      for (int k = 0; k < m; ++k) {
        sum += c.density(u[0][i], u[1][j], u[2][k], theta) * w[0][i] * w[1][j] * w[2][k];
      }
  return sum;
}

// The same from the CDF, by inclusion-exclusion over the box's corners.
double box_cdf(const Copula& c, double theta, const double a[3], const double b[3]) {
  double sum = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const double x = corner & 1 ? b[0] : a[0], y = corner & 2 ? b[1] : a[1];
    const double z = corner & 4 ? b[2] : a[2];
    const int lows = !(corner & 1) + !(corner & 2) + !(corner & 4);
    sum += (lows % 2 ? -1 : 1) * c.cdf(x, y, z, theta);
  }
  return sum;
}

TEST(CopulaRegistry, NamesRoundTripThroughParsing) {
  std::vector<CopulaFamily> listed = listed_families();
  ASSERT_EQ(listed.size(), kCopulaFamilyCount);
  const std::string list = family_list(", ");
  for (const CopulaFamilyRow& row : kCopulaFamilies) {
    SCOPED_TRACE(std::string(row.name));
    EXPECT_FALSE(row.name.empty());
    EXPECT_EQ(family_from_name(row.name), row.id);
    EXPECT_EQ(family_name(row.id), row.name);
    EXPECT_STREQ(cbrdf_family_name(int(row.id)), std::string(row.name).c_str());
    EXPECT_TRUE(family_valid(std::uint8_t(row.id)));
    // The family's mathematics reports the row it sits in.
    EXPECT_EQ(row.copula().family(), row.id);
    EXPECT_EQ(copula_for(row.id).family(), row.id);
    EXPECT_EQ(std::count(listed.begin(), listed.end(), row.id), 1);
    EXPECT_NE(list.find(std::string(row.name)), std::string::npos);
    // Names are exact: no case folding, no prefixes.
    EXPECT_FALSE(family_from_name(std::string(row.name) + "x"));
  }
  // One past the last row is no family, for the C API and for files.
  if (kCopulaFamilyCount < 256) {
    EXPECT_FALSE(family_valid(std::uint8_t(kCopulaFamilyCount)));
    EXPECT_STREQ(cbrdf_family_name(int(kCopulaFamilyCount)), "unknown");
  }
}

TEST(CopulaRegistry, IdRoundTripsThroughTheContainer) {
  ContainerSettings fast = testing::coding_1_2();
  fast.zstd_level = 1;
  for (const CopulaFamilyRow& row : kCopulaFamilies) {
    for (double theta : {row.search_lo, row.search_hi, parameters(row).back()}) {
      SCOPED_TRACE(label(row, theta));
      Model m = testing::make_model({0, 45, 90});
      for (Slice& s : m.slices) {
        for (ChannelSlice& cs : s.channel) {
          cs.family = row.id;
          cs.theta = theta;
        }
      }
      auto bytes = encode_model(m, fast);
      ASSERT_TRUE(bytes.ok()) << bytes.status().message();
      auto back = decode_model(*bytes);
      ASSERT_TRUE(back.ok()) << back.status().message();
      for (const Slice& s : back->slices) {
        for (const ChannelSlice& cs : s.channel) {
          EXPECT_EQ(cs.family, row.id);
          EXPECT_EQ(cs.theta, theta);
        }
      }
      // Just outside the range a file may hold, the encoder refuses the parameter.
      if (row.has_parameter()) {
        m.slices[0].channel[0].theta = std::nextafter(row.search_hi, 1e300);
        EXPECT_FALSE(encode_model(m, fast).ok());
      }
    }
  }
}

// The format's contract lists every row: the MODL family byte's values and the ranges a file may
// hold (spec/container.md, section 4.2).
TEST(CopulaRegistry, SpecListsEveryRow) {
  std::ifstream in(CBRDF_TEST_DATA_DIR "/../../spec/container.md");
  ASSERT_TRUE(in.good());
  std::stringstream text;
  text << in.rdbuf();
  const std::string spec = text.str();
  std::string ids;
  for (const CopulaFamilyRow& row : kCopulaFamilies) {
    ids += (ids.empty() ? "" : ", ") + std::to_string(int(row.id)) + " " + std::string(row.title);
  }
  EXPECT_NE(spec.find("u8  family  (" + ids + ":"), std::string::npos) << ids;
  EXPECT_NE(spec.find("family at most " + std::to_string(kCopulaFamilyCount - 1) + ";"),
            std::string::npos);
  auto number = [](double v) {
    if (v == std::numbers::ln2) return std::string("ln 2");
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return std::string(buf);
  };
  for (const CopulaFamilyRow& row : kCopulaFamilies) {
    const std::string range = row.has_parameter()
                                  ? "[" + number(row.search_lo) + ", " + number(row.search_hi) + "]"
                                  : "{" + number(row.search_lo) + "}";
    const std::size_t line = spec.find("\n| " + std::string(row.title));
    ASSERT_NE(line, std::string::npos) << row.title;
    const std::string cells = spec.substr(line, spec.find('\n', line + 1) - line);
    EXPECT_NE(cells.find("| " + range + " |"), std::string::npos) << cells << " lacks " << range;
  }
}

TEST(CopulaRegistry, DensityIntegratesToOneAndIsFiniteAtTheEdges) {
  for (const CopulaFamilyRow& row : kCopulaFamilies) {
    const Copula& c = row.copula();
    const std::vector<double> thetas = parameters(row);
    for (double theta : thetas) {
      SCOPED_TRACE(label(row, theta));
      EXPECT_DOUBLE_EQ(c.cdf(1, 1, 1, theta), 1.0);
      // A fixed rule resolves the density's ridge along the diagonal only for weak dependence;
      // stronger ones are held to the CDF point by point (DensityIsTheCdfsMixedDerivative).
      if (theta == thetas.back() && thetas.size() > 2) continue;
      const double zero[3] = {0, 0, 0}, one[3] = {1, 1, 1};
      EXPECT_NEAR(box_mass(c, theta, zero, one, 64), 1.0, 0.01);
    }
    // At the edges of the range a file may hold: never NaN on the closed cube, finite inside,
    // and the fitter's and evaluator's grid finite at every bin.
    for (double theta : {row.search_lo, row.search_hi}) {
      SCOPED_TRACE(label(row, theta));
      EXPECT_TRUE(c.in_domain(theta));
      const double us[] = {0.0, 1e-300, 1e-9, 0.25, 0.5, 0.75, 1 - 1e-9, 1.0};
      for (double u1 : us)
        for (double u2 : us)
          for (double u3 : us) {
            const double l = c.log_density(u1, u2, u3, theta);
            EXPECT_FALSE(std::isnan(l)) << u1 << " " << u2 << " " << u3;
            const bool inside = u1 > 0 && u1 < 1 && u2 > 0 && u2 < 1 && u3 > 0 && u3 < 1;
            if (inside) {
              EXPECT_LT(l, std::numeric_limits<double>::infinity());
            }
          }
      std::vector<double> u(9);
      for (int i = 0; i < 9; ++i) u[i] = (i + 0.5) / 9;
      std::unique_ptr<internal::GridCopula> grids[] = {
          internal::make_grid_copula(row.id), internal::make_evaluation_grid(row.id, theta)};
      for (const auto& grid : grids) {
        ASSERT_NE(grid, nullptr);
        EXPECT_EQ(grid->family(), row.id);
        grid->prepare(theta, u, u, u);
        for (int i = 0; i < 9; ++i)
          for (int j = 0; j < 9; ++j)
            for (int k = 0; k < 9; ++k) {
              const double d = grid->density(i, j, k);
              EXPECT_TRUE(std::isfinite(d) && d >= 0) << i << " " << j << " " << k << ": " << d;
            }
      }
    }
  }
}

// d^3 C / du1 du2 du3 by central differences (step h) equals the density, at every parameter
// checked, weak or strong.
TEST(CopulaRegistry, DensityIsTheCdfsMixedDerivative) {
  constexpr double h = 1e-3;
  for (const CopulaFamilyRow& row : kCopulaFamilies) {
    const Copula& c = row.copula();
    for (double theta : parameters(row)) {
      SCOPED_TRACE(label(row, theta));
      for (double u1 : {0.2, 0.5, 0.8})
        for (double u2 : {0.3, 0.5, 0.7})
          for (double u3 : {0.25, 0.5, 0.9}) {
            const double a[3] = {u1 - h, u2 - h, u3 - h}, b[3] = {u1 + h, u2 + h, u3 + h};
            const double derivative = box_cdf(c, theta, a, b) / (8 * h * h * h);
            const double d = c.density(u1, u2, u3, theta);
            EXPECT_NEAR(derivative, d, 1e-3 * d + 1e-6) << u1 << " " << u2 << " " << u3;
          }
    }
  }
}

TEST(CopulaRegistry, SamplerDrawsTheCopulasDistribution) {
  constexpr int cells = 3, draws = 12000;
  for (const CopulaFamilyRow& row : kCopulaFamilies) {
    const Copula& c = row.copula();
    for (double theta : parameters(row)) {
      SCOPED_TRACE(label(row, theta));
      std::mt19937_64 rng(7);
      std::uniform_real_distribution<double> uniform(0.0, 1.0);
      std::vector<int> count(cells * cells * cells, 0);
      for (int n = 0; n < draws; ++n) {
        const double u1 = uniform(rng);
        const double u2 = c.conditional2_inverse(uniform(rng), u1, theta);
        const double u3 = c.conditional3_inverse(uniform(rng), u1, u2, theta);
        ASSERT_TRUE(u2 >= 0 && u2 <= 1 && u3 >= 0 && u3 <= 1) << u2 << " " << u3;
        auto cell = [](double u) { return std::min(cells - 1, int(u * cells)); };
        ++count[(cell(u1) * cells + cell(u2)) * cells + cell(u3)];
      }
      // Pearson's chi-square over the cells against the CDF's masses (the density is the CDF's
      // mixed derivative, DensityIsTheCdfsMixedDerivative): 26 degrees of freedom,
      // so a correct sampler stays below 60 but for one seed in about 4000.
      double chi2 = 0, total = 0;
      for (int i = 0; i < cells; ++i)
        for (int j = 0; j < cells; ++j)
          for (int k = 0; k < cells; ++k) {
            const double a[3] = {double(i) / cells, double(j) / cells, double(k) / cells};
            const double b[3] = {double(i + 1) / cells, double(j + 1) / cells,
                                 double(k + 1) / cells};
            const double p = box_cdf(c, theta, a, b);
            total += p;
            const double expected = p * draws;
            const double d = count[(i * cells + j) * cells + k] - expected;
            chi2 += d * d / std::max(expected, 1.0);
          }
      EXPECT_NEAR(total, 1.0, 1e-12);
      EXPECT_LT(chi2, 60.0);
    }
  }
}

}  // namespace
}  // namespace cbrdf
