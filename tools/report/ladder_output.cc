// SPDX-License-Identifier: MIT
#include "report/ladder_output.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cbrdf/metrics.h"
#include "report/ladder_check.h"
#include "report/svg.h"

namespace cbrdf::report {
namespace {

std::string fmt(const char* f, double v) {
  return format_value(f, v, "n/a");
}
std::string kb(double bytes) {
  return fmt(bytes < 1e4 ? "%.2f" : "%.1f", bytes / 1000);
}

const char* const kMethods[] = {kLadderBase, kLadderResidual, kLadderNoiseFloor, kLadderLossless,
                                kLadderZfp,  kLadderFloat16,  kLadderZstd,       kLadderXz};

// Any point measured against a truth (`cbrdf report --truth`).
bool have_truth(const std::vector<LadderMaterial>& ladders) {
  for (const LadderMaterial& m : ladders) {
    for (const LadderPoint& p : m.points) {
      if (!std::isnan(p.psnr_truth_tonemapped)) return true;
    }
  }
  return false;
}

// The mean PSNR ceiling of the noisy materials (NaN when none is noisy).
double mean_noise_ceiling(const std::vector<LadderMaterial>& ladders) {
  double s = 0;
  int n = 0;
  for (const LadderMaterial& m : ladders) {
    if (m.noise_ceiling_tonemapped > 0 && m.noise_ceiling_tonemapped < kPsnrCapDb) {
      s += m.noise_ceiling_tonemapped;
      ++n;
    }
  }
  return n > 0 ? s / n : NAN;
}

// Every (method, setting) in the first material's order, with its points over the materials.
struct Setting {
  std::string method, setting;
  std::vector<const LadderPoint*> points;
};
std::vector<Setting> settings_of(const std::vector<LadderMaterial>& ladders) {
  std::vector<Setting> out;
  std::map<std::string, std::size_t> index;
  for (const LadderMaterial& m : ladders) {
    for (const LadderPoint& p : m.points) {
      const std::string key = p.method + "\n" + p.setting;
      auto [it, fresh] = index.emplace(key, out.size());
      if (fresh) out.push_back({p.method, p.setting, {}});
      out[it->second].points.push_back(&p);
    }
  }
  return out;
}

double mean(const std::vector<const LadderPoint*>& pts, double LadderPoint::*field) {
  double s = 0;
  for (const LadderPoint* p : pts) s += p->*field;
  return pts.empty() ? NAN : s / double(pts.size());
}

TextTable mean_table(const std::vector<LadderMaterial>& ladders) {
  TextTable t;
  t.id = "ladder";
  t.title = "Ladder: bytes against sphere PSNR from the base model to lossless";
  t.note = "Means over " + std::to_string(ladders.size()) +
           " materials per method and setting. cbrdf base: the copula model alone (kK components, "
           "bB bits); cbrdf residual: base (1 component) + residual layer as --target-psnr "
           "writes it (RESD mode 4 in 1.3 files, 3 in 1.2: a bound per (theta_h, theta_d) row, "
           "codes correcting an interpolation): |log1p decoded - log1p source| <= E in the rows "
           "that weigh most in rendering, up to 64 E where they weigh least, 32, 16 or 8 times "
           "that on the finest level (odd theta_d or phi_d; E from 1.5e-3, from 6e-4, below) and "
           "a quarter of that on the next (1.3; in 1.2 the finest level 8 times); ZFP: fixed "
           "accuracy on "
           "log1p of physical values (tolerance tol); lossless points are bit-exact (PSNR shown "
           "as the cap). Times: encode (fit included) and decode to a full table, seconds.";
  t.header = {"method",       "setting",       "materials", "KB",
              "PSNR tm (dB)", "PSNR lin (dB)", "encode s",  "decode s"};
  const bool truth = have_truth(ladders);
  const double ceiling = mean_noise_ceiling(ladders);
  if (truth) {
    t.header.push_back("PSNR tm truth (dB)");
    t.note +=
        " PSNR tm truth: against the noise-free truth (--truth); the input's own is the "
        "lossless rows'.";
  }
  if (!std::isnan(ceiling)) {
    t.note +=
        " Noisy input: its noise floor (the PSNR against the input beyond which a file "
        "reproduces noise, cbrdf info) is " +
        fmt("%.1f", ceiling) +
        " dB on average; cbrdf noise floor is the residual --target-psnr stops at.";
  }
  for (const Setting& s : settings_of(ladders)) {
    t.rows.push_back({s.method, s.setting, std::to_string(s.points.size()),
                      kb(mean(s.points, &LadderPoint::bytes)),
                      fmt("%.2f", mean(s.points, &LadderPoint::psnr_tonemapped)),
                      fmt("%.2f", mean(s.points, &LadderPoint::psnr_linear)),
                      fmt("%.3f", mean(s.points, &LadderPoint::encode_s)),
                      fmt("%.3f", mean(s.points, &LadderPoint::decode_s))});
    if (truth) {
      t.rows.back().push_back(fmt("%.2f", mean(s.points, &LadderPoint::psnr_truth_tonemapped)));
    }
  }
  return t;
}

TextTable target_table(const std::vector<LadderMaterial>& ladders) {
  TextTable t;
  t.id = "ladder-targets";
  t.title = "Ladder targets: bytes for a tone-mapped PSNR, ZFP and float16+zstd against cbrdf";
  t.note =
      "Each curve (cbrdf: base, residual and lossless points together; ZFP; float16+zstd) is "
      "its points that nothing beats in both bytes and PSNR, read at each PSNR by "
      "interpolation in log bytes (below a curve's first point, its bytes). Means over the "
      "materials cbrdf reaches (where ZFP's finest point falls short, its largest file counts and "
      "the ZFP figures are lower bounds: column ZFP short); cbrdf aims for a ratio of at least "
      "4. " +
      ladder_60db_text(ladders) + ". " + ladder_lossless_text(ladders) + ".";
  t.header = {"PSNR tm (dB)",    "materials",          "ZFP short",       "cbrdf KB",
              "ZFP KB",          "ZFP / cbrdf",        "min ZFP / cbrdf", "float16 KB",
              "float16 / cbrdf", "min float16 / cbrdf"};
  for (const LadderTarget& x : ladder_targets(ladders)) {
    t.rows.push_back({fmt("%.0f", x.psnr), std::to_string(x.materials), std::to_string(x.zfp_short),
                      kb(x.cbrdf_bytes), kb(x.zfp_bytes), fmt("%.2f", x.zfp_bytes / x.cbrdf_bytes),
                      fmt("%.2f", x.zfp_ratio_min), kb(x.float16_bytes),
                      fmt("%.2f", x.float16_bytes / x.cbrdf_bytes),
                      fmt("%.2f", x.float16_ratio_min)});
  }
  return t;
}

TextTable lossless_table(const std::vector<LadderMaterial>& ladders) {
  TextTable t;
  t.id = "ladder-lossless";
  t.title = "Ladder lossless: cbrdf --lossless against xz and zstd of the .binary";
  t.note = "Bytes of a file whose decoded table equals the source bit for bit (verified).";
  t.header = {"material", "cbrdf KB", "xz KB", "zstd KB", "cbrdf / xz", "cbrdf / zstd"};
  for (const LosslessCheck& c : lossless_checks(ladders)) {
    t.rows.push_back({c.material, kb(c.cbrdf), c.xz > 0 ? kb(c.xz) : "n/a",
                      c.zstd > 0 ? kb(c.zstd) : "n/a",
                      c.xz > 0 ? fmt("%.3f", c.cbrdf / c.xz) : "n/a",
                      c.zstd > 0 ? fmt("%.3f", c.cbrdf / c.zstd) : "n/a"});
  }
  return t;
}

// A method's settings as (mean bytes, mean PSNR) points, PSNR the given member, by increasing
// bytes.
std::vector<std::pair<double, double>> method_points(const std::vector<Setting>& settings,
                                                     const char* method,
                                                     double LadderPoint::*psnr) {
  std::vector<std::pair<double, double>> pts;
  for (const Setting& s : settings) {
    if (s.method == method)
      pts.emplace_back(mean(s.points, &LadderPoint::bytes), mean(s.points, psnr));
  }
  std::sort(pts.begin(), pts.end());
  return pts;
}

// One series per method: its settings' mean (bytes, PSNR), by increasing bytes.
Chart ladder_chart(const std::vector<LadderMaterial>& ladders, const std::string& title) {
  Chart c;
  c.title = title;
  c.x_label = "bytes (log scale)";
  c.y_label = "sphere PSNR, tone-mapped (dB)";
  c.log_x = true;
  const std::vector<Setting> settings = settings_of(ladders);
  std::size_t colour = 0;
  for (const char* method : kMethods) {
    const auto pts = method_points(settings, method, &LadderPoint::psnr_tonemapped);
    if (pts.empty()) continue;
    // The base settings are not one curve (components and bits cross): points only.
    const bool line = pts.size() > 1 && std::string(method) != kLadderBase;
    Series series{method, {}, {}, palette(colour++), line, true};
    for (const auto& [x, y] : pts) {
      series.x.push_back(x);
      series.y.push_back(y);
    }
    c.series.push_back(std::move(series));
  }
  // Against the truth (--truth): cbrdf's curves again, dashed.
  if (have_truth(ladders)) {
    for (const char* method : {kLadderBase, kLadderResidual, kLadderNoiseFloor, kLadderLossless}) {
      const auto pts = method_points(settings, method, &LadderPoint::psnr_truth_tonemapped);
      if (pts.empty()) continue;
      Series series{std::string(method) + " vs truth",
                    {},
                    {},
                    palette(colour++),
                    pts.size() > 1 && std::string(method) != kLadderBase,
                    true};
      series.dashed = true;
      series.marker = Marker::kDiamond;
      for (const auto& [x, y] : pts) {
        series.x.push_back(x);
        series.y.push_back(y);
      }
      c.series.push_back(std::move(series));
    }
  }
  // The noise floor: a level line across the chart.
  const double ceiling = mean_noise_ceiling(ladders);
  if (!std::isnan(ceiling)) {
    double lo = INFINITY, hi = 0;
    for (const Series& s : c.series) {
      for (double x : s.x) lo = std::min(lo, x), hi = std::max(hi, x);
    }
    if (hi > 0) {
      Series floor{"noise floor (input)", {lo, hi}, {ceiling, ceiling}, "#888888", true, false};
      floor.dashed = true;
      c.series.push_back(std::move(floor));
    }
  }
  return c;
}

}  // namespace

std::vector<TextTable> ladder_tables(const std::vector<LadderMaterial>& ladders) {
  if (ladders.empty()) return {};
  return {target_table(ladders), mean_table(ladders), lossless_table(ladders)};
}

std::vector<Figure> ladder_figures(const std::vector<LadderMaterial>& ladders) {
  if (ladders.empty()) return {};
  std::vector<Figure> out;
  out.push_back({"ladder_mean.svg",
                 "The ladder: mean bytes (log scale) against mean tone-mapped sphere PSNR over " +
                     std::to_string(ladders.size()) +
                     " materials, for cbrdf (base, base + residual, lossless) and the baselines; "
                     "lossless points sit at the PSNR cap.",
                 render_chart(ladder_chart(ladders, "Ladder, mean over materials")), ""});
  for (const LadderMaterial& m : ladders) {
    out.push_back({"ladder_" + file_stem(m.name) + ".svg",
                   "The ladder of " + m.name + ": bytes against tone-mapped sphere PSNR.",
                   render_chart(ladder_chart({m}, "Ladder, " + m.name)), m.name});
  }
  return out;
}

std::string ladder_csv(const std::vector<LadderMaterial>& ladders) {
  std::ostringstream out;
  out << "material,method,setting,bytes,psnr_tonemapped,psnr_linear,encode_s,decode_s,exact,"
         "psnr_truth_tonemapped\n";
  for (const LadderMaterial& m : ladders) {
    for (const LadderPoint& p : m.points) {
      out << m.name << "," << p.method << "," << p.setting << "," << fmt("%.0f", p.bytes) << ","
          << fmt("%.4f", p.psnr_tonemapped) << "," << fmt("%.4f", p.psnr_linear) << ","
          << fmt("%.4f", p.encode_s) << "," << fmt("%.4f", p.decode_s) << ","
          << (p.exact ? "true" : "false") << ","
          << (std::isnan(p.psnr_truth_tonemapped) ? "" : fmt("%.4f", p.psnr_truth_tonemapped))
          << "\n";
    }
  }
  return out.str();
}

std::string ladder_json(const std::vector<LadderMaterial>& ladders) {
  nlohmann::json j;
  j["materials"] = nlohmann::json::array();
  for (const LadderMaterial& m : ladders) {
    nlohmann::json pts = nlohmann::json::array();
    for (const LadderPoint& p : m.points) {
      pts.push_back({{"method", p.method},
                     {"setting", p.setting},
                     {"bytes", p.bytes},
                     {"psnr_tonemapped", p.psnr_tonemapped},
                     {"psnr_linear", p.psnr_linear},
                     {"encode_s", p.encode_s},
                     {"decode_s", p.decode_s},
                     {"exact", p.exact},
                     {"psnr_truth_tonemapped", std::isnan(p.psnr_truth_tonemapped)
                                                   ? nlohmann::json()
                                                   : nlohmann::json(p.psnr_truth_tonemapped)}});
    }
    j["materials"].push_back(
        {{"name", m.name},
         {"points", pts},
         {"noise_sigma", m.noise_sigma},
         // As cbrdf info --json: a ceiling that cannot be measured is
         // said so, not written as null.
         {"noise_ceiling_tonemapped", std::isfinite(m.noise_ceiling_tonemapped)
                                          ? nlohmann::json(m.noise_ceiling_tonemapped)
                                          : nlohmann::json("not measurable")}});
  }
  nlohmann::json targets = nlohmann::json::array();
  for (const LadderTarget& t : ladder_targets(ladders)) {
    auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
    targets.push_back({{"psnr_tonemapped", t.psnr},
                       {"materials", t.materials},
                       {"zfp_short", t.zfp_short},
                       {"cbrdf_bytes", num(t.cbrdf_bytes)},
                       {"zfp_bytes", num(t.zfp_bytes)},
                       {"float16_bytes", num(t.float16_bytes)},
                       {"zfp_ratio_min", num(t.zfp_ratio_min)},
                       {"float16_ratio_min", num(t.float16_ratio_min)}});
  }
  j["targets"] = targets;
  return j.dump(1) + "\n";
}

std::vector<LadderMaterial> ladders_of(const std::vector<MaterialResult>& results) {
  std::vector<LadderMaterial> out;
  for (const MaterialResult& m : results)
    if (!m.ladder.points.empty()) out.push_back(m.ladder);
  return out;
}

}  // namespace cbrdf::report
