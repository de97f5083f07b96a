// SPDX-License-Identifier: MIT
// Invariants of every Model that decode_model returns, whatever the file: what the spec promises
// a decoded model satisfies, so that renderers and the MERL writer can trust it.
#pragma once

#include <bit>
#include <cmath>
#include <string>

#include "cbrdf/codec.h"
#include "cbrdf/model.h"
#include "common.h"

namespace cbrdf::fuzz {

inline void check_mass_table(const std::vector<double>& t, std::size_t size,
                             const std::string& what, Result* r) {
  if (t.size() != size) {
    r->check(false, what + " has " + std::to_string(t.size()) + " masses, expected " +
                        std::to_string(size));
    return;
  }
  double sum = 0.0;
  for (double m : t) {
    if (!std::isfinite(m) || m < 0.0) {
      r->check(false, what + " holds a mass that is negative or not finite");
      return;
    }
    sum += m;
  }
  // Either all zero (a K = 0 channel) or renormalized to 1.
  r->check(sum == 0.0 || std::abs(sum - 1.0) < 1e-12,
           what + " sums to " + std::to_string(sum) + ", neither 0 nor 1");
}

inline void check_decoded_model(const Model& m, Result* r) {
  if (m.slices.empty() || m.slices.size() > std::size_t{kThetaDBins}) {
    r->check(false, "decoded model has " + std::to_string(m.slices.size()) + " slices");
    return;
  }
  int begin = 0;
  for (std::size_t s = 0; s < m.slices.size(); ++s) {
    const Slice& slice = m.slices[s];
    const std::string name = "slice " + std::to_string(s);
    if (slice.theta_d_begin != begin || slice.theta_d_end <= begin ||
        slice.theta_d_end > kThetaDBins) {
      r->check(false, name + " bounds are not contiguous");
      return;
    }
    begin = slice.theta_d_end;
    for (int c = 0; c < kChannels; ++c) {
      const ChannelSlice& channel = slice.channel[std::size_t(c)];
      r->check(channel.components() <= 8, name + ": more than 8 components");
      for (int k = 0; k < channel.components(); ++k) {
        const Component& cs = channel.component(k);
        const std::string cname =
            name + " channel " + std::to_string(c) + " component " + std::to_string(k);
        r->check(copula_parameter_valid(cs.family, cs.theta), cname + ": parameter outside domain");
        r->check(std::isfinite(cs.scale) && cs.scale >= 0.0, cname + ": K not finite or negative");
        check_mass_table(cs.pdf_h, kThetaHBins, cname + " theta_h", r);
        check_mass_table(cs.pdf_d, std::size_t(slice.width()), cname + " theta_d", r);
        check_mass_table(cs.pdf_p, kPhiDBins, cname + " phi_d", r);
      }
    }
  }
  r->check(begin == kThetaDBins, "slices do not end at theta_d bin 90");
  const NotMeasured& nm = m.not_measured;
  constexpr std::size_t kBits = std::size_t{kChannels} * kBinsPerChannel;
  if (nm.bits.size() != (kBits + 63) / 64) {
    r->check(false, "mask has the wrong number of words");
    return;
  }
  r->check((nm.bits.back() >> (kBits % 64)) == 0, "mask has bits set past its last bin");
  std::size_t count = 0;
  for (std::uint64_t w : nm.bits) count += std::size_t(std::popcount(w));
  r->check(nm.values.size() == 1 || nm.values.size() == count,
           "not-measured values: " + std::to_string(nm.values.size()) + " for " +
               std::to_string(count) + " masked bins");
  for (double v : nm.values) {
    if (v >= 0.0) {
      r->check(false, "a not-measured value is >= 0 (it would read as measured)");
      break;
    }
  }
}

}  // namespace cbrdf::fuzz
