// Payload writers of the version-1 chunks (the inverses of decode_chunks.h). They assume a model
// that encode_model has validated.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/model.h"

namespace cbrdf {

std::vector<std::uint8_t> encode_header_chunk(const Model& model);
std::vector<std::uint8_t> encode_model_chunk(const Model& model);
std::vector<std::uint8_t> encode_marginals_chunk(const Model& model, int bits);
std::vector<std::uint8_t> encode_mask_chunk(const NotMeasured& mask);
std::vector<std::uint8_t> encode_metadata_chunk(
    const std::vector<std::pair<std::string, std::string>>& entries);

}  // namespace cbrdf
