// SPDX-License-Identifier: MIT
// std::bit_cast for the WebAssembly build: Debian's emscripten 3.1.6 ships a libc++ whose <bit>
// lacks it (the compiler, clang 14, has the builtin it is made of). Force-included into the
// library's sources by tools/wasm/CMakeLists.txt; a no-op where the library has it.
#pragma once

#include <bit>

#if !defined(__cpp_lib_bit_cast)
namespace std {
template <class To, class From>
constexpr To bit_cast(const From& from) noexcept {
  static_assert(sizeof(To) == sizeof(From), "bit_cast between types of one size");
  return __builtin_bit_cast(To, from);
}
}  // namespace std
#endif
