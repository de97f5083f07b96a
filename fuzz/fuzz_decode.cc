// SPDX-License-Identifier: MIT
// libFuzzer entry point: decode_model with checksums repaired, then evaluation
// (harness/decode_target.h).
#include <cstddef>
#include <cstdint>

#include "harness/decode_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return cbrdf::fuzz::finish(cbrdf::fuzz::run_decode({data, size}), "fuzz_decode");
}
