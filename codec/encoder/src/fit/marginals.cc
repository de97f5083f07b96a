#include "fit/marginals.h"

#include <algorithm>
#include <cmath>

namespace cbrdf::fit {
namespace {

void normalize(std::vector<double>* f) {
  double sum = 0;
  for (double v : *f) sum += v;
  if (sum > 0) {
    for (double& v : *f) v /= sum;
  } else {
    std::fill(f->begin(), f->end(), 1.0 / double(f->size()));
  }
}

// Largest change relative to the largest mass.
double change(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0, m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    d = std::max(d, std::abs(a[i] - b[i]));
    m = std::max(m, std::abs(b[i]));
  }
  return m > 0 ? d / m : 0;
}

}  // namespace

void prepare(GridCopula& copula, double theta, const Marginals& m) {
  copula.prepare(theta, m.u1, m.u2, m.u3);
}

Marginals naive_marginals(const SliceData& s) {
  Marginals m;
  m.f1.assign(s.nh, 0.0);
  m.f2.assign(s.nd, 0.0);
  m.f3.assign(s.np, 0.0);
  double total = 0;
  for (std::size_t n = 0; n < s.mv.size(); ++n) {
    m.f1[s.mi[n]] += s.mv[n];
    m.f2[s.mj[n]] += s.mv[n];
    m.f3[s.mk[n]] += s.mv[n];
    total += s.mv[n];
  }
  normalize(&m.f1);
  normalize(&m.f2);
  normalize(&m.f3);
  midpoint_cdf(m.f1, &m.u1);
  midpoint_cdf(m.f2, &m.u2);
  midpoint_cdf(m.f3, &m.u3);
  m.total = total;
  return m;
}

int impute_marginals(const SliceData& s, GridCopula& copula, double theta, int max_rounds,
                     double tolerance, Marginals* m) {
  // Measured sums per axis bin do not change: compute them once.
  std::vector<double> obs1(s.nh, 0.0), obs2(s.nd, 0.0), obs3(s.np, 0.0);
  for (std::size_t n = 0; n < s.mv.size(); ++n) {
    obs1[s.mi[n]] += s.mv[n];
    obs2[s.mj[n]] += s.mv[n];
    obs3[s.mk[n]] += s.mv[n];
  }
  const bool independent = theta == copula.independence();
  std::vector<double> pred_obs, pred_all, c(std::size_t(s.np), 1.0);
  int rounds = 0;
  double moved = 0;
  for (; rounds < max_rounds; ++rounds) {
    moved = 0;
    for (int axis = 0; axis < 3; ++axis) {
      prepare(copula, theta, *m);
      std::vector<double>& f = axis == 0 ? m->f1 : axis == 1 ? m->f2 : m->f3;
      const std::vector<double>& obs = axis == 0 ? obs1 : axis == 1 ? obs2 : obs3;
      pred_obs.assign(f.size(), 0.0);
      pred_all.assign(f.size(), 0.0);
      if (independent) {
        // c = 1: the other two axes' masses each sum to 1, so the whole is 1 and only the
        // measured part needs a pass, over the measured bins alone.
        std::fill(pred_all.begin(), pred_all.end(), 1.0);
        // One loop per axis, walking the measured bins row by row: f1 f2 is constant along a
        // row, so the inner loops are gathers of f3 only.
        for (int i = 0; i < s.nh; ++i) {
          for (int j = 0; j < s.nd; ++j) {
            const std::size_t row = std::size_t(i) * std::size_t(s.nd) + std::size_t(j);
            const std::uint32_t begin = s.row_begin[row], end = s.row_begin[row + 1];
            if (begin == end) continue;
            if (axis == 2) {
              const double f12 = m->f1[i] * m->f2[j];
              for (std::uint32_t q = begin; q < end; ++q) pred_obs[s.mk[q]] += f12;
              continue;
            }
            double f3_sum = 0;
            for (std::uint32_t q = begin; q < end; ++q) f3_sum += m->f3[s.mk[q]];
            if (axis == 0) {
              pred_obs[i] += m->f2[j] * f3_sum;
            } else {
              pred_obs[j] += m->f1[i] * f3_sum;
            }
          }
        }
      } else {
        // The model's mass over the other two axes, measured part and whole, per bin of this axis
        // (this axis's own mass cancels in the ratio).
        for (int i = 0; i < s.nh; ++i) {
          for (int j = 0; j < s.nd; ++j) {
            const double o12 = (axis == 0 ? 1.0 : m->f1[i]) * (axis == 1 ? 1.0 : m->f2[j]);
            if (o12 == 0.0) continue;
            if (!independent) copula.row(i, j, c.data(), nullptr);
            const std::uint8_t* meas = s.measured.data() + s.at(i, j, 0);
            double row_all = 0, row_obs = 0;
            for (int k = 0; k < s.np; ++k) {
              double w = o12 * (axis == 2 ? 1.0 : m->f3[k]);
              if (!independent) w *= c[k];
              if (axis == 2) {
                pred_all[k] += w;
                if (meas[k]) pred_obs[k] += w;
              } else {
                row_all += w;
                if (meas[k]) row_obs += w;
              }
            }
            if (axis != 2) {
              const int b = axis == 0 ? i : j;
              pred_all[b] += row_all;
              pred_obs[b] += row_obs;
            }
          }
        }
      }
      std::vector<double> next(f.size());
      for (std::size_t b = 0; b < f.size(); ++b) {
        // No model mass measured in this bin: it is either fully missing (no information, keep
        // nothing) or the model has no mass there yet (take its measured sum as it is).
        next[b] = pred_obs[b] > 0 ? obs[b] * (pred_all[b] / pred_obs[b]) : obs[b];
      }
      normalize(&next);
      moved = std::max(moved, change(f, next));
      f = std::move(next);
      std::vector<double>& u = axis == 0 ? m->u1 : axis == 1 ? m->u2 : m->u3;
      midpoint_cdf(f, &u);
    }
    if (moved <= tolerance) {
      ++rounds;
      break;
    }
  }
  m->total = 0;
  for (double v : s.mv) m->total += v;
  return rounds;
}

}  // namespace cbrdf::fit
