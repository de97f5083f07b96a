// SPDX-License-Identifier: MIT
#include "cbrdf/coords.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cbrdf {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kHalfPi = kPi / 2;

// Rodrigues rotation of v about a unit axis, as in the reference MERL code.
Vec3 rotate(const Vec3& v, const Vec3& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const double d = dot(axis, v);
  const Vec3 cross{axis.y * v.z - axis.z * v.y, axis.z * v.x - axis.x * v.z,
                   axis.x * v.y - axis.y * v.x};
  return {v.x * c + axis.x * d * (1 - c) + cross.x * s,
          v.y * c + axis.y * d * (1 - c) + cross.y * s,
          v.z * c + axis.z * d * (1 - c) + cross.z * s};
}

double clamp_acos(double x) {
  return std::acos(std::clamp(x, -1.0, 1.0));
}

}  // namespace

double theta_h_position(double theta_h);
double theta_d_position(double theta_d);
double phi_d_position(double phi_d);

namespace {

GridPosition to_positions(const HalfDiff& hd) {
  return {theta_h_position(hd.theta_h), theta_d_position(hd.theta_d), phi_d_position(hd.phi_d)};
}

}  // namespace

HalfDiff to_half_diff(const Vec3& wi, const Vec3& wo) {
  Vec3 h{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
  const double len = std::sqrt(dot(h, h));
  // wi = -wo has no half vector; any unit vector serves, take the normal.
  h = len > 0 ? Vec3{h.x / len, h.y / len, h.z / len} : Vec3{0, 0, 1};
  HalfDiff r;
  r.theta_h = clamp_acos(h.z);
  r.phi_h = std::atan2(h.y, h.x);
  const Vec3 t = rotate(wi, Vec3{0, 0, 1}, -r.phi_h);
  const Vec3 d = rotate(t, Vec3{0, 1, 0}, -r.theta_h);
  r.theta_d = clamp_acos(d.z);
  r.phi_d = std::atan2(d.y, d.x);
  return r;
}

void from_half_diff(const HalfDiff& hd, Vec3* wi, Vec3* wo) {
  const double st = std::sin(hd.theta_d);
  const Vec3 d{st * std::cos(hd.phi_d), st * std::sin(hd.phi_d), std::cos(hd.theta_d)};
  const Vec3 t = rotate(d, Vec3{0, 1, 0}, hd.theta_h);
  const Vec3 i = rotate(t, Vec3{0, 0, 1}, hd.phi_h);
  const double sh = std::sin(hd.theta_h);
  const Vec3 h{sh * std::cos(hd.phi_h), sh * std::sin(hd.phi_h), std::cos(hd.theta_h)};
  const double c = 2 * dot(i, h);
  *wi = i;
  *wo = Vec3{c * h.x - i.x, c * h.y - i.y, c * h.z - i.z};
}

int theta_h_index(double theta_h) {
  if (!(theta_h > 0.0)) return 0;
  const double deg = theta_h / kHalfPi * kThetaHBins;
  const int i = int(std::sqrt(deg * kThetaHBins));
  return std::clamp(i, 0, kThetaHBins - 1);
}

int theta_d_index(double theta_d) {
  const double x = theta_d / kHalfPi * kThetaDBins;
  if (!(x > 0.0)) return 0;
  return std::clamp(int(x), 0, kThetaDBins - 1);
}

int phi_d_index(double phi_d) {
  if (phi_d < 0.0) phi_d += kPi;
  const double x = phi_d / kPi * kPhiDBins;
  if (!(x > 0.0)) return 0;
  return std::clamp(int(x), 0, kPhiDBins - 1);
}

double theta_h_position(double theta_h) {
  return theta_h > 0 ? std::sqrt(theta_h / kHalfPi) * kThetaHBins : 0.0;
}
double theta_d_position(double theta_d) {
  return theta_d / kHalfPi * kThetaDBins;
}
double phi_d_position(double phi_d) {
  double p = std::fmod(phi_d, kPi);
  if (p < 0) p += kPi;
  return p / kPi * kPhiDBins;
}

double theta_h_of(double position) {
  const double x = position / kThetaHBins;
  return x * x * kHalfPi;
}
double theta_d_of(double position) {
  return position / kThetaDBins * kHalfPi;
}
double phi_d_of(double position) {
  return position / kPhiDBins * kPi;
}

GridPosition grid_position(const Vec3& wi, const Vec3& wo) {
  Vec3 h{wi.x + wo.x, wi.y + wo.y, wi.z + wo.z};
  const double len2 = dot(h, h);
  if (!(len2 > 0)) return to_positions(to_half_diff(wi, wo));
  const double inv = 1.0 / std::sqrt(len2);
  h = {h.x * inv, h.y * inv, h.z * inv};
  const double sin_h = std::sqrt(h.x * h.x + h.y * h.y);
  // The difference frame: to_half_diff rotates by -phi_h about z, then by -theta_h about y, so in
  // world space its x axis is (cos t cos p, cos t sin p, -sin t) and its y axis (-sin p, cos p, 0).
  double cp = 1.0, sp = 0.0;
  if (sin_h > 1e-300) {
    cp = h.x / sin_h;
    sp = h.y / sin_h;
  }
  const double ct = h.z;
  const double dx = wi.x * ct * cp + wi.y * ct * sp - wi.z * sin_h;
  const double dy = -wi.x * sp + wi.y * cp;
  const double dz = dot(wi, h);
  GridPosition g;
  g.theta_h = theta_h_position(clamp_acos(h.z));
  g.theta_d = theta_d_position(clamp_acos(dz));
  g.phi_d = phi_d_position(std::atan2(dy, dx));
  return g;
}

std::size_t nearest_bin(const Vec3& wi, const Vec3& wo) {
  const HalfDiff hd = to_half_diff(wi, wo);
  return merl_index(theta_h_index(hd.theta_h), theta_d_index(hd.theta_d), phi_d_index(hd.phi_d));
}

void lookup_nearest(const BrdfTable& table, const Vec3& wi, const Vec3& wo, double rgb[3]) {
  const std::size_t idx = nearest_bin(wi, wo);
  for (int c = 0; c < kChannels; ++c)
    rgb[c] = table.measured(c, idx) ? table.physical(c, idx) : 0.0;
}

void lookup_linear(const BrdfTable& table, const Vec3& wi, const Vec3& wo, double rgb[3]) {
  const HalfDiff hd = to_half_diff(wi, wo);
  const double ph = std::clamp(theta_h_position(hd.theta_h), 0.0, double(kThetaHBins - 1));
  const double pd = std::clamp(theta_d_position(hd.theta_d), 0.0, double(kThetaDBins - 1));
  const double pp = phi_d_position(hd.phi_d);
  const int h0 = std::min(int(ph), kThetaHBins - 2), d0 = std::min(int(pd), kThetaDBins - 2);
  const int p0 = std::min(int(pp), kPhiDBins - 1);
  const double fh = ph - h0, fd = pd - d0, fp = pp - p0;
  for (int c = 0; c < kChannels; ++c) rgb[c] = 0.0;
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      for (int e = 0; e < 2; ++e) {
        const double w = (a ? fh : 1 - fh) * (b ? fd : 1 - fd) * (e ? fp : 1 - fp);
        if (w == 0.0) continue;
        const std::size_t idx = merl_index(h0 + a, d0 + b, (p0 + e) % kPhiDBins);
        for (int c = 0; c < kChannels; ++c) {
          if (table.measured(c, idx)) rgb[c] += w * table.physical(c, idx);
        }
      }
    }
  }
}

bool bin_below_horizon(int theta_h, int theta_d, int phi_d) {
  // The same arithmetic, in the same order, as the grid generator of MERL-layout files, so that the
  // geometric mask matches real files bit for bit.
  const double th = double(theta_h) / kThetaHBins * double(theta_h) / kThetaHBins * kHalfPi;
  const double td = double(theta_d) / kThetaDBins * kHalfPi;
  const double pd = double(phi_d) / kPhiDBins * kPi;
  const double d[3] = {std::sin(td) * std::cos(pd), std::sin(td) * std::sin(pd), std::cos(td)};
  const double h[3] = {std::sin(th), 0.0, std::cos(th)};
  const double wi[3] = {d[0] * std::cos(th) + d[2] * std::sin(th), d[1],
                        -d[0] * std::sin(th) + d[2] * std::cos(th)};
  const double c = wi[0] * h[0] + wi[2] * h[2];
  const double wo_z = 2 * c * h[2] - wi[2];
  return wi[2] <= 0 || wo_z <= 0;
}

}  // namespace cbrdf
