// SPDX-License-Identifier: MIT
// encode_model: validates the model against what a file can hold, then writes the chunks.
#include <algorithm>
#include <cmath>
#include <string>

#include "bitstream/chunk_writers.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/version.h"
#include "utf8.h"

namespace cbrdf {
namespace {

Status invalid(std::string message) {
  return error(ErrorCode::kInvalidArgument, "cannot encode: " + std::move(message));
}

// Metadata is UTF-8 text without control characters (spec 4.5): a file name from any filesystem
// is stored with invalid bytes as U+FFFD and control characters as '?'.
std::string sanitized(const std::string& s) {
  std::string out = valid_utf8(s, kMaxMetadataValueBytes);
  for (char& ch : out) {
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7F) ch = '?';
  }
  return out;
}

// HEAD, MODL and MARG as versions 1.0-1.2 write them. MODL is small and mostly doubles: zstd
// rarely pays, and the writer keeps it only when it does.
std::vector<ChunkToWrite> old_model_chunks(const Model& model, int bits) {
  std::vector<ChunkToWrite> chunks;
  chunks.push_back({std::string(kTagHeader), encode_header_chunk(model, false), false});
  chunks.push_back({std::string(kTagModel), encode_model_chunk(model), true});
  chunks.push_back({std::string(kTagMarginals), encode_marginals_chunk(model, bits), true});
  return chunks;
}

}  // namespace

Expected<std::vector<std::uint8_t>> encode_model(const Model& model,
                                                 const ContainerSettings& settings) {
  if (settings.bits < kMinMarginalBits || settings.bits > kMaxMarginalBits) {
    return invalid("bits per code " + std::to_string(settings.bits) + " is outside " +
                   std::to_string(kMinMarginalBits) + ".." + std::to_string(kMaxMarginalBits));
  }
  if (settings.zstd_level < 1 || settings.zstd_level > 22) {
    return invalid("zstd level " + std::to_string(settings.zstd_level) + " is outside 1..22");
  }
  if (Status st = validate_model(model); !st.ok()) return invalid(st.message());

  // The model's own chunks in both codings; 1.3 where smaller (by the model chunks alone, so
  // that a residual file's base decodes as the file without the residual did), or where the
  // residual needs it.
  const std::uint16_t old_minor = container_minor(model);
  std::vector<ChunkToWrite> model_chunks;
  std::uint16_t minor = old_minor;
  if (settings.format != ContainerSettings::Format::kV12) {
    std::optional<std::vector<std::uint8_t>> base = encode_base_chunk(model, settings.bits);
    if (base) {
      std::vector<ChunkToWrite> v13;
      v13.push_back({std::string(kTagHeader), encode_header_chunk(model, true), false});
      v13.push_back({std::string(kTagBase), std::move(*base), false});
      // A residual with middle levels' steps (mode 4) exists only in 1.3.
      if (settings.format == ContainerSettings::Format::kV13 || model.residual.middle_steps()) {
        model_chunks = std::move(v13);
        minor = 3;
      } else {
        Expected<std::vector<std::uint8_t>> a = write_container(v13, settings.zstd_level, 3);
        Expected<std::vector<std::uint8_t>> b =
            write_container(old_model_chunks(model, settings.bits), settings.zstd_level, old_minor);
        if (!a.ok()) return a.status();
        if (!b.ok()) return b.status();
        if (a->size() < b->size()) {
          model_chunks = std::move(v13);
          minor = 3;
        }
      }
    }
  }
  if (model_chunks.empty()) model_chunks = old_model_chunks(model, settings.bits);
  if (model.residual.middle_steps() && minor < 3) {
    return invalid(
        "the residual's multipliers of middle levels (RESD mode 4) need container version 1.3, "
        "and this file is written as 1." +
        std::to_string(minor) + " (--format-version 1.2, or a model 1.3 cannot code)");
  }
  std::vector<ChunkToWrite> chunks = std::move(model_chunks);
  // One stored value per not-measured bin makes MASK up to 35 MB; zstd's top levels take minutes
  // on that for a few percent, so the level is capped for this chunk (a uniform value is tiny).
  chunks.push_back({std::string(kTagMask), encode_mask_chunk(model.not_measured), true, 9});
  if (model.residual.present()) {
    // The exact table's streams are zstd frames already.
    chunks.push_back({std::string(kTagResidual), encode_residual_chunk(model, minor >= 3),
                      model.residual.exact == nullptr, kResidualZstdLevel});
  }
  if (settings.write_metadata) {
    std::vector<std::pair<std::string, std::string>> meta;
    if (!settings.source_name.empty()) meta.emplace_back("source", sanitized(settings.source_name));
    meta.emplace_back("encoder", std::string("cbrdf ") + CBRDF_VERSION_STRING);
    if (settings.metadata == ContainerSettings::Metadata::kFull) {
      meta.emplace_back("bits", std::to_string(settings.bits));
      meta.emplace_back("zstd_level", std::to_string(settings.zstd_level));
    }
    chunks.push_back({std::string(kTagMetadata), encode_metadata_chunk(meta), true});
  }
  // The lowest version that holds the model: files without mixtures stay readable by 1.0 readers.
  return write_container(chunks, settings.zstd_level, minor);
}

}  // namespace cbrdf
