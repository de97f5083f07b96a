// SPDX-License-Identifier: MIT
#include "cbrdf/encoder.h"

#include "cbrdf/encoder_settings.h"
#include "cbrdf/parallel.h"
#include "encode_watch.h"
#include "residual_encode.h"

namespace cbrdf {

namespace {

// encode_table's work, on the encode's watch (encode_watch.h): fit, bits, residual.
Expected<EncodeResult> encode_watched(const BrdfTable& table, const EncoderSettings& settings) {
  const bool residual = settings.residual.max_error > 0 || settings.residual.lossless;
  // Shares of the time of a default encode (and of one with a residual layer) on real materials.
  const double fit_end = residual ? 0.45 : 0.7, bits_end = residual ? 0.6 : 1.0;
  EncodeResult r;
  auto model = [&] {
    const internal::ProgressPart part("fit", 0, fit_end);
    return fit_model(table, settings.fit, &r.report);
  }();
  if (!model.ok()) return model.status();
  if (settings.auto_bits.enabled) {
    const internal::ProgressPart part("bits", fit_end, bits_end);
    CBRDF_ASSIGN_OR_RETURN(auto choice,
                           choose_bits(table, *model, settings.container, settings.auto_bits));
    r.bits = choice.bits;
    r.bytes = std::move(choice.bytes);
  } else {
    CBRDF_ASSIGN_OR_RETURN(auto bytes, encode_model(*model, settings.container));
    r.bits = settings.container.bits;
    r.bytes = std::move(bytes);
  }
  CBRDF_RETURN_IF_ERROR(internal::check_cancel());
  r.model = std::move(model).value();
  if (settings.residual.max_error > 0 || settings.residual.lossless) {
    const internal::ProgressPart part("residual", bits_end, 1);
    CBRDF_RETURN_IF_ERROR(internal::add_residual(table, settings, &r));
  }
  return r;
}

}  // namespace

Expected<EncodeResult> encode_table(const BrdfTable& table, const EncoderSettings& settings) {
  CBRDF_RETURN_IF_ERROR(settings_status(validate(settings), cxx_spelling));
  if (settings.fit.threads == 0) {  // one per core
    EncoderSettings resolved = settings;
    resolved.fit.threads = thread_limit();
    return encode_table(table, resolved);
  }
  return internal::watched<EncodeResult>(settings.progress,
                                         [&] { return encode_watched(table, settings); });
}

}  // namespace cbrdf
