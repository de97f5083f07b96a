// What the codec costs: reading a table, fitting, decoding, and evaluating the model against the
// measured table's nearest-bin lookup. Run: build/tests/bench/cbrdf_bench [MATERIAL]
// (MATERIAL: a name from ../shared/data, default blue-metallic-paint; "sample:NAME" for a
// built-in one). Compare figures as ratios within one run.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "cbrdf/file_io.h"
#include "cbrdf/fit.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/samples.h"

namespace {

std::string g_material = "blue-metallic-paint";
std::filesystem::path g_path;

std::filesystem::path material_path() {
  if (!g_path.empty()) return g_path;
  if (g_material.rfind("sample:", 0) == 0) {
    g_path = std::filesystem::path(CBRDF_BUILD_DIR) / "bench-sample.binary";
    auto t = cbrdf::make_sample(g_material.substr(7));
    if (!t.ok() || !cbrdf::write_merl(g_path, *t).ok()) std::abort();
    return g_path;
  }
  const std::filesystem::path out = std::filesystem::path(CBRDF_BUILD_DIR) / "real-materials";
  g_path = out / (g_material + ".binary");
  if (!std::filesystem::exists(g_path)) {
    const std::string cmd = "bash '" CBRDF_SHARED_DIR "/tools/make-merl.sh' '" + out.string() +
                            "' " + g_material + " > /dev/null";
    if (std::system(cmd.c_str()) != 0 || !std::filesystem::exists(g_path)) {
      std::fprintf(stderr, "cannot make %s from ../shared; use sample:NAME\n", g_material.c_str());
      std::exit(1);
    }
  }
  return g_path;
}

const cbrdf::BrdfTable& table() {
  static cbrdf::BrdfTable t = *cbrdf::read_merl(material_path());
  return t;
}

const std::vector<std::uint8_t>& encoded() {
  static std::vector<std::uint8_t> bytes = [] {
    cbrdf::EncoderSettings st;
    return cbrdf::encode_table(table(), st)->bytes;
  }();
  return bytes;
}

std::vector<cbrdf::Vec3> random_directions(int n) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<cbrdf::Vec3> d(n);
  for (auto& v : d) {
    const double z = u(rng), phi = 2 * M_PI * u(rng), r = std::sqrt(1 - z * z);
    v = {r * std::cos(phi), r * std::sin(phi), z};
  }
  return d;
}

void BM_ReadMerl(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(cbrdf::read_merl(material_path()));
}
BENCHMARK(BM_ReadMerl)->Unit(benchmark::kMillisecond);

// Fitting one material on one core: 3 channels x 6 slices, marginals included.
void BM_FitOneCore(benchmark::State& state) {
  cbrdf::FitSettings st;
  st.threads = 1;
  for (auto _ : state) benchmark::DoNotOptimize(cbrdf::fit_model(table(), st));
}
BENCHMARK(BM_FitOneCore)->Unit(benchmark::kMillisecond);

void BM_EncodeFile(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(encoded());
  state.counters["bytes"] = double(encoded().size());
}
BENCHMARK(BM_EncodeFile)->Iterations(1);

// Decoding a full table on one core: parse, dequantize, rebuild 3 x 1,458,000 values.
void BM_DecodeTable(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(cbrdf::decode_table(encoded()));
}
BENCHMARK(BM_DecodeTable)->Unit(benchmark::kMillisecond);

constexpr int kPairs = 1 << 16;

void BM_EvalModel(benchmark::State& state) {
  const cbrdf::Model model = *cbrdf::decode_model(encoded());
  const cbrdf::ModelEvaluator ev(model);
  const auto d = random_directions(2 * kPairs);
  double rgb[3];
  for (auto _ : state) {
    for (int n = 0; n < kPairs; ++n) {
      ev.eval(d[2 * n], d[2 * n + 1], rgb);
      benchmark::DoNotOptimize(rgb);
    }
  }
  state.SetItemsProcessed(state.iterations() * kPairs);
}
BENCHMARK(BM_EvalModel)->Unit(benchmark::kMillisecond);

void BM_LookupMeasuredNearest(benchmark::State& state) {
  const auto d = random_directions(2 * kPairs);
  double rgb[3];
  for (auto _ : state) {
    for (int n = 0; n < kPairs; ++n) {
      cbrdf::lookup_nearest(table(), d[2 * n], d[2 * n + 1], rgb);
      benchmark::DoNotOptimize(rgb);
    }
  }
  state.SetItemsProcessed(state.iterations() * kPairs);
}
BENCHMARK(BM_LookupMeasuredNearest)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (argc > 1) g_material = argv[1];
  encoded();  // make, read and encode the material before timing anything
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
