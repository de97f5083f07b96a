// SPDX-License-Identifier: MIT
// Encodes a built-in sample with the installed library, decodes it, and checks the result; makes a
// measured sample from the weights compiled into the library.
#include <cbrdf/cbrdf.h>

#include <cmath>
#include <cstdio>

int main() {
  std::printf("cbrdf %s (headers %s)\n", cbrdf::version_string(), CBRDF_VERSION_STRING);
  auto table = cbrdf::make_sample("plastic");
  if (!table.ok()) {
    std::fprintf(stderr, "make_sample: %s\n", table.status().message().c_str());
    return 1;
  }
  cbrdf::EncoderSettings settings;
  settings.fit.threads = 1;
  auto encoded = cbrdf::encode_table(*table, settings);
  if (!encoded.ok()) {
    std::fprintf(stderr, "encode_table: %s\n", encoded.status().message().c_str());
    return 1;
  }
  auto model = cbrdf::decode_model(encoded->bytes);
  if (!model.ok()) {
    std::fprintf(stderr, "decode_model: %s\n", model.status().message().c_str());
    return 1;
  }
  const cbrdf::ModelEvaluator evaluator(*model);
  // Near the specular direction the plastic is bright; the model must agree with the table.
  const cbrdf::Vec3 wi{0.3, 0.0, std::sqrt(1 - 0.09)}, wo{-0.3, 0.0, std::sqrt(1 - 0.09)};
  double rgb[3];
  evaluator.eval(wi, wo, rgb);
  const cbrdf::BrdfTable back = evaluator.table();
  std::size_t measured = 0, close = 0;
  for (int c = 0; c < cbrdf::kChannels; ++c) {
    for (std::size_t i = 0; i < cbrdf::kBinsPerChannel; ++i) {
      if (!table->measured(c, i)) continue;
      ++measured;
      const double a = table->physical(c, i), b = back.physical(c, i);
      if (std::abs(a - b) <= 0.05 * a + 1e-3) ++close;
    }
  }
  std::printf(
      "%zu bytes; eval at the mirror direction %.4g %.4g %.4g; %.1f%% of %zu bins within 5%%\n",
      encoded->bytes.size(), rgb[0], rgb[1], rgb[2], 100.0 * double(close) / double(measured),
      measured);
  // A measured sample comes from weights compiled into the library: no data folder is read.
  auto nickel = cbrdf::make_sample("nickel");
  if (!nickel.ok()) {
    std::fprintf(stderr, "make_sample(nickel): %s\n", nickel.status().message().c_str());
    return 1;
  }
  const std::size_t index = cbrdf::merl_index(10, 20, 90);
  std::printf("measured sample nickel: %.4g at bin (10, 20, 90)\n", nickel->physical(0, index));
  const bool ok = encoded->bytes.size() < 16384 && rgb[0] > 0 && std::isfinite(rgb[0]) &&
                  double(close) > 0.5 * double(measured) && nickel->physical(0, index) > 0;
  std::printf("consumer_cpp: %s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
