// SPDX-License-Identifier: MIT
// Invariants of every Model that decode_model returns, whatever the file: what the spec promises
// a decoded model satisfies, so that renderers and the MERL writer can trust it.
#pragma once

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

// The rules of a model a file can hold are validate_model's (cbrdf/model.h), the encoder's own
// check; a decoded model besides holds its tables renormalized.
inline void check_decoded_model(const Model& m, Result* r) {
  const Status st = validate_model(m);
  if (!st.ok()) {
    r->check(false, "decoded model breaks a rule of validate_model: " + st.message());
    return;
  }
  for (std::size_t s = 0; s < m.slices.size(); ++s) {
    for (int c = 0; c < kChannels; ++c) {
      const ChannelSlice& channel = m.slices[s].channel[std::size_t(c)];
      for (int k = 0; k < channel.components(); ++k) {
        const Component& cs = channel.component(k);
        const std::string cname = "slice " + std::to_string(s) + " channel " + std::to_string(c) +
                                  " component " + std::to_string(k);
        check_mass_table(cs.pdf_h, kThetaHBins, cname + " theta_h", r);
        check_mass_table(cs.pdf_d, std::size_t(m.slices[s].width()), cname + " theta_d", r);
        check_mass_table(cs.pdf_p, kPhiDBins, cname + " phi_d", r);
      }
    }
  }
}

}  // namespace cbrdf::fuzz
