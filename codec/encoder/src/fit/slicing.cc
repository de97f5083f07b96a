// SPDX-License-Identifier: MIT
#include "cbrdf/slicing.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace cbrdf {
namespace {

// phi_d bins pooled per profile entry (4 degrees): shapes along phi_d are smooth at this scale,
// and the pairwise products, the bulk of the time, shrink fourfold.
constexpr int kPhiPool = 4;
constexpr int kPooledPhi = kPhiDBins / kPhiPool;
constexpr int kEntries = kChannels * kThetaHBins * kPooledPhi;
// A pair distance below this fraction of its terms' size is rounding, not a change of shape: it is
// set to exactly 0 so that partitions of a separable table tie exactly.
constexpr double kRoundoff = 1e-9;
constexpr double kLogFloor = 1e-3;

Status check_count(int slices, const char* what) {
  if (slices < 1 || slices > kThetaDBins) {
    return error(ErrorCode::kInvalidArgument, std::string(what) + " " + std::to_string(slices) +
                                                  " is outside 1 to " +
                                                  std::to_string(kThetaDBins));
  }
  return ok_status();
}

// Transformed profiles, one row per theta_d bin: q (0 where not measured), q^2 and the mask.
struct Profiles {
  Eigen::MatrixXd q, q2, m;
};

Expected<Profiles> build_profiles(const BrdfTable& table, SliceCost cost) {
  Profiles p;
  p.q.setZero(kThetaDBins, kEntries);
  p.m.setZero(kThetaDBins, kEntries);
  for (int c = 0; c < kChannels; ++c) {
    const double* data = table.channel_data(c);
    const double scale = kMerlScale[std::size_t(c)];
    double sum = 0;
    long count = 0;
    for (int i = 0; i < kThetaHBins; ++i) {
      for (int j = 0; j < kThetaDBins; ++j) {
        const double* row = data + merl_index(i, j, 0);
        for (int k = 0; k < kPooledPhi; ++k) {
          // A pooled entry is measured only when all its bins are, so it averages like with like.
          double v = 0;
          bool all = true;
          for (int t = 0; t < kPhiPool; ++t) {
            const double s = row[k * kPhiPool + t];
            if (!(s >= 0.0)) {
              all = false;
              continue;
            }
            if (!std::isfinite(s)) {
              return error(ErrorCode::kNumeric,
                           "channel " + std::to_string(c) + " holds a non-finite value at bin " +
                               "(theta_h " + std::to_string(i) + ", theta_d " + std::to_string(j) +
                               ", phi_d " + std::to_string(k * kPhiPool + t) + ")");
            }
            v += s * scale;
          }
          if (!all) continue;
          v /= kPhiPool;
          const Eigen::Index e = (Eigen::Index(c) * kThetaHBins + i) * kPooledPhi + k;
          p.q(j, e) = v;
          p.m(j, e) = 1.0;
          sum += v;
          ++count;
        }
      }
    }
    // Per-channel normalization by the mean keeps channels comparable and values near 1.
    const double mean = count > 0 ? sum / double(count) : 0.0;
    const Eigen::Index first = Eigen::Index(c) * kThetaHBins * kPooledPhi;
    const Eigen::Index width = Eigen::Index(kThetaHBins) * kPooledPhi;
    auto q = p.q.middleCols(first, width);
    const auto m = p.m.middleCols(first, width);
    if (cost == SliceCost::kLog) {
      // Clamping (not adding) keeps a scale an exact shift for every value above the floor.
      const double floor = mean > 0 ? kLogFloor * mean : 1.0;
      q = ((q.array().max(floor) / std::max(mean, floor)).log()) * m.array();
    } else if (mean > 0) {
      q /= mean;
      if (cost == SliceCost::kSqrt) q = q.array().sqrt();
    }
  }
  p.q2 = p.q.array().square();
  return p;
}

// D(j, l) of slicing.h for every pair, from masked inner products (one matrix product).
Eigen::MatrixXd pair_distances(const Profiles& p, SliceCost cost) {
  const int n = kThetaDBins;
  Eigen::MatrixXd r(2 * n, n);  // <q_j, m_l>, <q_j^2, m_l>
  r.topRows(n).noalias() = p.q * p.m.transpose();
  r.bottomRows(n).noalias() = p.q2 * p.m.transpose();
  // The symmetric products need only one triangle (l > j is read below).
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, n);             // <q_j, q_l>
  Eigen::MatrixXd common_count = Eigen::MatrixXd::Zero(n, n);  // <m_j, m_l>
  g.selfadjointView<Eigen::Upper>().rankUpdate(p.q);
  common_count.selfadjointView<Eigen::Upper>().rankUpdate(p.m);
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    for (int l = j + 1; l < n; ++l) {
      const double common = common_count(j, l);
      if (!(common > 0)) continue;  // nothing measured in both: no evidence of a difference
      const double a = r(j, l), b = r(l, j);  // sums over the common bins
      const double sjj = r(n + j, l), sll = r(n + l, j), sjl = g(j, l);
      double dist = 0, size = 0;
      if (cost == SliceCost::kLog) {
        dist = sjj - 2 * sjl + sll - (a - b) * (a - b) / common;
        size = sjj + sll + (a * a + b * b) / common;
      } else {
        // An all-zero profile is matched exactly by a zero scale.
        if (!(a > 0) || !(b > 0)) continue;
        const double ma = a / common, mb = b / common;
        dist = sjj / (ma * ma) - 2 * sjl / (ma * mb) + sll / (mb * mb);
        size = sjj / (ma * ma) + sll / (mb * mb);
      }
      if (!(dist > kRoundoff * size)) dist = 0;
      d(j, l) = d(l, j) = dist;
    }
  }
  return d;
}

// Segment costs C(a, b) from 2-D prefix sums of w_j w_l D(j, l).
class SegmentCosts {
 public:
  SegmentCosts(const Eigen::MatrixXd& d, const std::vector<double>& w)
      : prefix_((kThetaDBins + 1) * (kThetaDBins + 1), 0.0), weight_(kThetaDBins + 1, 0.0) {
    const int n = kThetaDBins;
    for (int x = 1; x <= n; ++x) {
      weight_[x] = weight_[x - 1] + w[std::size_t(x - 1)];
      for (int y = 1; y <= n; ++y) {
        at(x, y) = at(x - 1, y) + at(x, y - 1) - at(x - 1, y - 1) +
                   w[std::size_t(x - 1)] * w[std::size_t(y - 1)] * d(x - 1, y - 1);
      }
    }
  }
  double cost(int a, int b) const {
    const double pairs = 0.5 * (at(b, b) - at(a, b) - at(b, a) + at(a, a));
    const double w = weight_[b] - weight_[a];
    return w > 0 ? std::max(0.0, pairs) / w : 0.0;
  }

 private:
  double& at(int x, int y) { return prefix_[std::size_t(x) * (kThetaDBins + 1) + y]; }
  double at(int x, int y) const { return prefix_[std::size_t(x) * (kThetaDBins + 1) + y]; }
  std::vector<double> prefix_;
  std::vector<double> weight_;
};

// Exact minimum of the summed segment cost for every count up to max_slices; ties (within rounding
// of the total) go to the smaller sum of squared widths, i.e. the more uniform partition.
struct Partitions {
  std::vector<std::vector<double>> cost;   // [s][b]: best cost of s slices over bins [0, b)
  std::vector<std::vector<long>> squares;  // the sum of squared widths of that partition
  std::vector<std::vector<int>> last;      // start of its last slice
};

Partitions solve(const SegmentCosts& c, int max_slices) {
  const int n = kThetaDBins;
  const double inf = std::numeric_limits<double>::infinity();
  const double tolerance = 1e-12 * c.cost(0, n);
  Partitions p;
  p.cost.assign(max_slices + 1, std::vector<double>(n + 1, inf));
  p.squares.assign(max_slices + 1, std::vector<long>(n + 1, 0));
  p.last.assign(max_slices + 1, std::vector<int>(n + 1, -1));
  p.cost[0][0] = 0;
  for (int s = 1; s <= max_slices; ++s) {
    for (int b = s; b <= n; ++b) {
      for (int a = s - 1; a < b; ++a) {
        if (p.cost[s - 1][a] == inf) continue;
        const double total = p.cost[s - 1][a] + c.cost(a, b);
        const long squares = p.squares[s - 1][a] + long(b - a) * (b - a);
        const double best = p.cost[s][b];
        const bool better = best == inf || total < best - tolerance ||
                            (total <= best + tolerance && squares < p.squares[s][b]);
        if (better) {
          p.cost[s][b] = total;
          p.squares[s][b] = squares;
          p.last[s][b] = a;
        }
      }
    }
  }
  return p;
}

Expected<Partitions> partitions(const BrdfTable& table, int max_slices, const SlicingSettings& st) {
  CBRDF_ASSIGN_OR_RETURN(auto profiles, build_profiles(table, st.cost));
  const Eigen::MatrixXd d = pair_distances(profiles, st.cost);
  std::vector<double> w(kThetaDBins, 1.0);
  if (st.measure_weight) {
    const double deg = std::acos(-1.0) / 180.0;
    for (int j = 0; j < kThetaDBins; ++j) {
      const double lo = std::sin(j * deg), hi = std::sin((j + 1) * deg);
      w[std::size_t(j)] = (hi * hi - lo * lo) * kThetaDBins;  // mean weight 1
    }
  }
  return solve(SegmentCosts(d, w), max_slices);
}

}  // namespace

Expected<std::vector<int>> adaptive_slice_bounds(const BrdfTable& table, int slices,
                                                 const SlicingSettings& settings) {
  CBRDF_RETURN_IF_ERROR(check_count(slices, "slice count"));
  CBRDF_ASSIGN_OR_RETURN(auto p, partitions(table, slices, settings));
  std::vector<int> bounds(std::size_t(slices) + 1);
  bounds[std::size_t(slices)] = kThetaDBins;
  for (int s = slices; s >= 1; --s) {
    bounds[std::size_t(s - 1)] = p.last[s][bounds[std::size_t(s)]];
  }
  return bounds;
}

Expected<std::vector<double>> slicing_cost_curve(const BrdfTable& table, int max_slices,
                                                 const SlicingSettings& settings) {
  CBRDF_RETURN_IF_ERROR(check_count(max_slices, "largest slice count"));
  CBRDF_ASSIGN_OR_RETURN(auto p, partitions(table, max_slices, settings));
  std::vector<double> curve;
  for (int s = 1; s <= max_slices; ++s) curve.push_back(p.cost[s][kThetaDBins]);
  return curve;
}

Expected<int> choose_slice_count(const BrdfTable& table, double tolerance, int max_slices,
                                 const SlicingSettings& settings) {
  if (!(tolerance >= 0 && tolerance <= 1)) {
    return error(ErrorCode::kInvalidArgument,
                 "slice tolerance " + std::to_string(tolerance) + " is outside [0, 1]");
  }
  CBRDF_ASSIGN_OR_RETURN(auto curve, slicing_cost_curve(table, max_slices, settings));
  const double one = curve.front();
  for (int s = 1; s <= max_slices; ++s) {
    if (curve[std::size_t(s - 1)] <= tolerance * one) return s;
  }
  return max_slices;
}

}  // namespace cbrdf
