// SPDX-License-Identifier: MIT
// libFuzzer entry point: parse_merl on raw bytes or on a patched 35/70 MB template
// (harness/merl_target.h).
#include <cstddef>
#include <cstdint>

#include "harness/merl_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return cbrdf::fuzz::finish(cbrdf::fuzz::run_merl({data, size}), "fuzz_merl");
}
