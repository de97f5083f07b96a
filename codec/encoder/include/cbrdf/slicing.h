// SPDX-License-Identifier: MIT
/// @file
/// Slice boundaries along theta_d chosen from the data, for FitSettings::slice_bounds.
///
/// Within a slice the copula model gives every theta_d bin the same (theta_h, phi_d) profile up to
/// the scale f2(theta_d) (and the one-parameter copula's coupling). So the error a slice will have
/// is predicted by how much the theta_d bins' profiles differ in shape: each bin's profile, per
/// channel, is a vector over (theta_h, phi_d) (phi_d pooled in pairs), transformed (SliceCost), and
/// two bins j, l are compared on the bins both measured (not-measured bins are left out, never read
/// as 0):
///   D(j, l) = sum over channels and common bins of (q_j / mean q_j - q_l / mean q_l)^2
/// (power transforms; for kLog, the log profiles are centred instead: a scale is a shift). A
/// slice's cost is the (weighted) scatter of its profiles about their mean,
///   C(a, b) = sum_{a <= j < l < b} w_j w_l D(j, l) / sum_{a <= j < b} w_j,
/// which equals sum_j w_j |p_j - mean|^2 when all supports agree. Dynamic programming finds the
/// boundaries minimizing the sum of C over the slices exactly; among partitions of equal cost (a
/// BRDF whose shape does not change with theta_d) the most uniform one wins, so a separable table
/// gets the paper's uniform slices.
#pragma once

#include <cstdint>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// How profile values are transformed before comparing shapes (physical value v >= 0).
enum class SliceCost : std::uint8_t {
  kLinear,  ///< v: absolute error; the specular peak dominates
  kSqrt,    ///< sqrt(v): close to display gamma (1/2.2), the error a tone-mapped image shows
  kLog,     ///< log(max(v, 1e-3 x the channel's mean)): relative error everywhere
};

/// How adaptive and automatic slicing predict a slicing's cost.
struct SlicingSettings {
  SliceCost cost = SliceCost::kLinear;  ///< the error measure
  /// Weight theta_d bin j by its solid-angle measure sin^2(j + 1 deg) - sin^2(j deg) (the share of
  /// direction pairs it holds) instead of 1: grazing and near-retro bins count less.
  bool measure_weight = false;
};

/// Boundaries 0 = b0 < ... < bn = 90 (theta_d bins) of exactly `slices` slices (1 to 90) minimizing
/// the predicted cost above. Errors: kInvalidArgument for a count outside 1 to 90, kNumeric when a
/// measured bin holds a non-finite value.
Expected<std::vector<int>> adaptive_slice_bounds(const BrdfTable& table, int slices,
                                                 const SlicingSettings& settings = {});

/// The least predicted cost for 1, 2, ..., max_slices slices (entry s - 1 for s slices); it never
/// increases with s. Errors as adaptive_slice_bounds (max_slices outside 1 to 90).
Expected<std::vector<double>> slicing_cost_curve(const BrdfTable& table, int max_slices,
                                                 const SlicingSettings& settings = {});

/** The defaults of choose_slice_count(). */
///@{
inline constexpr double kDefaultSliceTolerance = 0.05;
inline constexpr int kDefaultMaxAutoSlices = 12;
///@}
/// `--slices auto`: the fewest slices (1 to max_slices) whose least predicted cost is at most
/// `tolerance` times the cost of one slice; max_slices when none is. A table whose shape does not
/// change with theta_d gets 1. Errors: kInvalidArgument for max_slices outside 1 to 90 or tolerance
/// outside [0, 1], and those of adaptive_slice_bounds.
Expected<int> choose_slice_count(const BrdfTable& table, double tolerance = kDefaultSliceTolerance,
                                 int max_slices = kDefaultMaxAutoSlices,
                                 const SlicingSettings& settings = {});

}  // namespace cbrdf
