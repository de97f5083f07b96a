// SPDX-License-Identifier: MIT
#include "fit/marginals.h"

#include <algorithm>
#include <cmath>

#include "encode_watch.h"

namespace cbrdf::internal {
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

// The measured values' sums per bin of each axis (theta_h, theta_d, phi_d).
struct AxisSums {
  std::vector<double> h, d, p;
  double total = 0;
};

AxisSums measured_sums(const SliceData& s) {
  AxisSums sums{std::vector<double>(s.nh, 0.0), std::vector<double>(s.nd, 0.0),
                std::vector<double>(s.np, 0.0)};
  for (std::size_t n = 0; n < s.mv.size(); ++n) {
    sums.h[s.mi[n]] += s.mv[n];
    sums.d[s.mj[n]] += s.mv[n];
    sums.p[s.mk[n]] += s.mv[n];
    sums.total += s.mv[n];
  }
  return sums;
}

// The model's mass over the other two axes, measured part only, per bin of `axis`, under the
// independence copula (c = 1: the whole is 1, since the other two axes' masses each sum to 1). One
// loop per axis, walking the measured bins row by row: pdf_h pdf_d is constant along a row, so the
// inner loops are gathers of pdf_p only.
void measured_mass_at_independence(const SliceData& s, const Marginals& m, int axis,
                                   std::vector<double>* pred_obs) {
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      const std::size_t row = std::size_t(i) * std::size_t(s.nd) + std::size_t(j);
      const std::uint32_t begin = s.row_begin[row], end = s.row_begin[row + 1];
      if (begin == end) continue;
      if (axis == 2) {
        const double pdf_hd = m.pdf_h[i] * m.pdf_d[j];
        for (std::uint32_t q = begin; q < end; ++q) (*pred_obs)[s.mk[q]] += pdf_hd;
        continue;
      }
      double pdf_p_sum = 0;
      for (std::uint32_t q = begin; q < end; ++q) pdf_p_sum += m.pdf_p[s.mk[q]];
      if (axis == 0) {
        (*pred_obs)[i] += m.pdf_d[j] * pdf_p_sum;
      } else {
        (*pred_obs)[j] += m.pdf_h[i] * pdf_p_sum;
      }
    }
  }
}

// The model's mass over the other two axes, measured part and whole, per bin of `axis` (this
// axis's own mass cancels in the ratio), with `copula` prepared at m's CDFs. `c` is scratch of np.
void model_mass(const SliceData& s, const GridCopula& copula, const Marginals& m, int axis,
                std::vector<double>* c, std::vector<double>* pred_obs,
                std::vector<double>* pred_all) {
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      const double pdf_hd = (axis == 0 ? 1.0 : m.pdf_h[i]) * (axis == 1 ? 1.0 : m.pdf_d[j]);
      if (pdf_hd == 0.0) continue;
      copula.row(i, j, c->data(), nullptr);
      const std::uint8_t* meas = s.measured.data() + s.at(i, j, 0);
      double row_all = 0, row_obs = 0;
      for (int k = 0; k < s.np; ++k) {
        double w = pdf_hd * (axis == 2 ? 1.0 : m.pdf_p[k]);
        w *= (*c)[k];
        if (axis == 2) {
          (*pred_all)[k] += w;
          if (meas[k]) (*pred_obs)[k] += w;
        } else {
          row_all += w;
          if (meas[k]) row_obs += w;
        }
      }
      if (axis != 2) {
        const int b = axis == 0 ? i : j;
        (*pred_all)[b] += row_all;
        (*pred_obs)[b] += row_obs;
      }
    }
  }
}

// One raking step of an axis: its masses become the measured sums scaled up by the model's whole
// over measured mass, normalized. Returns the largest change (relative to the largest mass).
double rake(const std::vector<double>& obs, const std::vector<double>& pred_obs,
            const std::vector<double>& pred_all, std::vector<double>* pdf,
            std::vector<double>* cdf) {
  std::vector<double> next(pdf->size());
  for (std::size_t b = 0; b < pdf->size(); ++b) {
    // No model mass measured in this bin: it is either fully missing (no information, keep
    // nothing) or the model has no mass there yet (take its measured sum as it is).
    next[b] = pred_obs[b] > 0 ? obs[b] * (pred_all[b] / pred_obs[b]) : obs[b];
  }
  normalize(&next);
  const double moved = change(*pdf, next);
  *pdf = std::move(next);
  midpoint_cdf(*pdf, cdf);
  return moved;
}

}  // namespace

void prepare(GridCopula& copula, double theta, const Marginals& m) {
  copula.prepare(theta, m.cdf_h, m.cdf_d, m.cdf_p);
}

Marginals naive_marginals(const SliceData& s) {
  AxisSums sums = measured_sums(s);
  Marginals m;
  m.pdf_h = std::move(sums.h);
  m.pdf_d = std::move(sums.d);
  m.pdf_p = std::move(sums.p);
  normalize(&m.pdf_h);
  normalize(&m.pdf_d);
  normalize(&m.pdf_p);
  midpoint_cdf(m.pdf_h, &m.cdf_h);
  midpoint_cdf(m.pdf_d, &m.cdf_d);
  midpoint_cdf(m.pdf_p, &m.cdf_p);
  m.total = sums.total;
  return m;
}

int impute_marginals(const SliceData& s, GridCopula& copula, double theta, int max_rounds,
                     double tolerance, Marginals* m) {
  // Measured sums per axis bin do not change: compute them once.
  const AxisSums sums = measured_sums(s);
  const bool independent = theta == copula.independence();
  std::vector<double> pred_obs, pred_all, c(std::size_t(s.np), 1.0);
  int rounds = 0;
  double moved = 0;
  for (; rounds < max_rounds; ++rounds) {
    if (cancel_requested()) break;  // the encode returns kCancelled: m need not be good
    moved = 0;
    for (int axis = 0; axis < 3; ++axis) {
      prepare(copula, theta, *m);
      std::vector<double>& pdf = axis == 0 ? m->pdf_h : axis == 1 ? m->pdf_d : m->pdf_p;
      std::vector<double>& cdf = axis == 0 ? m->cdf_h : axis == 1 ? m->cdf_d : m->cdf_p;
      const std::vector<double>& obs = axis == 0 ? sums.h : axis == 1 ? sums.d : sums.p;
      pred_obs.assign(pdf.size(), 0.0);
      pred_all.assign(pdf.size(), 0.0);
      if (independent) {
        std::fill(pred_all.begin(), pred_all.end(), 1.0);
        measured_mass_at_independence(s, *m, axis, &pred_obs);
      } else {
        model_mass(s, copula, *m, axis, &c, &pred_obs, &pred_all);
      }
      moved = std::max(moved, rake(obs, pred_obs, pred_all, &pdf, &cdf));
    }
    if (moved <= tolerance) {
      ++rounds;
      break;
    }
  }
  m->total = sums.total;
  return rounds;
}

}  // namespace cbrdf::internal
