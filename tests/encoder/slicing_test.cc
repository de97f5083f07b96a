// SPDX-License-Identifier: MIT
// Slice boundaries chosen from the data (cbrdf/slicing.h) on synthetic tables.
#include "cbrdf/slicing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "cbrdf/coords.h"
#include "cbrdf/fit.h"
#include "table_builder.h"

namespace cbrdf {
namespace {

using testing::make_table;

constexpr SliceCost kCosts[] = {SliceCost::kLinear, SliceCost::kSqrt, SliceCost::kLog};

std::string cost_name(SliceCost c) {
  switch (c) {
    case SliceCost::kLinear:
      return "linear";
    case SliceCost::kSqrt:
      return "sqrt";
    case SliceCost::kLog:
      return "log";
  }
  return "?";
}

// A lobe in theta_h whose width depends on theta_d, over a diffuse floor, with a phi_d ripple.
double lobe(int c, int i, int k, double width) {
  const double th = theta_h_of(i);
  const double pd = phi_d_of(k);
  return (0.3 + 0.1 * c) +
         20.0 * std::exp(-th * th / (width * width)) * (1.0 + 0.3 * std::cos(2 * pd));
}

// The shape is fixed below theta_d bin 70 and changes fast above it (the lobe widens tenfold), with
// a smooth overall scale along theta_d throughout that the model's f2 absorbs.
double grazing_brdf(int c, int i, int j, int k) {
  const double width = j < 70 ? 0.05 : 0.05 * (1.0 + 9.0 * (j - 69) / 20.0);
  return (1.0 + 0.02 * j) * lobe(c, i, k, width);
}

// A separable BRDF: the same (theta_h, phi_d) shape at every theta_d up to a scale.
double separable_brdf(int c, int i, int j, int k) {
  return (1.0 + 0.5 * std::cos(theta_d_of(j))) * lobe(c, i, k, 0.1);
}

// Built once: filling a table with its horizon mask takes a noticeable fraction of a second.
const BrdfTable& grazing_table() {
  static const BrdfTable t = make_table(grazing_brdf);
  return t;
}
const BrdfTable& separable_table() {
  static const BrdfTable t = make_table(separable_brdf);
  return t;
}

void expect_partition(const std::vector<int>& b, int slices) {
  ASSERT_EQ(b.size(), std::size_t(slices) + 1);
  EXPECT_EQ(b.front(), 0);
  EXPECT_EQ(b.back(), kThetaDBins);
  for (std::size_t s = 1; s < b.size(); ++s) EXPECT_LT(b[s - 1], b[s]) << "boundary " << s;
}

int slices_starting_at_or_above(const std::vector<int>& b, int bin) {
  int n = 0;
  for (std::size_t s = 0; s + 1 < b.size(); ++s) n += b[s] >= bin ? 1 : 0;
  return n;
}

TEST(Slicing, BoundariesConcentrateWhereTheShapeChanges) {
  const BrdfTable& t = grazing_table();
  for (SliceCost cost : kCosts) {
    for (bool measure : {false, true}) {
      SCOPED_TRACE(cost_name(cost) + (measure ? " measure-weighted" : ""));
      for (int slices : {3, 6, 9}) {
        auto b = adaptive_slice_bounds(t, slices, {cost, measure});
        ASSERT_TRUE(b.ok()) << b.status().message();
        expect_partition(*b, slices);
        // The 70 bins of fixed shape need one slice; every other slice goes to the changing 20.
        EXPECT_EQ(slices_starting_at_or_above(*b, 69), slices - 1) << "slices " << slices;
        EXPECT_GE((*b)[1], 69) << "slices " << slices;
      }
    }
  }
}

TEST(Slicing, SeparableTableGetsNearUniformSlices) {
  const BrdfTable& t = separable_table();
  for (SliceCost cost : kCosts) {
    SCOPED_TRACE(cost_name(cost));
    for (int slices : {1, 4, 6, 7, 90}) {
      auto b = adaptive_slice_bounds(t, slices, {cost, false});
      ASSERT_TRUE(b.ok()) << b.status().message();
      expect_partition(*b, slices);
      int lo = kThetaDBins, hi = 0;
      for (int s = 0; s < slices; ++s) {
        lo = std::min(lo, (*b)[s + 1] - (*b)[s]);
        hi = std::max(hi, (*b)[s + 1] - (*b)[s]);
      }
      EXPECT_LE(hi - lo, 1) << "slices " << slices;
    }
    // Every count costs nothing, so one slice suffices.
    auto curve = slicing_cost_curve(t, 8, {cost, false});
    ASSERT_TRUE(curve.ok());
    for (double v : *curve) EXPECT_EQ(v, 0.0);
    auto n = choose_slice_count(t, 0.05, 12, {cost, false});
    ASSERT_TRUE(n.ok());
    EXPECT_EQ(*n, 1);
  }
}

TEST(Slicing, NotMeasuredBinsDoNotMoveBoundaries) {
  // The separable table with the horizon mask, with the mask removed (the model's values there),
  // and with a further 30% of bins not measured at random must all cost 0 and slice alike. Were
  // not-measured bins read as 0, the masked profiles would differ in shape near grazing and pull
  // the boundaries there.
  const BrdfTable& masked = separable_table();
  const BrdfTable full = make_table(separable_brdf, false);
  BrdfTable holes = masked;
  std::mt19937 rng(7);
  std::bernoulli_distribution drop(0.3);
  for (std::size_t idx = 0; idx < kBinsPerChannel; ++idx) {
    if (drop(rng)) holes.set_not_measured(idx, -2.0);
  }
  for (SliceCost cost : kCosts) {
    SCOPED_TRACE(cost_name(cost));
    for (int slices : {3, 6, 12}) {
      auto a = adaptive_slice_bounds(full, slices, {cost, false});
      auto b = adaptive_slice_bounds(masked, slices, {cost, false});
      auto c = adaptive_slice_bounds(holes, slices, {cost, false});
      ASSERT_TRUE(a.ok() && b.ok() && c.ok());
      EXPECT_EQ(*a, *b) << "slices " << slices;
      EXPECT_EQ(*a, *c) << "slices " << slices;
    }
  }
  // Where the shape changes, distances are taken over fewer common bins, so boundaries may shift a
  // little, but they stay where the change is. (Read as 0, the random holes would make every
  // profile differ from every other.)
  const BrdfTable& grazing = grazing_table();
  BrdfTable grazing_holes = grazing;
  for (std::size_t idx = 0; idx < kBinsPerChannel; ++idx) {
    if (drop(rng)) grazing_holes.set_not_measured(idx);
  }
  for (SliceCost cost : kCosts) {
    SCOPED_TRACE(cost_name(cost));
    auto b = adaptive_slice_bounds(grazing_holes, 6, {cost, false});
    ASSERT_TRUE(b.ok());
    expect_partition(*b, 6);
    EXPECT_EQ(slices_starting_at_or_above(*b, 69), 5);
  }
}

TEST(Slicing, ZerosWhereNotMeasuredWouldMoveBoundaries) {
  // The counterpart of the test above: the horizon region stored as measured zeros changes the
  // profiles' shapes near grazing, and the boundaries follow. This shows the mask is what keeps
  // them uniform.
  const BrdfTable full = make_table(separable_brdf, false);
  BrdfTable zeros = separable_table();
  for (double& v : zeros.stored_values()) v = std::max(v, 0.0);
  for (SliceCost cost : kCosts) {
    SCOPED_TRACE(cost_name(cost));
    auto a = adaptive_slice_bounds(full, 6, {cost, false});
    auto b = adaptive_slice_bounds(zeros, 6, {cost, false});
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_NE(*a, *b);
    auto curve = slicing_cost_curve(zeros, 2, {cost, false});
    ASSERT_TRUE(curve.ok());
    EXPECT_GT((*curve)[0], 0.0);
  }
}

TEST(Slicing, CostCurveNeverIncreasesAndAutoCountFollowsIt) {
  const BrdfTable& t = grazing_table();
  auto curve = slicing_cost_curve(t, 12);
  ASSERT_TRUE(curve.ok());
  ASSERT_EQ(curve->size(), 12u);
  EXPECT_GT((*curve)[0], 0.0);
  for (std::size_t s = 1; s < curve->size(); ++s) EXPECT_LE((*curve)[s], (*curve)[s - 1]);
  for (double tolerance : {0.0, 0.01, 0.05, 0.2, 1.0}) {
    auto n = choose_slice_count(t, tolerance, 12);
    ASSERT_TRUE(n.ok());
    // The fewest slices within tolerance, or 12 when none is.
    int expected = 12;
    for (int s = 1; s <= 12; ++s) {
      if ((*curve)[std::size_t(s - 1)] <= tolerance * (*curve)[0]) {
        expected = s;
        break;
      }
    }
    EXPECT_EQ(*n, expected) << "tolerance " << tolerance;
  }
  auto one = choose_slice_count(t, 1.0, 12);
  ASSERT_TRUE(one.ok());
  EXPECT_EQ(*one, 1);
  auto strict = choose_slice_count(t, 1e-3, 12);
  ASSERT_TRUE(strict.ok());
  EXPECT_GT(*strict, 1);
}

TEST(Slicing, BoundsAreAcceptedByTheFit) {
  const BrdfTable& t = grazing_table();
  auto b = adaptive_slice_bounds(t, 4);
  ASSERT_TRUE(b.ok());
  FitSettings st;
  st.slice_bounds = *b;
  auto checked = slice_bounds(st);
  ASSERT_TRUE(checked.ok()) << checked.status().message();
  EXPECT_EQ(*checked, *b);
}

TEST(Slicing, RefusesInvalidArguments) {
  const BrdfTable& t = separable_table();
  for (int slices : {0, -3, 91, 1000}) {
    auto b = adaptive_slice_bounds(t, slices);
    ASSERT_FALSE(b.ok());
    EXPECT_EQ(b.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(b.status().message().find(std::to_string(slices)), std::string::npos)
        << b.status().message();
    EXPECT_NE(b.status().message().find("1 to 90"), std::string::npos) << b.status().message();
    auto curve = slicing_cost_curve(t, slices);
    ASSERT_FALSE(curve.ok());
    EXPECT_EQ(curve.status().code(), ErrorCode::kInvalidArgument);
    auto n = choose_slice_count(t, 0.05, slices);
    ASSERT_FALSE(n.ok());
    EXPECT_EQ(n.status().code(), ErrorCode::kInvalidArgument);
  }
  for (double tolerance : {-0.1, 1.5, std::nan("")}) {
    auto n = choose_slice_count(t, tolerance, 12);
    ASSERT_FALSE(n.ok());
    EXPECT_EQ(n.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(n.status().message().find("tolerance"), std::string::npos) << n.status().message();
  }
  BrdfTable bad = t;
  bad.set_stored(1, merl_index(3, 40, 11), std::numeric_limits<double>::infinity());
  auto b = adaptive_slice_bounds(bad, 6);
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.status().code(), ErrorCode::kNumeric);
  EXPECT_NE(b.status().message().find("theta_h 3, theta_d 40, phi_d 11"), std::string::npos)
      << b.status().message();
}

}  // namespace
}  // namespace cbrdf
