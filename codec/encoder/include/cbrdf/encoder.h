// One-call encoding of whole tables: fit + quantize + container (decode_table, the way back, is
// the decoder's: codec.h).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/codec.h"
#include "cbrdf/export.h"
#include "cbrdf/fit.h"
#include "cbrdf/model.h"
#include "cbrdf/status.h"

namespace cbrdf {

struct EncoderSettings {
  FitSettings fit;
  ContainerSettings container;
};

struct EncodeResult {
  std::vector<std::uint8_t> bytes;  // the .cbrdf file
  Model model;                      // as fitted, before quantization
  FitReport report;
};

// Fits the model to the table and writes it as a .cbrdf container.
CBRDF_EXPORT Expected<EncodeResult> encode_table(const BrdfTable& table,
                                                 const EncoderSettings& settings);

}  // namespace cbrdf
