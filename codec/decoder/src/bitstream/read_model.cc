// SPDX-License-Identifier: MIT
// decode_model and inspect_container: the container parser, then each chunk's payload parser,
// with every error prefixed by the chunk's tag and file offset.
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "chunks.h"

namespace cbrdf {
namespace {

struct Decoded {
  Model model;
  ContainerInfo info;
};

std::string where(const ParsedContainer& pc, int index) {
  const ChunkInfo& c = pc.layout.chunks[std::size_t(index)];
  return "chunk '" + c.tag + "' at offset " + std::to_string(c.offset);
}

// The residual's summary in ContainerInfo; `predictor` is the RESD chunk's coding byte.
void describe_residual(const Residual& res, std::uint8_t predictor, ContainerInfo* info) {
  info->residual_mode = res.exact               ? kResidualModeExact
                        : res.middle_steps()    ? kResidualModeLevelSteps
                        : res.interpolated()    ? kResidualModeInterp
                        : res.row_shift.empty() ? kResidualModeLog
                                                : kResidualModeRows;
  // Mode 2: the bound over every bin is the coarsest row's; the finest row's beside it. Modes 3
  // and 4: the coarsest row's at the level with the largest multiplier.
  info->residual_max_error = res.bound();
  info->residual_min_error = std::ldexp(res.max_error, res.min_row_shift());
  info->residual_knee = res.knee;
  info->residual_coding = res.exact ? -1 : int(predictor);
  info->residual_escapes = res.escapes.size();
}

// A slice as ContainerInfo describes it: its theta_d range and each channel's copula.
SliceParams slice_params(const Slice& s) {
  SliceParams p;
  p.theta_d_begin = s.theta_d_begin;
  p.theta_d_end = s.theta_d_end;
  for (std::size_t c = 0; c < kChannels; ++c) {
    p.family[c] = s.channel[c].family;
    p.theta[c] = s.channel[c].theta;
    p.scale[c] = s.channel[c].scale;
    p.components[c] = s.channel[c].components();
  }
  return p;
}

Expected<Decoded> decode_all(std::span<const std::uint8_t> bytes) {
  CBRDF_ASSIGN_OR_RETURN(ParsedContainer pc, parse_container(bytes));
  const std::uint16_t minor = pc.layout.minor;
  Decoded d;
  d.info.layout = pc.layout;

  // parse_container guarantees each critical chunk exactly once (MODL and MARG, or BASE).
  const int head = pc.find(kTagHeader), modl = pc.find(kTagModel);
  const int marg = pc.find(kTagMarginals), mask = pc.find(kTagMask), meta = pc.find(kTagMetadata);
  const int resd = pc.find(kTagResidual), base = pc.find(kTagBase);
  auto payload = [&](int i) { return std::span<const std::uint8_t>(pc.payloads[std::size_t(i)]); };
  // A payload is freed once its reader is done: the 36 MiB MASK then does not coexist with the
  // 40 MiB RESD and its codes (spec 7, the decode peak).
  auto release = [&](int i) { std::vector<std::uint8_t>().swap(pc.payloads[std::size_t(i)]); };

  HeaderFields header;
  Status st = decode_header_chunk(payload(head), minor, base >= 0, &header);
  if (!st.ok()) return st.with_context(where(pc, head));
  d.info.colour_scale = header.colour_scale;

  if (base >= 0) {
    // Version 1.3 (parse_container has checked the version and that MODL and MARG are absent).
    st = decode_base_chunk(payload(base), header.slice_count, &d.model.slices, &d.info.bits);
    if (!st.ok()) return st.with_context(where(pc, base));
    release(base);
  } else {
    st = decode_model_chunk(payload(modl), minor, header.slice_count, &d.model.slices);
    if (!st.ok()) return st.with_context(where(pc, modl));

    st = decode_marginals_chunk(payload(marg), minor, &d.model.slices, &d.info.bits);
    if (!st.ok()) return st.with_context(where(pc, marg));
    release(marg);
  }

  MaskFields mask_fields;
  st = decode_mask_chunk(payload(mask), minor, &d.model.not_measured, &mask_fields);
  if (!st.ok()) return st.with_context(where(pc, mask));
  release(mask);

  if (resd >= 0) {
    // parse_container has refused RESD in a file older than 1.2 (before decompressing it).
    std::uint8_t predictor = 0;
    st = decode_residual_chunk(payload(resd), minor, d.model.not_measured, &d.model.residual,
                               &predictor);
    if (!st.ok()) return st.with_context(where(pc, resd));
    describe_residual(d.model.residual, predictor, &d.info);
  }

  if (meta >= 0) {
    st = decode_metadata_chunk(payload(meta), &d.info.metadata);
    if (!st.ok()) return st.with_context(where(pc, meta));
  }

  for (const Slice& s : d.model.slices) d.info.slices.push_back(slice_params(s));
  d.info.not_measured_bins = count_set_bits(d.model.not_measured.bits);
  d.info.mask_relative_to_horizon = mask_fields.reference == MaskReference::kBelowHorizon;
  d.info.per_bin_values = mask_fields.values == MaskValues::kPerBin;
  return d;
}

}  // namespace

Expected<Model> decode_model(std::span<const std::uint8_t> bytes, ContainerInfo* info) {
  CBRDF_ASSIGN_OR_RETURN(Decoded d, decode_all(bytes));
  if (info) *info = std::move(d.info);
  return std::move(d.model);
}

Expected<ContainerInfo> inspect_container(std::span<const std::uint8_t> bytes) {
  CBRDF_ASSIGN_OR_RETURN(Decoded d, decode_all(bytes));
  return std::move(d.info);
}

Expected<BrdfTable> decode_table(std::span<const std::uint8_t> bytes) {
  CBRDF_ASSIGN_OR_RETURN(auto model, decode_model(bytes));
  return model.table();
}

}  // namespace cbrdf
