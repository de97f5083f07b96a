// SPDX-License-Identifier: MIT
// MARG (spec 4.3): the quantized marginal tables. The reader (the writer is the encoder's,
// marg_writer.cc).
#include <string>

#include "byte_reader.h"
#include "chunks.h"
#include "quantize.h"

namespace cbrdf {
namespace {

const char* const kAxisNames[3] = {"theta_h", "theta_d", "phi_d"};

// The layout byte and the table count against the components MODL declared; returns the count.
Expected<std::size_t> expected_table_count(const std::vector<Slice>& slices,
                                           std::uint16_t file_minor, std::uint8_t layout,
                                           std::uint16_t table_count) {
  std::size_t components = 0;
  for (const Slice& slice : slices) {
    for (const ChannelSlice& cs : slice.channel) components += std::size_t(cs.components());
  }
  const bool mixtures = components > slices.size() * kChannels;
  if (file_minor == 0 && layout != 0) {
    return error(ErrorCode::kCorrupt, "reserved byte at payload offset 1 is not 0");
  }
  if (layout != (mixtures ? kMarginalLayoutComponents : kMarginalLayoutSingle)) {
    return error(ErrorCode::kCorrupt, "table layout byte at payload offset 1 is " +
                                          std::to_string(layout) + "; it must be " +
                                          (mixtures ? "1: MODL declares further components"
                                                    : "0: MODL declares no further components"));
  }
  const std::size_t expected_tables = components * 3;
  if (table_count != expected_tables) {
    return error(ErrorCode::kCorrupt,
                 "table count " + std::to_string(table_count) + " does not match " +
                     (mixtures ? std::to_string(components) + " components x 3 axes"
                               : std::to_string(slices.size()) + " slices x 3 channels x 3 axes"));
  }
  return expected_tables;
}

// One table's codes, stored as zigzag varint differences from the code before.
Status read_codes(ByteReader& r, const std::string& where, std::int64_t top,
                  std::vector<std::uint32_t>* codes) {
  std::int64_t prev = 0;
  for (std::uint32_t& q : *codes) {
    std::uint32_t z = 0;
    const std::uint64_t at = r.offset();
    CBRDF_RETURN_IF_ERROR(r.varint32(&z, "code residual"));
    const std::int64_t code = prev + unzigzag(z);
    if (code < 0 || code > top) {
      return error(ErrorCode::kCorrupt,
                   where + ": residual at payload offset " + std::to_string(at) + " gives code " +
                       std::to_string(code) + " outside 0.." + std::to_string(top));
    }
    q = std::uint32_t(code);
    prev = code;
  }
  return ok_status();
}

}  // namespace

Status decode_marginals_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                              std::vector<Slice>* slices, int* bits_out) {
  ByteReader r = payload_reader(payload);
  std::uint8_t bits = 0, reserved = 0;
  std::uint16_t table_count = 0;
  CBRDF_RETURN_IF_ERROR(r.u8(&bits, "bits per code"));
  CBRDF_RETURN_IF_ERROR(r.u8(&reserved, "reserved byte"));
  CBRDF_RETURN_IF_ERROR(r.u16(&table_count, "table count"));
  if (bits < kMinMarginalBits || bits > kMaxMarginalBits) {
    return error(ErrorCode::kCorrupt, "bits per code " + std::to_string(bits) + " is outside " +
                                          std::to_string(kMinMarginalBits) + ".." +
                                          std::to_string(kMaxMarginalBits));
  }
  CBRDF_ASSIGN_OR_RETURN(std::size_t expected_tables,
                         expected_table_count(*slices, file_minor, reserved, table_count));
  std::vector<QuantizedTable> tables(expected_tables);
  for (QuantizedTable& t : tables) {
    CBRDF_RETURN_IF_ERROR(r.f32(&t.lo, "table range lo"));
    CBRDF_RETURN_IF_ERROR(r.f32(&t.hi, "table range hi"));
  }
  std::size_t t_index = 0;
  const std::int64_t top = max_code(bits);
  for (std::size_t s = 0; s < slices->size(); ++s) {
    Slice& slice = (*slices)[s];
    for (int c = 0; c < kChannels; ++c) {
      ChannelSlice& channel = slice.channel[std::size_t(c)];
      for (int comp = 0; comp < channel.components(); ++comp) {
        Component& cs = channel.component(comp);
        std::vector<double>* axes[3] = {&cs.pdf_h, &cs.pdf_d, &cs.pdf_p};
        const int sizes[3] = {kThetaHBins, slice.width(), kPhiDBins};
        for (int a = 0; a < 3; ++a, ++t_index) {
          QuantizedTable& t = tables[t_index];
          const std::string where =
              "slice " + std::to_string(s) + " channel " + kChannelNames[c] +
              (comp > 0 ? " component " + std::to_string(comp) : std::string()) + " " +
              kAxisNames[a] + " table";
          t.codes.resize(std::size_t(sizes[a]));
          CBRDF_RETURN_IF_ERROR(read_codes(r, where, top, &t.codes));
          Expected<std::vector<double>> m = dequantize_masses(t, bits);
          if (!m.ok()) return m.status().with_context(where);
          *axes[a] = std::move(m.value());
        }
      }
    }
  }
  *bits_out = bits;
  return check_trailing(r.remaining(), file_minor);
}

}  // namespace cbrdf
