// SPDX-License-Identifier: MIT
// libFuzzer entry point: parse_container and inspect_container on raw bytes
// (harness/container_target.h).
#include <cstddef>
#include <cstdint>

#include "harness/container_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return cbrdf::fuzz::finish(cbrdf::fuzz::run_container({data, size}), "fuzz_container");
}
