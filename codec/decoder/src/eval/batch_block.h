// SPDX-License-Identifier: MIT
// The batch evaluation's blocks (InterpTables::eval_batch) and their first stage, shared by the
// vector kernels (vector_kernels.h) and the portable ones (portable_kernels.h). Included by
// batch_dispatch.cc only: its functions are compiled there once per instruction set.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "eval/eval_internal.h"
#include "eval/position.h"

namespace cbrdf::internal {
namespace {

// ---- Batches (InterpTables::eval_batch) ----------------------------------------------------
// A chunk of pairs is evaluated in blocks of kBlock, each block by one call of a function compiled
// for AVX-512, AVX2 and the baseline (chosen once per process; batch_dispatch.cc): (1) the block's
// inputs copied into one object, then one branch-free loop that the compiler vectorizes across
// pairs: the grid positions (the coordinates, three atan2 polynomials and four square roots per
// pair), bin indices, fractions and each pair's kind but one (below the horizon, the rest, inside
// one slice); (2) with the vector kernels (vector_kernels.h), per pair, the two bins' rows of each
// axis interpolated and the copula ratios formed, kGroup slots at a time (the slice tables'
// grouped layout), vectorized across slots, two pairs at a time (one per half of an 8-wide vector)
// where the CPU has such vectors natively. For the paper's model (one slot per channel in every
// slice) at unit output stride, every pair of the block is evaluated as if inside its slice, eight
// at a time: their fractions permuted from vectors of eight pairs', their sums and saturation
// formed across the vectors, and the results transposed in registers and stored as whole vectors
// per channel; then the few pairs of other kinds (found from bit masks) are written over: below
// the horizon 0, across a slice boundary (known from the bins' entries the evaluations read) two
// slice evaluations, as in eval. Other models and strides list the pairs by kind, without
// branches, and write each pair's values. Every value is formed by the same operations in the same
// order as eval's, so the results are equal bit for bit: vector lanes round as scalar instructions
// do, and no path contracts multiply-adds (eval_internal.h: AVX-512 has FMA instructions). Pairs
// across the phi_d period (1 in 180) and models with generic terms go back to the caller, which
// evaluates them with eval's own code. The portable kernels (portable_kernels.h) hand every pair
// above the horizon back so.
constexpr int kBlock = 32;

// One block's inputs and stage (1)'s results, in one object: its arrays provably do not alias, so
// the stage's loop vectorizes without versioning.
template <class T>
struct BlockState {
  alignas(64) T in[6][kBlock];  // wi x, y, z, wo x, y, z
  alignas(64) T ph[kBlock], pd[kBlock], pp[kBlock];
  alignas(64) T fh[kBlock], fd[kBlock], fp[kBlock];
  alignas(64) int h0[kBlock], d0[kBlock], p0[kBlock];
  alignas(64) int kind[kBlock];  // a LaneKind
};

// How a lane is evaluated: 0 (below the horizon), by eval's own code, across a slice boundary (two
// slice evaluations), inside one slice.
enum LaneKind : int { kZero, kRest, kAcross, kInside };

// Pairs base .. base + m (m <= kBlock) of the batch into b.in, zero-padded to kBlock.
template <class T>
CBRDF_FORCE_INLINE void load_block(BlockState<T>& b, const BatchArgs<T>& args, std::size_t base,
                                   std::size_t end, int m) {
  const std::size_t is = args.in_stride;
  for (int a = 0; a < 6; ++a) {
    const T* src = args.in[a] + base * is;
    if (is == 1 && m == kBlock) {
      for (int l = 0; l < kBlock; ++l) b.in[a][l] = src[l];  // a fixed size: moved inline
      // The block after next, into the cache while this one is evaluated: six streams of
      // pairs outrun the hardware's prefetching.
      if (base + 3 * kBlock <= end) {
#if defined(__GNUC__) || defined(__clang__)
        for (int l = 0; l < kBlock; l += int(64 / sizeof(T)))
          __builtin_prefetch(src + 2 * kBlock + l);
#endif
      }
    } else {
      for (int l = 0; l < m; ++l) b.in[a][l] = src[std::size_t(l) * is];
      for (int l = m; l < kBlock; ++l) b.in[a][l] = T(0);
    }
  }
}

// Stage (1): positions, bin indices and fractions, as position() and eval_impl form them, and
// each lane's kind but for kAcross (mark_across), in one loop (with -fno-math-errno its square
// roots vectorize). Bitwise &, not &&: no branches.
template <class T>
CBRDF_FORCE_INLINE void block_positions(BlockState<T>& b, bool any_generic) {
  const T inside = any_generic ? T(kRest) : T(kInside);
  for (int l = 0; l < kBlock; ++l) {
    const T ix = b.in[0][l], iy = b.in[1][l], iz = b.in[2][l];
    const T ox = b.in[3][l], oy = b.in[4][l], oz = b.in[5][l];
    const Squares<T> q = position_squares(ix, iy, iz, ox, oy, oz);
    const Position<T> g = position_angles(ix, iy, iz, ox, oy, oz, q.rho2, std::sqrt(q.rho2),
                                          std::sqrt(q.len2), std::sqrt(q.chord2));
    const T h = position_h(std::sqrt(g.h)), d = g.d, p = g.p;
    b.ph[l] = h;
    b.pd[l] = d;
    b.pp[l] = p;
    const int i = std::min(int(h), kThetaHBins - 1);
    const int j = std::min(int(d), kThetaDBins - 1);
    const int k = std::min(int(p), kPhiDBins - 1);
    b.h0[l] = i;
    b.d0[l] = j;
    b.p0[l] = k;
    b.fh[l] = h - T(i);
    b.fd[l] = d - T(j);
    b.fp[l] = p - T(k);
    // Across the phi_d period (k is its last bin and fp > 0: p > 179), or with generic terms:
    // eval's own code. Selects between values of T, so that every mask has T's lanes.
    const T rest = p > T(kPhiDBins - 1) ? T(kRest) : inside;
    b.kind[l] = int(((iz > 0) & (oz > 0)) ? rest : T(kZero));
  }
}

template <class T>
struct BlockContext {
  const SliceTables<T>* tables;  // per slice
  const SliceView<T>* views;     // per slice
  const BinRows* bins;           // per theta_d bin
  bool any_generic;
  bool uniform;  // every slice has one group of one slot per channel (the paper's model)
};

}  // namespace
}  // namespace cbrdf::internal
