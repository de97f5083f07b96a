// SPDX-License-Identifier: MIT
// The batch's second stage with GCC/Clang vector extensions (vector_size types and
// __builtin_shufflevector), for x86-64 and WebAssembly SIMD128 (eval_internal.h:
// CBRDF_VECTOR_KERNELS); batch_dispatch.cc compiles block_eval for AVX-512, AVX2 and the baseline
// on x86-64, for SIMD128 alone in WebAssembly. Included by batch_dispatch.cc only.
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>

#include "eval/batch_block.h"

#if !CBRDF_VECTOR_KERNELS
#error "vector_kernels.h needs GCC or Clang on x86-64 or WebAssembly SIMD128 (eval_internal.h)"
#endif

namespace cbrdf::internal {
namespace {

// Per slice evaluation, per group of kGroup slots, the interpolated terms of the two bins' rows on
// each axis, g1 g2 g3, 1 - h, 1 + h and the ratio k g (1 + h) / (1 - h)^3, each a vector
// operation across the group's slots (GCC/Clang vector types: the same operations, in the same
// order, as add_slice's per slot, so each lane rounds as the scalar code does); then per channel
// the sum over its R slots in add_slice's order. In float32 two evaluations whose slices have as
// many groups share one 8-wide vector, one per half. `v` holds 2 G kGroup values.
// Helpers write vectors through pointers rather than return them: GCC warns (-Wpsabi) about
// returning a 32-byte vector by value where AVX is not enabled, in the baseline clone.
using V4d = double __attribute__((vector_size(32)));
using V8d = double __attribute__((vector_size(64)));
using V4f = float __attribute__((vector_size(16)));
using V8f = float __attribute__((vector_size(32)));

// Every lane x (x - 0 is x exactly, -0 included).
template <class V, class T>
[[gnu::always_inline]] inline void splat(V* v, T x) {
  *v = x - V{};
}

template <class V>
[[gnu::always_inline]] inline void load_vec(V* v, const void* p) {
  std::memcpy(v, p, sizeof *v);
}

// The 4-lane and 8-lane vectors of T.
template <class T>
struct Lanes;
template <>
struct Lanes<double> {
  using V4 = V4d;
  using V8 = V8d;
};
template <>
struct Lanes<float> {
  using V4 = V4f;
  using V8 = V8f;
};

// Two 4-lane vectors from pa and pb as one 8-lane one.
template <class T>
[[gnu::always_inline]] inline void load_two(typename Lanes<T>::V8* v, const T* pa, const T* pb) {
  typename Lanes<T>::V4 a, b;
  load_vec(&a, pa);
  load_vec(&b, pb);
  *v = __builtin_shufflevector(a, b, 0, 1, 2, 3, 4, 5, 6, 7);
}

// A slice evaluation's row pointers and fractions.
template <class T>
struct JobRows {
  const T* r[3];  // bin rows of theta_h, theta_d, phi_d (the next bin's row at + row())
  T a[3];         // fractions
  const T* k;     // constants
  std::size_t n;  // row length
  int groups, slots;
};

// Slice st at theta_h bin h0, theta_d bin jl (inside the slice) and phi_d bin p0, fractions fh,
// fd and fp.
template <class T>
[[gnu::always_inline]] inline JobRows<T> job_rows(const SliceTables<T>& st, int h0, int jl, int p0,
                                                  T fh, T fd, T fp) {
  JobRows<T> r;
  r.n = st.row();
  r.r[0] = st.h.data() + std::size_t(h0) * r.n;
  r.r[1] = st.d.data() + std::size_t(jl) * r.n;
  r.r[2] = st.p.data() + std::size_t(p0) * r.n;
  r.a[0] = fh;
  r.a[1] = fd;
  r.a[2] = fp;
  r.k = st.consts.data();
  r.groups = st.groups;
  r.slots = st.slots_per_channel;
  return r;
}

// Per channel the sum of R slot values v, in add_slice's order.
template <class T>
inline void slot_sums(const T* v, int R, T sums[3]) {
  for (int c = 0; c < kChannels; ++c) {
    T sum = 0;
    for (int r = 0; r < R; ++r) sum += v[c * R + r];
    sums[c] = sum;
  }
}

// The loads of one evaluation's rows (V4d, V4f), or of two evaluations' (V8f: A in the low half,
// B in the high one).
template <class V, class T>
struct OneJob {
  const JobRows<T>& J;
  [[gnu::always_inline]] void load(V* v, int x, int bin, std::size_t off) const {
    load_vec(v, J.r[x] + (bin ? J.n : 0) + off);
  }
  [[gnu::always_inline]] void fractions(V* a, V* b, int x) const {
    splat(a, J.a[x]);
    splat(b, T(1 - J.a[x]));
  }
  [[gnu::always_inline]] void constant(V* v, std::size_t off) const { load_vec(v, J.k + off); }
};

template <class T>
struct TwoJobs {
  using V4 = typename Lanes<T>::V4;
  using V8 = typename Lanes<T>::V8;
  const JobRows<T>& A;
  const JobRows<T>& B;
  [[gnu::always_inline]] void load(V8* v, int x, int bin, std::size_t off) const {
    load_two<T>(v, A.r[x] + (bin ? A.n : 0) + off, B.r[x] + (bin ? B.n : 0) + off);
  }
  [[gnu::always_inline]] void fractions(V8* a, V8* b, int x) const {
    V4 fa, fb, ga, gb;
    splat(&fa, A.a[x]);
    splat(&fb, B.a[x]);
    splat(&ga, T(1 - A.a[x]));
    splat(&gb, T(1 - B.a[x]));
    *a = __builtin_shufflevector(fa, fb, 0, 1, 2, 3, 4, 5, 6, 7);
    *b = __builtin_shufflevector(ga, gb, 0, 1, 2, 3, 4, 5, 6, 7);
  }
  [[gnu::always_inline]] void constant(V8* v, std::size_t off) const {
    // Both loads even where the slices are one: the lanes' slices vary at random, and a branch
    // on them would mispredict often.
    load_two<T>(v, A.k + off, B.k + off);
  }
};

// Axis x's terms g, w, y of a group (its offset o in the row), interpolated between the rows.
template <class V, class S>
[[gnu::always_inline]] inline void lerp_axis(const S& s, int x, std::size_t o, V* g, V* w, V* y) {
  V a, b, u0, u1;
  s.fractions(&a, &b, x);
  s.load(&u0, x, 0, o);
  s.load(&u1, x, 1, o);
  *g = u0 * b + u1 * a;
  s.load(&u0, x, 0, o + kGroup);
  s.load(&u1, x, 1, o + kGroup);
  *w = u0 * b + u1 * a;
  s.load(&u0, x, 0, o + 2 * kGroup);
  s.load(&u1, x, 1, o + 2 * kGroup);
  *y = u0 * b + u1 * a;
}

// Group gi's ratios k g (1 + h) / (1 - h)^3.
template <class V, class S>
[[gnu::always_inline]] inline void group_ratio(const S& s, int gi, V* ratio) {
  const std::size_t o = std::size_t(gi) * kGroupTerms;
  V g1, w1, y1, g2, w2, y2, g3, w3, y3;
  lerp_axis(s, 0, o, &g1, &w1, &y1);
  lerp_axis(s, 1, o, &g2, &w2, &y2);
  lerp_axis(s, 2, o, &g3, &w3, &y3);
  const std::size_t c = std::size_t(gi) * kGroupConstants;
  V k0, k1, k2, k3, k4, k5, k6;
  s.constant(&k0, c);
  s.constant(&k1, c + kGroup);
  s.constant(&k2, c + 2 * kGroup);
  s.constant(&k3, c + 3 * kGroup);
  s.constant(&k4, c + 4 * kGroup);
  s.constant(&k5, c + 5 * kGroup);
  s.constant(&k6, c + 6 * kGroup);
  const V w12 = w1 * w2, W = w12 * w3, Y = y1 + w1 * y2 + w12 * y3;
  const V omh = k1 + k2 * Y + k3 * W;
  const V oph = k4 + k5 * Y + k6 * W;
  *ratio = k0 * (g1 * g2 * g3) * oph / (omh * omh * omh);
}

// One slice evaluation's per-channel sums: with one group of one slot per channel (the paper's
// model) channel c is lane c, taken straight from the vector; else the groups' values go
// through v.
template <class V, class T>
[[gnu::always_inline]] inline void job_sums(const JobRows<T>& J, T* v, T sums[3]) {
  const OneJob<V, T> s{J};
  if (J.groups == 1 && J.slots == 1) {
    V ratio;
    group_ratio(s, 0, &ratio);
    for (int c = 0; c < kChannels; ++c) sums[c] = T(0) + ratio[c];
    return;
  }
  for (int gi = 0; gi < J.groups; ++gi) {
    V ratio;
    group_ratio(s, gi, &ratio);
    std::memcpy(v + gi * kGroup, &ratio, sizeof ratio);
  }
  slot_sums(v, J.slots, sums);
}

// Two slice evaluations of as many groups in 8-wide vectors.
template <class T>
[[gnu::always_inline]] inline void job_pair_sums(const JobRows<T>& A, const JobRows<T>& B, T* v,
                                                 T sa[3], T sb[3]) {
  using V8 = typename Lanes<T>::V8;
  const TwoJobs<T> s{A, B};
  if (A.groups == 1 && A.slots == 1 && B.slots == 1) {
    V8 ratio;
    group_ratio(s, 0, &ratio);
    for (int c = 0; c < kChannels; ++c) {
      sa[c] = T(0) + ratio[c];
      sb[c] = T(0) + ratio[kGroup + c];
    }
    return;
  }
  T* vb = v + A.groups * kGroup;
  for (int gi = 0; gi < A.groups; ++gi) {
    V8 ratio;
    group_ratio(s, gi, &ratio);
    T r[2 * kGroup];
    std::memcpy(r, &ratio, sizeof r);
    std::memcpy(v + gi * kGroup, r, sizeof(T) * kGroup);
    std::memcpy(vb + gi * kGroup, r + kGroup, sizeof(T) * kGroup);
  }
  slot_sums(v, A.slots, sa);
  slot_sums(vb, B.slots, sb);
}

// What a block's evaluation reads of the evaluator.

// Whether lane l, if inside, is across a slice boundary instead.
template <class T>
[[gnu::always_inline]] inline bool lane_across(const BinRows& bins, const BlockState<T>& b, int l) {
  return (bins.last[b.d0[l]] != 0) & (b.fd[l] != 0);
}

// The inside lanes across a slice boundary marked kAcross.
template <class T>
[[gnu::always_inline]] inline void mark_across(const BinRows& bins, BlockState<T>& b) {
  for (int l = 0; l < kBlock; ++l) {
    const int k = b.kind[l];
    b.kind[l] = ((k == kInside) & lane_across(bins, b, l)) ? kAcross : k;
  }
}

// Lane l of a block inside one slice: its evaluation in its slice (weight 1). kUniform: every
// slice's row has one group (its length a constant).
template <bool kUniform, class T>
[[gnu::always_inline]] inline JobRows<T> inside_rows(const BlockContext<T>& cx,
                                                     const BlockState<T>& b, int l) {
  const int j = b.d0[l];
  const SliceView<T>& v = cx.views[cx.bins->slice[j]];
  const std::size_t n = kUniform ? std::size_t(kGroupTerms) : v.n;
  JobRows<T> r;
  r.n = n;
  r.r[0] = v.h + std::size_t(b.h0[l]) * n;
  r.r[1] = v.d + std::size_t(cx.bins->d[j]);
  r.r[2] = v.p + std::size_t(b.p0[l]) * n;
  r.a[0] = b.fh[l];
  r.a[1] = b.fd[l];
  r.a[2] = b.fp[l];
  r.k = v.k;
  r.groups = v.groups;
  r.slots = v.slots;
  return r;
}

// Every lane of x saturated as saturate() does.
template <class V, class T>
[[gnu::always_inline]] inline void saturate_vec(V* x) {
  constexpr T kMax = std::numeric_limits<T>::max();
  V max, zero;
  splat(&max, kMax);
  splat(&zero, T(0));
  *x = *x < max ? *x : (*x == *x ? max : zero);
}

// The paper's model (one slot per channel, one slice each): a lane's eval_impl
// rgb[c] = 0 + 1 * (0 + ratio) before saturation, in a 4-lane vector (r, g, b, 0), or two lanes'
// in the halves of an 8-lane one.
template <class T, class S = TwoJobs<T>>
[[gnu::always_inline]] inline void pair_one_slot(const S& s, typename Lanes<T>::V8* rgb) {
  using V8 = typename Lanes<T>::V8;
  V8 ratio, zero, one;
  group_ratio(s, 0, &ratio);
  splat(&zero, T(0));
  splat(&one, T(1));
  *rgb = zero + one * (zero + ratio);
}

template <class T>
[[gnu::always_inline]] inline void one_slot(const JobRows<T>& A, typename Lanes<T>::V4* rgb) {
  using V4 = typename Lanes<T>::V4;
  const OneJob<V4, T> s{A};
  V4 ratio, zero, one;
  group_ratio(s, 0, &ratio);
  splat(&zero, T(0));
  splat(&one, T(1));
  *rgb = zero + one * (zero + ratio);
}

// One lane of the paper's model, saturated, to the outputs at o.
template <class T>
[[gnu::always_inline]] inline void store_one_slot(const JobRows<T>& A, T* const out[3],
                                                  std::size_t o) {
  using V4 = typename Lanes<T>::V4;
  V4 rgb;
  one_slot(A, &rgb);
  saturate_vec<V4, T>(&rgb);
  for (int c = 0; c < kChannels; ++c) out[c][o] = rgb[c];
}

// Two lanes of the paper's model, saturated, to the outputs at oa and ob.
template <class T>
[[gnu::always_inline]] inline void pair_store_one_slot(const JobRows<T>& A, const JobRows<T>& B,
                                                       T* const out[3], std::size_t oa,
                                                       std::size_t ob) {
  using V8 = typename Lanes<T>::V8;
  V8 rgb;
  pair_one_slot<T>(TwoJobs<T>{A, B}, &rgb);
  saturate_vec<V8, T>(&rgb);
  for (int c = 0; c < kChannels; ++c) {
    out[c][oa] = rgb[c];
    out[c][ob] = rgb[kGroup + c];
  }
}

// Eight lanes' (r, g, b, 0), lanes 2i and 2i + 1 in q[i]'s halves, transposed to r, g and b
// stored at out[c] + l (a permutation: every value as it was).
template <class V8, class T>
[[gnu::always_inline]] inline void store_transposed8(const V8 q[4], T* const out[3], int l) {
  const V8 t0 = __builtin_shufflevector(q[0], q[1], 0, 4, 8, 12, 1, 5, 9, 13);
  const V8 t1 = __builtin_shufflevector(q[2], q[3], 0, 4, 8, 12, 1, 5, 9, 13);
  const V8 u0 = __builtin_shufflevector(q[0], q[1], 2, 6, 10, 14, 3, 7, 11, 15);
  const V8 u1 = __builtin_shufflevector(q[2], q[3], 2, 6, 10, 14, 3, 7, 11, 15);
  V8 c[3] = {__builtin_shufflevector(t0, t1, 0, 1, 2, 3, 8, 9, 10, 11),
             __builtin_shufflevector(t0, t1, 4, 5, 6, 7, 12, 13, 14, 15),
             __builtin_shufflevector(u0, u1, 0, 1, 2, 3, 8, 9, 10, 11)};
  for (int i = 0; i < kChannels; ++i) {
    saturate_vec<V8, T>(&c[i]);
    std::memcpy(out[i] + l, &c[i], sizeof c[i]);
  }
}

// Four lanes' (r, g, b, 0), lane i in q[i], transposed as store_transposed8.
template <class V4, class T>
[[gnu::always_inline]] inline void store_transposed4(const V4 q[4], T* const out[3], int l) {
  const V4 t0 = __builtin_shufflevector(q[0], q[1], 0, 4, 1, 5);
  const V4 t1 = __builtin_shufflevector(q[2], q[3], 0, 4, 1, 5);
  const V4 u0 = __builtin_shufflevector(q[0], q[1], 2, 6, 3, 7);
  const V4 u1 = __builtin_shufflevector(q[2], q[3], 2, 6, 3, 7);
  V4 c[3] = {__builtin_shufflevector(t0, t1, 0, 1, 4, 5),
             __builtin_shufflevector(t0, t1, 2, 3, 6, 7),
             __builtin_shufflevector(u0, u1, 0, 1, 4, 5)};
  for (int i = 0; i < kChannels; ++i) {
    saturate_vec<V4, T>(&c[i]);
    std::memcpy(out[i] + l, &c[i], sizeof c[i]);
  }
}

// TwoJobs with the fractions (and 1 - them) of two adjacent lanes taken from vectors of eight
// lanes' by a permutation, rather than formed from their scalars and broadcast.
template <class T>
struct AdjacentJobs : TwoJobs<T> {
  using V8 = typename Lanes<T>::V8;
  V8 f[3], g[3];
  [[gnu::always_inline]] void fractions(V8* a, V8* b, int x) const {
    *a = f[x];
    *b = g[x];
  }
};

// Lanes l + 2i and l + 2i + 1 of the paper's model (uniform_block) into q.
template <int I, class T>
[[gnu::always_inline]] inline void adjacent_pair(const BlockContext<T>& cx, const BlockState<T>& b,
                                                 int l, const typename Lanes<T>::V8 f[3],
                                                 const typename Lanes<T>::V8 g[3],
                                                 typename Lanes<T>::V8* q) {
  const JobRows<T> A = inside_rows<true>(cx, b, l + 2 * I);
  const JobRows<T> B = inside_rows<true>(cx, b, l + 2 * I + 1);
  AdjacentJobs<T> s{{A, B}, {}, {}};
  for (int x = 0; x < 3; ++x) {
    constexpr int a = 2 * I, c = 2 * I + 1;
    s.f[x] = __builtin_shufflevector(f[x], f[x], a, a, a, a, c, c, c, c);
    s.g[x] = __builtin_shufflevector(g[x], g[x], a, a, a, a, c, c, c, c);
  }
  pair_one_slot<T>(s, q);
}

// Stage (2) of the paper's model for a whole block of unit-stride outputs: every lane evaluated
// as if inside its slice (positions are clamped and the tables have a row past every bin, so any
// lane's rows can be read) and the results stored as whole vectors per channel; the caller then
// writes over the lanes of other kinds. Returns the lanes (bit l: lane l) that are across a slice
// boundary if inside (lane_across).
template <class T, bool kPairs>
[[gnu::always_inline]] inline std::uint32_t uniform_block(const BlockContext<T>& cx,
                                                          const BlockState<T>& b, T* const out[3]) {
  using V4 = typename Lanes<T>::V4;
  using V8 = typename Lanes<T>::V8;
  std::uint32_t across = 0;
  for (int l = 0; l < kBlock; ++l) across |= std::uint32_t(lane_across(*cx.bins, b, l)) << l;
  if constexpr (kPairs) {
    for (int l = 0; l < kBlock; l += 8) {
      // Eight lanes' fractions per axis and 1 - them (each lane as TwoJobs forms it).
      V8 f[3], g[3], one;
      splat(&one, T(1));
      load_vec(&f[0], b.fh + l);
      load_vec(&f[1], b.fd + l);
      load_vec(&f[2], b.fp + l);
      for (int x = 0; x < 3; ++x) g[x] = one - f[x];
      V8 q[4];
      adjacent_pair<0>(cx, b, l, f, g, &q[0]);
      adjacent_pair<1>(cx, b, l, f, g, &q[1]);
      adjacent_pair<2>(cx, b, l, f, g, &q[2]);
      adjacent_pair<3>(cx, b, l, f, g, &q[3]);
      store_transposed8<V8, T>(q, out, l);
    }
  } else {
    for (int l = 0; l < kBlock; l += 4) {
      V4 q[4];
      for (int i = 0; i < 4; ++i) one_slot(inside_rows<true>(cx, b, l + i), &q[i]);
      store_transposed4<V4, T>(q, out, l);
    }
  }
  return across;
}

// eval_impl's rgb[c] = 0 + 1 * sum (one slice, weight 1), saturated, at out[c][o].
template <class T>
[[gnu::always_inline]] inline void store_inside(const T sums[3], T* const out[3], std::size_t o) {
  for (int c = 0; c < kChannels; ++c) out[c][o] = saturate(T(0) + T(1) * sums[c]);
}

// Stage (2) for the lanes inside one slice; with kPairs two at a time (one per half of 8-wide
// vectors) where their slices have as many groups. Without a native 8-wide vector of T (double
// below AVX-512) the pairs' vectors would be split and go through memory: one at a time.
template <class T, bool kPairs>
[[gnu::always_inline]] inline void inside_values(const BlockContext<T>& cx, const BlockState<T>& b,
                                                 const int* lanes, int count, T* const out[3],
                                                 std::size_t os, T* v) {
  using V4 = typename Lanes<T>::V4;
  int x = 0;
  if (cx.uniform) {
    for (; kPairs && x + 1 < count; x += 2) {
      pair_store_one_slot(inside_rows<true>(cx, b, lanes[x]),
                          inside_rows<true>(cx, b, lanes[x + 1]), out, std::size_t(lanes[x]) * os,
                          std::size_t(lanes[x + 1]) * os);
    }
    for (; x < count; ++x)
      store_one_slot(inside_rows<true>(cx, b, lanes[x]), out, std::size_t(lanes[x]) * os);
    return;
  }
  for (; kPairs && x + 1 < count; x += 2) {
    const JobRows<T> A = inside_rows<false>(cx, b, lanes[x]);
    const JobRows<T> B = inside_rows<false>(cx, b, lanes[x + 1]);
    T sa[3], sb[3];
    if (A.groups == B.groups) {
      job_pair_sums(A, B, v, sa, sb);
    } else {
      job_sums<V4>(A, v, sa);
      job_sums<V4>(B, v, sb);
    }
    store_inside(sa, out, std::size_t(lanes[x]) * os);
    store_inside(sb, out, std::size_t(lanes[x + 1]) * os);
  }
  for (; x < count; ++x) {
    T s[3];
    job_sums<V4>(inside_rows<false>(cx, b, lanes[x]), v, s);
    store_inside(s, out, std::size_t(lanes[x]) * os);
  }
}

// Lane l across a boundary, in eval_impl's order: the lower slice at fd = 0 with weight 1 - fd,
// then the upper one at its first bin with weight fd; saturated, to the outputs at o.
template <class T, bool kPairs>
[[gnu::always_inline]] inline void across_value(const BlockContext<T>& cx, const BlockState<T>& b,
                                                int l, T* v, T* const out[3], std::size_t o) {
  const int d0 = b.d0[l];
  const SliceTables<T>& lo = cx.tables[cx.bins->slice[d0]];
  const SliceTables<T>& hi = cx.tables[cx.bins->slice[d0 + 1]];
  const JobRows<T> A =
      job_rows(lo, b.h0[l], d0 - lo.theta_d_begin, b.p0[l], b.fh[l], T(0), b.fp[l]);
  const JobRows<T> B =
      job_rows(hi, b.h0[l], d0 + 1 - hi.theta_d_begin, b.p0[l], b.fh[l], T(0), b.fp[l]);
  T s0[3], s1[3];
  if (kPairs && A.groups == B.groups) {
    job_pair_sums(A, B, v, s0, s1);
  } else {
    job_sums<typename Lanes<T>::V4>(A, v, s0);
    job_sums<typename Lanes<T>::V4>(B, v, s1);
  }
  const T fd = b.fd[l], weight = 1 - fd;
  for (int c = 0; c < kChannels; ++c) {
    T acc = T(0) + weight * s0[c];
    acc += fd * s1[c];
    out[c][o] = saturate(acc);
  }
}

// A block of m pairs (base .. base + m of the batch): stages (1) and (2). Writes the results of all
// but the pairs eval's own code evaluates, whose lanes it returns in rest (their count).
template <class T, bool kPairs>
[[gnu::always_inline]] inline int block_eval(const BlockContext<T>& cx, BlockState<T>& b,
                                             const BatchArgs<T>& args, std::size_t base,
                                             std::size_t end, T* v, int* rest) {
  const int m = int(std::min<std::size_t>(kBlock, end - base));
  load_block(b, args, base, end, m);
  block_positions(b, cx.any_generic);
  const std::size_t os = args.out_stride;
  T* const out[3] = {args.out[0] + base * os, args.out[1] + base * os, args.out[2] + base * os};
  int nr = 0;
  if (cx.uniform && !cx.any_generic && os == 1 && m == kBlock) {
    // The paper's model at unit stride: every lane at once, then the few of other kinds (their
    // lanes found from bit masks: nearly always there are none).
    std::uint32_t fix = uniform_block<T, kPairs>(cx, b, out);
    for (int l = 0; l < kBlock; ++l) fix |= std::uint32_t(b.kind[l] != kInside) << l;
    for (; fix != 0; fix &= fix - 1) {
      const int l = __builtin_ctz(fix), k = b.kind[l];
      if (k == kZero) {
        for (int c = 0; c < kChannels; ++c) out[c][l] = T(0);
      } else if (k == kRest) {
        rest[nr++] = l;
      } else {
        across_value<T, kPairs>(cx, b, l, v, out, std::size_t(l));
      }
    }
    return nr;
  }
  // The lanes of each kind, listed without branches.
  mark_across(*cx.bins, b);
  int zero[kBlock], inside[kBlock], across[kBlock];
  int nz = 0, ni = 0, na = 0;
  for (int l = 0; l < m; ++l) {
    const int k = b.kind[l];
    zero[nz] = rest[nr] = across[na] = inside[ni] = l;
    nz += k == kZero;
    nr += k == kRest;
    na += k == kAcross;
    ni += k == kInside;
  }
  for (int x = 0; x < nz; ++x) {
    for (int c = 0; c < kChannels; ++c) out[c][std::size_t(zero[x]) * os] = T(0);
  }
  inside_values<T, kPairs>(cx, b, inside, ni, out, os, v);
  for (int x = 0; x < na; ++x) {
    across_value<T, kPairs>(cx, b, across[x], v, out, std::size_t(across[x]) * os);
  }
  return nr;
}

}  // namespace
}  // namespace cbrdf::internal
