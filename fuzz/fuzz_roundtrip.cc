// SPDX-License-Identifier: MIT
// libFuzzer entry point: encode_model -> decode_model on Models built from bytes
// (harness/roundtrip_target.h).
#include <cstddef>
#include <cstdint>

#include "harness/roundtrip_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return cbrdf::fuzz::finish(cbrdf::fuzz::run_roundtrip({data, size}), "fuzz_roundtrip");
}
