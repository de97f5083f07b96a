// SPDX-License-Identifier: MIT
// Continuous evaluation of a Model between MERL bins, prepared once per model
// (ModelEvaluator::eval).
//
// Per slice, channel and component, each axis (theta_h, theta_d, phi_d) holds, at every bin, the
// three terms the Frank density is a product and ratio of (frank_grid.h, with t = -alpha,
// b = 1 - e^{-t}, e = e^{-t u}, w = (1 - e) / b, y = 1 - w formed without cancellation):
//   g = f e  (the bin's mass times the density's per-axis factor), w, y,
// so that the bin value is
//   K (t / b)^2 g1 g2 g3 (1 + h) / (1 - h)^3,  h = b w1 w2 w3,
// with 1 - h and 1 + h affine in W = w1 w2 w3 and Y = y1 + w1 y2 + w1 w2 y3 (frank_grid.h).
// Between bins each axis term is linear in the continuous grid position, and the value is the
// formula above at the interpolated terms: one density per channel and component (the paper's
// Algorithm 4: the marginals and the copula at the continuous coordinates) instead of 8 corner
// bins. At a bin position every weight is 0 or 1, so the value is the bin's (bin_value up to
// rounding); the terms are continuous in position, so the value is; the separable part g1 g2 g3 is
// exactly the trilinear interpolation of the corners' products, and only the copula's ratio is
// evaluated at the interpolated terms (it varies with the CDFs, slowly across one bin). The
// independence family and Frank at alpha = 0 are the same formula with w = y = 0 and a ratio of 1.
//
// Families without this product form (Clayton, Gumbel, Joe, and Frank beyond kFrankGridMinAlpha,
// where the terms underflow) are evaluated as before: trilinear between the 8 surrounding bins'
// values from their GridCopula. A slice holds them in `generic`, and the sum of its generic terms
// at a bin (per channel) is kept once computed: a bin costs their copula densities (15 to 100 ns
// each, against the product form's few ns per slot) once, not at every pair that lands next to
// it, so that sampling and the albedo of such a model cost about what a Frank model's do. The
// store is sized on a slice's first evaluation (24 bytes per bin of the slice: at most 35 MB for
// a model of generic terms only) and filled bin by bin, so a caller who evaluates few pairs pays
// for few bins.
//
// Across a slice boundary (theta_d bins j and j + 1 in different slices) and across the phi_d
// period (bin 179 to bin 0, where the CDF returns from 1 to 0) the terms are not interpolated: the
// value is linear in position between the two bins' values, as before.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <vector>

#include "cbrdf/model.h"

namespace cbrdf::internal {
class GridCopula;
}

namespace cbrdf::internal {

// The per-axis terms of one bin of one (channel, component) slot.
template <class T>
struct AxisTerms {
  T g, w, y;
};

// Per slot: 1 - h = a0 + a1 Y + a2 W, 1 + h = b0 + b1 Y + b2 W, value = k g (1 + h) / (1 - h)^3.
template <class T>
struct SlotConstants {
  T k, a0, a1, a2, b0, b1, b2;
};

// Slots are stored in groups of kGroup, each group term-major (all its g, then all w, then all y),
// so that a group's interpolation and copula ratio are kGroup-wide vector operations for one
// pair (eval_batch); the last group is padded with zero slots.
inline constexpr int kGroup = 4;
inline constexpr int kGroupTerms = 3 * kGroup;      // g, w, y of a group's slots
inline constexpr int kGroupConstants = 7 * kGroup;  // k, a0, a1, a2, b0, b1, b2 of its slots

// Offset of slot q's g in a bin's row (w at + kGroup, y at + 2 kGroup), and of its k in the
// constants (a0 at + kGroup, ..., b2 at + 6 kGroup).
inline std::size_t term_offset(int q) {
  return std::size_t(q / kGroup) * kGroupTerms + std::size_t(q % kGroup);
}
inline std::size_t constant_offset(int q) {
  return std::size_t(q / kGroup) * kGroupConstants + std::size_t(q % kGroup);
}

// The tables of one slice in precision T. Slots are (channel c, component r) at c * R + r, R the
// most components of a channel in the slice; a channel with fewer holds zero slots (k = g = 0).
// Axis arrays are bin-major: bin b's row, G groups of kGroupTerms entries, at b * G kGroupTerms,
// so the two bins an evaluation interpolates between are two contiguous rows per axis.
template <class T>
struct SliceTables {
  int theta_d_begin = 0, theta_d_end = 0;
  int slots_per_channel = 0;  // R
  bool product = false;       // a slot holds a component (else every slot is zero: skipped)
  int groups = 0;             // G = ceil(3 R / kGroup)
  std::vector<T> h;           // kThetaHBins + 1 rows (the last repeated)
  std::vector<T> d;           // width + 1 rows (the last repeated)
  std::vector<T> p;           // kPhiDBins + 1 rows (the last repeated)
  std::vector<T> consts;      // G kGroupConstants
  std::size_t row() const { return std::size_t(groups) * kGroupTerms; }
  std::size_t bytes() const;
};

// A component without the product form, evaluated through its grid copula at the 8 corners.
struct GenericTerm {
  const Component* component = nullptr;
  int channel = 0;
  std::unique_ptr<internal::GridCopula> copula;
  GenericTerm();
  GenericTerm(GenericTerm&&) noexcept;
  GenericTerm& operator=(GenericTerm&&) noexcept;
  ~GenericTerm();
  // Its value at a bin (j inside the slice), as ModelEvaluator::bin_value forms it.
  double value(int i, int j, int k) const;
};

// Continuous position on the MERL grid of a direction pair with wi.z > 0 and wo.z > 0, clamped to
// theta_h in [0, 89], theta_d in [0, 89], phi_d in [0, 180] (a NaN maps to 0).
template <class T>
struct Position {
  T h, d, p;
};

// A batch of direction pairs and its results, each coordinate its own array read (or written) at
// index k * stride: stride 1 for structure-of-arrays, 3 for interleaved (x, y, z) triples.
template <class T>
struct BatchArgs {
  const T* in[6] = {};  // wi x, y, z, wo x, y, z
  std::size_t in_stride = 1;
  T* out[3] = {};  // r, g, b
  std::size_t out_stride = 1;
};

// The instruction sets eval_batch's kernels are compiled for (the vector kernels with GCC on
// x86-64; elsewhere, and with the portable kernels, only the baseline). kAuto, the default, is the
// best this CPU runs.
enum class BatchTarget { kAuto, kAvx512, kAvx2, kBaseline };

// Makes every later eval_batch use the kernels for `t` (tests compare each with eval), or, with
// kAuto, the best again. False, and nothing changed, where this build or CPU cannot run `t`.
bool set_batch_target(BatchTarget t);

class InterpTables {
 public:
  explicit InterpTables(const Model& model);
  ~InterpTables();

  // ModelEvaluator::eval and eval_f32: RGB at a direction pair, 0 at or below the horizon.
  void eval(const Vec3& wi, const Vec3& wo, double rgb[3]) const;
  void eval(const float wi[3], const float wo[3], float rgb[3]) const;
  // n pairs at once, bit for bit equal to eval per pair: blocks of pairs with the grid positions
  // computed across the block and each pair's slots kGroup at a time (vectorized, two pairs per
  // 8-wide vector where the CPU has them), split into chunks over at most `threads` threads of the
  // library's pool (<= 0: the thread limit).
  void eval_batch(std::size_t n, const BatchArgs<double>& args, int threads) const;
  void eval_batch(std::size_t n, const BatchArgs<float>& args, int threads) const;

  // Memory held, in bytes (tables, constants, generic terms' grids).
  std::size_t footprint_bytes() const;

 private:
  template <class T>
  void eval_impl(const std::vector<SliceTables<T>>& tables, const Position<T>& pos, T rgb[3]) const;
  // eval at a computed position (wi and wo above the horizon), saturated.
  void eval_at(const Position<double>& pos, double rgb[3]) const;
  void eval_at(const Position<float>& pos, float rgb[3]) const;
  template <class T>
  void eval_chunk(const std::vector<SliceTables<T>>& tables, std::size_t begin, std::size_t end,
                  const BatchArgs<T>& args) const;
  // batch_, from the tables.
  void prepare_batch();
  // The generic terms, trilinear between the 8 bins around the position.
  void add_generic(int i0, double fh, int j0, double fd, int k0, double fp, double rgb[3]) const;
  // The sum of slice s's generic terms per channel at bin (i, jl, k) (jl inside the slice), from
  // the slice's store (computed and kept on its first use; thread-safe).
  void generic_bin(std::size_t s, int i, int jl, int k, double out[3]) const;

  std::vector<SliceTables<double>> f64_;
  std::vector<SliceTables<float>> f32_;
  std::vector<std::vector<GenericTerm>> generic_;  // per slice
  bool any_generic_ = false;
  struct GenericStore;                             // interp_tables.cc
  std::unique_ptr<GenericStore[]> generic_store_;  // per slice (generic_bin)
  mutable std::atomic<std::size_t> generic_store_bytes_{0};
  int slice_of_bin_[kThetaDBins] = {};
  unsigned char last_in_slice_[kThetaDBins] = {};  // bin j + 1 is in another slice (or none)
  int max_slots_per_channel_ = 1;                  // R over all slices
  struct BatchViews;
  std::unique_ptr<BatchViews> batch_;  // eval_batch's per-slice views and per-bin rows
};

}  // namespace cbrdf::internal
