#include "report/measure.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "cbrdf/encoder.h"
#include "cbrdf/file_io.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/metrics.h"
#include "cbrdf/samples.h"

namespace cbrdf::report {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Mean cost of one ModelEvaluator::eval over random upper-hemisphere direction pairs.
double eval_ns(const Model& model) {
  const ModelEvaluator ev(model);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  constexpr int kPairs = 4096, kRounds = 50;
  std::vector<Vec3> dirs(2 * kPairs);
  for (Vec3& d : dirs) {
    const double z = u(rng), phi = 2 * M_PI * u(rng), r = std::sqrt(1 - z * z);
    d = {r * std::cos(phi), r * std::sin(phi), z};
  }
  double sink = 0, rgb[3];
  const auto t0 = Clock::now();
  for (int round = 0; round < kRounds; ++round) {
    for (int n = 0; n < kPairs; ++n) {
      ev.eval(dirs[2 * n], dirs[2 * n + 1], rgb);
      sink += rgb[0];
    }
  }
  const double ns = 1e9 * since(t0) / (double(kPairs) * kRounds);
  return sink >= 0 ? ns : ns;  // keeps the loop from being optimized away
}

Expected<Row> measure(const Material& m, const Settings& st, int fit_threads) {
  Row r;
  r.material = m.name;
  auto table = m.builtin ? make_sample(m.name) : read_merl(m.path);
  if (!table.ok()) return table.status();
  r.input_bytes = double(kMerlFileBytes);
  EncoderSettings es;
  es.fit.slices = st.slices;
  es.fit.threads = fit_threads;
  es.container.bits = st.bits;
  es.container.source_name = m.name;
  auto t0 = Clock::now();
  auto enc = encode_table(*table, es);
  if (!enc.ok()) return enc.status().with_context(m.name);
  r.encode_seconds = since(t0);
  r.container_bytes = double(enc->bytes.size());
  t0 = Clock::now();
  auto model = decode_model(enc->bytes);
  if (!model.ok()) return model.status().with_context(m.name);
  const BrdfTable decoded = model->table();
  r.decode_seconds = since(t0);
  const BrdfMetrics bm = brdf_metrics(*table, decoded);
  r.rel_rmse = bm.rel_rmse_mean;
  r.log_rmse = bm.log_rmse_mean;
  SphereSetup sphere;
  sphere.threads = 1;
  const ImageMetrics im = sphere_psnr(nearest_lookup_fn(*table), nearest_lookup_fn(decoded), sphere);
  r.psnr_linear = im.psnr_linear;
  r.psnr_tonemapped = im.psnr_tonemapped;
  r.eval_ns_per_sample = eval_ns(*model);
  return r;
}

}  // namespace

Expected<std::vector<Row>> measure_all(const std::vector<Material>& materials, const Settings& st) {
  std::vector<Row> rows(materials.size());
  std::vector<Status> errors(materials.size());
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex print;
  const int jobs = std::max(1, std::min<int>(st.jobs, int(materials.size())));
  // With one job, the fit itself uses every core; with several, each material gets one.
  const int fit_threads = jobs == 1 ? std::max(1, st.jobs) : 1;
  auto worker = [&] {
    for (std::size_t i = next++; i < materials.size(); i = next++) {
      auto r = measure(materials[i], st, fit_threads);
      if (r.ok()) {
        rows[i] = *r;
      } else {
        errors[i] = r.status();
      }
      const std::size_t n = ++done;
      if (st.progress) {
        std::lock_guard<std::mutex> lock(print);
        std::fprintf(stderr, "\r[%zu/%zu] %-32s", n, materials.size(), materials[i].name.c_str());
        if (n == materials.size()) std::fprintf(stderr, "\r%60s\r", "");
        std::fflush(stderr);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < jobs; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  for (const Status& e : errors) {
    if (!e.ok()) return e;
  }
  return rows;
}

std::string format_table(const std::vector<Row>& rows) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-28s %9s %8s %9s %9s %8s %9s %9s %8s\n", "material", "bytes",
                "ratio", "PSNR dB", "PSNR tm", "relRMSE", "encode s", "decode s", "eval ns");
  out << line;
  double bytes = 0, psnr = 0, psnr_tm = 0, enc = 0;
  for (const Row& r : rows) {
    std::snprintf(line, sizeof line, "%-28s %9.0f %7.0f:1 %9.2f %9.2f %8.4f %9.3f %9.3f %8.1f\n",
                  r.material.c_str(), r.container_bytes, r.input_bytes / r.container_bytes,
                  r.psnr_linear, r.psnr_tonemapped, r.rel_rmse, r.encode_seconds,
                  r.decode_seconds, r.eval_ns_per_sample);
    out << line;
    bytes += r.container_bytes;
    psnr += r.psnr_linear;
    psnr_tm += r.psnr_tonemapped;
    enc += r.encode_seconds;
  }
  if (!rows.empty()) {
    const double n = double(rows.size());
    std::snprintf(line, sizeof line, "%-28s %9.0f %8s %9.2f %9.2f %8s %9.3f\n", "mean", bytes / n,
                  "", psnr / n, psnr_tm / n, "", enc / n);
    out << line;
  }
  return out.str();
}

Status write_files(const std::vector<Row>& rows, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return error(ErrorCode::kIo, dir + ": cannot create the directory: " + ec.message());
  std::ostringstream md, csv;
  md << "# cbrdf report\n\nSphere PSNR: 256x256 direct-lit spheres, lights at 10, 45 and 75 "
        "degrees, decoded against input; 'tm' after tone mapping.\n\n";
  md << "| material | bytes | ratio | PSNR dB | PSNR tm dB | rel RMSE | encode s | decode s | "
        "eval ns |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  csv << "material,input_bytes,container_bytes,psnr_linear_db,psnr_tonemapped_db,rel_rmse,"
         "log_rmse,encode_s,decode_s,eval_ns\n";
  nlohmann::json j = nlohmann::json::array();
  for (const Row& r : rows) {
    char line[512];
    std::snprintf(line, sizeof line, "| %s | %.0f | %.0f:1 | %.2f | %.2f | %.4f | %.3f | %.3f | %.1f |\n",
                  r.material.c_str(), r.container_bytes, r.input_bytes / r.container_bytes,
                  r.psnr_linear, r.psnr_tonemapped, r.rel_rmse, r.encode_seconds,
                  r.decode_seconds, r.eval_ns_per_sample);
    md << line;
    std::snprintf(line, sizeof line, "%s,%.0f,%.0f,%.4f,%.4f,%.6g,%.6g,%.4f,%.4f,%.2f\n",
                  r.material.c_str(), r.input_bytes, r.container_bytes, r.psnr_linear,
                  r.psnr_tonemapped, r.rel_rmse, r.log_rmse, r.encode_seconds, r.decode_seconds,
                  r.eval_ns_per_sample);
    csv << line;
    j.push_back({{"material", r.material},
                 {"input_bytes", r.input_bytes},
                 {"container_bytes", r.container_bytes},
                 {"psnr_linear_db", r.psnr_linear},
                 {"psnr_tonemapped_db", r.psnr_tonemapped},
                 {"rel_rmse", r.rel_rmse},
                 {"log_rmse", r.log_rmse},
                 {"encode_s", r.encode_seconds},
                 {"decode_s", r.decode_seconds},
                 {"eval_ns", r.eval_ns_per_sample}});
  }
  auto write = [&](const std::string& name, const std::string& text) {
    return write_file_atomic(std::filesystem::path(dir) / name,
                             std::span<const std::uint8_t>(
                                 reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  };
  CBRDF_RETURN_IF_ERROR(write("report.md", md.str()));
  CBRDF_RETURN_IF_ERROR(write("report.csv", csv.str()));
  return write("report.json", j.dump(2) + "\n");
}

}  // namespace cbrdf::report
