// SPDX-License-Identifier: MIT
#include "density/frank_grid.h"

#include <numbers>

namespace cbrdf::internal {
namespace {

// 2/t - 2/(e^t - 1), the derivative of 2 log(t / b) in t; a series near 0 where both terms cancel.
double log_k2_derivative(double t) {
  if (std::abs(t) < 1e-3) return 2.0 * (0.5 - t / 12.0 + t * t * t / 720.0);
  return 2.0 * (std::expm1(t) - t) / (t * std::expm1(t));
}

}  // namespace

void FrankGrid::prepare_axis(const std::vector<double>& u, FrankAxis* a) const {
  const std::size_t n = u.size();
  a->u = u;
  a->e.resize(n);
  a->w.resize(n);
  a->y.resize(n);
  a->q.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = u[i];
    a->e[i] = std::exp(-t_ * x);
    a->w[i] = -std::expm1(-t_ * x) / b_;
    a->y[i] = -a->e[i] * std::expm1(-t_ * (1.0 - x)) / b_;
    a->q[i] = x > 0 ? x / std::expm1(t_ * x) : 1.0 / t_;
  }
}

void FrankGrid::prepare(double alpha, const std::vector<double>& u1, const std::vector<double>& u2,
                        const std::vector<double>& u3) {
  alpha_ = alpha;
  t_ = -alpha;
  if (t_ == 0.0) {
    for (FrankAxis& a : ax_) a = FrankAxis{};
    ax_[0].u = u1;
    ax_[1].u = u2;
    ax_[2].u = u3;
    return;
  }
  b_ = -std::expm1(-t_);
  et_ = std::exp(-t_);
  // 2 - e^{alpha} = -2 expm1(alpha - ln 2), with ln 2 split in two doubles so that the difference
  // is exact near alpha = ln 2, where this factor sets the density's zero.
  constexpr double kLn2Lo = 2.319046813846299558e-17;  // ln 2 - std::numbers::ln2
  one_plus_b_ = -2.0 * std::expm1((alpha - std::numbers::ln2) - kLn2Lo);
  const double r = t_ / b_;
  k2_ = r * r;
  d0_ = log_k2_derivative(t_);
  q1_ = 1.0 / std::expm1(t_);
  prepare_axis(u1, &ax_[0]);
  prepare_axis(u2, &ax_[1]);
  prepare_axis(u3, &ax_[2]);
}

double FrankGrid::density_and_derivative(int i, int j, int k, double* dc_dalpha) const {
  const double u1 = ax_[0].u[i], u2 = ax_[1].u[j], u3 = ax_[2].u[k];
  if (t_ == 0.0) {
    // d log c / dt at t = 0 is 1 - (u1 + u2 + u3) + 4 u1 u2 u3 (it integrates to 0 over the cube).
    *dc_dalpha = -(1.0 - (u1 + u2 + u3) + 4.0 * u1 * u2 * u3);
    return 1.0;
  }
  const double w1 = ax_[0].w[i], w2 = ax_[1].w[j], w3 = ax_[2].w[k];
  const double h = b_ * w1 * w2 * w3;
  double omh, oph;
  terms(i, j, k, w1, w2, w3, &omh, &oph);
  const double c = k2_ * ax_[0].e[i] * ax_[1].e[j] * ax_[2].e[k] * oph / (omh * omh * omh);
  // d log h / dt = sum_i u_i / expm1(t u_i) - 2 / expm1(t).
  const double hp = h * (ax_[0].q[i] + ax_[1].q[j] + ax_[2].q[k] - 2.0 * q1_);
  const double dlogc_dt = d0_ - (u1 + u2 + u3) + hp / oph + 3.0 * hp / omh;
  *dc_dalpha = -c * dlogc_dt;  // alpha = -t
  return c;
}

void FrankGrid::row(int i, int j, double* c, double* dc) const {
  const FrankAxis &a1 = ax_[0], &a2 = ax_[1], &a3 = ax_[2];
  const int n = int(a3.u.size());
  if (t_ == 0.0) {
    for (int k = 0; k < n; ++k) {
      c[k] = 1.0;
      if (dc) dc[k] = -(1.0 - (a1.u[i] + a2.u[j] + a3.u[k]) + 4.0 * a1.u[i] * a2.u[j] * a3.u[k]);
    }
    return;
  }
  const double e12 = k2_ * a1.e[i] * a2.e[j], w12 = a1.w[i] * a2.w[j];
  const double y12 = a1.y[i] + a1.w[i] * a2.y[j];
  const double b = b_;
  const double* e3 = a3.e.data();
  const double* w3 = a3.w.data();
  const double* y3 = a3.y.data();
  // Branch once per row on the sign of t (see the header for the two cancellation-free forms).
  const double s_omh = t_ > 0 ? 1.0 : 0.0, s_oph = 1.0 - s_omh;
  const double omh0 = t_ > 0 ? et_ : 1.0, oph0 = t_ > 0 ? 1.0 : one_plus_b_;
  if (!dc) {
    for (int k = 0; k < n; ++k) {
      const double w = w12 * w3[k], y = y12 + w12 * y3[k];
      const double omh = omh0 + s_omh * b * y - s_oph * b * w;
      const double oph = oph0 + s_omh * b * w - s_oph * b * y;
      c[k] = e12 * e3[k] * oph / (omh * omh * omh);
    }
    return;
  }
  const double u12 = a1.u[i] + a2.u[j], q12 = a1.q[i] + a2.q[j] - 2.0 * q1_;
  for (int k = 0; k < n; ++k) {
    const double w = w12 * w3[k], y = y12 + w12 * y3[k];
    const double omh = omh0 + s_omh * b * y - s_oph * b * w;
    const double oph = oph0 + s_omh * b * w - s_oph * b * y;
    const double ck = e12 * e3[k] * oph / (omh * omh * omh);
    const double hp = b * w * (q12 + a3.q[k]);
    c[k] = ck;
    dc[k] = -ck * (d0_ - (u12 + a3.u[k]) + hp / oph + 3.0 * hp / omh);
  }
}

}  // namespace cbrdf::internal
