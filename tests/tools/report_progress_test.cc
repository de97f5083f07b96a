// SPDX-License-Identifier: MIT
// The report's progress bar fed by the encoder's callback (issue 41, item 4): whole steps plus
// the running steps' shares, one per material, never moving backwards; a step's several encodes
// each get their part; the callback cancels once the flag is set. The bar is off (no drawing).
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "report/progress.h"

namespace cbrdf::report {
namespace {

EncodeProgress at(double fraction) {
  return EncodeProgress{fraction, "fit"};
}

TEST(ReportProgress, CountsStepsAndTheRunningSharesOfEveryMaterial) {
  Progress p(10, false, 2);
  EXPECT_DOUBLE_EQ(p.fraction(), 0.0);
  p.partial(0, 0.5);
  EXPECT_DOUBLE_EQ(p.fraction(), 0.05);
  p.partial(1, 0.25);
  EXPECT_DOUBLE_EQ(p.fraction(), 0.075);
  // Material 0's step ends: one whole step, its share back to 0, material 1's kept.
  p.step(0, "a: k1");
  EXPECT_EQ(p.done(), 1u);
  EXPECT_DOUBLE_EQ(p.fraction(), 0.125);
}

TEST(ReportProgress, NeverMovesBackwardsWithinAStep) {
  Progress p(4, false, 1);
  p.partial(0, 0.6);
  p.partial(0, 0.3);   // a later encode of the step starting again at 0
  p.partial(0, -1.0);  // unknown
  EXPECT_DOUBLE_EQ(p.fraction(), 0.15);
  // A running step counts less than a whole one until it is marked done.
  p.partial(0, 1.0);
  EXPECT_LT(p.fraction(), 0.25);
  EXPECT_GT(p.fraction(), 0.2495);
  p.step(0, "done");
  EXPECT_DOUBLE_EQ(p.fraction(), 0.25);
}

TEST(ReportProgress, CallbackMapsTheEncodeOntoItsPartOfTheStep) {
  Progress p(2, false, 1);
  const ProgressCallback first = p.callback(0, 0.0, 0.5), second = p.callback(0, 0.5, 0.9);
  EXPECT_TRUE(first(at(0.5)));
  EXPECT_DOUBLE_EQ(p.fraction(), 0.125);  // 0.25 of one step of two
  EXPECT_TRUE(first(at(1.0)));
  EXPECT_DOUBLE_EQ(p.fraction(), 0.25);
  // The second encode's fractions start again from 0: mapped after the first's, the bar goes on.
  EXPECT_TRUE(second(at(0.0)));
  EXPECT_DOUBLE_EQ(p.fraction(), 0.25);
  EXPECT_TRUE(second(at(0.5)));
  EXPECT_DOUBLE_EQ(p.fraction(), 0.35);
  EXPECT_TRUE(second(at(-1)));  // unknown: no change, still asked whether to go on
  EXPECT_DOUBLE_EQ(p.fraction(), 0.35);
}

TEST(ReportProgress, PartsOfAPartNestAndStayMonotone) {
  // The ladder: one step, residual encodes each an equal part of [0.2, 0.8].
  Progress p(1, false, 1);
  const ProgressCallback ladder = p.callback(0);
  std::vector<double> seen;
  for (int call = 0; call < 3; ++call) {
    const ProgressCallback encode = part_of(ladder, 0.2 + 0.2 * call, 0.4 + 0.2 * call);
    for (double f : {0.0, 0.3, 0.7, 1.0, 0.9}) {
      ASSERT_TRUE(encode(at(f)));
      seen.push_back(p.fraction());
    }
  }
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]) << i;
  EXPECT_NEAR(seen[1], 0.26, 1e-12);  // 0.2 + 0.3 * 0.2
  EXPECT_NEAR(seen[7], 0.54, 1e-12);  // 0.4 + 0.7 * 0.2
  EXPECT_NEAR(seen.back(), 0.8, 1e-12);
  EXPECT_FALSE(part_of(ProgressCallback{}, 0, 1));  // no callback, none made
}

TEST(ReportProgress, CallbackCancelsOnceTheFlagIsSet) {
  Progress p(1, false, 1);
  std::atomic<bool> cancel{false};
  const ProgressCallback cb = p.callback(0, 0, 1, &cancel);
  EXPECT_TRUE(cb(at(0.1)));
  cancel = true;
  EXPECT_FALSE(cb(at(0.2)));
  EXPECT_FALSE(cb(at(-1)));
}

TEST(ReportProgress, MaterialsOnSeveralThreadsAddUp) {
  constexpr int kMaterials = 4, kSteps = 50;
  Progress p(kMaterials * kSteps, false, kMaterials);
  std::vector<std::thread> threads;
  for (int m = 0; m < kMaterials; ++m) {
    threads.emplace_back([&p, m] {
      const ProgressCallback cb = p.callback(std::size_t(m));
      for (int s = 0; s < kSteps; ++s) {
        for (double f : {0.25, 0.5, 0.75}) cb(at(f));
        p.step(std::size_t(m), "step");
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(p.done(), std::size_t(kMaterials * kSteps));
  EXPECT_DOUBLE_EQ(p.fraction(), 1.0);
}

}  // namespace
}  // namespace cbrdf::report
