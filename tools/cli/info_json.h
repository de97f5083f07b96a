// SPDX-License-Identifier: MIT
// `cbrdf info --json`: one description of a .cbrdf container or a MERL table, printed by the
// command and returned as a dict by Python's cbrdf.info (so the two never drift apart).
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "cbrdf/brdf_table.h"
#include "cbrdf/codec.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/noise.h"

namespace cbrdf::cli {

// The container's chunks, header, slices, residual layer and metadata, and what the evaluator
// holds in memory. The caller sets "file".
nlohmann::json container_info_json(const ContainerInfo& info, std::size_t evaluator_bytes);

// The table's dimensions, per-channel statistics and noise estimate ("noise": noise_json). The
// caller sets "file".
nlohmann::json merl_info_json(const BrdfTable& table, const MerlInfo& mi);

// The noise estimate (noise.h): "sigma" per channel, "bands" of theta_d, "grazing_growth",
// "noisy", "psnr_ceiling_tonemapped", "psnr_ceiling_linear" (dB, or the string "not measurable").
nlohmann::json noise_json(const NoiseEstimate& estimate);

// Stored bytes of the residual chunk 'RESD' (0 when absent).
std::uint32_t residual_chunk_bytes(const ContainerInfo& info);

// Invalid UTF-8 (a file name, metadata written by an older encoder) becomes U+FFFD: the JSON
// text never fails on bytes.
std::string dump_json(const nlohmann::json& j, int indent);

}  // namespace cbrdf::cli
