// SPDX-License-Identifier: MIT
#include <map>
#include <utility>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "encode_watch.h"
#include "metrics.h"

namespace cbrdf {
namespace {

// ContainerSettings::bits' range.
constexpr int kFewestBits = 6, kMostBits = 16;

struct Probe {
  bool passes = false;
  std::vector<std::uint8_t> bytes;
};

// Within the allowed loss of the reference (NaN never is; -inf passes only against -inf).
bool within(double test_db, double reference_db, double max_loss_db) {
  return test_db >= reference_db - max_loss_db;
}

}  // namespace

Expected<AutoBitsChoice> choose_bits(const BrdfTable& source, const Model& model,
                                     const ContainerSettings& container,
                                     const AutoBitsSettings& settings) {
  const SphereScorer scorer(source);
  const ImageMetrics reference = scorer.score(model);
  std::map<int, Probe> probes;
  // Progress: a bisection of 6..16 writes and scores 3 or 4 files.
  const internal::ProgressPart part("bits", 0, 1);
  auto probe = [&](int bits) -> Expected<const Probe*> {
    CBRDF_RETURN_IF_ERROR(internal::check_cancel());
    part.report(double(probes.size()) / 4);
    ContainerSettings c = container;
    c.bits = bits;
    CBRDF_ASSIGN_OR_RETURN(auto file, encode_and_score(model, c, scorer));
    const ImageMetrics& m = file.metrics;
    Probe p{within(m.psnr_tonemapped, reference.psnr_tonemapped, settings.max_tonemapped_loss_db) &&
                within(m.psnr_linear, reference.psnr_linear, settings.max_linear_loss_db),
            std::move(file.bytes)};
    return &(probes[bits] = std::move(p));
  };
  // The fewest passing bits in [lo, hi]; hi is taken without a probe when nothing below passes
  // (16 bits is as close to the unquantized model as a file gets).
  int lo = kFewestBits, hi = kMostBits;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    CBRDF_ASSIGN_OR_RETURN(auto p, probe(mid));
    if (p->passes) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  if (!probes.count(hi)) CBRDF_RETURN_IF_ERROR(probe(hi).status());
  return AutoBitsChoice{hi, std::move(probes[hi].bytes)};
}

}  // namespace cbrdf
