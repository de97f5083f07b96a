// SPDX-License-Identifier: MIT
#include "cbrdf/encoder.h"

#include "cbrdf/encoder_settings.h"
#include "cbrdf/parallel.h"
#include "residual_encode.h"

namespace cbrdf {

Expected<EncodeResult> encode_table(const BrdfTable& table, const EncoderSettings& settings) {
  CBRDF_RETURN_IF_ERROR(settings_status(validate(settings), cxx_spelling));
  if (settings.fit.threads == 0) {  // one per core
    EncoderSettings resolved = settings;
    resolved.fit.threads = thread_limit();
    return encode_table(table, resolved);
  }
  EncodeResult r;
  auto model = fit_model(table, settings.fit, &r.report);
  if (!model.ok()) return model.status();
  if (settings.auto_bits.enabled) {
    auto choice = choose_bits(table, *model, settings.container, settings.auto_bits);
    if (!choice.ok()) return choice.status();
    r.bits = choice->bits;
    r.bytes = std::move(choice->bytes);
  } else {
    auto bytes = encode_model(*model, settings.container);
    if (!bytes.ok()) return bytes.status();
    r.bits = settings.container.bits;
    r.bytes = std::move(bytes).value();
  }
  r.model = std::move(model).value();
  if (settings.residual.max_error > 0 || settings.residual.lossless) {
    CBRDF_RETURN_IF_ERROR(internal::add_residual(table, settings, &r));
  }
  return r;
}

}  // namespace cbrdf
