// SPDX-License-Identifier: MIT
// This file's functions set no errno (its square roots never see a negative argument) and may
// evaluate both sides of a select (neither changes a value: no reassociation), so that the batch's
// position loop vectorizes; they contract no multiply-add (the AVX-512 kernels have FMA
// instructions, and eval and eval_batch must round alike). The build's other flags are kept.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-math-errno", "no-trapping-math", "fp-contract=off")
#endif
#include "eval/interp_tables.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <type_traits>

#include "cbrdf/parallel_for.h"
#include "density/frank_grid.h"
#include "density/grid_copula.h"

namespace cbrdf::eval {
namespace {

// Parameters are evaluated clamped to [-1e300, 1e300] (model.cc, spec/container.md).
constexpr double kMaxEvaluatedParameter = 1e300;

template <class T>
inline T saturate(T v) {
  constexpr T kMax = std::numeric_limits<T>::max();
  return v < kMax ? v : (v == v ? kMax : T(0));
}

// Whether a component has the product form (see the header) and, if so, its slot constants and
// per-axis (e, w, y) at CDF values u, as FrankGrid::prepare forms them.
struct ProductForm {
  bool ok = false;
  double t = 0, b = 0;
  SlotConstants<double> k{};
};

ProductForm product_form(const Component& c) {
  ProductForm f;
  const double theta = std::clamp(c.theta, -kMaxEvaluatedParameter, kMaxEvaluatedParameter);
  if (c.family == CopulaFamily::kIndependence ||
      (c.family == CopulaFamily::kFrank && theta == 0.0)) {
    f.ok = true;
    f.k = {c.scale, 1, 0, 0, 1, 0, 0};
    return f;
  }
  if (c.family != CopulaFamily::kFrank || theta < fit::kFrankGridMinAlpha) return f;
  f.ok = true;
  f.t = -theta;
  f.b = -std::expm1(-f.t);
  const double et = std::exp(-f.t);
  constexpr double kLn2Lo = 2.319046813846299558e-17;  // as frank_grid.cc
  const double one_plus_b = -2.0 * std::expm1((theta - std::numbers::ln2) - kLn2Lo);
  const double r = f.t / f.b;
  const double k = c.scale * (r * r);
  if (f.t > 0) {
    f.k = {k, et, f.b, 0, 1, 0, f.b};  // 1 - h = e^{-t} + b Y, 1 + h = 1 + b W
  } else {
    f.k = {k, 1, 0, -f.b, one_plus_b, -f.b, 0};  // 1 - h = 1 - b W, 1 + h = (2 - e^{-t}) - b Y
  }
  return f;
}

// Axis terms of masses `pdf` (their midpoint CDF) for a product form.
void axis_terms(const ProductForm& f, const std::vector<double>& pdf,
                std::vector<AxisTerms<double>>* out) {
  std::vector<double> u;
  fit::midpoint_cdf(pdf, &u);
  out->resize(pdf.size());
  for (std::size_t i = 0; i < pdf.size(); ++i) {
    AxisTerms<double>& a = (*out)[i];
    if (f.t == 0.0) {
      a = {pdf[i], 0, 0};
      continue;
    }
    const double x = u[i], e = std::exp(-f.t * x);
    a.g = pdf[i] * e;
    a.w = -std::expm1(-f.t * x) / f.b;
    a.y = -e * std::expm1(-f.t * (1.0 - x)) / f.b;
  }
}

// Slot q's constants in a slice's grouped array.
void set_constants(SliceTables<double>* st, int q, const SlotConstants<double>& k) {
  double* c = st->consts.data() + constant_offset(q);
  const double v[7] = {k.k, k.a0, k.a1, k.a2, k.b0, k.b1, k.b2};
  for (int e = 0; e < 7; ++e) c[e * kGroup] = v[e];
}

// Slot q's terms on one axis into its rows (row length n): bins 0 .. bins, the last repeated.
void set_rows(const std::vector<AxisTerms<double>>& terms, int bins, std::size_t n, int q,
              std::vector<double>* rows) {
  for (int i = 0; i <= bins; ++i) {
    const AxisTerms<double>& a = terms[std::size_t(std::min(i, bins - 1))];
    double* t = rows->data() + std::size_t(i) * n + term_offset(q);
    t[0] = a.g;
    t[kGroup] = a.w;
    t[2 * kGroup] = a.y;
  }
}

// Adds weight * the slice's value at the interpolated position to rgb. The axis rows of the two
// bins around the position: h0/h1, d0/d1, p0/p1, fractions fh, fd, fp.
template <class T>
inline void add_slice(const SliceTables<T>& st, int i0, T fh, int jl0, T fd, int k0, T fp, T weight,
                      T rgb[3]) {
  const int R = st.slots_per_channel;
  const std::size_t n = st.row();
  const T* h0 = st.h.data() + std::size_t(i0) * n;
  const T* h1 = h0 + n;
  const T* d0 = st.d.data() + std::size_t(jl0) * n;
  const T* d1 = d0 + n;
  const T* p0 = st.p.data() + std::size_t(k0) * n;
  const T* p1 = p0 + n;
  const T gh = 1 - fh, gd = 1 - fd, gp = 1 - fp;
  constexpr int W_ = kGroup, Y_ = 2 * kGroup;
  for (int c = 0; c < kChannels; ++c) {
    T sum = 0;
    for (int r = 0; r < R; ++r) {
      const int q = c * R + r;
      const std::size_t o = term_offset(q);
      const T g1 = h0[o] * gh + h1[o] * fh, w1 = h0[o + W_] * gh + h1[o + W_] * fh,
              y1 = h0[o + Y_] * gh + h1[o + Y_] * fh;
      const T g2 = d0[o] * gd + d1[o] * fd, w2 = d0[o + W_] * gd + d1[o + W_] * fd,
              y2 = d0[o + Y_] * gd + d1[o + Y_] * fd;
      const T g3 = p0[o] * gp + p1[o] * fp, w3 = p0[o + W_] * gp + p1[o + W_] * fp,
              y3 = p0[o + Y_] * gp + p1[o + Y_] * fp;
      const T* k = st.consts.data() + constant_offset(q);
      const T w12 = w1 * w2, W = w12 * w3, Y = y1 + w1 * y2 + w12 * y3;
      const T omh = k[kGroup] + k[2 * kGroup] * Y + k[3 * kGroup] * W;
      const T oph = k[4 * kGroup] + k[5 * kGroup] * Y + k[6 * kGroup] * W;
      sum += k[0] * (g1 * g2 * g3) * oph / (omh * omh * omh);
    }
    rgb[c] += weight * sum;
  }
}

// atan(x) for |x| <= 7/16: fdlibm's s_atan.c polynomial (relative error below 3e-16).
template <class T>
inline T atan_core(T x) {
  const T z = x * x, w = z * z;
  const T s1 =
      z *
      (T(3.33333333333329318027e-01) +
       w * (T(1.42857142725034663711e-01) +
            w * (T(9.09088713343650656196e-02) +
                 w * (T(6.66107313738753120669e-02) +
                      w * (T(4.97687799461593236017e-02) + w * T(1.62858201153657823623e-02))))));
  const T s2 =
      w * (T(-1.99999999998764832476e-01) +
           w * (T(-1.11111104054623557880e-01) +
                w * (T(-7.69187620504482999495e-02) +
                     w * (T(-5.83357013379057348645e-02) + w * T(-3.65315727442169155270e-02)))));
  return x - x * (s1 + s2);
}

// atan2(a, b) for a, b >= 0 (0 when both are): one division and one polynomial, the argument
// reduced to |x| <= tan(pi/8) by atan(a/b) = pi/4 + atan((a - b) / (a + b)) and
// atan(a/b) = pi/2 - atan(b/a). Relative error below 1e-15 (tests/model_eval_test.cc).
template <class T>
inline T atan2_first_quadrant(T a, T b) {
  constexpr T kTanPi8 = T(0.41421356237309504880);
  constexpr T kPi4 = T(std::numbers::pi / 4), kPi2 = T(std::numbers::pi / 2);
  // Selected without branches: the case is data dependent, so a branch mispredicts often.
  const bool above = a > kTanPi8 * b, below_far = !(b > kTanPi8 * a);
  const bool mid = above && !below_far, far = above && below_far;
  const T num = mid ? a - b : (far ? -b : a);
  const T den = mid ? a + b : (far ? a : b);
  const T base = mid ? kPi4 : (far ? kPi2 : T(0));
  // A select, not an early return, so that loops over blocks of pairs vectorize (eval_batch).
  const T r = base + atan_core(num / den);
  return den > 0 ? r : T(0);
}

// Grid position of a direction pair with wi.z, wo.z > 0 (unit vectors). With H = wi + wo and
// D = wi - wo: tan theta_h = |H_xy| / H_z, tan theta_d = |D| / |H|, and phi_d the angle of D (so
// of wi) in the difference frame (grid_position's), its components scaled by |H_xy| |H| > 0:
//   dx = (D_xy . H_xy) H_z - D_z |H_xy|^2,  dy = (D_y H_x - D_x H_y) |H|,
// folded to [0, pi) by reciprocity. Swapping wi and wo leaves H and |D| as they are and negates
// D, bit for bit, so dx and dy change sign exactly and the fold gives the same phi_d.
// position() in three steps around its square roots, so that a batch can take the roots in loops
// of their own (a square root that may set errno keeps a loop from vectorizing): the squared
// lengths; theta_d, phi_d and the argument of theta_h's root; the clamped positions.
template <class T>
struct Squares {
  T rho2, len2, chord2;  // |H_xy|^2, |H|^2, |D|^2
};

template <class T>
inline Squares<T> position_squares(T ix, T iy, T iz, T ox, T oy, T oz) {
  const T hx = ix + ox, hy = iy + oy, hz = iz + oz;
  const T ex = ix - ox, ey = iy - oy, ez = iz - oz;
  const T rho2 = hx * hx + hy * hy;
  return {rho2, rho2 + hz * hz, ex * ex + ey * ey + ez * ez};
}

// From the roots rho = |H_xy|, len = |H|, chord = |D|: theta_h * 2 / pi (to take the root of),
// theta_d and phi_d in degrees, clamped (a NaN to 0).
template <class T>
inline Position<T> position_angles(T ix, T iy, T iz, T ox, T oy, T oz, T rho2, T rho, T len,
                                   T chord) {
  constexpr T kDeg = T(180 / std::numbers::pi), kPi = T(std::numbers::pi);
  const T hx = ix + ox, hy = iy + oy, hz = iz + oz;
  const T ex = ix - ox, ey = iy - oy, ez = iz - oz;
  const T theta_h = atan2_first_quadrant(rho, hz);
  const T theta_d = atan2_first_quadrant(chord, len);
  // From D, not wi: D is orthogonal to h (wi and wo have one length), so its azimuth in the frame
  // is wi's, without the cancellation of wi's large component along h when theta_d is small.
  // Where h is the normal: the frame of phi_h = 0, as grid_position takes it (selects, as above).
  const bool tilted = rho2 > std::numeric_limits<T>::min();
  const T dx = tilted ? (ex * hx + ey * hy) * hz - ez * rho2 : ex;
  const T dy = tilted ? (ey * hx - ex * hy) * len : ey;
  const T alpha = atan2_first_quadrant(std::abs(dy), std::abs(dx));
  // atan2(dy, dx) folded to [0, pi]: alpha where dx and dy have one sign, pi - alpha elsewhere.
  const T phi = (dx >= 0) == (dy >= 0) ? alpha : kPi - alpha;
  Position<T> g;
  g.h = theta_h * T(2 / std::numbers::pi);
  g.d = std::min(T(kThetaDBins - 1), std::max(T(0), theta_d * kDeg));
  g.p = std::min(T(kPhiDBins), std::max(T(0), phi * kDeg));
  return g;
}

// theta_h's position from the root of position_angles' h: sqrt(theta_h / 90deg) * 90, clamped.
template <class T>
inline T position_h(T root) {
  return std::min(T(kThetaHBins - 1), std::max(T(0), root * T(kThetaHBins)));
}

// Grid position of a direction pair with wi.z, wo.z > 0 (unit vectors). With H = wi + wo and
// D = wi - wo: tan theta_h = |H_xy| / H_z, tan theta_d = |D| / |H|, and phi_d the angle of D (so
// of wi) in the difference frame (grid_position's), its components scaled by |H_xy| |H| > 0:
//   dx = (D_xy . H_xy) H_z - D_z |H_xy|^2,  dy = (D_y H_x - D_x H_y) |H|,
// folded to [0, pi) by reciprocity. Swapping wi and wo leaves H and |D| as they are and negates
// D, bit for bit, so dx and dy change sign exactly and the fold gives the same phi_d.
template <class T>
inline Position<T> position(T ix, T iy, T iz, T ox, T oy, T oz) {
  const Squares<T> q = position_squares(ix, iy, iz, ox, oy, oz);
  Position<T> g = position_angles(ix, iy, iz, ox, oy, oz, q.rho2, std::sqrt(q.rho2),
                                  std::sqrt(q.len2), std::sqrt(q.chord2));
  g.h = position_h(std::sqrt(g.h));
  return g;
}

// ---- Batches (InterpTables::eval_batch) ----------------------------------------------------
// A chunk of pairs is evaluated in blocks of kBlock, each block by one call of a function compiled
// for AVX-512, AVX2 and the baseline (chosen once per process): (1) the block's inputs copied into
// one object, the grid positions of the whole block, branch-free loops (the coordinates, three
// atan2 polynomials and four square roots per pair) that the compiler vectorizes across pairs,
// then per pair its slice, row offsets and kind; (2) the pairs listed, without branches, by kind:
// inside one slice (nearly all), across a slice boundary, below the horizon, the rest; (3) per
// pair, the two bins' rows of each axis interpolated and the copula ratios formed, kGroup slots at
// a time (the slice tables' grouped layout), vectorized across slots, two pairs at a time (one per
// half of an 8-wide vector) where the CPU has such vectors natively; for the paper's model (one
// slot per channel in every slice) the sums and their saturation are formed across the vector
// too, and the results written straight to the outputs. Every value is formed by the same
// operations in the same order as eval's, so the results are equal bit for bit: vector lanes round
// as scalar instructions do, and no path contracts multiply-adds (fp-contract=off above: AVX-512
// has FMA instructions). A pair across a slice boundary is two slice evaluations, as in eval; pairs
// below the horizon are 0; pairs across the phi_d period (1 in 180) and models with generic terms
// go back to the caller, which evaluates them with eval's own code.
constexpr int kBlock = 32;

// One block's inputs and stage (1)'s results, in one object: its arrays provably do not alias, so
// the stage's loop vectorizes without versioning.
template <class T>
struct BlockState {
  alignas(64) T in[6][kBlock];  // wi x, y, z, wo x, y, z
  alignas(64) T rho2[kBlock], rho[kBlock], len[kBlock], chord[kBlock];
  alignas(64) T ph[kBlock], pd[kBlock], pp[kBlock];
  alignas(64) T fh[kBlock], fd[kBlock], fp[kBlock];
  alignas(64) int h0[kBlock], d0[kBlock], p0[kBlock];
  alignas(64) int sl[kBlock], oh[kBlock], od[kBlock], op[kBlock];  // block_rows
  alignas(64) int kind[kBlock];                                    // a LaneKind
};

// How a lane is evaluated: 0 (below the horizon), by eval's own code, across a slice boundary (two
// slice evaluations), inside one slice.
enum LaneKind : int { kZero, kRest, kAcross, kInside };

// Pairs base .. base + m (m <= kBlock) of the batch into b.in, zero-padded to kBlock.
template <class T>
[[gnu::always_inline]] inline void load_block(BlockState<T>& b, const BatchArgs<T>& args,
                                              std::size_t base, std::size_t end, int m) {
  const std::size_t is = args.in_stride;
  for (int a = 0; a < 6; ++a) {
    const T* src = args.in[a] + base * is;
    if (is == 1 && m == kBlock) {
      for (int l = 0; l < kBlock; ++l) b.in[a][l] = src[l];  // a fixed size: moved inline
      // The block after next, into the cache while this one is evaluated: six streams of
      // pairs outrun the hardware's prefetching.
      if (base + 3 * kBlock <= end) {
        for (int l = 0; l < kBlock; l += int(64 / sizeof(T)))
          __builtin_prefetch(src + 2 * kBlock + l);
      }
    } else {
      for (int l = 0; l < m; ++l) b.in[a][l] = src[std::size_t(l) * is];
      for (int l = m; l < kBlock; ++l) b.in[a][l] = T(0);
    }
  }
}

// Stage (1): positions, bin indices and fractions, as position() and eval_impl form them. The
// square roots have loops of their own: with -fno-math-errno they vectorize too, without it they
// stay scalar and the other loops still vectorize.
template <class T>
[[gnu::always_inline]] inline void block_positions(BlockState<T>& b) {
  for (int l = 0; l < kBlock; ++l) {
    const Squares<T> q =
        position_squares(b.in[0][l], b.in[1][l], b.in[2][l], b.in[3][l], b.in[4][l], b.in[5][l]);
    b.rho2[l] = q.rho2;
    b.len[l] = q.len2;
    b.chord[l] = q.chord2;
  }
  for (int l = 0; l < kBlock; ++l) {
    b.rho[l] = std::sqrt(b.rho2[l]);
    b.len[l] = std::sqrt(b.len[l]);
    b.chord[l] = std::sqrt(b.chord[l]);
  }
  for (int l = 0; l < kBlock; ++l) {
    const Position<T> g =
        position_angles(b.in[0][l], b.in[1][l], b.in[2][l], b.in[3][l], b.in[4][l], b.in[5][l],
                        b.rho2[l], b.rho[l], b.len[l], b.chord[l]);
    b.ph[l] = g.h;
    b.pd[l] = g.d;
    b.pp[l] = g.p;
  }
  for (int l = 0; l < kBlock; ++l) b.ph[l] = std::sqrt(b.ph[l]);
  for (int l = 0; l < kBlock; ++l) {
    const T h = position_h(b.ph[l]), d = b.pd[l], p = b.pp[l];
    b.ph[l] = h;
    const int i = std::min(int(h), kThetaHBins - 1);
    const int j = std::min(int(d), kThetaDBins - 1);
    const int k = std::min(int(p), kPhiDBins - 1);
    b.h0[l] = i;
    b.d0[l] = j;
    b.p0[l] = k;
    b.fh[l] = h - T(i);
    b.fd[l] = d - T(j);
    b.fp[l] = p - T(k);
  }
}

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

// A slice's tables as a lane reads them.
template <class T>
struct SliceView {
  const T *h, *d, *p, *k;
  std::size_t n;  // row length
  int groups, slots;
};

// Per theta_d bin j: its slice, the slice's row length, and the offset of j's row in the slice's
// theta_d axis.
struct BinRows {
  int slice[kThetaDBins], n[kThetaDBins], d[kThetaDBins];
  int last[kThetaDBins];  // 1: the next bin is in another slice (or there is none)
};

// What a block's evaluation reads of the evaluator.
template <class T>
struct BlockContext {
  const SliceTables<T>* tables;  // per slice
  const SliceView<T>* views;     // per slice
  const BinRows* bins;           // per theta_d bin
  bool any_generic;
  bool uniform;  // every slice has one group of one slot per channel (the paper's model)
};

// Per lane, its slice and the offsets of its bins' rows (a loop across the block).
template <class T>
[[gnu::always_inline]] inline void block_rows(const BinRows& bins, bool any_generic,
                                              BlockState<T>& b) {
  for (int l = 0; l < kBlock; ++l) {
    const int j = b.d0[l], n = bins.n[j];
    // Across the phi_d period, or with generic terms: eval's own code.
    const bool rest = any_generic || !(b.p0[l] + 1 < kPhiDBins || b.fp[l] == 0);
    const bool across = bins.last[j] != 0 && b.fd[l] != 0;
    const bool above = b.in[2][l] > 0 && b.in[5][l] > 0;
    b.kind[l] = above ? (rest ? kRest : (across ? kAcross : kInside)) : kZero;
    b.sl[l] = bins.slice[j];
    b.oh[l] = b.h0[l] * n;
    b.od[l] = bins.d[j];
    b.op[l] = b.p0[l] * n;
  }
}

// Lane l of a block inside one slice: its evaluation in its slice (weight 1).
template <class T>
[[gnu::always_inline]] inline JobRows<T> inside_rows(const BlockContext<T>& cx,
                                                     const BlockState<T>& b, int l) {
  const SliceView<T>& v = cx.views[b.sl[l]];
  JobRows<T> r;
  r.n = v.n;
  r.r[0] = v.h + b.oh[l];
  r.r[1] = v.d + b.od[l];
  r.r[2] = v.p + b.op[l];
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

// Two lanes of the paper's model (one slot per channel, one slice each): eval_impl's
// rgb[c] = 0 + 1 * (0 + ratio), saturated, formed across both lanes' vectors, then stored.
template <class T>
[[gnu::always_inline]] inline void pair_store_one_slot(const JobRows<T>& A, const JobRows<T>& B,
                                                       T* const out[3], std::size_t oa,
                                                       std::size_t ob) {
  using V8 = typename Lanes<T>::V8;
  const TwoJobs<T> s{A, B};
  V8 ratio, zero, one;
  group_ratio(s, 0, &ratio);
  splat(&zero, T(0));
  splat(&one, T(1));
  V8 rgb = zero + one * (zero + ratio);
  saturate_vec<V8, T>(&rgb);
  for (int c = 0; c < kChannels; ++c) {
    out[c][oa] = rgb[c];
    out[c][ob] = rgb[kGroup + c];
  }
}

// One lane of the paper's model, as pair_store_one_slot.
template <class T>
[[gnu::always_inline]] inline void store_one_slot(const JobRows<T>& A, T* const out[3],
                                                  std::size_t o) {
  using V4 = typename Lanes<T>::V4;
  const OneJob<V4, T> s{A};
  V4 ratio, zero, one;
  group_ratio(s, 0, &ratio);
  splat(&zero, T(0));
  splat(&one, T(1));
  V4 rgb = zero + one * (zero + ratio);
  saturate_vec<V4, T>(&rgb);
  for (int c = 0; c < kChannels; ++c) out[c][o] = rgb[c];
}

// eval_impl's rgb[c] = 0 + 1 * sum (one slice, weight 1), saturated, at out[c][o].
template <class T>
[[gnu::always_inline]] inline void store_inside(const T sums[3], T* const out[3], std::size_t o) {
  for (int c = 0; c < kChannels; ++c) out[c][o] = saturate(T(0) + T(1) * sums[c]);
}

// Stage (3) for the lanes inside one slice; with kPairs two at a time (one per half of 8-wide
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
      pair_store_one_slot(inside_rows(cx, b, lanes[x]), inside_rows(cx, b, lanes[x + 1]), out,
                          std::size_t(lanes[x]) * os, std::size_t(lanes[x + 1]) * os);
    }
    for (; x < count; ++x)
      store_one_slot(inside_rows(cx, b, lanes[x]), out, std::size_t(lanes[x]) * os);
    return;
  }
  for (; kPairs && x + 1 < count; x += 2) {
    const JobRows<T> A = inside_rows(cx, b, lanes[x]), B = inside_rows(cx, b, lanes[x + 1]);
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
    job_sums<V4>(inside_rows(cx, b, lanes[x]), v, s);
    store_inside(s, out, std::size_t(lanes[x]) * os);
  }
}

// A block of m pairs (base .. base + m of the batch): stages (1) to (3). Writes the results of all
// but the pairs eval's own code evaluates, whose lanes it returns in rest (their count).
template <class T, bool kPairs>
[[gnu::always_inline]] inline int block_eval(const BlockContext<T>& cx, BlockState<T>& b,
                                             const BatchArgs<T>& args, std::size_t base,
                                             std::size_t end, T* v, int* rest) {
  const int m = int(std::min<std::size_t>(kBlock, end - base));
  load_block(b, args, base, end, m);
  block_positions(b);
  block_rows(*cx.bins, cx.any_generic, b);
  const std::size_t os = args.out_stride;
  T* const out[3] = {args.out[0] + base * os, args.out[1] + base * os, args.out[2] + base * os};
  // Stage (2): the lanes of each kind, listed without branches.
  int zero[kBlock], inside[kBlock], across[kBlock];
  int nz = 0, ni = 0, na = 0, nr = 0;
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
  // Across a boundary, in eval_impl's order: the lower slice at fd = 0 with weight 1 - fd, then
  // the upper one at its first bin with weight fd.
  for (int x = 0; x < na; ++x) {
    const int l = across[x], d0 = b.d0[l];
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
      out[c][std::size_t(l) * os] = saturate(acc);
    }
  }
  return nr;
}

// The block's entry points, compiled for AVX-512, AVX2 and the baseline where the toolchain
// supports it (GCC on x86-64; not under the sanitizers), and chosen once by a CPU check. Lanes are
// paired (8-wide vectors) where the target has such vectors natively: floats with AVX2, doubles
// with AVX-512; elsewhere the halves would be split and go through memory.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define CBRDF_VECTOR_TARGETS 1
#else
#define CBRDF_VECTOR_TARGETS 0
#endif

template <class T, bool kPairs>
int block_eval_base(const BlockContext<T>& cx, BlockState<T>& b, const BatchArgs<T>& args,
                    std::size_t base, std::size_t end, T* v, int* rest) {
  return block_eval<T, kPairs>(cx, b, args, base, end, v, rest);
}

#if CBRDF_VECTOR_TARGETS
template <class T, bool kPairs>
[[gnu::target("avx2")]] int block_eval_avx2(const BlockContext<T>& cx, BlockState<T>& b,
                                            const BatchArgs<T>& args, std::size_t base,
                                            std::size_t end, T* v, int* rest) {
  return block_eval<T, kPairs>(cx, b, args, base, end, v, rest);
}
template <class T, bool kPairs>
[[gnu::target("avx512f")]] int block_eval_avx512(const BlockContext<T>& cx, BlockState<T>& b,
                                                 const BatchArgs<T>& args, std::size_t base,
                                                 std::size_t end, T* v, int* rest) {
  return block_eval<T, kPairs>(cx, b, args, base, end, v, rest);
}
#endif

template <class T>
using BlockEvalFn = int (*)(const BlockContext<T>&, BlockState<T>&, const BatchArgs<T>&,
                            std::size_t, std::size_t, T*, int*);

bool target_supported(BatchTarget t) {
#if CBRDF_VECTOR_TARGETS
  __builtin_cpu_init();  // the CPU model may not be read yet where a static constructor calls this
#endif
  switch (t) {
    case BatchTarget::kAuto:
    case BatchTarget::kBaseline:
      return true;
#if CBRDF_VECTOR_TARGETS
    case BatchTarget::kAvx512:
      return __builtin_cpu_supports("avx512f");
    case BatchTarget::kAvx2:
      return __builtin_cpu_supports("avx2");
#endif
    default:
      return false;
  }
}

// The entry point for a supported target other than kAuto.
template <class T>
BlockEvalFn<T> block_eval_for(BatchTarget t) {
#if CBRDF_VECTOR_TARGETS
  if (t == BatchTarget::kAvx512) return block_eval_avx512<T, true>;
  if (t == BatchTarget::kAvx2) return block_eval_avx2<T, std::is_same_v<T, float>>;
#endif
  (void)t;
  return block_eval_base<T, false>;
}

// The best target this CPU runs.
BatchTarget best_target() {
  for (BatchTarget t : {BatchTarget::kAvx512, BatchTarget::kAvx2}) {
    if (target_supported(t)) return t;
  }
  return BatchTarget::kBaseline;
}

std::atomic<BatchTarget> g_batch_target{BatchTarget::kAuto};  // set_batch_target

template <class T>
BlockEvalFn<T> pick_block_eval() {
  static const BlockEvalFn<T> best = block_eval_for<T>(best_target());
  const BatchTarget t = g_batch_target.load(std::memory_order_relaxed);
  return t == BatchTarget::kAuto ? best : block_eval_for<T>(t);
}

}  // namespace

template <class T>
std::size_t SliceTables<T>::bytes() const {
  return sizeof(*this) +
         (h.capacity() + d.capacity() + p.capacity() + consts.capacity()) * sizeof(T);
}
template struct SliceTables<double>;
template struct SliceTables<float>;

GenericTerm::GenericTerm() = default;
GenericTerm::GenericTerm(GenericTerm&&) noexcept = default;
GenericTerm& GenericTerm::operator=(GenericTerm&&) noexcept = default;
GenericTerm::~GenericTerm() = default;

double GenericTerm::value(int i, int j, int k) const {
  const Component& cs = *component;
  const double f = cs.pdf_h[std::size_t(i)] * cs.pdf_d[std::size_t(j)] * cs.pdf_p[std::size_t(k)];
  if (f == 0.0 || cs.scale == 0.0) return 0.0;
  return saturate(cs.scale * copula->density(i, j, k) * f);
}

InterpTables::InterpTables(const Model& model) {
  for (int j = 0; j < kThetaDBins; ++j) slice_of_bin_[j] = model.slice_of(j);
  const std::size_t ns = model.slices.size();
  f64_.resize(ns);
  f32_.resize(ns);
  generic_.resize(ns);
  std::vector<AxisTerms<double>> th, td, tp;
  for (std::size_t s = 0; s < ns; ++s) {
    const Slice& slice = model.slices[s];
    SliceTables<double>& st = f64_[s];
    st.theta_d_begin = slice.theta_d_begin;
    st.theta_d_end = slice.theta_d_end;
    int R = 1;
    for (const ChannelSlice& cs : slice.channel) R = std::max(R, cs.components());
    st.slots_per_channel = R;
    max_slots_per_channel_ = std::max(max_slots_per_channel_, R);
    const int width = slice.width();
    st.groups = (3 * R + kGroup - 1) / kGroup;
    const std::size_t n = st.row();
    st.h.assign(std::size_t(kThetaHBins + 1) * n, 0.0);
    st.d.assign(std::size_t(width + 1) * n, 0.0);
    st.p.assign(std::size_t(kPhiDBins + 1) * n, 0.0);
    st.consts.assign(std::size_t(st.groups) * kGroupConstants, 0.0);
    // Zero slots (and the padding): k = g = 0 and 1 - h = 1 + h = 1, a value of 0.
    for (int q = 0; q < st.groups * kGroup; ++q) set_constants(&st, q, {0, 1, 0, 0, 1, 0, 0});
    for (int c = 0; c < kChannels; ++c) {
      const ChannelSlice& cs = slice.channel[std::size_t(c)];
      for (int r = 0; r < cs.components(); ++r) {
        const Component& comp = cs.component(r);
        const int q = c * R + r;
        const ProductForm f = product_form(comp);
        if (!f.ok) {
          GenericTerm g;
          g.component = &comp;
          g.channel = c;
          const double theta =
              std::clamp(comp.theta, -kMaxEvaluatedParameter, kMaxEvaluatedParameter);
          g.copula = comp.family == CopulaFamily::kFrank ? fit::make_archimedean_grid(comp.family)
                                                         : fit::make_grid_copula(comp.family);
          std::vector<double> u1, u2, u3;
          fit::midpoint_cdf(comp.pdf_h, &u1);
          fit::midpoint_cdf(comp.pdf_d, &u2);
          fit::midpoint_cdf(comp.pdf_p, &u3);
          g.copula->prepare(theta, u1, u2, u3);
          generic_[s].push_back(std::move(g));
          any_generic_ = true;
          continue;  // its slot stays zero
        }
        if (comp.scale == 0.0) continue;
        set_constants(&st, q, f.k);
        axis_terms(f, comp.pdf_h, &th);
        axis_terms(f, comp.pdf_d, &td);
        axis_terms(f, comp.pdf_p, &tp);
        set_rows(th, kThetaHBins, n, q, &st.h);
        set_rows(td, width, n, q, &st.d);
        set_rows(tp, kPhiDBins, n, q, &st.p);
      }
    }
    SliceTables<float>& sf = f32_[s];
    sf.theta_d_begin = st.theta_d_begin;
    sf.theta_d_end = st.theta_d_end;
    sf.slots_per_channel = R;
    sf.groups = st.groups;
    auto cast_all = [](const std::vector<double>& from, std::vector<float>* to) {
      to->resize(from.size());
      for (std::size_t i = 0; i < from.size(); ++i) (*to)[i] = float(from[i]);
    };
    cast_all(st.h, &sf.h);
    cast_all(st.d, &sf.d);
    cast_all(st.p, &sf.p);
    cast_all(st.consts, &sf.consts);
  }
  for (int j = 0; j < kThetaDBins; ++j)
    last_in_slice_[j] = j + 1 >= f64_[std::size_t(slice_of_bin_[j])].theta_d_end;
}

InterpTables::~InterpTables() = default;

template <class T>
void InterpTables::eval_impl(const std::vector<SliceTables<T>>& tables, const Position<T>& pos,
                             T rgb[3]) const {
  const int h0 = std::min(int(pos.h), kThetaHBins - 1);
  const int d0 = std::min(int(pos.d), kThetaDBins - 1);
  const int p0 = std::min(int(pos.p), kPhiDBins - 1);
  const T fh = pos.h - T(h0), fd = pos.d - T(d0), fp = pos.p - T(p0);
  const int s0 = slice_of_bin_[d0];
  const SliceTables<T>& st = tables[std::size_t(s0)];
  // Across the phi_d period (bin 179 to bin 0, where the CDF returns from 1 to 0) and across a
  // slice boundary (two slices' marginals and copulas), the terms are not interpolated: the value
  // is linear between the two bins' values, as trilinear interpolation has it.
  auto along_p = [&](const SliceTables<T>& sl, int jl, T fd_in, T weight) {
    if (p0 + 1 < kPhiDBins || fp == 0) {
      add_slice(sl, h0, fh, jl, fd_in, p0, fp, weight, rgb);
    } else {
      add_slice(sl, h0, fh, jl, fd_in, p0, T(0), weight * (1 - fp), rgb);
      add_slice(sl, h0, fh, jl, fd_in, 0, T(0), weight * fp, rgb);
    }
  };
  if (d0 + 1 < st.theta_d_end || fd == 0) {
    along_p(st, d0 - st.theta_d_begin, fd, T(1));
  } else {
    const SliceTables<T>& next = tables[std::size_t(slice_of_bin_[d0 + 1])];
    along_p(st, d0 - st.theta_d_begin, T(0), 1 - fd);
    along_p(next, d0 + 1 - next.theta_d_begin, T(0), fd);
  }
}

void InterpTables::add_generic(int i0, double fh, int j0, double fd, int k0, double fp,
                               double rgb[3]) const {
  for (int b = 0; b < 2; ++b) {
    const double wb = b ? fd : 1 - fd;
    if (wb == 0.0) continue;
    const int j = j0 + b;
    const std::size_t s = std::size_t(slice_of_bin_[j]);
    const int jl = j - f64_[s].theta_d_begin;
    for (const GenericTerm& g : generic_[s]) {
      double v = 0;
      for (int a = 0; a < 2; ++a) {
        const double wa = a ? fh : 1 - fh;
        if (wa == 0.0) continue;
        for (int e = 0; e < 2; ++e) {
          const double w = wa * (e ? fp : 1 - fp);
          if (w == 0.0) continue;
          v += w * g.value(i0 + a, jl, (k0 + e) % kPhiDBins);
        }
      }
      rgb[g.channel] += wb * v;
    }
  }
}

void InterpTables::eval(const Vec3& wi, const Vec3& wo, double rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0;
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return;
  eval_at(position(wi.x, wi.y, wi.z, wo.x, wo.y, wo.z), rgb);
}

void InterpTables::eval(const float wi[3], const float wo[3], float rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0f;
  if (!(wi[2] > 0.0f) || !(wo[2] > 0.0f)) return;
  eval_at(position(wi[0], wi[1], wi[2], wo[0], wo[1], wo[2]), rgb);
}

void InterpTables::eval_at(const Position<double>& pos, double rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0;
  eval_impl(f64_, pos, rgb);
  if (any_generic_) {
    const int h0 = std::min(int(pos.h), kThetaHBins - 1);
    const int d0 = std::min(int(pos.d), kThetaDBins - 1);
    const int p0 = std::min(int(pos.p), kPhiDBins - 1);
    add_generic(h0, pos.h - h0, d0, pos.d - d0, p0, pos.p - p0, rgb);
  }
  for (int c = 0; c < kChannels; ++c) rgb[c] = saturate(rgb[c]);
}

void InterpTables::eval_at(const Position<float>& pos, float rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0f;
  eval_impl(f32_, pos, rgb);
  if (any_generic_) {
    const int h0 = std::min(int(pos.h), kThetaHBins - 1);
    const int d0 = std::min(int(pos.d), kThetaDBins - 1);
    const int p0 = std::min(int(pos.p), kPhiDBins - 1);
    double g[3] = {0, 0, 0};
    add_generic(h0, double(pos.h) - h0, d0, double(pos.d) - d0, p0, double(pos.p) - p0, g);
    for (int c = 0; c < kChannels; ++c) rgb[c] += float(g[c]);
  }
  for (int c = 0; c < kChannels; ++c) rgb[c] = saturate(rgb[c]);
}

template <class T>
void InterpTables::eval_chunk(const std::vector<SliceTables<T>>& tables, std::size_t begin,
                              std::size_t end, const BatchArgs<T>& args) const {
  BlockState<T> bs;
  std::vector<SliceView<T>> views(tables.size());
  BinRows bins;
  bool uniform = true;
  for (std::size_t s = 0; s < tables.size(); ++s) {
    const SliceTables<T>& st = tables[s];
    views[s] = {st.h.data(), st.d.data(), st.p.data(),         st.consts.data(),
                st.row(),    st.groups,   st.slots_per_channel};
    uniform = uniform && st.groups == 1 && st.slots_per_channel == 1;
  }
  for (int j = 0; j < kThetaDBins; ++j) {
    const SliceTables<T>& st = tables[std::size_t(slice_of_bin_[j])];
    bins.slice[j] = slice_of_bin_[j];
    bins.n[j] = int(st.row());
    bins.d[j] = (j - st.theta_d_begin) * int(st.row());
    bins.last[j] = last_in_slice_[j];
  }
  const BlockContext<T> cx{tables.data(), views.data(), &bins, any_generic_, uniform};
  std::vector<T> values(2 * std::size_t(3 * max_slots_per_channel_ + kGroup));
  int rest[kBlock];
  const std::size_t os = args.out_stride;
  const BlockEvalFn<T> fn = pick_block_eval<T>();
  for (std::size_t base = begin; base < end; base += kBlock) {
    const int nr = fn(cx, bs, args, base, end, values.data(), rest);
    for (int r = 0; r < nr; ++r) {
      const int l = rest[r];
      T rgb[3];
      eval_at(Position<T>{bs.ph[l], bs.pd[l], bs.pp[l]}, rgb);
      const std::size_t o = (base + std::size_t(l)) * os;
      for (int c = 0; c < kChannels; ++c) args.out[c][o] = rgb[c];
    }
  }
}

namespace {

// Chunks of pairs handed to the pool: large enough to amortize a task, small enough to balance.
constexpr std::size_t kChunk = 2048;

}  // namespace

void InterpTables::eval_batch(std::size_t n, const BatchArgs<double>& args, int threads) const {
  internal::parallel_chunks(n, kChunk, threads,
                            [&](std::size_t b, std::size_t e) { eval_chunk(f64_, b, e, args); });
}

void InterpTables::eval_batch(std::size_t n, const BatchArgs<float>& args, int threads) const {
  internal::parallel_chunks(n, kChunk, threads,
                            [&](std::size_t b, std::size_t e) { eval_chunk(f32_, b, e, args); });
}

bool set_batch_target(BatchTarget t) {
  if (!target_supported(t)) return false;
  g_batch_target.store(t, std::memory_order_relaxed);
  return true;
}

std::size_t InterpTables::footprint_bytes() const {
  std::size_t n = sizeof(*this);
  for (const auto& s : f64_) n += s.bytes();
  for (const auto& s : f32_) n += s.bytes();
  for (const auto& gs : generic_) {
    n += gs.capacity() * sizeof(GenericTerm);
    for (const GenericTerm& g : gs) {
      // The grid's prepared per-axis arrays: Archimedean grids hold two prepared grids of four
      // arrays per axis (generic terms are never FrankGrid).
      const std::size_t bins =
          g.component->pdf_h.size() + g.component->pdf_d.size() + g.component->pdf_p.size();
      n += 2 * 4 * bins * sizeof(double) + 256;
    }
  }
  return n;
}

}  // namespace cbrdf::eval
