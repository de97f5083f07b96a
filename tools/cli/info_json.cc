// SPDX-License-Identifier: MIT
#include "info_json.h"

#include <cmath>

#include "cbrdf/container.h"

namespace cbrdf::cli {

std::uint32_t residual_chunk_bytes(const ContainerInfo& info) {
  for (const ChunkInfo& c : info.layout.chunks) {
    if (c.tag == kTagResidual) return c.stored_bytes;
  }
  return 0;
}

nlohmann::json container_info_json(const ContainerInfo& info, std::size_t evaluator_bytes) {
  nlohmann::json j;
  j["format"] = "cbrdf";
  j["version"] = {info.layout.major, info.layout.minor};
  j["bytes"] = info.layout.file_bytes;
  for (const ChunkInfo& c : info.layout.chunks) {
    j["chunks"].push_back({{"tag", c.tag},
                           {"offset", c.offset},
                           {"stored_bytes", c.stored_bytes},
                           {"payload_bytes", c.payload_bytes},
                           {"compressed", c.compressed},
                           {"critical", c.critical},
                           {"known", c.known}});
  }
  j["bits"] = info.bits;
  j["colour_scale"] = info.colour_scale;
  j["not_measured_bins"] = info.not_measured_bins;
  if (info.residual_mode >= 0) {
    // spec 4.6: 0 one bound, 1 exact, 2 a bound per row (max_error the coarsest row's), 3 row
    // bounds with interpolated levels, 4 the same with a step per level (max_error the coarsest
    // row's at the level with the largest multiplier).
    j["residual"] = {
        {"mode", info.residual_mode},
        {"max_error", info.residual_max_error},
        {"min_error", info.residual_mode >= 2 ? info.residual_min_error : info.residual_max_error},
        {"knee", info.residual_knee},
        {"escapes", info.residual_escapes},
        {"stored_bytes", residual_chunk_bytes(info)}};
    // spec 4.6's predictor byte: 0 varints, 1 varints after the previous phi_d bin, 2 range
    // coded, 3 range coded after a prediction across slabs and channels.
    if (info.residual_coding >= 0) j["residual"]["coding"] = info.residual_coding;
  }
  j["evaluator_bytes"] = evaluator_bytes;
  for (const SliceParams& s : info.slices) {
    nlohmann::json js;
    js["theta_d_bins"] = {s.theta_d_begin, s.theta_d_end};
    for (int c = 0; c < kChannels; ++c) {
      js["channels"].push_back({{"family", family_name(s.family[std::size_t(c)])},
                                {"theta", s.theta[std::size_t(c)]},
                                {"scale", s.scale[std::size_t(c)]},
                                {"components", s.components[std::size_t(c)]}});
    }
    j["slices"].push_back(js);
  }
  for (const auto& [k, v] : info.metadata) j["metadata"][k] = v;
  return j;
}

nlohmann::json merl_info_json(const BrdfTable& table, const MerlInfo& mi) {
  const MerlStats st = merl_stats(table);
  const HorizonMaskCheck hm = check_horizon_mask(table);
  static const char* kNames[] = {"R", "G", "B"};
  nlohmann::json j;
  j["format"] = "merl";
  j["dims"] = mi.dims;
  j["folded_from_360"] = mi.folded_from_360;
  j["mask_matches_horizon"] = hm.matches();
  for (int c = 0; c < kChannels; ++c) {
    const MerlChannelStats& s = st.channel[c];
    j["channels"][kNames[c]] = {{"measured", s.measured}, {"not_measured", s.not_measured},
                                {"zeros", s.zeros},       {"min", s.min},
                                {"max", s.max},           {"mean", s.mean}};
  }
  j["noise"] = noise_json(estimate_noise(table));
  return j;
}

nlohmann::json noise_json(const NoiseEstimate& e) {
  static const char* kNames[] = {"R", "G", "B"};
  nlohmann::json j;
  for (int c = 0; c < kChannels; ++c) j["sigma"][kNames[c]] = e.sigma[std::size_t(c)];
  for (int b = 0; b < kNoiseBands; ++b) {
    const auto& s = e.band_sigma[std::size_t(b)];
    j["bands"].push_back({{"theta_d_begin", b * kNoiseBandDegrees},
                          {"theta_d_end", (b + 1) * kNoiseBandDegrees},
                          {"sigma", {{"R", s[0]}, {"G", s[1]}, {"B", s[2]}}}});
  }
  j["grazing_growth"] = e.grazing_growth;
  j["noisy"] = e.noisy();
  // NaN (noise too large to render, noise.h) would print as null: said instead.
  const auto ceiling = [](double db) -> nlohmann::json {
    if (std::isfinite(db)) return db;
    return "not measurable";
  };
  j["psnr_ceiling_tonemapped"] = ceiling(e.psnr_ceiling_tonemapped);
  j["psnr_ceiling_linear"] = ceiling(e.psnr_ceiling_linear);
  return j;
}

std::string dump_json(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace cbrdf::cli
