#include "report/export.h"

#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

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

}  // namespace

std::string to_csv(const std::vector<MaterialResult>& results) {
  std::ostringstream out;
  out << "material,model,kind,slices,bits,in_sweep,primary,input_bytes,bytes,ratio,rel_rmse,"
         "log_rmse,cos_rmse,psnr_linear_db,psnr_tonemapped_db,encode_s,decode_s,eval_ns,detail\n";
  for (const MaterialResult& m : results) {
    for (const Row& r : m.rows) {
      out << csv_field(r.material) << ',' << csv_field(r.model) << ',' << r.kind << ',' << r.slices
          << ',' << r.bits << ',' << int(r.in_sweep) << ',' << int(r.primary) << ','
          << g(r.input_bytes) << ',' << g(r.bytes) << ',' << g(r.ratio()) << ',' << g(r.rel_rmse)
          << ',' << g(r.log_rmse) << ',' << g(r.cos_rmse) << ',' << g(r.psnr_linear) << ','
          << g(r.psnr_tonemapped) << ',' << g(r.encode_s) << ',' << g(r.decode_s) << ','
          << g(r.eval_ns) << ',' << csv_field(r.detail) << '\n';
    }
  }
  return out.str();
}

std::string to_json(const std::vector<MaterialResult>& results, const Settings& st,
                    double elapsed_s) {
  nlohmann::json settings = {
      {"families", st.sweep.families},
      {"slices", st.sweep.slices},
      {"bits", st.sweep.bits},
      {"primary", st.sweep.primary().label()},
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
  nlohmann::json rows = nlohmann::json::array();
  nlohmann::json polar = nlohmann::json::array();
  for (const MaterialResult& m : results) {
    for (const Row& r : m.rows) {
      rows.push_back({{"material", r.material},
                      {"model", r.model},
                      {"label", r.label()},
                      {"kind", r.kind},
                      {"slices", r.slices},
                      {"bits", r.bits},
                      {"in_sweep", r.in_sweep},
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
                      {"detail", r.detail}});
    }
    for (const PolarCurve& c : m.polar) {
      polar.push_back({{"material", m.name},
                       {"model", c.model},
                       {"theta_i_deg", c.theta_i_deg},
                       {"theta_o_deg", c.theta_o_deg},
                       {"value", c.value}});
    }
  }
  return nlohmann::json{{"settings", settings}, {"rows", rows}, {"polar", polar}}.dump(1) + "\n";
}

}  // namespace cbrdf::report
