// SPDX-License-Identifier: MIT
// Links only the installed static decoder (cbrdf::decoder_static) through the C++ API: decodes a
// golden file, evaluates it and rebuilds its table. Usage: consumer_cpp_decoder FILE.cbrdf
#include <cbrdf/decoder.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer_cpp_decoder FILE.cbrdf\n");
    return 2;
  }
  std::ifstream in(argv[1], std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
  auto model = cbrdf::decode_model(bytes);
  if (!model.ok()) {
    std::fprintf(stderr, "decode_model: %s\n", model.status().message().c_str());
    return 1;
  }
  const cbrdf::ModelEvaluator evaluator(*model);
  const cbrdf::Vec3 wi{0.0, 0.6, 0.8}, wo{0.0, -0.6, 0.8};
  double rgb[3], back[3];
  evaluator.eval(wi, wo, rgb);
  evaluator.eval(wo, wi, back);
  const cbrdf::BrdfTable table = evaluator.table();
  std::size_t measured = 0;
  for (int c = 0; c < cbrdf::kChannels; ++c) {
    for (std::size_t i = 0; i < cbrdf::kBinsPerChannel; ++i) measured += table.measured(c, i);
  }
  std::printf("cbrdf %s: eval %.6g %.6g %.6g; %zu measured bins\n", cbrdf::version_string(), rgb[0],
              rgb[1], rgb[2], measured);
  // A real value, reciprocal, and a table with measured bins.
  const bool ok = rgb[0] > 0 && std::isfinite(rgb[0]) && rgb[0] == back[0] && measured > 0;
  // A damaged file is refused with a message, not decoded.
  std::vector<std::uint8_t> damaged = bytes;
  damaged[damaged.size() / 2] ^= 0x40;
  const bool refused = !cbrdf::decode_model(damaged).ok();
  std::printf("consumer_cpp_decoder: %s\n", ok && refused ? "ok" : "FAILED");
  return ok && refused ? 0 : 1;
}
