// SPDX-License-Identifier: MIT
#include "residual_encode.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>

#include "bitstream/chunk_writers.h"
#include "bitstream/residual_levels_writer.h"
#include "cbrdf/container.h"
#include "encode_watch.h"

namespace cbrdf::internal {
namespace {

// Just under 2E: rounding to the nearest code then errs by at most step/2 < E, and the margin
// (about 1e-6 E) absorbs the reconstruction's rounding; the decode check catches the rest.
constexpr double kStepFraction = 1.0 - 1.0 / 1024.0 / 1024.0;
constexpr double kTargetLimit = kMaxResidualValue - kMaxResidualError;

// The residual to code: log1p(src / k) - log1p(base / k) at every measured bin against the
// decoded base table, NaN at the others (code 0 in modes 0 and 2; any value will do in mode 3).
std::vector<double> residual_target(const BrdfTable& source, const BrdfTable& base,
                                    const NotMeasured& mask, double knee) {
  std::vector<double> t(kMaskBits, std::numeric_limits<double>::quiet_NaN());
  for (int c = 0; c < kChannels; ++c) {
    const double* s = source.channel_data(c);
    const double* b = base.channel_data(c);
    double* out = t.data() + std::size_t(c) * kBinsPerChannel;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (mask.test(c, i)) continue;
      // Within the format's residual limit less the largest bound, so every rebuilt residual
      // stays inside it; a bin beyond fails the check and is stored exactly.
      const double r = std::log1p(s[i] / knee) - std::log1p(b[i] / knee);
      out[i] = std::clamp(r, -kTargetLimit, kTargetLimit);
    }
  }
  return t;
}

}  // namespace

double residual_knee(const BrdfTable& source) {
  double peak = 0;
  for (double v : source.stored_values()) {
    if (v > peak) peak = v;  // not-measured values are negative or NaN
  }
  // Every real MERL table peaks far above 1 (stored units): k = 1e-4 as measured (spec 4.6).
  // Below, k sits as far under the peak's power of two as 1e-4 under a bright material's peak of
  // 2^13, so the bound stays relative at any scale, and a table scaled by a power of two gets the
  // same codes.
  if (!(peak < 1.0) || peak == 0.0) return kResidualKnee;
  return std::max(std::ldexp(kResidualKnee, std::ilogb(peak) - 13), kMinResidualKnee);
}

double max_log_error(const BrdfTable& source, const BrdfTable& decoded, const Residual& residual,
                     std::vector<std::uint32_t>* violations) {
  const double knee = residual.knee;
  double worst = 0;
  for (int c = 0; c < kChannels; ++c) {
    const double* s = source.channel_data(c);
    const double* d = decoded.channel_data(c);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (!(s[i] >= 0.0)) continue;  // not measured
      const double e = std::abs(std::log1p(d[i] / knee) - std::log1p(s[i] / knee));
      const double b = residual.bound_at(i);
      // A NaN error (never expected) counts as a violation.
      if (violations && !(e <= b)) {
        violations->push_back(std::uint32_t(std::size_t(c) * kBinsPerChannel + i));
      }
      if (!(e <= worst)) worst = e;
    }
  }
  return worst;
}

std::vector<std::uint8_t> residual_row_shifts(double max_error, int largest_multiplier) {
  std::vector<double> w(kResidualRows, 0.0);
  for (int h = 0; h < kThetaHBins; ++h) {
    // Bin centres; theta_h's bins widen with theta_h (MERL's square-root spacing).
    const double th = theta_h_of(h + 0.5), dth = theta_h_of(h + 1.0) - theta_h_of(h);
    for (int d = 0; d < kThetaDBins; ++d) {
      const double td = theta_d_of(d + 0.5);
      double cosines = 0;
      for (int p = 0; p < kPhiDBins; ++p) {
        Vec3 wi, wo;
        from_half_diff({th, 0.0, td, phi_d_of(p + 0.5)}, &wi, &wo);
        cosines += std::max(wi.z, 0.0) * std::max(wo.z, 0.0);
      }
      // d(wi) d(wo) = 4 cos(theta_d) d(wh) d(wd) (Rusinkiewicz): sin and cos of theta_d.
      w[std::size_t(h) * kThetaDBins + d] =
          std::sin(th) * dth * std::sin(td) * std::cos(td) * cosines;
    }
  }
  const double top = *std::max_element(w.begin(), w.end());
  // No row's bound above the format's largest.
  const int cap = std::min(
      kRowStepShiftCap,
      int(std::floor(std::log2(kMaxResidualError / (max_error * double(largest_multiplier))))));
  std::vector<std::uint8_t> shifts(kResidualRows);
  for (std::size_t r = 0; r < kResidualRows; ++r) {
    const double s = w[r] > 0 ? std::nearbyint(0.5 * std::log2(top / w[r])) : double(cap);
    shifts[r] = std::uint8_t(std::clamp(s, 0.0, double(std::max(cap, 0))));
  }
  return shifts;
}

namespace {

// Mode 1: the source itself, checked bit for bit after decoding.
Status add_exact(const BrdfTable& source, const ContainerSettings& container,
                 EncodeResult* result) {
  result->model.residual = Residual{};
  result->model.residual.exact = std::make_shared<const BrdfTable>(source);
  CBRDF_ASSIGN_OR_RETURN(std::vector<std::uint8_t> bytes, encode_model(result->model, container));
  CBRDF_ASSIGN_OR_RETURN(BrdfTable decoded, decode_table(bytes));
  const std::vector<double>&a = source.stored_values(), &b = decoded.stored_values();
  if (a.size() != b.size() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) != 0) {
    return error(ErrorCode::kInternal, "the lossless file does not decode to the source");
  }
  result->bytes = std::move(bytes);
  return ok_status();
}

// The levels and multipliers within the format's limits.
Status check_levels(const ResidualSettings& rs) {
  const auto out_of_range = [](int m) { return m < 1 || m > kMaxFineMultiplier; };
  if (rs.levels < 0 || rs.levels > kMaxResidualLevels ||
      (rs.levels > 0 &&
       (out_of_range(rs.fine_multiplier) ||
        std::any_of(rs.middle_multipliers.begin(), rs.middle_multipliers.end(), out_of_range) ||
        (rs.mode3_fine_multiplier != 0 && out_of_range(rs.mode3_fine_multiplier))))) {
    return error(ErrorCode::kInvalidArgument,
                 "residual levels " + std::to_string(rs.levels) + ", finest multiplier " +
                     std::to_string(rs.fine_multiplier) + " (" +
                     std::to_string(rs.mode3_fine_multiplier) + " in mode 3) and middle " +
                     "multipliers " + std::to_string(rs.middle_multipliers[0]) + ", " +
                     std::to_string(rs.middle_multipliers[1]) + ", " +
                     std::to_string(rs.middle_multipliers[2]) + ": levels must be 0.." +
                     std::to_string(kMaxResidualLevels) + " and each multiplier 1.." +
                     std::to_string(kMaxFineMultiplier) + " (0 also for mode 3's: the finest)");
  }
  return ok_status();
}

// Everything of the layer but its codes and escapes: bound, step, knee, levels, multipliers
// and row steps, for the version that `base_bytes` (the base's file) is written in.
Status set_residual_layout(const ResidualSettings& rs, const std::vector<std::uint8_t>& base_bytes,
                           double knee, Residual* residual) {
  const double bound = rs.max_error;
  residual->max_error = bound;
  residual->step = 2.0 * bound * kStepFraction;
  residual->knee = knee;
  residual->row_shift.clear();
  residual->levels = std::uint8_t(rs.levels);
  // Middle levels' multipliers are RESD mode 4, version 1.3 only: a file its base writes as 1.2
  // takes them as 1, and the finest level mode 3's multiplier.
  CBRDF_ASSIGN_OR_RETURN(ContainerLayout version, read_container_version(base_bytes));
  const bool v13 = version.minor >= 3;
  const int fine =
      !v13 && rs.mode3_fine_multiplier > 0 ? rs.mode3_fine_multiplier : rs.fine_multiplier;
  residual->fine_multiplier = std::uint8_t(rs.levels > 0 ? fine : 1);
  residual->middle_multipliers = {1, 1, 1};
  for (int l = 1; v13 && l < rs.levels; ++l) {
    residual->middle_multipliers[std::size_t(l - 1)] =
        std::uint8_t(rs.middle_multipliers[std::size_t(l - 1)]);
  }
  residual->values.clear();
  const int multiplier = residual->max_multiplier();
  if (rs.row_steps) {
    residual->row_shift = residual_row_shifts(bound, multiplier);
  } else if (residual->interpolated()) {
    residual->row_shift.assign(kResidualRows, 0);  // mode 3 always has them
  }
  return ok_status();
}

// The layer's codes for `target`, with no escapes yet.
void quantize_residual(const std::vector<double>& target, Residual* residual) {
  if (residual->interpolated()) {
    quantize_interpolated(target.data(), residual);
  } else {
    // One code per bin; a code clamped to the format's range fails add_residual's check and
    // becomes an escape.
    residual->codes.assign(kMaskBits, 0);
    for (std::size_t b = 0; b < kMaskBits; ++b) {
      residual->codes[b] = residual_code(target[b], residual->step_at(b % kBinsPerChannel));
    }
  }
  residual->escapes.clear();
}

}  // namespace

Status add_residual(const BrdfTable& source, const EncoderSettings& settings, EncodeResult* result,
                    const BrdfTable* base_table, BrdfTable* decoded_out) {
  CBRDF_RETURN_IF_ERROR(check_cancel());
  ContainerSettings container = settings.container;
  container.bits = result->bits > 0 ? result->bits : container.bits;
  if (settings.residual.lossless) return add_exact(source, container, result);
  const double bound = settings.residual.max_error;
  CBRDF_RETURN_IF_ERROR(check_levels(settings.residual));
  // The base exactly as every decoder of the file rebuilds it.
  BrdfTable own_base;
  if (base_table == nullptr) {
    CBRDF_ASSIGN_OR_RETURN(Model base, decode_model(result->bytes));
    own_base = base.table();
    base_table = &own_base;
  }

  Model& model = result->model;
  CBRDF_RETURN_IF_ERROR(set_residual_layout(settings.residual, result->bytes, residual_knee(source),
                                            &model.residual));
  CBRDF_RETURN_IF_ERROR(check_cancel());
  const std::vector<double> target =
      residual_target(source, *base_table, model.not_measured, model.residual.knee);
  CBRDF_RETURN_IF_ERROR(check_cancel());
  quantize_residual(target, &model.residual);
  // Write, decode, check every bin; bins that miss the bound (rounding at the margin, or a code
  // beyond the format's range) are stored exactly as escapes and the file written again.
  for (int attempt = 0; attempt < 2; ++attempt) {
    CBRDF_RETURN_IF_ERROR(check_cancel());
    CBRDF_ASSIGN_OR_RETURN(std::vector<std::uint8_t> bytes, encode_model(model, container));
    CBRDF_RETURN_IF_ERROR(check_cancel());
    CBRDF_ASSIGN_OR_RETURN(BrdfTable decoded, decode_table(bytes));
    CBRDF_RETURN_IF_ERROR(check_cancel());
    std::vector<std::uint32_t> bad;
    max_log_error(source, decoded, model.residual, &bad);
    if (bad.empty()) {
      result->bytes = std::move(bytes);
      if (decoded_out != nullptr) *decoded_out = std::move(decoded);
      return ok_status();
    }
    if (attempt == 1 || model.residual.escapes.size() + bad.size() > kMaxResidualEscapes) break;
    std::vector<ResidualEscape> merged;
    for (std::uint32_t b : bad) merged.push_back({b, source.stored_values()[b]});
    for (const ResidualEscape& e : model.residual.escapes) merged.push_back(e);
    std::sort(merged.begin(), merged.end(),
              [](const ResidualEscape& a, const ResidualEscape& b) { return a.bin < b.bin; });
    model.residual.escapes = std::move(merged);
  }
  char text[32];
  std::snprintf(text, sizeof text, "%g", bound);
  return error(ErrorCode::kNumeric,
               std::string("the residual layer cannot hold the bound ") + text +
                   " on this table (too many bins need exact storage); use a larger --max-error");
}

}  // namespace cbrdf::internal

namespace cbrdf {

ResidualSettings target_residual_settings(double max_error) {
  ResidualSettings rs;
  rs.max_error = max_error;
  rs.row_steps = true;  // a target in PSNR or bytes, not a bound: steps by visibility
  // Measured over a 1-component 10-bit base on gold-metallic-paint, chrome-steel and
  // beige-fabric, levels 2-4 and multipliers 1-8 at E 0.02-0.005: more levels than 2 helped
  // two of three, and each doubling of the multiplier saved bytes at the same tone-mapped PSNR
  // (8: 2-10% fewer than 4); docs/benchmarks.md has the bytes at 60 dB against mode 2.
  rs.levels = 3;
  // Levels 0 and 1 coarser than their rows (mode 4 in 1.3 files), more so at coarse bounds: the
  // finer a level, the fewer predictions its errors feed (docs/benchmarks.md has the bytes).
  // Multipliers never fall as E grows, so bytes and PSNR stay monotonic in E for rate control's
  // search, and m x E stays within the format's bound 16.
  const int fine = max_error >= 1.5e-3 ? 32 : max_error >= 6e-4 ? 16 : 8;
  const int level1 = fine / 4;
  rs.fine_multiplier = std::max(1, std::min(fine, int(std::floor(kMaxResidualError / max_error))));
  rs.middle_multipliers = {std::min(level1, rs.fine_multiplier), 1, 1};
  // Mode 3 (a 1.2 file) keeps 8 at every bound: a coarser fine level there costs bytes and PSNR.
  rs.mode3_fine_multiplier = std::min(8, rs.fine_multiplier);
  return rs;
}

Status add_residual_layer(const BrdfTable& table, const EncoderSettings& settings,
                          EncodeResult* result) {
  return internal::run_watched(settings.progress, [&] {
    const internal::ProgressPart part("residual", 0, 1);
    return internal::add_residual(table, settings, result);
  });
}

}  // namespace cbrdf
