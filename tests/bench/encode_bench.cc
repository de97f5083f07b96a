// SPDX-License-Identifier: MIT
// What encoding costs at the CLI's settings: the default encode, rate control (--target-bytes,
// --target-psnr) and a 4-component encode, each as a ratio to the default encode of the same
// material in the same run (the speed issue's targets: rate control at most 5x, a 4-component
// encode under 2 s), and how soon a cancelled encode returns (BM_CancelLatency). Run:
// build/tests/bench/cbrdf_encode_bench [threads=N] [model-only] [MATERIAL...] (names from
// ../shared/data, default blue-metallic-paint and nickel; "sample:NAME" for a built-in one when
// ../shared is absent). Each figure is one encode of the table in memory (reading it is not timed),
// on all cores as `cbrdf encode` runs it, or on N threads (`--threads N`). The targets search the
// whole ladder as `cbrdf encode` does (encode_to_target_ladder: the model, then the model plus the
// residual layer); model-only: the model's search alone (encode_to_target).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/file_io.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/metrics.h"
#include "cbrdf/parallel.h"
#include "cbrdf/progress.h"
#include "cbrdf/rate_control.h"
#include "cbrdf/samples.h"

namespace {

// The table of a material: from ../shared (MERL layout, made into the build tree) or built in.
cbrdf::BrdfTable load(const std::string& material) {
  if (material.rfind("sample:", 0) == 0) {
    auto t = cbrdf::make_sample(material.substr(7));
    if (!t.ok()) {
      std::fprintf(stderr, "unknown sample %s\n", material.c_str());
      std::exit(1);
    }
    return std::move(t).value();
  }
  const std::filesystem::path out = std::filesystem::path(CBRDF_BUILD_DIR) / "real-materials";
  const std::filesystem::path path = out / (material + ".binary");
  if (!std::filesystem::exists(path)) {
    const std::string cmd = "bash '" CBRDF_SHARED_DIR "/tools/make-merl.sh' '" + out.string() +
                            "' " + material + " > /dev/null 2>&1";
    if (std::system(cmd.c_str()) != 0 || !std::filesystem::exists(path)) {
      std::fprintf(stderr, "cannot make %s from ../shared: using sample:ward\n", material.c_str());
      return load("sample:ward");
    }
  }
  auto t = cbrdf::read_merl(path);
  if (!t.ok()) std::exit(1);
  return std::move(t).value();
}

int& threads() {
  static int n = 0;  // 0: one per core, as the CLI
  return n;
}

bool& model_only() {
  static bool m = false;  // false: the whole ladder, as the CLI
  return m;
}

std::map<std::string, cbrdf::BrdfTable>& tables() {
  static std::map<std::string, cbrdf::BrdfTable> t;
  return t;
}

// The settings `cbrdf encode` uses by default (all cores).
cbrdf::EncoderSettings cli_settings(const char* components = "1") {
  cbrdf::EncoderOptions o;
  o.components = components;
  o.threads = threads();
  return cbrdf::encoder_settings(o).value();
}

// The search reports how much it did.
void count(benchmark::State& state, const cbrdf::RateResult& r) {
  state.counters["settings"] = double(r.tried.size());
  state.counters["fits"] = double(r.fits);
  state.counters["bytes"] = r.chosen.bytes;
  state.counters["psnr_tm"] = r.chosen.psnr_tonemapped;
  state.counters["met"] = r.met ? 1 : 0;
  state.counters["residual"] = r.chosen.max_error > 0 ? 1 : 0;
}

void BM_Default(benchmark::State& state, const std::string& m) {
  const cbrdf::EncoderSettings st = cli_settings();
  for (auto _ : state) {
    auto r = cbrdf::encode_table(tables().at(m), st);
    if (!r.ok()) state.SkipWithError("encode failed");
    state.counters["bytes"] = double(r->bytes.size());
  }
}

// Also reports the file's tone-mapped sphere PSNR (measured after timing) and the HALS sweeps the
// mixture fit spent, so that a faster fit shows what it costs in quality.
void BM_Components4(benchmark::State& state, const std::string& m) {
  const cbrdf::EncoderSettings st = cli_settings("4");
  std::vector<std::uint8_t> bytes;
  long long sweeps = 0;
  for (auto _ : state) {
    auto r = cbrdf::encode_table(tables().at(m), st);
    if (!r.ok()) {
      state.SkipWithError("encode failed");
      return;
    }
    bytes = std::move(r->bytes);
    sweeps = 0;
    for (const auto& slice : r->report.slices)
      for (const cbrdf::ChannelSliceFit& f : slice) sweeps += f.hals_sweeps;
  }
  state.counters["bytes"] = double(bytes.size());
  state.counters["hals_sweeps"] = double(sweeps);
  auto decoded = cbrdf::decode_model(bytes);
  if (decoded.ok())
    state.counters["psnr_tm"] =
        cbrdf::sphere_psnr(tables().at(m), decoded->table()).psnr_tonemapped;
}

// As `cbrdf encode --target-bytes N` / `--target-psnr DB` (up to 4 components).
void BM_Target(benchmark::State& state, const std::string& m, double bytes, double psnr) {
  const cbrdf::EncoderSettings st = cli_settings();
  cbrdf::RateTarget target;
  target.max_bytes = bytes;
  target.min_psnr = psnr;
  for (auto _ : state) {
    auto r = model_only() ? cbrdf::encode_to_target(tables().at(m), st, target)
                          : cbrdf::encode_to_target_ladder(tables().at(m), st, target);
    if (!r.ok()) {
      state.SkipWithError("rate control failed");
      break;
    }
    count(state, *r);
  }
}

// How promptly a --target-psnr 60 encode (cbrdf encode's ladder) stops when its progress
// callback returns false `after_ms` into the work: the issue-41 aim is 100 ms from the false to
// the return. The tests hold only a bound that a missing checkpoint would break (300 ms), since
// the figure depends on the machine's load; this is where the aim is measured. cancel_ms is the
// latency, cancel_fraction how far the encode had gone.
void BM_CancelLatency(benchmark::State& state, const std::string& m, int after_ms) {
  using Clock = std::chrono::steady_clock;
  cbrdf::EncoderSettings st = cli_settings();
  cbrdf::RateTarget target;
  target.min_psnr = 60;
  for (auto _ : state) {
    const Clock::time_point start = Clock::now();
    Clock::time_point cancelled{};
    double fraction = -1;
    st.progress = [&](const cbrdf::EncodeProgress& p) {
      if (Clock::now() - start < std::chrono::milliseconds(after_ms)) return true;
      if (fraction < 0) cancelled = Clock::now(), fraction = p.fraction;
      return false;
    };
    auto r = cbrdf::encode_to_target_ladder(tables().at(m), st, target);
    const Clock::time_point returned = Clock::now();
    if (r.ok() || r.status().code() != cbrdf::ErrorCode::kCancelled) {
      state.SkipWithError("the encode was not cancelled");
      break;
    }
    state.counters["cancel_ms"] =
        std::chrono::duration<double, std::milli>(returned - cancelled).count();
    state.counters["cancel_fraction"] = fraction;
  }
}

// Prints each run's time over the default encode's of its material.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name != "median") continue;
      seconds_.push_back({r.benchmark_name(), r.GetAdjustedRealTime() / 1e3,  // ms -> s
                          r.GetAdjustedCPUTime() / 1e3});
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    // CPU time of the whole process (all threads): on a shared machine the wall time also
    // counts waiting for a core.
    std::printf("\n%-56s %9s %10s %9s %10s\n", "encode", "s", "x default", "cpu s", "x default");
    for (const auto& [name, s, cpu] : seconds_) {
      // Names are BM_Kind/material[/...]: the material's default encode is BM_Default/material.
      const std::size_t slash = name.find('/');
      std::string material = slash == std::string::npos ? "" : name.substr(slash + 1);
      material = material.substr(0, material.find('/'));
      double base = 0, base_cpu = 0;
      for (const auto& [n, t, c] : seconds_) {
        if (n.rfind("BM_Default/" + material, 0) == 0) base = t, base_cpu = c;
      }
      std::printf("%-56s %9.2f %10.2f %9.2f %10.2f\n", name.c_str(), s, base > 0 ? s / base : 0.0,
                  cpu, base_cpu > 0 ? cpu / base_cpu : 0.0);
    }
  }

 private:
  struct Seconds {
    std::string name;
    double real, cpu;
  };
  std::vector<Seconds> seconds_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::vector<std::string> materials;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("threads=", 0) == 0) {
      threads() = std::atoi(arg.c_str() + 8);
    } else if (arg == "model-only") {
      model_only() = true;
    } else {
      materials.push_back(arg);
    }
  }
  if (materials.empty()) materials = {"blue-metallic-paint", "nickel"};
  for (const std::string& m : materials) {
    tables().emplace(m, load(m));
    const auto reg = [&](const std::string& kind, auto fn) {
      benchmark::RegisterBenchmark((kind + "/" + m).c_str(), fn)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->MeasureProcessCPUTime()
          ->Iterations(1);
    };
    reg("BM_Default", [m](benchmark::State& s) { BM_Default(s, m); });
    // Budgets and PSNRs across the range where one and several components win.
    for (const int bytes : {3000, 6000, 12000}) {
      reg("BM_TargetBytes" + std::to_string(bytes),
          [m, bytes](benchmark::State& s) { BM_Target(s, m, bytes, 0); });
    }
    for (const int psnr : {40, 45, 50}) {
      reg("BM_TargetPsnr" + std::to_string(psnr),
          [m, psnr](benchmark::State& s) { BM_Target(s, m, 0, psnr); });
    }
    // Unreachable: every row the pruning leaves is fitted (the 264 settings in 133 s).
    reg("BM_TargetPsnr1000", [m](benchmark::State& s) { BM_Target(s, m, 0, 1000); });
    reg("BM_Components4", [m](benchmark::State& s) { BM_Components4(s, m); });
    // Early in the model search and late in it (or in the residual layer's tries).
    for (const int after_ms : {200, 1500}) {
      reg("BM_CancelLatency" + std::to_string(after_ms),
          [m, after_ms](benchmark::State& s) { BM_CancelLatency(s, m, after_ms); });
    }
  }
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
