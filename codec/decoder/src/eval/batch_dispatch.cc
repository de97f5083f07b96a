// SPDX-License-Identifier: MIT
// InterpTables::eval_batch: chunks of pairs over the library's threads, blocks of pairs through
// the kernels this build and CPU have (vector_kernels.h for AVX-512, AVX2 or the baseline;
// portable_kernels.h elsewhere), and the pairs the kernels hand back through eval's own code.
// This file's functions set no errno (its square roots never see a negative argument) and may
// evaluate both sides of a select (neither changes a value: no reassociation), so that the batch's
// position loop vectorizes; they contract no multiply-add (the AVX-512 kernels have FMA
// instructions, and eval and eval_batch must round alike). The build's other flags are kept;
// other compilers get the same from CMakeLists.txt (-fno-math-errno -ffp-contract=off).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-math-errno", "no-trapping-math", "fp-contract=off")
#endif
#include <atomic>
#include <cstddef>
#include <type_traits>
#include <vector>

#include "eval/batch_block.h"
#include "eval/eval_internal.h"
#include "eval/interp_tables.h"
#include "parallel_for.h"
#if CBRDF_VECTOR_KERNELS
#include "eval/vector_kernels.h"
#else
#include "eval/portable_kernels.h"
#endif

namespace cbrdf::internal {

namespace {

// The block's entry points, compiled for AVX-512, AVX2 and the baseline where the toolchain
// supports it (the vector kernels with GCC on x86-64; not under the sanitizers), and chosen once
// by a CPU check. Lanes are paired (8-wide vectors) where the target has such vectors natively:
// floats with AVX2, doubles with AVX-512; elsewhere the halves would be split and go through
// memory. The portable kernels have the baseline only.
#if CBRDF_VECTOR_KERNELS && defined(__GNUC__) && !defined(__clang__) && \
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

}  // namespace cbrdf::internal
