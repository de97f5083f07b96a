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
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <type_traits>

#include "cbrdf/parallel_for.h"
#include "density/frank_grid.h"
#include "density/grid_copula.h"

namespace cbrdf::eval {

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
// one object, then one branch-free loop that the compiler vectorizes across pairs: the grid
// positions (the coordinates, three atan2 polynomials and four square roots per pair), bin
// indices, fractions and each pair's kind but one (below the horizon, the rest, inside one
// slice); (2) per pair, the two bins' rows of each axis interpolated and the copula ratios formed,
// kGroup slots at a time (the slice tables' grouped layout), vectorized across slots, two pairs at
// a time (one per half of an 8-wide vector) where the CPU has such vectors natively. For the
// paper's model (one slot per channel in every slice) at unit output stride, every pair of the
// block is evaluated as if inside its slice, eight at a time: their fractions permuted from
// vectors of eight pairs', their sums and saturation formed across the vectors, and the results
// transposed in registers and stored as whole vectors per channel; then the few pairs of other
// kinds (found from bit masks) are written over: below the horizon 0, across a slice boundary
// (known from the bins' entries the evaluations read) two slice evaluations, as in eval. Other
// models and strides list the pairs by kind, without branches, and write each pair's values.
// Every value is formed by the same operations in the same order as eval's, so the results are
// equal bit for bit: vector lanes round as scalar instructions do, and no path contracts
// multiply-adds (fp-contract=off above: AVX-512 has FMA instructions). Pairs across the phi_d
// period (1 in 180) and models with generic terms go back to the caller, which evaluates them
// with eval's own code.
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

// Stage (1): positions, bin indices and fractions, as position() and eval_impl form them, and
// each lane's kind but for kAcross (mark_across), in one loop (with -fno-math-errno its square
// roots vectorize). Bitwise &, not &&: no branches.
template <class T>
[[gnu::always_inline]] inline void block_positions(BlockState<T>& b, bool any_generic) {
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
template <class T>
struct BlockContext {
  const SliceTables<T>* tables;  // per slice
  const SliceView<T>* views;     // per slice
  const BinRows* bins;           // per theta_d bin
  bool any_generic;
  bool uniform;  // every slice has one group of one slot per channel (the paper's model)
};

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
  prepare_batch();
}

// eval_batch's views of the slices and rows of the bins.
void InterpTables::prepare_batch() {
  const std::size_t ns = f64_.size();
  batch_ = std::make_unique<BatchViews>();
  BatchViews& bv = *batch_;
  auto view = [](const auto& st) {
    using T = typename std::decay_t<decltype(st.h)>::value_type;
    return SliceView<T>{st.h.data(), st.d.data(), st.p.data(),         st.consts.data(),
                        st.row(),    st.groups,   st.slots_per_channel};
  };
  for (std::size_t s = 0; s < ns; ++s) {
    bv.f64.push_back(view(f64_[s]));
    bv.f32.push_back(view(f32_[s]));
    bv.uniform = bv.uniform && f64_[s].groups == 1 && f64_[s].slots_per_channel == 1;
  }
  for (int j = 0; j < kThetaDBins; ++j) {
    const SliceTables<double>& st = f64_[std::size_t(slice_of_bin_[j])];
    bv.bins.slice[j] = slice_of_bin_[j];
    bv.bins.d[j] = (j - st.theta_d_begin) * int(st.row());
    bv.bins.last[j] = last_in_slice_[j];
  }
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
  const BatchViews& bv = *batch_;
  const BlockContext<T> cx{tables.data(), bv.of(T()).data(), &bv.bins, any_generic_, bv.uniform};
  // Room for two slice evaluations' slot values (job_pair_sums), on the stack where it fits.
  const std::size_t need = 2 * std::size_t(3 * max_slots_per_channel_ + kGroup);
  T small[64];
  std::vector<T> large(need > 64 ? need : 0);
  T* const values = need > 64 ? large.data() : small;
  int rest[kBlock];
  const std::size_t os = args.out_stride;
  const BlockEvalFn<T> fn = pick_block_eval<T>();
  for (std::size_t base = begin; base < end; base += kBlock) {
    const int nr = fn(cx, bs, args, base, end, values, rest);
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
  std::size_t n = sizeof(*this) + sizeof(BatchViews) +
                  batch_->f64.capacity() * sizeof(batch_->f64[0]) +
                  batch_->f32.capacity() * sizeof(batch_->f32[0]);
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
