// SPDX-License-Identifier: MIT
// What the codec costs: reading a table, fitting, decoding, and evaluating the model against the
// measured table's nearest-bin lookup. Run: build/tests/bench/cbrdf_bench [MATERIAL]
// (MATERIAL: a name from ../shared/data, default blue-metallic-paint; "sample:NAME" for a
// built-in one). Compare figures as ratios within one run.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "cbrdf/cbrdf_c.h"
#include "cbrdf/codec.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/encoder.h"
#include "cbrdf/file_io.h"
#include "cbrdf/fit.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/parallel.h"
#include "cbrdf/samples.h"
#include "cbrdf/sampling.h"

namespace {

// What these benchmarks have always measured: 12 bits (no bits search), the 1.2 coding, full
// metadata; EncoderSettings{} is the command's default instead.
cbrdf::EncoderSettings fixed_settings() {
  cbrdf::EncoderSettings st;
  st.auto_bits.enabled = false;
  st.container.format = cbrdf::ContainerSettings::Format::kV12;
  st.container.metadata = cbrdf::ContainerSettings::Metadata::kFull;
  return st;
}

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
    cbrdf::EncoderSettings st = fixed_settings();
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

// The same model in the 1.2 coding (arg 12) and the 1.3 one (arg 13): decode time side by side.
const std::vector<std::uint8_t>& encoded_as(std::int64_t version) {
  static const std::vector<std::uint8_t> bytes[2] = {
      [] {
        cbrdf::EncoderSettings st = fixed_settings();
        st.container.format = cbrdf::ContainerSettings::Format::kV12;
        return cbrdf::encode_table(table(), st)->bytes;
      }(),
      [] {
        cbrdf::EncoderSettings st = fixed_settings();
        st.container.format = cbrdf::ContainerSettings::Format::kV13;
        return cbrdf::encode_table(table(), st)->bytes;
      }()};
  return bytes[version == 13 ? 1 : 0];
}

// Parse and dequantize only (what the coding changes), then the whole table.
void BM_DecodeModelFormat(benchmark::State& state) {
  const std::vector<std::uint8_t>& b = encoded_as(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(cbrdf::decode_model(b));
  state.counters["bytes"] = double(b.size());
}
BENCHMARK(BM_DecodeModelFormat)->Arg(12)->Arg(13)->Unit(benchmark::kMicrosecond);

void BM_DecodeTableFormat(benchmark::State& state) {
  const std::vector<std::uint8_t>& b = encoded_as(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(cbrdf::decode_table(b));
}
BENCHMARK(BM_DecodeTableFormat)->Arg(12)->Arg(13)->Unit(benchmark::kMillisecond);

// A file with the residual layer at bound 10^-exponent (as --target-psnr writes it: steps by
// visibility, interpolated levels) in the 1.2 coding (zstd'd varint codes) and the 1.3 one
// (range-coded codes, spec 4.6): the decode time the coding costs, side by side.
const std::vector<std::uint8_t>& residual_file(std::int64_t version, std::int64_t exponent) {
  static std::vector<std::uint8_t> files[2][4];
  std::vector<std::uint8_t>& f = files[version == 13 ? 1 : 0][exponent];
  if (f.empty()) {
    cbrdf::EncoderSettings st = fixed_settings();
    st.container.format = version == 13 ? cbrdf::ContainerSettings::Format::kV13
                                        : cbrdf::ContainerSettings::Format::kV12;
    st.container.bits = 10;
    st.residual = cbrdf::target_residual_settings(std::pow(10.0, -double(exponent)));
    f = cbrdf::encode_table(table(), st)->bytes;
  }
  return f;
}

void BM_DecodeResidualFormat(benchmark::State& state) {
  const std::vector<std::uint8_t>& b = residual_file(state.range(0), state.range(1));
  for (auto _ : state) benchmark::DoNotOptimize(cbrdf::decode_table(b));
  state.counters["bytes"] = double(b.size());
}
BENCHMARK(BM_DecodeResidualFormat)
    ->ArgNames({"version", "E10^-"})
    ->Args({12, 2})
    ->Args({13, 2})
    ->Args({12, 3})
    ->Args({13, 3})
    ->Unit(benchmark::kMillisecond);

constexpr int kPairs = 1 << 16;

// The bench material fitted with a 4-component mixture (fit_model, one core): what a mixture
// costs to evaluate.
const cbrdf::Model& model4() {
  static cbrdf::Model m = [] {
    cbrdf::FitSettings st;
    st.components = 4;
    auto fit = cbrdf::fit_model(table(), st);
    if (!fit.ok()) std::abort();
    return std::move(fit).value();
  }();
  return m;
}

void eval_pairs(benchmark::State& state, const cbrdf::Model& model) {
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
  state.counters["ns_per_pair"] =
      benchmark::Counter(double(state.iterations()) * kPairs,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["footprint_bytes"] = double(ev.footprint_bytes());
}

// ModelEvaluator::eval, one component per slice and channel (the paper's model).
void BM_EvalModel(benchmark::State& state) {
  eval_pairs(state, *cbrdf::decode_model(encoded()));
}
BENCHMARK(BM_EvalModel)->Unit(benchmark::kMillisecond)->UseRealTime();

// ModelEvaluator::eval, four components per slice and channel.
void BM_EvalModel4(benchmark::State& state) {
  eval_pairs(state, model4());
}
BENCHMARK(BM_EvalModel4)->Unit(benchmark::kMillisecond)->UseRealTime();

// ModelEvaluator::eval_f32 (a renderer's path), one and four components.
void eval_pairs_f32(benchmark::State& state, const cbrdf::Model& model) {
  const cbrdf::ModelEvaluator ev(model);
  const auto d = random_directions(2 * kPairs);
  std::vector<float> f(d.size() * 3);
  for (std::size_t i = 0; i < d.size(); ++i) {
    f[3 * i] = float(d[i].x);
    f[3 * i + 1] = float(d[i].y);
    f[3 * i + 2] = float(d[i].z);
  }
  float rgb[3];
  for (auto _ : state) {
    for (int n = 0; n < kPairs; ++n) {
      ev.eval_f32(&f[6 * std::size_t(n)], &f[6 * std::size_t(n) + 3], rgb);
      benchmark::DoNotOptimize(rgb);
    }
  }
  state.SetItemsProcessed(state.iterations() * kPairs);
  state.counters["ns_per_pair"] =
      benchmark::Counter(double(state.iterations()) * kPairs,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void BM_EvalModelFloat(benchmark::State& state) {
  eval_pairs_f32(state, *cbrdf::decode_model(encoded()));
}
BENCHMARK(BM_EvalModelFloat)->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_EvalModelFloat4(benchmark::State& state) {
  eval_pairs_f32(state, model4());
}
BENCHMARK(BM_EvalModelFloat4)->Unit(benchmark::kMillisecond)->UseRealTime();

// ModelEvaluator::eval_batch (structure of arrays), at a thread count (state.range(0)); float64
// and float32. Compare its ns_per_pair with BM_EvalModel's (the scalar loop) in the table at
// the end.
struct SoaPairs {
  std::vector<double> x[6];
  std::vector<float> f[6];
  explicit SoaPairs(int n) {
    const auto d = random_directions(2 * n);
    for (int k = 0; k < n; ++k) {
      const cbrdf::Vec3 &wi = d[2 * std::size_t(k)], &wo = d[2 * std::size_t(k) + 1];
      const double v[6] = {wi.x, wi.y, wi.z, wo.x, wo.y, wo.z};
      for (int a = 0; a < 6; ++a) {
        x[a].push_back(v[a]);
        f[a].push_back(float(v[a]));
      }
    }
  }
};

void set_pair_counters(benchmark::State& state, int pairs) {
  state.SetItemsProcessed(state.iterations() * pairs);
  // Wall time: the batch's threads do the work, the calling thread only part of it.
  state.counters["ns_per_pair"] =
      benchmark::Counter(double(state.iterations()) * pairs,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["pairs_per_s"] =
      benchmark::Counter(double(state.iterations()) * pairs, benchmark::Counter::kIsRate);
}

void BM_EvalBatch(benchmark::State& state) {
  const cbrdf::ModelEvaluator ev(*cbrdf::decode_model(encoded()));
  const SoaPairs p(kPairs);
  std::vector<double> r(kPairs), g(kPairs), b(kPairs);
  const int threads = int(state.range(0));
  for (auto _ : state) {
    ev.eval_batch(kPairs, p.x[0].data(), p.x[1].data(), p.x[2].data(), p.x[3].data(), p.x[4].data(),
                  p.x[5].data(), r.data(), g.data(), b.data(), threads);
    benchmark::DoNotOptimize(r.data());
  }
  set_pair_counters(state, kPairs);
}
BENCHMARK(BM_EvalBatch)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EvalBatch4(benchmark::State& state) {
  const cbrdf::ModelEvaluator ev(model4());
  const SoaPairs p(kPairs);
  std::vector<double> r(kPairs), g(kPairs), b(kPairs);
  for (auto _ : state) {
    ev.eval_batch(kPairs, p.x[0].data(), p.x[1].data(), p.x[2].data(), p.x[3].data(), p.x[4].data(),
                  p.x[5].data(), r.data(), g.data(), b.data(), 1);
    benchmark::DoNotOptimize(r.data());
  }
  set_pair_counters(state, kPairs);
}
BENCHMARK(BM_EvalBatch4)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EvalBatchFloat(benchmark::State& state) {
  const cbrdf::ModelEvaluator ev(*cbrdf::decode_model(encoded()));
  const SoaPairs p(kPairs);
  std::vector<float> r(kPairs), g(kPairs), b(kPairs);
  const int threads = int(state.range(0));
  for (auto _ : state) {
    ev.eval_batch_f32(kPairs, p.f[0].data(), p.f[1].data(), p.f[2].data(), p.f[3].data(),
                      p.f[4].data(), p.f[5].data(), r.data(), g.data(), b.data(), threads);
    benchmark::DoNotOptimize(r.data());
  }
  set_pair_counters(state, kPairs);
}
BENCHMARK(BM_EvalBatchFloat)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// Thread scaling of the batch API: 2^18 pairs (128 chunks) through the library's pool at 1 and 2
// threads (state.range(1)), float64 (state.range(0) == 0) and float32. pairs_per_s is wall
// time; the CPU column is the whole process's (all threads), so CPU per pair stays flat when the
// work scales. The ratio of /2 to /1 is in the table at the end.
void BM_EvalBatchThreads(benchmark::State& state) {
  constexpr int kMany = 1 << 18;
  const cbrdf::ModelEvaluator ev(*cbrdf::decode_model(encoded()));
  const SoaPairs p(kMany);
  std::vector<double> r(kMany), g(kMany), b(kMany);
  std::vector<float> rf(kMany), gf(kMany), bf(kMany);
  const bool f32 = state.range(0) != 0;
  const int threads = int(state.range(1));
  for (auto _ : state) {
    if (f32) {
      ev.eval_batch_f32(kMany, p.f[0].data(), p.f[1].data(), p.f[2].data(), p.f[3].data(),
                        p.f[4].data(), p.f[5].data(), rf.data(), gf.data(), bf.data(), threads);
      benchmark::DoNotOptimize(rf.data());
    } else {
      ev.eval_batch(kMany, p.x[0].data(), p.x[1].data(), p.x[2].data(), p.x[3].data(),
                    p.x[4].data(), p.x[5].data(), r.data(), g.data(), b.data(), threads);
      benchmark::DoNotOptimize(r.data());
    }
  }
  set_pair_counters(state, kMany);
}
BENCHMARK(BM_EvalBatchThreads)
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->ArgNames({"f32", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// Importance sampling with weights (direction, pdf, f cos / pdf), the model's sampler: the scalar
// loop (sample() and eval per draw, as a renderer does) and BrdfSampler::sample_batch at 1 and 2
// threads. The sampler's tables are built before timing.
constexpr int kDraws = 1 << 15;

struct SampleInputs {
  std::vector<double> x, y, z, u1, u2;
  SampleInputs() {
    const auto d = random_directions(kDraws);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (const cbrdf::Vec3& v : d) {
      x.push_back(v.x);
      y.push_back(v.y);
      z.push_back(v.z);
      u1.push_back(u(rng));
      u2.push_back(u(rng));
    }
  }
};

const cbrdf::ModelEvaluator& bench_evaluator() {
  static const cbrdf::ModelEvaluator ev(*cbrdf::decode_model(encoded()));
  return ev;
}

const cbrdf::BrdfSampler& bench_sampler() {
  static const cbrdf::BrdfSampler s = [] {
    cbrdf::BrdfSampler sampler = cbrdf::make_model_sampler(bench_evaluator());
    const SampleInputs in;
    std::vector<double> o(6 * std::size_t(kDraws));
    sampler.sample_batch(kDraws, in.x.data(), in.y.data(), in.z.data(), in.u1.data(), in.u2.data(),
                         o.data(), o.data() + kDraws, o.data() + 2 * kDraws, o.data() + 3 * kDraws,
                         o.data() + 4 * kDraws, o.data() + 5 * kDraws, o.data() + 5 * kDraws);
    return sampler;
  }();
  return s;
}

void BM_SampleScalar(benchmark::State& state) {
  const cbrdf::BrdfSampler& s = bench_sampler();
  const cbrdf::ModelEvaluator& ev = bench_evaluator();
  const SampleInputs in;
  double w[3];
  for (auto _ : state) {
    for (int k = 0; k < kDraws; ++k) {
      const cbrdf::Vec3 wo{in.x[k], in.y[k], in.z[k]};
      const cbrdf::BrdfSample smp = s.sample(wo, in.u1[k], in.u2[k]);
      double f[3] = {0, 0, 0};
      if (smp.valid) ev.eval(smp.wi, wo, f);
      for (int c = 0; c < 3; ++c) w[c] = smp.valid ? f[c] * smp.wi.z / smp.pdf : 0.0;
      benchmark::DoNotOptimize(w);
    }
  }
  set_pair_counters(state, kDraws);
}
BENCHMARK(BM_SampleScalar)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SampleBatch(benchmark::State& state) {
  const cbrdf::BrdfSampler& s = bench_sampler();
  const SampleInputs in;
  std::vector<double> o(7 * std::size_t(kDraws));
  double* p = o.data();
  const int threads = int(state.range(0));
  for (auto _ : state) {
    s.sample_batch(kDraws, in.x.data(), in.y.data(), in.z.data(), in.u1.data(), in.u2.data(), p,
                   p + kDraws, p + 2 * kDraws, p + 3 * kDraws, p + 4 * kDraws, p + 5 * kDraws,
                   p + 6 * kDraws, threads);
    benchmark::DoNotOptimize(p);
  }
  set_pair_counters(state, kDraws);
}
BENCHMARK(BM_SampleBatch)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// Small batches, as a renderer's path tracer makes them (one bounce of a few paths): kDraws draws
// in calls of n (interleaved arrays, the calling thread only), for the cost per draw at each n
// against the large batch's (n = 1024 is one pool chunk).
void BM_SampleSmallBatch(benchmark::State& state) {
  const cbrdf::BrdfSampler& s = bench_sampler();
  const SampleInputs in;
  const std::size_t n = std::size_t(state.range(0));
  std::vector<double> wo(3 * std::size_t(kDraws)), u(2 * std::size_t(kDraws));
  for (int k = 0; k < kDraws; ++k) {
    wo[3 * k] = in.x[k], wo[3 * k + 1] = in.y[k], wo[3 * k + 2] = in.z[k];
    u[2 * k] = in.u1[k], u[2 * k + 1] = in.u2[k];
  }
  std::vector<double> wi(3 * n), pdf(n), weight(3 * n);
  for (auto _ : state) {
    for (std::size_t b = 0; b + n <= std::size_t(kDraws); b += n) {
      s.sample_batch(n, &wo[3 * b], &u[2 * b], wi.data(), pdf.data(), weight.data(), 1);
      benchmark::DoNotOptimize(weight.data());
    }
  }
  set_pair_counters(state, kDraws / int(n) * int(n));
}
BENCHMARK(BM_SampleSmallBatch)
    ->Arg(1)
    ->Arg(4)
    ->Arg(16)
    ->Arg(64)
    ->Arg(1024)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// ---- The C API as a renderer calls it (cbrdf/cbrdf_c.h), on the bench material encoded as
// `cbrdf encode` writes it by default (EncoderSettings{}): opening a file, one call per pair or
// draw, and batch calls on the calling thread alone (threads = 1, as from a renderer's own
// workers). ns_per_pair is per pair for evaluation and per draw for sampling.
const std::filesystem::path& default_file() {
  static const std::filesystem::path path = [] {
    const std::filesystem::path p = std::filesystem::path(CBRDF_BUILD_DIR) / "bench-default.cbrdf";
    auto enc = cbrdf::encode_table(table(), cbrdf::EncoderSettings{});
    if (!enc.ok() || !cbrdf::write_file_atomic(p, enc->bytes).ok()) std::abort();
    return p;
  }();
  return path;
}

const cbrdf_model* capi_model() {
  static cbrdf_model* m = [] {
    cbrdf_model* h = cbrdf_model_open_file(default_file().c_str());
    if (h == nullptr) std::abort();
    return h;
  }();
  return m;
}

// Interleaved (x, y, z) triples: kPairs pairs of wi and wo, and kDraws wo with their (u1, u2).
struct CApiInputs {
  std::vector<double> wi, wo, draw_wo, u;
  std::vector<float> wi_f, wo_f;
  CApiInputs() {
    const auto d = random_directions(2 * kPairs);
    for (int k = 0; k < kPairs; ++k) {
      for (const double v : {d[2 * k].x, d[2 * k].y, d[2 * k].z}) wi.push_back(v);
      for (const double v : {d[2 * k + 1].x, d[2 * k + 1].y, d[2 * k + 1].z}) wo.push_back(v);
    }
    wi_f.assign(wi.begin(), wi.end());
    wo_f.assign(wo.begin(), wo.end());
    const SampleInputs in;
    for (int k = 0; k < kDraws; ++k) {
      for (const double v : {in.x[k], in.y[k], in.z[k]}) draw_wo.push_back(v);
      for (const double v : {in.u1[k], in.u2[k]}) u.push_back(v);
    }
  }
};

// cbrdf_model_open_file and cbrdf_model_free of the default file, a new model each iteration
// (read, full validation, the evaluator's tables); with first:1 also the first draw, which builds
// the sampler and its tables for one elevation, as a renderer's first bounce does.
void BM_CApi_Open(benchmark::State& state) {
  const std::string path = default_file().string();
  const bool draw = state.range(0) != 0;
  const double wo[3] = {0.0, 0.6, 0.8};
  double wi[3], pdf, weight[3];
  for (auto _ : state) {
    cbrdf_model* m = cbrdf_model_open_file(path.c_str());
    if (m == nullptr) {
      state.SkipWithError(cbrdf_last_error_message());
      break;
    }
    if (draw && cbrdf_model_sample(m, wo, 0.3, 0.7, wi, &pdf, weight) != CBRDF_OK) {
      state.SkipWithError(cbrdf_last_error_message());
    }
    cbrdf_model_free(m);
  }
}
BENCHMARK(BM_CApi_Open)->ArgName("first_draw")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_CApi_Eval(benchmark::State& state) {
  const cbrdf_model* m = capi_model();
  const CApiInputs in;
  double rgb[3];
  for (auto _ : state) {
    for (int k = 0; k < kPairs; ++k) {
      cbrdf_model_eval(m, &in.wi[3 * k], &in.wo[3 * k], rgb);
      benchmark::DoNotOptimize(rgb);
    }
  }
  set_pair_counters(state, kPairs);
}
BENCHMARK(BM_CApi_Eval)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CApi_EvalBatch(benchmark::State& state) {
  const cbrdf_model* m = capi_model();
  const CApiInputs in;
  std::vector<double> rgb(3 * std::size_t(kPairs));
  for (auto _ : state) {
    if (cbrdf_model_eval_batch(m, kPairs, in.wi.data(), in.wo.data(), rgb.data(), 1) != CBRDF_OK) {
      state.SkipWithError(cbrdf_last_error_message());
    }
    benchmark::DoNotOptimize(rgb.data());
  }
  set_pair_counters(state, kPairs);
}
BENCHMARK(BM_CApi_EvalBatch)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CApi_EvalBatchF32(benchmark::State& state) {
  const cbrdf_model* m = capi_model();
  const CApiInputs in;
  std::vector<float> rgb(3 * std::size_t(kPairs));
  for (auto _ : state) {
    if (cbrdf_model_eval_batch_f32(m, kPairs, in.wi_f.data(), in.wo_f.data(), rgb.data(), 1) !=
        CBRDF_OK) {
      state.SkipWithError(cbrdf_last_error_message());
    }
    benchmark::DoNotOptimize(rgb.data());
  }
  set_pair_counters(state, kPairs);
}
BENCHMARK(BM_CApi_EvalBatchF32)->Unit(benchmark::kMillisecond)->UseRealTime();

// The sampler's tables for every elevation drawn below, built before timing.
void warm_capi_sampler(const CApiInputs& in) {
  std::vector<double> wi(in.draw_wo.size()), pdf(kDraws), weight(in.draw_wo.size());
  if (cbrdf_model_sample_batch(capi_model(), kDraws, in.draw_wo.data(), in.u.data(), wi.data(),
                               pdf.data(), weight.data(), 1) != CBRDF_OK) {
    std::abort();
  }
}

void BM_CApi_Sample(benchmark::State& state) {
  const cbrdf_model* m = capi_model();
  const CApiInputs in;
  warm_capi_sampler(in);
  double wi[3], pdf, weight[3];
  for (auto _ : state) {
    for (int k = 0; k < kDraws; ++k) {
      cbrdf_model_sample(m, &in.draw_wo[3 * k], in.u[2 * k], in.u[2 * k + 1], wi, &pdf, weight);
      benchmark::DoNotOptimize(weight);
    }
  }
  set_pair_counters(state, kDraws);
}
BENCHMARK(BM_CApi_Sample)->Unit(benchmark::kMillisecond)->UseRealTime();

// kDraws draws in calls of n: a path tracer's small batches up to one call for all.
void BM_CApi_SampleBatch(benchmark::State& state) {
  const cbrdf_model* m = capi_model();
  const CApiInputs in;
  warm_capi_sampler(in);
  const std::size_t n = std::size_t(state.range(0));
  std::vector<double> wi(3 * n), pdf(n), weight(3 * n);
  for (auto _ : state) {
    for (std::size_t b = 0; b + n <= std::size_t(kDraws); b += n) {
      cbrdf_model_sample_batch(m, n, &in.draw_wo[3 * b], &in.u[2 * b], wi.data(), pdf.data(),
                               weight.data(), 1);
      benchmark::DoNotOptimize(weight.data());
    }
  }
  set_pair_counters(state, kDraws / int(n) * int(n));
}
BENCHMARK(BM_CApi_SampleBatch)
    ->ArgName("n")
    ->Arg(1)
    ->Arg(16)
    ->Arg(1024)
    ->Arg(kDraws)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The density of drawn pairs (a renderer's multiple importance sampling asks it of a light
// sample's direction): the accepted draws of the inputs, one call each.
void BM_CApi_SamplePdf(benchmark::State& state) {
  const cbrdf_model* m = capi_model();
  const CApiInputs in;
  std::vector<double> wi(in.draw_wo.size()), pdf(kDraws), weight(in.draw_wo.size());
  if (cbrdf_model_sample_batch(m, kDraws, in.draw_wo.data(), in.u.data(), wi.data(), pdf.data(),
                               weight.data(), 1) != CBRDF_OK) {
    std::abort();
  }
  std::vector<int> accepted;
  for (int k = 0; k < kDraws; ++k) {
    if (pdf[std::size_t(k)] > 0) accepted.push_back(k);
  }
  double p;
  for (auto _ : state) {
    for (const int k : accepted) {
      cbrdf_model_sample_pdf(m, &wi[3 * std::size_t(k)], &in.draw_wo[3 * std::size_t(k)], &p);
      benchmark::DoNotOptimize(p);
    }
  }
  set_pair_counters(state, int(accepted.size()));
}
BENCHMARK(BM_CApi_SamplePdf)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- Parameter grid: every copula family from small parameters to the largest a file may hold
// ---- A synthetic file of 90 one-bin slices x 3 channels x 8 components (the most a file holds),
// all of one family at one parameter, encoded in memory. Per file, four operations on one thread:
// open (decode_model and the evaluator), table() (decode to the MERL table), 2,000 samples with
// weights including the sampler's warm-up (a new sampler each time, its tables built by the draws)
// and one albedo. The summary at the end gives each file's time over the slowest Frank file's (the
// encoder's default family) for the same operation, from this one run.
struct ParamCase {
  cbrdf::CopulaFamily family;
  double theta;
};
constexpr ParamCase kParamCases[] = {
    {cbrdf::CopulaFamily::kIndependence, 0.0}, {cbrdf::CopulaFamily::kFrank, -200.0},
    {cbrdf::CopulaFamily::kFrank, -20.0},      {cbrdf::CopulaFamily::kFrank, -1.0},
    {cbrdf::CopulaFamily::kFrank, 0.6931},     {cbrdf::CopulaFamily::kClayton, 0.01},
    {cbrdf::CopulaFamily::kClayton, 2.0},      {cbrdf::CopulaFamily::kClayton, 10.0},
    {cbrdf::CopulaFamily::kClayton, 50.0},     {cbrdf::CopulaFamily::kGumbel, 1.01},
    {cbrdf::CopulaFamily::kGumbel, 2.0},       {cbrdf::CopulaFamily::kGumbel, 5.0},
    {cbrdf::CopulaFamily::kGumbel, 20.0},      {cbrdf::CopulaFamily::kJoe, 1.01},
    {cbrdf::CopulaFamily::kJoe, 2.0},          {cbrdf::CopulaFamily::kJoe, 5.0},
    {cbrdf::CopulaFamily::kJoe, 20.0}};
constexpr int kParamCaseCount = int(std::size(kParamCases));
constexpr const char* kParamOps[] = {"open", "table", "sample2000", "albedo"};

std::vector<double> lobe(int bins, double center, double width, double floor) {
  std::vector<double> t(std::size_t(bins), 0.0);
  double sum = 0;
  for (int i = 0; i < bins; ++i) {
    const double x = (i + 0.5) / bins - center;
    t[std::size_t(i)] = std::exp(-x * x / (width * width)) + floor;
    sum += t[std::size_t(i)];
  }
  for (double& v : t) v /= sum;
  return t;
}

const std::vector<std::uint8_t>& param_file(int index) {
  static std::vector<std::uint8_t> files[kParamCaseCount];
  std::vector<std::uint8_t>& f = files[index];
  if (!f.empty()) return f;
  const ParamCase pc = kParamCases[index];
  cbrdf::Model m;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int j = 0; j < cbrdf::kThetaDBins; ++j) {
    cbrdf::Slice slice;
    slice.theta_d_begin = j;
    slice.theta_d_end = j + 1;
    for (cbrdf::ChannelSlice& cs : slice.channel) {
      for (int r = 0; r < 8; ++r) {
        cbrdf::Component c;
        c.family = pc.family;
        c.theta = pc.theta;
        c.scale = 10.0 + 100.0 * u(rng);
        c.pdf_h = lobe(cbrdf::kThetaHBins, 0.1 * u(rng), 0.02 + 0.3 * u(rng), 1e-5);
        c.pdf_d = {1.0};
        c.pdf_p = lobe(cbrdf::kPhiDBins, 0.5, 0.2 + 0.5 * u(rng), 1e-2);
        if (r == 0) {
          static_cast<cbrdf::Component&>(cs) = c;
        } else {
          cs.extra.push_back(c);
        }
      }
    }
    m.slices.push_back(slice);
  }
  auto bytes = cbrdf::encode_model(m, fixed_settings().container);
  if (!bytes.ok()) {
    std::fprintf(stderr, "param_file %d: %s\n", index, bytes.status().message().c_str());
    std::abort();
  }
  f = std::move(bytes).value();
  return f;
}

void BM_ParamGrid(benchmark::State& state) {
  const int index = int(state.range(0)), op = int(state.range(1));
  const std::vector<std::uint8_t>& file = param_file(index);
  const auto wo = random_directions(2000);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> ud(0, 1);
  std::vector<double> u(4000);
  for (double& v : u) v = ud(rng);
  cbrdf::set_thread_limit(1);  // every operation on the calling thread: CPU time is the cost
  std::shared_ptr<const cbrdf::ModelEvaluator> ev;
  if (op != 0) ev = std::make_shared<const cbrdf::ModelEvaluator>(*cbrdf::decode_model(file));
  for (auto _ : state) {
    switch (op) {
      case 0:
        benchmark::DoNotOptimize(cbrdf::ModelEvaluator(*cbrdf::decode_model(file)));
        break;
      case 1:
        benchmark::DoNotOptimize(ev->table());
        break;
      case 2: {
        const cbrdf::BrdfSampler s = cbrdf::make_model_sampler(ev);
        double w[3];
        for (int k = 0; k < 2000; ++k) {
          benchmark::DoNotOptimize(
              s.sample(wo[std::size_t(k)], u[2 * std::size_t(k)], u[2 * std::size_t(k) + 1], w));
        }
        break;
      }
      default: {
        double rgb[3];
        ev->albedo(0.7, rgb, 1);
        benchmark::DoNotOptimize(rgb);
      }
    }
  }
  cbrdf::set_thread_limit(0);
  const ParamCase pc = kParamCases[index];
  state.SetLabel(std::string(cbrdf::family_name(pc.family)) + " " + std::to_string(pc.theta) + " " +
                 kParamOps[op]);
}
BENCHMARK(BM_ParamGrid)
    ->ArgsProduct({benchmark::CreateDenseRange(0, kParamCaseCount - 1, 1), {0, 1, 2, 3}})
    ->ArgNames({"case", "op"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(1);

// The measured table's nearest-bin lookup (the reference reader's), the baseline the model's
// evaluation is compared with.
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
  state.counters["ns_per_pair"] =
      benchmark::Counter(double(state.iterations()) * kPairs,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LookupMeasuredNearest)->Unit(benchmark::kMillisecond)->UseRealTime();

// The coordinate transform alone: grid_position (the continuous MERL position of a pair).
void BM_CoordinateTransform(benchmark::State& state) {
  const auto d = random_directions(2 * kPairs);
  for (auto _ : state) {
    for (int n = 0; n < kPairs; ++n) {
      cbrdf::GridPosition g = cbrdf::grid_position(d[2 * n], d[2 * n + 1]);
      benchmark::DoNotOptimize(g);
    }
  }
  state.SetItemsProcessed(state.iterations() * kPairs);
  state.counters["ns_per_pair"] =
      benchmark::Counter(double(state.iterations()) * kPairs,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CoordinateTransform)->Unit(benchmark::kMillisecond);

// The console output, and at the end the evaluation benchmarks' ns per pair and their ratios to
// the nearest-bin lookup, all from this one run.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.run_type == Run::RT_Iteration && r.benchmark_name().rfind("BM_ParamGrid/", 0) == 0) {
        grid_.push_back({r.benchmark_name(), r.report_label, r.GetAdjustedCPUTime()});
      }
      // Single runs, or the median of repetitions; the counter is in seconds per pair.
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name != "median") continue;
      auto it = r.counters.find("ns_per_pair");
      if (it != r.counters.end()) {
        ns_.emplace_back(r.benchmark_name(), 1e9 * double(it->second));
        // CPU time of the calling thread per iteration (ms), which a loaded machine disturbs
        // less than wall time: comparable between runs on one thread only.
        cpu_.emplace_back(r.benchmark_name(), r.GetAdjustedCPUTime());
        // CPU ns per pair: the counter is per wall second under UseRealTime ("/real_time" in
        // the name), else per CPU second. Not known (NaN) for a run on 2 threads that measures
        // the calling thread's CPU only (not "process_time").
        const std::string& name = r.benchmark_name();
        const bool wall = name.find("real_time") != std::string::npos;
        const bool partial =
            name.find("/2/") != std::string::npos && name.find("process_time") == std::string::npos;
        const double real = r.GetAdjustedRealTime();
        cpu_ns_.push_back(partial            ? std::nan("")
                          : wall && real > 0 ? ns_.back().second * r.GetAdjustedCPUTime() / real
                                             : ns_.back().second);
      }
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    grid_summary();
    double nearest = 0;
    for (const auto& [name, ns] : ns_) {
      if (name.find("LookupMeasuredNearest") != std::string::npos) nearest = ns;
    }
    if (ns_.empty()) return;
    std::printf("\n%-66s %10s %10s %18s\n", "per direction pair", "ns", "cpu ns",
                "nearest lookup / it");
    for (std::size_t i = 0; i < ns_.size(); ++i) {
      const auto& [name, ns] = ns_[i];
      std::printf("%-66s %10.1f %10.1f %18.2f\n", name.c_str(), ns, cpu_ns_[i],
                  nearest > 0 ? nearest / ns : 0.0);
    }
    // The batch paths against their scalar loops (all timed as wall time, in this one run).
    const std::pair<const char*, const char*> pairs[] = {
        {"BM_EvalBatch/1/", "BM_EvalModel/"},
        {"BM_EvalBatch/2/", "BM_EvalModel/"},
        {"BM_EvalBatch/2/", "BM_EvalBatch/1/"},
        {"BM_EvalBatch4", "BM_EvalModel4"},
        {"BM_EvalBatchFloat/1/", "BM_EvalModelFloat/"},
        {"BM_EvalBatchFloat/2/", "BM_EvalModelFloat/"},
        {"BM_EvalBatchFloat/2/", "BM_EvalBatchFloat/1/"},
        {"BM_EvalBatchThreads/f32:0/threads:2", "BM_EvalBatchThreads/f32:0/threads:1"},
        {"BM_EvalBatchThreads/f32:1/threads:2", "BM_EvalBatchThreads/f32:1/threads:1"},
        {"BM_SampleBatch/1/", "BM_SampleScalar"},
        {"BM_SampleBatch/2/", "BM_SampleScalar"},
        {"BM_SampleBatch/2/", "BM_SampleBatch/1/"},
        {"BM_CApi_EvalBatch/", "BM_CApi_Eval/"},
        {"BM_CApi_EvalBatchF32/", "BM_CApi_Eval/"},
        {"BM_CApi_SampleBatch/n:32768/", "BM_CApi_Sample/"},
        {"BM_CApi_SampleBatch/n:16/", "BM_CApi_Sample/"}};
    auto find = [&](const char* key) {
      for (const auto& [name, ns] : ns_)
        if (name.find(key) != std::string::npos) return ns;
      return 0.0;
    };
    auto find_cpu = [&](const char* key) {
      for (const auto& [name, ms] : cpu_)
        if (name.find(key) != std::string::npos) return ms;
      return 0.0;
    };
    // Both runs on one thread (not /2): the ratio of CPU times too.
    auto one_thread = [](const char* key) {
      const std::string k(key);
      return k.find("/2/") == std::string::npos && k.find("threads:2") == std::string::npos;
    };
    std::printf("\n%-38s %-38s %10s %10s\n", "speed-up of", "over", "wall", "cpu");
    for (const auto& [fast, slow] : pairs) {
      const double a = find(fast), b = find(slow);
      if (!(a > 0 && b > 0)) continue;
      const double ca = find_cpu(fast), cb = find_cpu(slow);
      if (one_thread(fast) && one_thread(slow) && ca > 0 && cb > 0) {
        std::printf("%-38s %-38s %10.2f %10.2f\n", fast, slow, b / a, cb / ca);
      } else {
        std::printf("%-38s %-38s %10.2f %10s\n", fast, slow, b / a, "-");
      }
    }
  }

 private:
  // BM_ParamGrid: per operation, each file's CPU time over the slowest Frank file's.
  struct GridRun {
    std::string name, label;
    double ms;
  };
  void grid_summary() const {
    if (grid_.empty()) return;
    std::printf("\n%-34s %12s %12s\n", "parameter grid (90 slices x 8)", "cpu ms",
                "/ slowest Frank");
    for (const char* op : kParamOps) {
      const std::string suffix = std::string(" ") + op;
      auto is_op = [&](const GridRun& g) {
        return g.label.size() >= suffix.size() &&
               g.label.compare(g.label.size() - suffix.size(), suffix.size(), suffix) == 0;
      };
      double frank = 0, worst = 0;
      for (const GridRun& g : grid_) {
        if (is_op(g) && g.label.rfind("frank ", 0) == 0) frank = std::max(frank, g.ms);
      }
      for (const GridRun& g : grid_) {
        if (!is_op(g)) continue;
        const double ratio = frank > 0 ? g.ms / frank : 0.0;
        worst = std::max(worst, ratio);
        std::printf("%-34s %12.1f %12.2f\n", g.label.c_str(), g.ms, ratio);
      }
      std::printf("%-34s %12s %12.2f\n", (std::string("worst ") + op).c_str(), "", worst);
    }
  }
  std::vector<GridRun> grid_;
  std::vector<std::pair<std::string, double>> ns_;
  std::vector<std::pair<std::string, double>> cpu_;  // ms per iteration
  std::vector<double> cpu_ns_;                       // CPU ns per pair, as ns_
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (argc > 1) g_material = argv[1];
  // Make, read and encode the material before timing anything (the parameter grid alone, as
  // --benchmark_filter=ParamGrid runs it, uses none of it: it encodes its files before timing).
  if (benchmark::GetBenchmarkFilter().find("ParamGrid") == std::string::npos) {
    encoded();
    model4();
  }
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
