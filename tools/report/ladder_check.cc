// SPDX-License-Identifier: MIT
#include "report/ladder_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace cbrdf::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const LadderPoint* find_point(const LadderMaterial& m, const char* method) {
  for (const LadderPoint& p : m.points)
    if (p.method == method) return &p;
  return nullptr;
}

std::string fmt(const char* f, double v) {
  char text[64];
  std::snprintf(text, sizeof text, f, v);
  return text;
}

}  // namespace

const std::vector<std::string>& cbrdf_methods() {
  static const std::vector<std::string> m = {kLadderBase, kLadderResidual, kLadderLossless};
  return m;
}

std::vector<CurvePoint> ladder_curve(const LadderMaterial& m,
                                     const std::vector<std::string>& methods) {
  std::vector<CurvePoint> all;
  for (const LadderPoint& p : m.points) {
    if (std::find(methods.begin(), methods.end(), p.method) == methods.end()) continue;
    if (std::isfinite(p.psnr_tonemapped) && p.bytes > 0)
      all.push_back({p.bytes, p.psnr_tonemapped});
  }
  // By bytes, then keep each point that raises the best PSNR so far: the lower envelope.
  std::sort(all.begin(), all.end(), [](const CurvePoint& a, const CurvePoint& b) {
    return a.bytes != b.bytes ? a.bytes < b.bytes : a.psnr > b.psnr;
  });
  std::vector<CurvePoint> curve;
  for (const CurvePoint& p : all)
    if (curve.empty() || p.psnr > curve.back().psnr) curve.push_back(p);
  return curve;
}

double bytes_at(const std::vector<CurvePoint>& curve, double psnr) {
  if (curve.empty() || psnr > curve.back().psnr) return kNaN;
  if (psnr <= curve.front().psnr) return curve.front().bytes;
  for (std::size_t i = 1; i < curve.size(); ++i) {
    if (psnr <= curve[i].psnr) {
      const CurvePoint& a = curve[i - 1];
      const CurvePoint& b = curve[i];
      const double t = (psnr - a.psnr) / (b.psnr - a.psnr);
      return std::exp(std::log(a.bytes) + t * (std::log(b.bytes) - std::log(a.bytes)));
    }
  }
  return kNaN;
}

std::vector<LadderTarget> ladder_targets(const std::vector<LadderMaterial>& ladders) {
  std::vector<LadderTarget> out;
  for (double psnr = 45; psnr <= 80.5; psnr += 5) {
    LadderTarget t;
    t.psnr = psnr;
    t.zfp_ratio_min = t.float16_ratio_min = std::numeric_limits<double>::infinity();
    double sum_c = 0, sum_z = 0, sum_f = 0;
    bool all_f = true, any_z = false;
    for (const LadderMaterial& m : ladders) {
      const double c = bytes_at(ladder_curve(m, cbrdf_methods()), psnr);
      const std::vector<CurvePoint> zfp = ladder_curve(m, {kLadderZfp});
      double z = bytes_at(zfp, psnr);
      const double f = bytes_at(ladder_curve(m, {kLadderFloat16}), psnr);
      if (!std::isfinite(c) || zfp.empty()) continue;
      if (!std::isfinite(z)) {
        z = zfp.back().bytes;
        ++t.zfp_short;
      }
      ++t.materials;
      sum_c += c;
      sum_z += z;
      any_z = true;
      t.zfp_ratio_min = std::min(t.zfp_ratio_min, z / c);
      if (std::isfinite(f)) {
        sum_f += f;
        t.float16_ratio_min = std::min(t.float16_ratio_min, f / c);
      } else {
        all_f = false;
      }
    }
    const double n = t.materials;
    t.cbrdf_bytes = n > 0 ? sum_c / n : kNaN;
    t.zfp_bytes = any_z ? sum_z / n : kNaN;
    t.float16_bytes = n > 0 && all_f ? sum_f / n : kNaN;
    if (!any_z) t.zfp_ratio_min = kNaN;
    if (!(n > 0 && all_f)) t.float16_ratio_min = kNaN;
    out.push_back(t);
  }
  return out;
}

std::vector<LosslessCheck> lossless_checks(const std::vector<LadderMaterial>& ladders) {
  std::vector<LosslessCheck> out;
  for (const LadderMaterial& m : ladders) {
    LosslessCheck c{m.name};
    if (const LadderPoint* p = find_point(m, kLadderLossless)) c.cbrdf = p->bytes;
    if (const LadderPoint* p = find_point(m, kLadderXz)) c.xz = p->bytes;
    if (const LadderPoint* p = find_point(m, kLadderZstd)) c.zstd = p->bytes;
    if (c.cbrdf > 0) out.push_back(c);
  }
  return out;
}

std::string ladder_check_text(const std::vector<LadderMaterial>& ladders) {
  std::ostringstream out;
  out << "Ladder check (cbrdf's targets, tone-mapped PSNR, means over materials):\n";
  for (const LadderTarget& t : ladder_targets(ladders)) {
    out << "  " << fmt("%.0f dB", t.psnr) << ": ";
    if (t.materials == 0) {
      out << "not reached by cbrdf and ZFP on any material\n";
      continue;
    }
    const double rz = t.zfp_bytes / t.cbrdf_bytes, rf = t.float16_bytes / t.cbrdf_bytes;
    out << "cbrdf " << fmt("%.0f", t.cbrdf_bytes / 1000) << " KB; ZFP/cbrdf " << fmt("%.2f", rz)
        << " (min " << fmt("%.2f", t.zfp_ratio_min) << ")"
        << (std::isfinite(rz) ? (rz >= 4 ? " ok" : " BELOW 4x") : "") << "; float16/cbrdf "
        << (std::isfinite(rf) ? fmt("%.2f", rf) + " (min " + fmt("%.2f", t.float16_ratio_min) +
                                    ")" + (rf >= 4 ? " ok" : " BELOW 4x")
                              : std::string("n/a (float16 does not reach it everywhere)"))
        << " [" << t.materials << " materials"
        << (t.zfp_short > 0 ? "; ZFP short of it on " + std::to_string(t.zfp_short) +
                                  ", its largest file counted: ZFP figures are lower bounds"
                            : std::string())
        << "]\n";
  }
  const std::string at60 = ladder_60db_text(ladders);
  const std::string lossless = ladder_lossless_text(ladders);
  if (!at60.empty()) out << "  " << at60 << "\n";
  if (!lossless.empty()) out << "  " << lossless << "\n";
  return out.str();
}

std::string ladder_60db_text(const std::vector<LadderMaterial>& ladders) {
  double sum60 = 0, max60 = 0;
  int n60 = 0, above = 0;
  for (const LadderMaterial& m : ladders) {
    const double b = bytes_at(ladder_curve(m, cbrdf_methods()), 60);
    if (!std::isfinite(b)) continue;
    sum60 += b;
    max60 = std::max(max60, b);
    above += b >= 100000 ? 1 : 0;
    ++n60;
  }
  if (n60 == 0) return "";
  // The target is the mean; the materials above it are named by count beside it.
  const double mean = sum60 / n60;
  return "60 dB: cbrdf mean " + fmt("%.1f", mean / 1000) + " KB" +
         (mean < 100000 ? " ok" : " ABOVE 100 KB") + ", largest " + fmt("%.1f", max60 / 1000) +
         " KB (" + std::to_string(above) + " of " + std::to_string(n60) +
         " materials at or above 100 KB) [" + std::to_string(n60) + " of " +
         std::to_string(ladders.size()) + " materials reach 60 dB]";
}

std::string ladder_lossless_text(const std::vector<LadderMaterial>& ladders) {
  int smaller = 0, with_xz = 0;
  double worst = 0;
  for (const LosslessCheck& c : lossless_checks(ladders)) {
    if (c.xz <= 0) continue;
    ++with_xz;
    smaller += c.cbrdf < c.xz ? 1 : 0;
    worst = std::max(worst, c.cbrdf / c.xz);
  }
  if (with_xz == 0) return "";
  return "lossless: smaller than xz on " + std::to_string(smaller) + " of " +
         std::to_string(with_xz) + " materials (largest cbrdf/xz " + fmt("%.3f", worst) + ")" +
         (smaller == with_xz ? " ok" : " NOT ALL");
}

}  // namespace cbrdf::report
