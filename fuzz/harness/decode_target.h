// SPDX-License-Identifier: MIT
// fuzz_decode: decode_model, then evaluation of the decoded model.
//
// Every mutation of a chunk breaks its XXH64 (1.3: the file's checksum), which would stop almost
// every input at the chunk layer (fuzz_container covers that layer). So this target first rewrites
// each chunk's checksum that it can locate (repair_checksums): mutations then reach the payload
// parsers. The seeds are .cbrdf files whose chunks are stored uncompressed, so that mutations land
// on payload fields rather than inside zstd frames; compressed seeds keep the zstd paths covered.
//
// Each accepted model is checked (model_checks.h), evaluated at fixed bins and direction pairs
// (every value finite and >= 0: a renderer or the MERL writer must never see NaN or Inf), and for
// one input in kTableEvery (chosen by a hash of the input, so replays take the same path) also
// reconstructed in full with table() and re-encoded. table() evaluates 4,374,000 bins, 0.1-0.2 s
// in a release build and seconds under the sanitizers, 10-100 times the cost of a decode; doing it
// for every input would cut the fuzzer's speed by that factor, and the per-bin code it runs (the
// copula's row()) differs from bin_value() only in the loop around it, which the sampled comparison
// below pins. tests/fuzz/fuzz_regression_test.cc runs table() on every replayed file.
//
// A residual layer (RESD) is 4.4 million codes: decoding one takes 50 ms to seconds under the
// sanitizers, a file without one a few milliseconds, so a corpus with a few residual files ran at
// about 30 inputs per second. A file with RESD is decoded whole for one input in kResidualEvery
// (by the input's hash, and always with the table); for the others the chunk is cut out first
// (without_chunk: still a valid file of any version), so the other payloads, the model checks and
// the evaluation run at the speed of small files. The replay test decodes every file whole.
#pragma once

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/coords.h"
#include "cbrdf/model.h"
#include "common.h"
#include "model_checks.h"

namespace cbrdf::fuzz {

inline constexpr std::uint64_t kTableEvery = 32;
inline constexpr std::uint64_t kResidualEvery = 8;  // kTableEvery is a multiple of it
static_assert(kTableEvery % kResidualEvery == 0, "a reconstructed file is decoded whole");

struct DecodeOptions {
  bool always_table = false;  // the regression test reconstructs every accepted file (whole)
};

inline std::uint32_t read_u32le(const std::vector<std::uint8_t>& b, std::size_t at) {
  return std::uint32_t(b[at]) | (std::uint32_t(b[at + 1]) << 8) | (std::uint32_t(b[at + 2]) << 16) |
         (std::uint32_t(b[at + 3]) << 24);
}

// LEB128 of at most 5 bytes at `*at`; false when it runs past the end or is longer.
inline bool read_varint(const std::vector<std::uint8_t>& b, std::size_t* at, std::uint64_t* v) {
  *v = 0;
  for (int i = 0; i < 5 && *at < b.size(); ++i) {
    const std::uint8_t c = b[(*at)++];
    *v |= std::uint64_t(c & 0x7F) << (7 * i);
    if ((c & 0x80) == 0) return true;
  }
  return false;
}

// The compact framing (minor >= 3): walks the frames to the end chunk and rewrites the file
// checksum after it; leaves the file as it is when a frame does not fit.
inline void repair_file_checksum(std::vector<std::uint8_t>* out) {
  std::size_t at = kContainerHeaderBytes;
  while (out->size() - at >= kCompactFrameMinBytes) {
    const bool end = std::memcmp(out->data() + at, "CEND", 4) == 0;
    at += 4;
    std::uint64_t field = 0;
    std::uint64_t payload = 0;
    if (!read_varint(*out, &at, &field)) return;
    if ((field & 1) != 0 && !read_varint(*out, &at, &payload)) return;
    if ((field >> 2) > out->size() - at) return;
    at += std::size_t(field >> 2);
    if (end) {
      if (out->size() - at < kFileChecksumBytes) return;
      const std::uint32_t sum = file_checksum(std::span<const std::uint8_t>(*out).first(at));
      for (int i = 0; i < 4; ++i) (*out)[at + std::size_t(i)] = std::uint8_t(sum >> (8 * i));
      return;
    }
  }
}

// Walks the chunks from the file header on and rewrites the checksum of each chunk whose declared
// length fits in the file; stops at the first chunk that does not. In the compact framing, the
// one file checksum.
inline std::vector<std::uint8_t> repair_checksums(Bytes bytes) {
  std::vector<std::uint8_t> out(bytes.begin(), bytes.end());
  if (out.size() >= kContainerHeaderBytes &&
      uses_compact_framing(std::uint16_t(out[10] | (out[11] << 8)))) {
    repair_file_checksum(&out);
    return out;
  }
  std::size_t at = kContainerHeaderBytes;
  while (out.size() >= at && out.size() - at >= kChunkHeaderBytes) {
    const std::uint64_t stored = read_u32le(out, at + 4);
    const std::uint64_t end = at + kChunkHeaderBytes + stored;
    if (end + kChunkChecksumBytes > out.size()) break;
    const std::uint64_t sum =
        chunk_checksum(std::span<const std::uint8_t>(out).subspan(at, std::size_t(end - at)));
    for (int i = 0; i < 8; ++i)
      out[std::size_t(end) + std::size_t(i)] = std::uint8_t(sum >> (8 * i));
    at = std::size_t(end + kChunkChecksumBytes);
  }
  return out;
}

// The file without its chunk `tag` (checksums repaired as repair_checksums does), or as it is
// when the chunk is absent or a frame before it does not fit.
inline std::vector<std::uint8_t> without_chunk(std::vector<std::uint8_t> file,
                                               std::string_view tag) {
  if (file.size() < kContainerHeaderBytes) return file;
  const bool compact = uses_compact_framing(std::uint16_t(file[10] | (file[11] << 8)));
  std::size_t at = kContainerHeaderBytes;
  while (file.size() - at >= (compact ? kCompactFrameMinBytes : kChunkHeaderBytes)) {
    const std::size_t start = at;
    const bool end = std::memcmp(file.data() + at, "CEND", 4) == 0;
    std::uint64_t stored = 0;
    if (compact) {
      at += 4;
      std::uint64_t field = 0, payload = 0;
      if (!read_varint(file, &at, &field)) return file;
      if ((field & 1) != 0 && !read_varint(file, &at, &payload)) return file;
      stored = field >> 2;
      if (stored > file.size() - at) return file;
      at += std::size_t(stored);
    } else {
      stored = read_u32le(file, at + 4);
      if (stored + kChunkHeaderBytes + kChunkChecksumBytes > file.size() - at) return file;
      at += kChunkHeaderBytes + std::size_t(stored) + kChunkChecksumBytes;
    }
    if (end) return file;
    if (std::memcmp(file.data() + start, tag.data(), 4) == 0) {
      file.erase(file.begin() + std::ptrdiff_t(start), file.begin() + std::ptrdiff_t(at));
      if (compact) repair_file_checksum(&file);
      return file;
    }
  }
  return file;
}

// The bytes a harness decodes: the input with its checksums repaired, and for all but one input
// in kResidualEvery (or with `whole`) without its RESD chunk.
inline std::vector<std::uint8_t> decodable_bytes(Bytes input, bool whole) {
  std::vector<std::uint8_t> bytes = repair_checksums(input);
  if (whole || input_hash(input) % kResidualEvery == 0) return bytes;
  return without_chunk(std::move(bytes), kTagResidual);
}

inline Vec3 unit_dir(double x, double y, double z) {
  const double n = std::sqrt(x * x + y * y + z * z);
  return Vec3{x / n, y / n, z / n};
}

inline void check_value(double v, const std::string& where, Result* r) {
  r->check(std::isfinite(v) && v >= 0.0,
           where + ": model value " + std::to_string(v) + " is not finite and >= 0");
}

inline void check_evaluation(const Model& m, const ModelEvaluator& ev, Result* r) {
  for (const Slice& s : m.slices) {
    const int mid = (s.theta_d_begin + s.theta_d_end) / 2;
    const int bins[4][3] = {{0, s.theta_d_begin, 0},
                            {kThetaHBins - 1, s.theta_d_end - 1, kPhiDBins - 1},
                            {45, s.theta_d_begin, 90},
                            {7, mid, 33}};
    for (const auto& b : bins) {
      for (int c = 0; c < kChannels; ++c) {
        check_value(ev.bin_value(c, b[0], b[1], b[2]),
                    "bin_value(" + std::to_string(c) + ", " + std::to_string(b[0]) + ", " +
                        std::to_string(b[1]) + ", " + std::to_string(b[2]) + ")",
                    r);
      }
    }
  }
  const Vec3 pairs[][2] = {
      {unit_dir(0, 0, 1), unit_dir(0, 0, 1)},
      {unit_dir(0.5, 0, 0.866), unit_dir(-0.5, 0, 0.866)},
      {unit_dir(0.6, 0, 0.8), unit_dir(0, 0.6, 0.8)},
      {unit_dir(0.999, 0, 0.0447), unit_dir(-0.5, 0.5, 0.707)},
      {unit_dir(-0.3, -0.2, 0.93), unit_dir(0.1, 0.7, 0.7)},
  };
  for (const auto& p : pairs) {
    double rgb[3];
    ev.eval(p[0], p[1], rgb);
    for (double v : rgb) check_value(v, "eval at a fixed direction pair", r);
  }
}

// The full reconstruction: masked bins hold the stored values bit for bit, the others finite,
// non-negative values equal to bin_value() (sampled) in the stored scale.
inline void check_table(const Model& m, const ModelEvaluator& ev, Result* r) {
  const BrdfTable t = ev.table();
  const NotMeasured& nm = m.not_measured;
  std::size_t next_value = 0;
  for (int c = 0; c < kChannels; ++c) {
    const double* v = t.channel_data(c);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (nm.test(c, i)) {
        const double want = nm.values.size() == 1 ? nm.values[0] : nm.values[next_value++];
        if (std::memcmp(&want, &v[i], sizeof(double)) != 0) {
          r->check(false, "table(): a not-measured bin does not hold its stored value");
          return;
        }
      } else if (!(std::isfinite(v[i]) && v[i] >= 0.0)) {
        const BinIndex b = merl_bin(i);
        r->check(false, "table(): channel " + std::to_string(c) + " bin (" +
                            std::to_string(b.theta_h) + ", " + std::to_string(b.theta_d) + ", " +
                            std::to_string(b.phi_d) + ") holds " + std::to_string(v[i]));
        return;
      } else if (i % 9973 == 0) {
        const BinIndex b = merl_bin(i);
        const double want =
            ev.bin_value(c, b.theta_h, b.theta_d, b.phi_d) / kMerlScale[std::size_t(c)];
        // Values beyond the double range saturate (model.cc), in physical or stored units.
        const bool saturated = want > 1e300 || v[i] > 1e300;
        r->check(saturated || std::abs(v[i] - want) <= 1e-9 * std::abs(want) + 1e-300,
                 "table() and bin_value() disagree at a bin: " + std::to_string(v[i]) + " vs " +
                     std::to_string(want));
      }
    }
  }
}

// Whatever the decoder accepts, the encoder must be able to write again, unchanged except for
// the marginals' quantization.
inline void check_reencode(const Model& m, int bits, Result* r) {
  ContainerSettings settings;
  settings.bits = bits;
  settings.zstd_level = 1;
  settings.write_metadata = false;
  // RESD mode 4 exists only in 1.3, whose binary32 parameters the decoded model holds already.
  settings.format = m.residual.middle_steps() ? ContainerSettings::Format::kAuto
                                              : ContainerSettings::Format::kV12;
  Expected<std::vector<std::uint8_t>> again = encode_model(m, settings);
  if (!again.ok()) {
    r->check(false, "a decoded model cannot be encoded again: " + again.status().message());
    return;
  }
  Expected<Model> back = decode_model(*again);
  if (!back.ok()) {
    r->check(false, "the re-encoded file does not decode: " + back.status().message());
    return;
  }
  r->check(back->slices.size() == m.slices.size(), "re-encoding changed the slice count");
  for (std::size_t s = 0; s < m.slices.size() && s < back->slices.size(); ++s) {
    for (std::size_t c = 0; c < kChannels; ++c) {
      const ChannelSlice &ac = m.slices[s].channel[c], &bc = back->slices[s].channel[c];
      if (ac.components() != bc.components()) {
        r->check(false, "re-encoding changed a component count");
        continue;
      }
      for (int k = 0; k < ac.components(); ++k) {
        const Component &a = ac.component(k), &b = bc.component(k);
        r->check(a.family == b.family && std::memcmp(&a.theta, &b.theta, 8) == 0 &&
                     std::memcmp(&a.scale, &b.scale, 8) == 0,
                 "re-encoding changed a family, parameter or K");
      }
    }
  }
  r->check(back->not_measured.bits == m.not_measured.bits, "re-encoding changed the mask");
  const std::vector<double>&va = m.not_measured.values, &vb = back->not_measured.values;
  r->check(
      va.size() == vb.size() && std::memcmp(va.data(), vb.data(), va.size() * sizeof(double)) == 0,
      "re-encoding changed the not-measured values");
}

inline Result run_decode(Bytes input, const DecodeOptions& options = {}) {
  Result r;
  const bool table = options.always_table || input_hash(input) % kTableEvery == 0;
  const std::vector<std::uint8_t> bytes = decodable_bytes(input, table);
  Expected<Model> decoded = decode_model(bytes);
  if (!decoded.ok()) {
    r.reject(decoded.status(), "decode_model");
    return r;
  }
  r.accept();
  check_decoded_model(*decoded, &r);
  if (!r.violations.empty()) return r;  // evaluating a broken model would only add noise
  // Shared, not copied: a Model holds megabytes (mask, residual codes).
  const auto model = std::make_shared<const Model>(std::move(decoded).value());
  const Model& m = *model;
  const ModelEvaluator ev(model);
  check_evaluation(m, ev, &r);
  if (table) {
    check_table(m, ev, &r);
    Expected<ContainerInfo> info = inspect_container(bytes);
    r.check(info.ok(), "inspect_container refused what decode_model accepted");
    if (info.ok()) check_reencode(m, info->bits, &r);
  }
  return r;
}

}  // namespace cbrdf::fuzz
