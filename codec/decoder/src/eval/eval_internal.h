// SPDX-License-Identifier: MIT
// What InterpTables' files share: which batch kernels this build compiles, the batch's views of
// the tables (interp_tables.cc prepares them, batch_dispatch.cc reads them) and saturation.
//
// InterpTables is split by job: interp_tables.cc builds the tables, scalar_eval.cc evaluates one
// pair (the reference every other path equals bit for bit), trig.h and position.h hold the grid
// position's polynomials, batch_block.h the batch's first stage (positions of a block of pairs),
// vector_kernels.h and portable_kernels.h its second stage, batch_dispatch.cc the choice of kernel
// and the loop over chunks. Every file is compiled with no FMA contraction and no errno from
// math functions (CMakeLists.txt; a pragma for GCC): eval and eval_batch must round alike.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

#include "eval/interp_tables.h"

// The batch kernels: GCC/Clang vector extensions (vector_kernels.h) on x86-64, where they were
// written and measured, and in WebAssembly with SIMD128 (-msimd128: Clang lowers each vector to
// v128 operations; tools/wasm), unless the build asks for the portable ones
// (CBRDF_PORTABLE_KERNELS, so that CI tests them on x86-64); plain C++ (portable_kernels.h) with
// any other compiler or target.
#if !defined(CBRDF_PORTABLE_KERNELS) && (defined(__GNUC__) || defined(__clang__)) && \
    (defined(__x86_64__) || defined(__wasm_simd128__))
#define CBRDF_VECTOR_KERNELS 1
#else
#define CBRDF_VECTOR_KERNELS 0
#endif

// Inlined where the compiler takes the hint as an order (GCC, Clang): the batch's stages are
// written as small functions that must fold into one loop.
#if defined(__GNUC__) || defined(__clang__)
#define CBRDF_FORCE_INLINE [[gnu::always_inline]] inline
#else
#define CBRDF_FORCE_INLINE inline
#endif

namespace cbrdf::internal {

// A slice's tables as a lane reads them.
template <class T>
struct SliceView {
  const T *h, *d, *p, *k;
  std::size_t n;  // row length
  int groups, slots;
};

// Per theta_d bin j: its slice and the offset of j's row in the slice's theta_d axis.
struct BinRows {
  int slice[kThetaDBins], d[kThetaDBins];
  int last[kThetaDBins];  // 1: the next bin is in another slice (or there is none)
};

// What eval_batch reads of the evaluator beyond its tables, prepared once.
struct InterpTables::BatchViews {
  BinRows bins;
  std::vector<SliceView<double>> f64;
  std::vector<SliceView<float>> f32;
  bool uniform = true;  // every slice has one group of one slot per channel (the paper's model)
  const std::vector<SliceView<double>>& of(double) const { return f64; }
  const std::vector<SliceView<float>>& of(float) const { return f32; }
};

namespace {

template <class T>
inline T saturate(T v) {
  constexpr T kMax = std::numeric_limits<T>::max();
  return v < kMax ? v : (v == v ? kMax : T(0));
}

}  // namespace

}  // namespace cbrdf::internal
