// SPDX-License-Identifier: MIT
// fuzz_container: parse_container and inspect_container (the `cbrdf info` path) on raw bytes.
// Checksums are left as they are: this target is about the chunk layer (signature, version,
// bounds, flags, checksums, zstd frames, order); fuzz_decode repairs checksums to reach payloads.
#pragma once

#include <algorithm>
#include <string>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "common.h"

namespace cbrdf::fuzz {

// What the spec promises about an accepted container's layout.
inline void check_layout(const ParsedContainer& pc, Bytes bytes, Result* r) {
  const ContainerLayout& l = pc.layout;
  r->check(l.major == kContainerMajorVersion, "accepted major version " + std::to_string(l.major));
  r->check(l.file_bytes == bytes.size(), "layout.file_bytes differs from the input size");
  r->check(pc.payloads.size() == l.chunks.size(), "payloads and chunks differ in number");
  if (l.chunks.empty() || pc.payloads.size() != l.chunks.size()) {
    r->check(false, "accepted a container without chunks");
    return;
  }
  r->check(l.chunks.size() <= kMaxChunks, "more chunks than kMaxChunks");
  r->check(l.chunks.front().tag == kTagHeader, "first chunk is not HEAD");
  r->check(l.chunks.back().tag == kTagEnd, "last chunk is not CEND");
  std::uint64_t expected_offset = kContainerHeaderBytes;
  for (std::size_t i = 0; i < l.chunks.size(); ++i) {
    const ChunkInfo& c = l.chunks[i];
    const std::string name = "chunk " + std::to_string(i) + " '" + c.tag + "'";
    r->check(chunk_tag_valid(c.tag), name + ": invalid tag accepted");
    r->check(c.offset == expected_offset, name + ": offset does not follow the previous chunk");
    const std::uint64_t frame =
        uses_compact_framing(l.minor) ? 0 : kChunkHeaderBytes + kChunkChecksumBytes;
    if (frame != 0) r->check(c.frame_bytes == frame, name + ": frame_bytes is not 24");
    r->check(c.frame_bytes >= (frame != 0 ? frame : kCompactFrameMinBytes),
             name + ": frame_bytes below the framing's minimum");
    expected_offset = c.offset + c.frame_bytes + c.stored_bytes;
    r->check((c.flags & ~kChunkFlagZstd) == 0, name + ": reserved flags accepted");
    r->check(c.compressed || c.payload_bytes == c.stored_bytes, name + ": P != L uncompressed");
    r->check(c.known || !c.critical, name + ": unknown critical chunk accepted");
    if (c.known) {
      r->check(pc.payloads[i].size() == c.payload_bytes, name + ": payload size is not P");
      r->check(c.payload_bytes <= max_chunk_payload_bytes(c.tag) || c.tag == kTagEnd,
               name + ": payload above its limit");
      const auto same = std::count_if(l.chunks.begin(), l.chunks.end(),
                                      [&](const ChunkInfo& o) { return o.tag == c.tag; });
      r->check(same == 1, name + ": known chunk appears " + std::to_string(same) + " times");
    } else {
      r->check(pc.payloads[i].empty(), name + ": unknown chunk was decompressed");
    }
  }
  r->check(expected_offset == bytes.size(), "bytes after the end chunk were accepted");
  for (std::string_view tag : {kTagHeader, kTagMask, kTagEnd}) {
    r->check(pc.find(tag) >= 0, "missing critical chunk " + std::string(tag) + " accepted");
  }
  // MODL and MARG, or (version 1.3) BASE in their place, never both.
  const bool base = pc.find(kTagBase) >= 0;
  r->check(!base || pc.layout.minor >= 3, "BASE accepted in a file of minor below 3");
  for (std::string_view tag : {kTagModel, kTagMarginals}) {
    r->check((pc.find(tag) >= 0) != base,
             std::string(base ? "BASE beside " : "missing critical chunk ") + std::string(tag) +
                 " accepted");
  }
}

inline void check_info(const ContainerInfo& info, const ParsedContainer& pc, Result* r) {
  r->check(info.layout.chunks.size() == pc.layout.chunks.size(), "info layout differs");
  r->check(info.bits >= 6 && info.bits <= 16, "bits " + std::to_string(info.bits));
  r->check(!info.slices.empty() && info.slices.size() <= std::size_t{kThetaDBins}, "slice count");
  int begin = 0;
  for (const SliceParams& s : info.slices) {
    r->check(s.theta_d_begin == begin && s.theta_d_end > begin, "info slices not contiguous");
    begin = s.theta_d_end;
    for (int c = 0; c < kChannels; ++c) {
      r->check(copula_parameter_valid(s.family[std::size_t(c)], s.theta[std::size_t(c)]),
               "info: parameter outside its domain");
    }
  }
  r->check(begin == kThetaDBins, "info slices do not end at 90");
  r->check(info.not_measured_bins <= std::size_t{kChannels} * kBinsPerChannel, "mask count");
  for (std::size_t i = 0; i < info.metadata.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      r->check(info.metadata[i].first != info.metadata[j].first, "duplicate metadata key");
    }
  }
}

inline Result run_container(Bytes bytes) {
  Result r;
  Expected<ParsedContainer> pc = parse_container(bytes);
  Expected<ContainerInfo> info = inspect_container(bytes);
  if (!pc.ok()) {
    // inspect_container parses the container first: it must fail the same way.
    r.check(!info.ok(), "inspect_container accepted what parse_container refused");
    if (!info.ok()) {
      r.check(info.status().message() == pc.status().message(),
              "parse_container and inspect_container disagree: '" + pc.status().message() +
                  "' vs '" + info.status().message() + "'");
    }
    r.reject(pc.status(), "parse_container");
    return r;
  }
  check_layout(*pc, bytes, &r);
  if (!info.ok()) {
    r.reject(info.status(), "inspect_container");
    return r;
  }
  check_info(*info, *pc, &r);
  r.accept();
  return r;
}

}  // namespace cbrdf::fuzz
