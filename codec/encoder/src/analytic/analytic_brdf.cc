// SPDX-License-Identifier: MIT
#include <cmath>
#include <string>
#include <utility>

#include "analytic/lobes.h"
#include "cbrdf/analytic.h"

namespace cbrdf {
namespace {

Status check_lobe(const Lobe& lobe, std::size_t index) {
  const std::string where =
      "lobe " + std::to_string(index) + " (" + std::string(lobe_kind_name(lobe.kind)) + ")";
  if (lobe_kind_name(lobe.kind) == "unknown") {
    return error(ErrorCode::kInvalidArgument,
                 where + ": unknown lobe kind " + std::to_string(int(lobe.kind)));
  }
  static constexpr const char* kChannelNames[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const double v = lobe.rgb[c];
    if (!std::isfinite(v) || v < 0.0) {
      return error(ErrorCode::kInvalidArgument, where + ": colour " + kChannelNames[c] + " = " +
                                                    std::to_string(v) + " must be finite and >= 0");
    }
  }
  const double s = lobe.shape;
  switch (lobe.kind) {
    case LobeKind::kGgx:
    case LobeKind::kWard:
      if (!(s >= kMinAlpha && s <= kMaxAlpha)) {
        return error(ErrorCode::kInvalidArgument,
                     where + ": roughness alpha = " + std::to_string(s) + " must lie in [" +
                         std::to_string(kMinAlpha) + ", " + std::to_string(kMaxAlpha) + "]");
      }
      break;
    case LobeKind::kAshikhminShirley:
      if (!(s >= 0.0 && s <= kMaxExponent)) {
        return error(ErrorCode::kInvalidArgument, where + ": exponent n = " + std::to_string(s) +
                                                      " must lie in [0, " +
                                                      std::to_string(kMaxExponent) + "]");
      }
      break;
    case LobeKind::kLambertian:
      break;
  }
  return ok_status();
}

}  // namespace

std::string_view lobe_kind_name(LobeKind kind) {
  switch (kind) {
    case LobeKind::kLambertian:
      return "lambertian";
    case LobeKind::kGgx:
      return "ggx";
    case LobeKind::kWard:
      return "ward";
    case LobeKind::kAshikhminShirley:
      return "ashikhmin-shirley";
  }
  return "unknown";
}

Lobe lambertian(const std::array<double, 3>& albedo) {
  return {LobeKind::kLambertian, albedo, 0.0};
}
Lobe ggx(const std::array<double, 3>& f0, double alpha) {
  return {LobeKind::kGgx, f0, alpha};
}
Lobe ward(const std::array<double, 3>& rho_s, double alpha) {
  return {LobeKind::kWard, rho_s, alpha};
}
Lobe ashikhmin_shirley(const std::array<double, 3>& rs, double exponent) {
  return {LobeKind::kAshikhminShirley, rs, exponent};
}

void AnalyticBrdf::eval(const Vec3& wi, const Vec3& wo, double rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0;
  internal::PairGeometry g;
  if (!internal::pair_geometry(wi, wo, &g)) return;
  for (const Lobe& lobe : lobes) internal::add_lobe(lobe, g, rgb);
}

int AnalyticBrdf::num_params() const {
  int n = 0;
  for (const Lobe& lobe : lobes) n += lobe.num_params();
  return n;
}

void AnalyticBrdf::to_params(std::span<double> out) const {
  std::size_t k = 0;
  for (const Lobe& lobe : lobes) {
    for (int c = 0; c < 3; ++c) out[k++] = lobe.rgb[c];
    if (lobe.num_params() == 4) out[k++] = lobe.shape;
  }
}

Status AnalyticBrdf::from_params(std::span<const double> params) {
  if (params.size() != std::size_t(num_params())) {
    return error(ErrorCode::kInvalidArgument,
                 "analytic BRDF parameters: got " + std::to_string(params.size()) +
                     " values, the lobes take " + std::to_string(num_params()));
  }
  AnalyticBrdf next = *this;
  std::size_t k = 0;
  for (Lobe& lobe : next.lobes) {
    for (int c = 0; c < 3; ++c) lobe.rgb[c] = params[k++];
    if (lobe.num_params() == 4) lobe.shape = params[k++];
  }
  CBRDF_RETURN_IF_ERROR(next.validate());
  *this = std::move(next);
  return ok_status();
}

Status AnalyticBrdf::validate() const {
  for (std::size_t i = 0; i < lobes.size(); ++i) CBRDF_RETURN_IF_ERROR(check_lobe(lobes[i], i));
  return ok_status();
}

}  // namespace cbrdf
