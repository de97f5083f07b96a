// SPDX-License-Identifier: MIT
#include "report/export.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "report/frontier.h"
#include "report/tables.h"

namespace cbrdf::report {
namespace {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string g(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// The frontier's labels, per material and for the means.
nlohmann::json frontier_json(const std::vector<MaterialResult>& results, const Settings& st) {
  auto labels = [](const std::vector<RdPoint>& points) {
    nlohmann::json out = nlohmann::json::array();
    for (std::size_t i : pareto_frontier(points)) out.push_back(points[i].label);
    return out;
  };
  nlohmann::json per = nlohmann::json::object();
  for (const MaterialResult& m : results) per[m.name] = labels(material_points(m).sweep);
  return {{"mean", labels(mean_sweep_points(results, st))}, {"per_material", per}};
}

}  // namespace

std::string to_csv(const std::vector<MaterialResult>& results) {
  std::ostringstream out;
  out << "material,model,kind,slices,bits,in_sweep,primary,input_bytes,bytes,ratio,rel_rmse,"
         "log_rmse,cos_rmse,psnr_linear_db,psnr_tonemapped_db,encode_s,decode_s,eval_ns,"
         "components,paper,detail,max_error\n";
  for (const MaterialResult& m : results) {
    for (const Row& r : m.rows) {
      out << csv_field(r.material) << ',' << csv_field(r.model) << ',' << r.kind << ',' << r.slices
          << ',' << r.bits << ',' << int(r.in_sweep) << ',' << int(r.primary) << ','
          << g(r.input_bytes) << ',' << g(r.bytes) << ',' << g(r.ratio()) << ',' << g(r.rel_rmse)
          << ',' << g(r.log_rmse) << ',' << g(r.cos_rmse) << ',' << g(r.psnr_linear) << ','
          << g(r.psnr_tonemapped) << ',' << g(r.encode_s) << ',' << g(r.decode_s) << ','
          << g(r.eval_ns) << ','
          << (r.kind == std::string(kKindCopula) ? components_name(r.components) : "") << ','
          << int(r.paper) << ',' << csv_field(r.detail) << ',' << g(r.max_error) << '\n';
    }
  }
  return out.str();
}

namespace {

// The report's settings: the sweep, the baselines and how the run went.
nlohmann::json settings_json(const Settings& st, double elapsed_s) {
  nlohmann::json components = nlohmann::json::array();
  for (int k : st.sweep.components) {
    if (k == kAutoComponents) {
      components.push_back("auto");
    } else {
      components.push_back(k);
    }
  }
  return {
      {"families", st.sweep.families},
      {"slices", st.sweep.slices},
      {"bits", st.sweep.bits},
      {"components", components},
      {"residual", st.sweep.residual},
      {"primary", st.sweep.primary().label()},
      {"paper", paper_setting().label()},
      {"baselines",
       {{"lossless", st.baselines.lossless},
        {"float16", st.baselines.float16},
        {"separable", st.baselines.separable},
        {"families", st.baselines.families},
        {"analytic", st.baselines.analytic}}},
      {"lossless_zstd_level", st.lossless_zstd_level},
      {"xz_preset", st.xz_preset},
      {"float16_zstd_level", st.float16_zstd_level},
      {"analytic_bins", st.analytic_bins},
      {"analytic_loss", st.analytic_loss == AnalyticLoss::kLog ? "log" : "cosine-weighted"},
      {"sphere_size", st.sphere_size},
      {"jobs", st.jobs},
      {"hardware_threads", std::thread::hardware_concurrency()},
      {"elapsed_s", elapsed_s},
  };
}

nlohmann::json row_fields(const Row& r) {
  return {{"material", r.material},
          {"model", r.model},
          {"label", r.label()},
          {"kind", r.kind},
          {"slices", r.slices},
          {"bits", r.bits},
          {"components", r.kind == std::string(kKindCopula)
                             ? nlohmann::json(components_name(r.components))
                             : nlohmann::json(nullptr)},
          {"max_error", r.max_error},
          {"in_sweep", r.in_sweep},
          {"paper", r.paper},
          {"primary", r.primary},
          {"input_bytes", r.input_bytes},
          {"bytes", r.bytes},
          {"ratio", r.ratio()},
          {"rel_rmse", r.rel_rmse},
          {"log_rmse", r.log_rmse},
          {"cos_rmse", r.cos_rmse},
          {"psnr_linear_db", r.psnr_linear},
          {"psnr_tonemapped_db", r.psnr_tonemapped},
          {"encode_s", r.encode_s},
          {"decode_s", r.decode_s},
          {"eval_ns", r.eval_ns},
          {"render_s",
           std::isfinite(r.render_s) ? nlohmann::json(r.render_s) : nlohmann::json(nullptr)},
          {"detail", r.detail}};
}

nlohmann::json row_json(const Row& r) {
  nlohmann::json j = row_fields(r);
  // Only with side-by-side codings (--format-version auto,1.2): each coding's measurements.
  if (!r.codings.empty()) {
    nlohmann::json codings = nlohmann::json::array();
    for (const CodingResult& c : r.codings) {
      codings.push_back({{"coding", c.coding},
                         {"bytes", c.bytes},
                         {"psnr_linear_db", c.psnr_linear},
                         {"psnr_tonemapped_db", c.psnr_tonemapped},
                         {"encode_s", c.encode_s}});
    }
    j["codings"] = std::move(codings);
  }
  return j;
}

// The mean and per-material gains over the paper's setting at each budget factor.
nlohmann::json gains_json(const std::vector<MaterialResult>& results) {
  nlohmann::json gains = nlohmann::json::array();
  for (double f : kBudgetFactors) {
    const BudgetGain b = budget_gain(material_points(results), f);
    nlohmann::json per = nlohmann::json::array();
    for (const MaterialGain& m : b.per_material) {
      per.push_back(
          {{"material", m.material},
           {"qualifying", m.qualifying},
           {"setting", m.best},
           {"gain_db", m.qualifying ? nlohmann::json(m.gain_db) : nlohmann::json(nullptr)},
           {"bytes_ratio", m.qualifying ? nlohmann::json(m.bytes_ratio) : nlohmann::json(nullptr)},
           {"encode_ratio",
            m.qualifying ? nlohmann::json(m.encode_ratio) : nlohmann::json(nullptr)}});
    }
    auto num = [](double v) {
      return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
    };
    gains.push_back({{"factor", f},
                     {"materials", b.materials},
                     {"qualifying", b.qualifying},
                     {"mean_gain_db", num(b.mean_gain_db)},
                     {"min_gain_db", num(b.min_gain_db)},
                     {"max_gain_db", num(b.max_gain_db)},
                     {"target_gain_db", num(target_gain_db(f))},
                     {"mean_bytes_ratio", num(b.mean_bytes_ratio)},
                     {"mean_encode_ratio", num(b.mean_encode_ratio)},
                     {"per_material", per}});
  }
  return gains;
}

}  // namespace

std::string to_json(const std::vector<MaterialResult>& results, const Settings& st,
                    double elapsed_s) {
  nlohmann::json rows = nlohmann::json::array();
  nlohmann::json polar = nlohmann::json::array();
  nlohmann::json renders = nlohmann::json::array();
  for (const MaterialResult& m : results) {
    for (const Row& r : m.rows) rows.push_back(row_json(r));
    // The measured table's render times (Table 3), when measured.
    if (std::isfinite(m.render_nearest_s)) {
      renders.push_back({{"material", m.name},
                         {"width", m.render_width},
                         {"height", m.render_height},
                         {"nearest_s", m.render_nearest_s},
                         {"trilinear_s", m.render_trilinear_s},
                         {"nearest_eval_ns", m.nearest_eval_ns},
                         {"trilinear_eval_ns", m.trilinear_eval_ns}});
    }
    for (const PolarCurve& c : m.polar) {
      polar.push_back({{"material", m.name},
                       {"model", c.model},
                       {"theta_i_deg", c.theta_i_deg},
                       {"theta_o_deg", c.theta_o_deg},
                       {"value", c.value}});
    }
  }
  return nlohmann::json{{"settings", settings_json(st, elapsed_s)},
                        {"rows", rows},
                        {"polar", polar},
                        {"table_renders", renders},
                        {"gains", gains_json(results)},
                        {"frontier", frontier_json(results, st)}}
             .dump(1, ' ', false, nlohmann::json::error_handler_t::replace) +
         "\n";
}

std::string frontier_csv(const std::vector<MaterialResult>& results, const Settings& st) {
  std::ostringstream out;
  out << "scope,setting,bytes,psnr_tonemapped_db,encode_s\n";
  auto add = [&](const std::string& scope, const std::vector<RdPoint>& points) {
    for (std::size_t i : pareto_frontier(points)) {
      const RdPoint& p = points[i];
      out << csv_field(scope) << ',' << csv_field(p.label) << ',' << g(p.bytes) << ',' << g(p.psnr)
          << ',' << g(p.encode_s) << '\n';
    }
  };
  for (const MaterialResult& m : results) add(m.name, material_points(m).sweep);
  add("mean", mean_sweep_points(results, st));
  return out.str();
}

}  // namespace cbrdf::report
