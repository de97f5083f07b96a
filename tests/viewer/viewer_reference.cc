// SPDX-License-Identifier: MIT
// The native library's float32 evaluation for the viewer's browser test (viewer_test.mjs):
//   viewer_reference FILE   stdin: wi (3n float32), wo (3n float32)
//                           stdout: rgb (3n float32), ModelEvaluator::eval_f32 per pair
// Exit status 0, or 1 with a message on stderr (2 for bad usage).
#include <cstdio>
#include <cstring>
#include <iterator>
#include <span>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/file_io.h"
#include "cbrdf/model.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: viewer_reference FILE.cbrdf < pairs > values\n");
    return 2;
  }
  auto bytes = cbrdf::read_file(argv[1], cbrdf::kMaxContainerBytes);
  if (!bytes.ok()) {
    std::fprintf(stderr, "viewer_reference: %s\n", bytes.status().message().c_str());
    return 1;
  }
  auto model = cbrdf::decode_model(*bytes);
  if (!model.ok()) {
    std::fprintf(stderr, "viewer_reference: %s: %s\n", argv[1], model.status().message().c_str());
    return 1;
  }
  const cbrdf::ModelEvaluator evaluator(std::move(model.value()));
  std::vector<float> in;
  float buf[4096];
  for (std::size_t got; (got = std::fread(buf, sizeof(float), std::size(buf), stdin)) > 0;)
    in.insert(in.end(), buf, buf + got);
  if (in.size() % 6 != 0) {
    std::fprintf(stderr, "viewer_reference: %zu floats on stdin, expected 6 per pair\n", in.size());
    return 1;
  }
  const std::size_t n = in.size() / 6;
  std::vector<float> out(3 * n);
  for (std::size_t k = 0; k < n; ++k) evaluator.eval_f32(&in[3 * k], &in[3 * (n + k)], &out[3 * k]);
  if (std::fwrite(out.data(), sizeof(float), out.size(), stdout) != out.size()) return 1;
  return 0;
}
