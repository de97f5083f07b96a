// SPDX-License-Identifier: MIT
// The batch's second stage in plain C++, for any compiler and target (eval_internal.h:
// CBRDF_VECTOR_KERNELS is 0): the block's positions are formed across the block as the vector
// kernels form them (batch_block.h), and every pair above the horizon is handed back to the
// caller, which evaluates it with eval's own code at that position. Equal to eval bit for bit by
// construction: the position is position()'s (the same operations in the same order) and the rest
// is eval's code. Included by batch_dispatch.cc only.
#pragma once

#include <algorithm>
#include <cstddef>

#include "eval/batch_block.h"

namespace cbrdf::internal {
namespace {

// A block of m pairs (base .. base + m of the batch): writes 0 for the pairs below the horizon and
// returns the others' lanes in rest (their count). The vector kernels' signature: the context, the
// scratch values and kPairs are unused here.
template <class T, bool kPairs>
inline int block_eval(const BlockContext<T>& cx, BlockState<T>& b, const BatchArgs<T>& args,
                      std::size_t base, std::size_t end, T* /*v*/, int* rest) {
  const int m = int(std::min<std::size_t>(kBlock, end - base));
  load_block(b, args, base, end, m);
  block_positions(b, cx.any_generic);
  const std::size_t os = args.out_stride;
  int nr = 0;
  for (int l = 0; l < m; ++l) {
    if (b.kind[l] == kZero) {
      for (int c = 0; c < kChannels; ++c) args.out[c][(base + std::size_t(l)) * os] = T(0);
    } else {
      rest[nr++] = l;
    }
  }
  return nr;
}

}  // namespace
}  // namespace cbrdf::internal
