// SPDX-License-Identifier: MIT
// libFuzzer entry point: encode_model -> decode_model on Models built from bytes
// (tests/encoder/fuzz_roundtrip_target.h: the harness uses the encoder's internals as its oracle).
#include <cstddef>
#include <cstdint>

#include "../tests/encoder/fuzz_roundtrip_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return cbrdf::fuzz::finish(cbrdf::fuzz::run_roundtrip({data, size}), "fuzz_roundtrip");
}
