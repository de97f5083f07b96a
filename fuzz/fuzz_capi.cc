// SPDX-License-Identifier: MIT
// libFuzzer entry point: the C API's open, eval and sample on every input, asserting finite,
// non-negative values, pdfs and weights (harness/capi_target.h).
#include <cstddef>
#include <cstdint>

#include "harness/capi_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return cbrdf::fuzz::finish(cbrdf::fuzz::run_capi({data, size}), "fuzz_capi");
}
