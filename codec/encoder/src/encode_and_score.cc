// SPDX-License-Identifier: MIT
// One setting's file, decoded and scored (cbrdf/metrics.h): the probe that rate control,
// `--bits auto` and the report share.
#include "cbrdf/codec.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/metrics.h"

namespace cbrdf {

Expected<ScoredEncoding> encode_and_score(const Model& model, const ContainerSettings& container,
                                          const SphereScorer& scorer) {
  CBRDF_ASSIGN_OR_RETURN(auto bytes, encode_model(model, container));
  CBRDF_ASSIGN_OR_RETURN(const Model decoded, decode_model(bytes));
  const ImageMetrics metrics = scorer.score(decoded);
  return ScoredEncoding{std::move(bytes), metrics};
}

}  // namespace cbrdf
