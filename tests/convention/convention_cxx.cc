// SPDX-License-Identifier: MIT
// The C++ side of the (wi, wo) convention and rejected-draw tests (issue 42), on the installed
// C++ headers (ModelEvaluator, BrdfSampler).
//
//   convention_cxx pairs C_REFERENCE MODEL.cbrdf
//     Runs `C_REFERENCE pairs MODEL` (convention_reference.c) and compares its f and pdf, pair by
//     pair, with ModelEvaluator::eval, eval_batch and BrdfSampler::sample_pdf(wi, wo) (the C
//     API's sampler: make_model_sampler with the default settings), to 1e-12 relative.
//   convention_cxx draws N MODEL.cbrdf...
//     N draws over the models and 16 elevations through sample_batch (structure of arrays), fed
//     straight back into eval_batch and sample_pdf: nothing NaN, a rejected draw exactly 0. Under
//     a sanitizer N is divided by 100.
// Exits 0 when every check holds, 1 otherwise, 2 on a usage error.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "cbrdf/decoder.h"

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

namespace {

int failures = 0;

void fail(const std::string& what, long index) {
  if (failures < 20) std::fprintf(stderr, "FAILED: %s (at %ld)\n", what.c_str(), index);
  ++failures;
}

std::shared_ptr<const cbrdf::ModelEvaluator> open_model(const char* path) {
  auto m = cbrdf::decode_model_file(path);
  if (!m.ok()) {
    std::fprintf(stderr, "cannot open %s: %s\n", path, m.status().message().c_str());
    return nullptr;
  }
  return std::make_shared<const cbrdf::ModelEvaluator>(std::move(m).value());
}

// a and b equal to 1e-12 relative (both NaN counts as a difference: neither may be NaN).
bool close(double a, double b) {
  return std::fabs(a - b) <= 1e-12 * std::max(std::fabs(a), std::fabs(b));
}

int run_pairs(const char* reference, const char* path) {
  const auto ev = open_model(path);
  if (!ev) return 1;
  const cbrdf::BrdfSampler sampler = cbrdf::make_model_sampler(ev);
  const std::string cmd = std::string("'") + reference + "' pairs '" + path + "'";
  FILE* in = popen(cmd.c_str(), "r");
  if (in == nullptr) {
    std::fprintf(stderr, "cannot run %s\n", cmd.c_str());
    return 1;
  }
  std::vector<double> wi, wo, f, pdf;
  double v[10];
  while (std::fscanf(in, "%lg %lg %lg %lg %lg %lg %lg %lg %lg %lg", &v[0], &v[1], &v[2], &v[3],
                     &v[4], &v[5], &v[6], &v[7], &v[8], &v[9]) == 10) {
    wi.insert(wi.end(), v, v + 3);
    wo.insert(wo.end(), v + 3, v + 6);
    f.insert(f.end(), v + 6, v + 9);
    pdf.push_back(v[9]);
  }
  if (pclose(in) != 0) fail(cmd + " failed", -1);
  const std::size_t n = pdf.size();
  if (n < 300) fail("too few pairs from the C reference: " + std::to_string(n), -1);
  std::vector<double> batch(3 * n);
  ev->eval_batch(n, wi.data(), wo.data(), batch.data(), 1);
  for (std::size_t k = 0; k < n; ++k) {
    const cbrdf::Vec3 i{wi[3 * k], wi[3 * k + 1], wi[3 * k + 2]};
    const cbrdf::Vec3 o{wo[3 * k], wo[3 * k + 1], wo[3 * k + 2]};
    double rgb[3];
    ev->eval(i, o, rgb);
    for (int c = 0; c < 3; ++c) {
      if (!close(rgb[c], f[3 * k + c])) fail("eval(wi, wo) differs from C's", long(k));
      if (!close(batch[3 * k + c], f[3 * k + c])) fail("eval_batch differs from C's", long(k));
    }
    if (!close(sampler.sample_pdf(i, o), pdf[k])) {
      fail("sample_pdf(wi, wo) differs from C's cbrdf_model_sample_pdf(wi, wo)", long(k));
    }
  }
  std::fprintf(stderr, "%zu pairs compared with C, %d failures\n", n, failures);
  return failures ? 1 : 0;
}

int run_draws(long total, int models, char** paths) {
  if (kSanitized) total /= 100;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  long draws = 0, rejected = 0;
  constexpr std::size_t kBlock = 4096;
  std::vector<double> o[3], u1(kBlock), u2(kBlock), i[3], pdf(kBlock), w[3], f[3];
  for (int c = 0; c < 3; ++c) {
    for (auto* v : {&o[c], &i[c], &w[c], &f[c]}) v->resize(kBlock);
  }
  for (int mi = 0; mi < models; ++mi) {
    const auto ev = open_model(paths[mi]);
    if (!ev) return 1;
    const cbrdf::BrdfSampler sampler = cbrdf::make_model_sampler(ev);
    const long per_elevation = total / models / 16;
    for (int e = 0; e < 16; ++e) {
      const double theta = 89.0 * e / 15 * std::numbers::pi / 180;
      for (long done = 0; done < per_elevation;) {
        const std::size_t n = std::size_t(std::min<long>(per_elevation - done, long(kBlock)));
        for (std::size_t k = 0; k < n; ++k) {
          const double phi = 2 * std::numbers::pi * uni(rng);
          o[0][k] = std::sin(theta) * std::cos(phi);
          o[1][k] = std::sin(theta) * std::sin(phi);
          o[2][k] = std::cos(theta);
          u1[k] = uni(rng);
          u2[k] = uni(rng);
        }
        sampler.sample_batch(n, o[0].data(), o[1].data(), o[2].data(), u1.data(), u2.data(),
                             i[0].data(), i[1].data(), i[2].data(), pdf.data(), w[0].data(),
                             w[1].data(), w[2].data(), 0);
        ev->eval_batch(n, i[0].data(), i[1].data(), i[2].data(), o[0].data(), o[1].data(),
                       o[2].data(), f[0].data(), f[1].data(), f[2].data(), 0);
        for (std::size_t k = 0; k < n; ++k) {
          const double p =
              sampler.sample_pdf({i[0][k], i[1][k], i[2][k]}, {o[0][k], o[1][k], o[2][k]});
          if (std::isnan(p) || std::isnan(pdf[k]) || std::isnan(f[0][k]) || std::isnan(f[1][k]) ||
              std::isnan(f[2][k])) {
            fail("NaN", draws + long(k));
          }
          if (pdf[k] == 0.0) {
            ++rejected;
            if (i[0][k] != 0 || i[1][k] != 0 || i[2][k] != 0 || p != 0 || f[0][k] != 0 ||
                f[1][k] != 0 || f[2][k] != 0) {
              fail("a rejected draw is not exactly 0", draws + long(k));
            }
          } else if (p != pdf[k]) {
            fail("sample_pdf(wi, wo) differs from the drawn pdf", draws + long(k));
          }
        }
        done += long(n);
        draws += long(n);
      }
    }
  }
  std::printf("%ld draws over %d models and 16 elevations, %ld rejected, %d failures\n", draws,
              models, rejected, failures);
  if (draws == 0) fail("no draws", 0);
  return failures ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "pairs" && argc == 4) return run_pairs(argv[2], argv[3]);
  if (mode == "draws" && argc >= 4) {
    return run_draws(std::strtol(argv[2], nullptr, 10), argc - 3, argv + 3);
  }
  std::fprintf(stderr, "usage: %s pairs C_REFERENCE MODEL.cbrdf | draws N MODEL.cbrdf...\n",
               argv[0]);
  return 2;
}
