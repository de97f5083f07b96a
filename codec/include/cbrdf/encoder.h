// One-call encoding and decoding of whole tables: fit + quantize + container, and back.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/codec.h"
#include "cbrdf/fit.h"
#include "cbrdf/model.h"
#include "cbrdf/status.h"

namespace cbrdf {

struct EncoderSettings {
  FitSettings fit;
  EncodeSettings container;
};

struct EncodeResult {
  std::vector<std::uint8_t> bytes;  // the .cbrdf file
  Model model;                      // as fitted, before quantization
  FitReport report;
};

// Fits the model to the table and writes it as a .cbrdf container.
Expected<EncodeResult> encode_table(const BrdfTable& table, const EncoderSettings& settings);

// Decodes a .cbrdf container to a full MERL-resolution table.
Expected<BrdfTable> decode_table(std::span<const std::uint8_t> bytes);

}  // namespace cbrdf
