// SPDX-License-Identifier: MIT
#include "cbrdf/rate_control.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <utility>

#include "cbrdf/codec.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/fit.h"
#include "cbrdf/samples.h"
#include "coding_1_2.h"
#include "metrics.h"
#include "rate/secant.h"

namespace cbrdf {
namespace {

TEST(RateControl, ByteBudgetAndPsnrTargetPickTheBestSettingTried) {
  auto table = make_sample("ward");
  ASSERT_TRUE(table.ok());
  EncoderSettings base = testing::encoder_1_2();
  base.fit.threads = 2;
  // Mixtures up to 2 components are part of the search (4 and six slice counts by default; fewer
  // keep the test short).
  auto by_bytes = encode_to_target(*table, base, {3000, 0, 2, {3}});
  ASSERT_TRUE(by_bytes.ok()) << by_bytes.status().message();
  EXPECT_TRUE(by_bytes->met);
  EXPECT_LE(by_bytes->encoded.bytes.size(), 3000u);
  EXPECT_EQ(double(by_bytes->encoded.bytes.size()), by_bytes->chosen.bytes);
  for (const RateCandidate& c : by_bytes->tried) {
    if (c.bytes <= 3000) {
      EXPECT_LE(c.psnr_tonemapped, by_bytes->chosen.psnr_tonemapped);
    }
  }
  const double goal = by_bytes->chosen.psnr_tonemapped - 3.0;
  auto by_psnr = encode_to_target(*table, base, {0, goal, 2, {3}});
  ASSERT_TRUE(by_psnr.ok());
  EXPECT_TRUE(by_psnr->met);
  EXPECT_GE(by_psnr->chosen.psnr_tonemapped, goal);
  for (const RateCandidate& c : by_psnr->tried) {
    if (c.psnr_tonemapped >= goal) {
      EXPECT_GE(c.bytes, by_psnr->chosen.bytes);
    }
  }
  // 3 dB less never costs more bytes.
  EXPECT_LE(by_psnr->chosen.bytes, by_bytes->chosen.bytes);
  // The decoded file is what was measured.
  auto decoded = decode_model(by_psnr->encoded.bytes);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(decoded->slices.size(), std::size_t(by_psnr->chosen.slices));
  EXPECT_EQ(decoded->slices[0].channel[0].components(), by_psnr->chosen.components);
  // Both component counts were tried (at a budget, each row is measured at the most bits within
  // it only: the bits are searched on bytes alone).
  int k1 = 0, k2 = 0;
  for (const RateCandidate& c : by_bytes->tried) (c.components == 1 ? k1 : k2) += 1;
  EXPECT_GT(k1, 0);
  EXPECT_GT(k2, 0);
}

// The search's economy: one fit per (slice count, component count), each component count
// continuing the factorization of the one before; bits bisected; larger counts not fitted once the
// target is bracketed.
TEST(RateControl, SearchReusesFitsAndStopsWhenBracketed) {
  auto table = make_sample("ward");
  ASSERT_TRUE(table.ok());
  EncoderSettings base = testing::encoder_1_2();
  base.fit.threads = 2;
  // Unreachable PSNR: every row is fitted once and measured at 16 bits; only the closest row is
  // also walked down in bits, while its PSNR stays saturated.
  auto all = encode_to_target(*table, base, {0, 1000, 2, {3}});
  ASSERT_TRUE(all.ok());
  EXPECT_FALSE(all->met);
  EXPECT_EQ(all->fits, 2);
  ASSERT_GE(all->tried.size(), 2u);
  EXPECT_EQ(all->tried[0].bits, 16);
  EXPECT_EQ(all->tried[1].bits, 16);
  for (std::size_t i = 2; i < all->tried.size(); ++i) {
    EXPECT_EQ(all->tried[i].bits, 17 - int(i));
    EXPECT_EQ(all->tried[i].components, all->tried[all->tried.size() > 2 ? 2 : 0].components);
  }
  for (const RateCandidate& c : all->tried) {
    EXPECT_LE(c.psnr_tonemapped, all->chosen.psnr_tonemapped);
  }
  // The 2-component fit spent only the sweeps of its second component: those of one fit at 2.
  EncoderSettings two = base;
  set_counts({3, false}, {2, false}, &two.fit);
  auto fit2 = encode_table(*table, two);
  ASSERT_TRUE(fit2.ok());
  long long sweeps = 0;
  for (const auto& s : fit2->report.slices) {
    for (const ChannelSliceFit& f : s) sweeps += f.hals_sweeps;
  }
  EXPECT_EQ(all->hals_sweeps, sweeps);
  // The chosen file is the one encode_table makes at its setting, mixtures' copulas left at
  // independence as the search leaves them (RateTarget::mixture_copulas).
  EncoderSettings chosen = base;
  set_counts({3, false}, {all->chosen.components, false}, &chosen.fit);
  ASSERT_EQ(all->chosen.components, 2);
  chosen.fit.mixture_copulas = false;
  chosen.container.bits = all->chosen.bits;
  auto direct = encode_table(*table, chosen);
  ASSERT_TRUE(direct.ok());
  EXPECT_EQ(all->encoded.bytes, direct->bytes);

  // A budget below anything: 3 slices at one component and 6 bits are over it, so neither more
  // components nor 6 slices are fitted.
  auto tiny = encode_to_target(*table, base, {10, 0, 2, {3, 6}});
  ASSERT_TRUE(tiny.ok());
  EXPECT_FALSE(tiny->met);
  EXPECT_EQ(tiny->fits, 1);
  EXPECT_EQ(tiny->tried.size(), 1u);

  // A PSNR reached at 6 bits by 3 slices and one component: nothing else can have fewer bytes.
  auto low = encode_to_target(*table, base, {0, 1.0, 2, {3, 6}});
  ASSERT_TRUE(low.ok());
  EXPECT_TRUE(low->met);
  EXPECT_EQ(low->chosen.slices, 3);
  EXPECT_EQ(low->chosen.components, 1);
  EXPECT_EQ(low->chosen.bits, 6);
  EXPECT_EQ(low->fits, 1);

  // A budget inside the bit range: the bits are bisected on bytes alone and only the most bits
  // within the budget are measured (decoded and rendered), not eleven settings.
  auto mid = encode_to_target(*table, base, {3000, 0, 1, {3}});
  ASSERT_TRUE(mid.ok());
  EXPECT_TRUE(mid->met);
  ASSERT_EQ(mid->tried.size(), 1u);
  ASSERT_LT(mid->chosen.bits, 16);
  ContainerSettings one_more = base.container;
  one_more.bits = mid->chosen.bits + 1;
  auto over = encode_model(mid->encoded.model, one_more);
  ASSERT_TRUE(over.ok());
  EXPECT_GT(over->size(), 3000u);
}

// Every row of a small grid fitted, and any of its settings measured on demand: the answer the
// search's pruning (forecast bytes, components and slices that stop paying) must not miss.
class Exhaustive {
 public:
  Exhaustive(const BrdfTable& table, const EncoderSettings& base, std::vector<int> slice_counts,
             int max_components)
      : table_(table), base_(base) {
    for (int s : slice_counts) {
      FitSettings fs = base.fit;
      set_counts({s, false}, {1, false}, &fs);
      FitLadder ladder(table, fs);
      for (int k = 1; k <= max_components; ++k) models_.emplace(std::pair{s, k}, *ladder.fit(k));
    }
  }
  double bytes(int s, int k, int bits) { return at(s, k, bits, false).first; }
  double psnr(int s, int k, int bits) { return at(s, k, bits, true).second; }

  // The best PSNR within the budget: per row the most bits within it (PSNR grows with bits).
  double best_psnr_within(double budget) {
    double best = -1e300;
    for (const auto& [sk, model] : models_) {
      int bits = 16;
      while (bits >= 6 && bytes(sk.first, sk.second, bits) > budget) --bits;
      if (bits >= 6) best = std::max(best, psnr(sk.first, sk.second, bits));
    }
    return best;
  }
  // The fewest bytes reaching the PSNR: per row the fewest bits reaching it.
  double fewest_bytes_reaching(double goal) {
    double best = 1e300;
    for (const auto& [sk, model] : models_) {
      for (int bits = 6; bits <= 16; ++bits) {
        if (psnr(sk.first, sk.second, bits) >= goal) {
          best = std::min(best, bytes(sk.first, sk.second, bits));
          break;
        }
      }
    }
    return best;
  }

 private:
  std::pair<double, double> at(int s, int k, int bits, bool with_psnr) {
    auto& e = measured_[{s, k, bits}];
    ContainerSettings cs = base_.container;
    cs.bits = bits;
    if (e.first == 0) e.first = double(encode_model(models_.at({s, k}), cs)->size());
    if (with_psnr && e.second == 0) {
      auto decoded = decode_model(*encode_model(models_.at({s, k}), cs));
      e.second = sphere_psnr(table_, decoded->table()).psnr_tonemapped;
    }
    return e;
  }
  const BrdfTable& table_;
  EncoderSettings base_ = testing::encoder_1_2();
  std::map<std::pair<int, int>, Model> models_;
  std::map<std::tuple<int, int, int>, std::pair<double, double>> measured_;
};

// The pruning only skips settings that cannot win: on a small grid (two slice counts, up to two
// components) the search finds what trying every row finds, at budgets and a PSNR spread over
// the grid's range of bytes.
TEST(RateControl, PruningKeepsTheBestSettingOfTheExhaustiveSearch) {
  auto table = make_sample("ggx-rough");
  ASSERT_TRUE(table.ok());
  EncoderSettings base = testing::encoder_1_2();
  base.fit.threads = 2;
  base.fit.impute_iterations = 2;  // cheaper fits; the search and the grid share them
  const std::vector<int> slices = {2, 6};
  Exhaustive all(*table, base, slices, 2);
  for (const double budget : {all.bytes(2, 2, 8), all.bytes(6, 1, 12)}) {
    auto r = encode_to_target(*table, base, {budget, 0, 2, slices});
    ASSERT_TRUE(r.ok());
    EXPECT_TRUE(r->met);
    EXPECT_LE(r->chosen.bytes, budget);
    EXPECT_GE(r->chosen.psnr_tonemapped, all.best_psnr_within(budget)) << budget << " bytes";
  }
  for (const double goal : {all.psnr(6, 2, 9)}) {
    auto r = encode_to_target(*table, base, {0, goal, 2, slices});
    ASSERT_TRUE(r.ok());
    EXPECT_TRUE(r->met);
    EXPECT_GE(r->chosen.psnr_tonemapped, goal);
    EXPECT_LE(r->chosen.bytes, all.fewest_bytes_reaching(goal)) << goal << " dB";
  }
}

TEST(RateControl, UnreachableTargetsReportTheClosestAndBadTargetsAreRefused) {
  auto table = make_sample("lambertian");
  ASSERT_TRUE(table.ok());
  EncoderSettings base = testing::encoder_1_2();
  base.fit.threads = 2;
  auto tiny = encode_to_target(*table, base, {10, 0, 1, {3, 6}});
  ASSERT_TRUE(tiny.ok());
  EXPECT_FALSE(tiny->met);
  for (const RateCandidate& c : tiny->tried) EXPECT_GE(c.bytes, tiny->chosen.bytes);
  EXPECT_EQ(encode_to_target(*table, base, {0, 0}).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(encode_to_target(*table, base, {100, 40}).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(encode_to_target(*table, base, {100, 0, 0}).status().message(),
            "RateTarget::max_components must be from 1 to 8, not 0");
  EXPECT_EQ(encode_to_target(*table, base, {100, 0, 1, {}}).status().message(),
            "RateTarget::slice_counts must list at least one slice count");
}

// The residual's bound is searched by the secant on a curve like PSNR against log E: the crossing
// is found in a few tries, every try stays in the range and, once bracketed, inside the bracket.
TEST(RateControl, SecantFindsTheCrossingInAFewTries) {
  const auto psnr = [](double x) { return 40.0 + 30.0 / (1.0 + std::exp(x + 3.0)); };
  const double x_min = std::log(1e-5), x_max = 0.0;
  for (const double goal : {42.0, 50.0, 65.0}) {
    internal::Secant secant(x_min, x_max, -7.0);
    double x = std::log(0.03), lo = x_min, hi = x_max;
    int tries = 0;
    bool found = false;
    for (; tries < 8 && !found; ++tries) {
      ASSERT_GE(x, x_min);
      ASSERT_LE(x, x_max);
      ASSERT_GT(x, lo - 1e-12) << "outside the bracket";
      ASSERT_LT(x, hi + 1e-12) << "outside the bracket";
      const double v = psnr(x);
      const bool met = v >= goal;
      found = met && v - goal <= 0.15;
      (met ? lo : hi) = x;  // met at smaller x (PSNR falls with E)
      secant.add(x, v, met);
      const auto next = secant.next(goal + 0.05);
      if (!found) {
        ASSERT_TRUE(next.has_value()) << goal;
        x = *next;
      }
    }
    EXPECT_TRUE(found) << goal << " dB";
    EXPECT_LE(tries, 5) << goal << " dB";
  }
  // Past the end of the range: the value at x_min misses, and nothing more is tried there.
  internal::Secant secant(x_min, x_max, -7.0);
  secant.add(x_min, 60.0, false);
  EXPECT_FALSE(secant.next(100.0).has_value());
  // A bracket narrower than kClose ends the search.
  internal::Secant narrow(x_min, x_max, -7.0);
  narrow.add(-3.0, 50.5, true);
  narrow.add(-3.0 + 0.5 * internal::Secant::kClose, 49.5, false);
  EXPECT_FALSE(narrow.next(50.0).has_value());
}

// The whole ladder at a PSNR beyond what mixtures add to the one-component rows: no mixture is
// fitted, and the residual layer goes on the one-component model at the settings' slice count;
// the file reaches the target and is what was measured. A budget: the file fits it.
TEST(RateControl, LadderPutsTheResidualOnTheOneComponentModelBeyondTheModelsReach) {
  auto table = make_sample("ward");
  ASSERT_TRUE(table.ok());
  EncoderSettings base = testing::encoder_1_2();
  base.fit.threads = 2;
  base.fit.slices = 6;
  base.fit.impute_iterations = 2;  // cheaper fits
  auto model = encode_to_target(*table, base, {0, 1000, 1, {6}});
  ASSERT_TRUE(model.ok());
  const double goal = model->chosen.psnr_tonemapped + 10.0;  // past kMixtureGainDb (8)
  auto r = encode_to_target_ladder(*table, base, {0, goal, 2, {6}});
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->met);
  EXPECT_GT(r->chosen.max_error, 0);
  EXPECT_EQ(r->chosen.components, 1);
  EXPECT_EQ(r->chosen.slices, 6);
  EXPECT_EQ(r->fits, 1);  // the mixture was not fitted
  EXPECT_GE(r->chosen.psnr_tonemapped, goal);
  EXPECT_EQ(double(r->encoded.bytes.size()), r->chosen.bytes);
  auto decoded = decode_table(r->encoded.bytes);
  ASSERT_TRUE(decoded.ok());
  EXPECT_DOUBLE_EQ(sphere_psnr(*table, *decoded).psnr_tonemapped, r->chosen.psnr_tonemapped);
  // Every try that met the PSNR costs at least the bytes chosen.
  for (const RateCandidate& c : r->tried) {
    if (c.max_error > 0 && c.psnr_tonemapped >= goal) {
      EXPECT_GE(c.bytes, r->chosen.bytes);
    }
  }

  // A budget: the file fits it and is what was measured.
  const double budget = r->chosen.bytes;
  auto b = encode_to_target_ladder(*table, base, {budget, 0, 1, {6}});
  ASSERT_TRUE(b.ok()) << b.status().message();
  EXPECT_TRUE(b->met);
  EXPECT_LE(b->chosen.bytes, budget);
  EXPECT_EQ(double(b->encoded.bytes.size()), b->chosen.bytes);
  decoded = decode_table(b->encoded.bytes);
  ASSERT_TRUE(decoded.ok());
  EXPECT_DOUBLE_EQ(sphere_psnr(*table, *decoded).psnr_tonemapped, b->chosen.psnr_tonemapped);
}

}  // namespace
}  // namespace cbrdf
