// SPDX-License-Identifier: MIT
#include "cbrdf/encoder.h"

namespace cbrdf {

Expected<EncodeResult> encode_table(const BrdfTable& table, const EncoderSettings& settings) {
  EncodeResult r;
  auto model = fit_model(table, settings.fit, &r.report);
  if (!model.ok()) return model.status();
  auto bytes = encode_model(*model, settings.container);
  if (!bytes.ok()) return bytes.status();
  r.model = std::move(model).value();
  r.bytes = std::move(bytes).value();
  return r;
}

}  // namespace cbrdf
