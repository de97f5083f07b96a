// SPDX-License-Identifier: MIT
#include "report/zfp_baseline.h"

#include <zfp.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>

namespace cbrdf::report {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct ZfpHandles {
  zfp_field* field = nullptr;
  zfp_stream* stream = nullptr;
  bitstream* bits = nullptr;
  ~ZfpHandles() {
    if (field) zfp_field_free(field);
    if (stream) zfp_stream_close(stream);
    if (bits) stream_close(bits);
  }
};

// Compresses (or, when `decompress`, decompresses into) one channel's array through `buffer`.
// Returns the compressed size in bytes, 0 on failure.
std::size_t zfp_channel(double* values, double tolerance, std::vector<std::uint8_t>* buffer,
                        bool decompress) {
  ZfpHandles h;
  h.field = zfp_field_3d(values, zfp_type_double, kPhiDBins, kThetaDBins, kThetaHBins);
  h.stream = zfp_stream_open(nullptr);
  if (!h.field || !h.stream) return 0;
  zfp_stream_set_accuracy(h.stream, tolerance);
  if (!decompress) buffer->resize(zfp_stream_maximum_size(h.stream, h.field));
  h.bits = stream_open(buffer->data(), buffer->size());
  if (!h.bits) return 0;
  zfp_stream_set_bit_stream(h.stream, h.bits);
  zfp_stream_rewind(h.stream);
  return decompress ? zfp_decompress(h.stream, h.field) : zfp_compress(h.stream, h.field);
}

}  // namespace

Expected<ZfpResult> zfp_log_round_trip(const BrdfTable& table, double tolerance) {
  if (!(tolerance > 0)) {
    return error(ErrorCode::kInvalidArgument, "ZFP tolerance must be positive");
  }
  ZfpResult r;
  auto t0 = Clock::now();
  std::vector<std::uint8_t> mask(kChannels * kBinsPerChannel / 8, 0);
  double not_measured_value = -1.0;
  std::vector<std::vector<std::uint8_t>> streams(kChannels);
  std::vector<double> values(kBinsPerChannel);
  std::size_t total = 0;
  for (int c = 0; c < kChannels; ++c) {
    double fill = 0;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (i % kPhiDBins == 0) fill = 0;
      const std::size_t b = std::size_t(c) * kBinsPerChannel + i;
      if (!table.measured(c, i)) {
        mask[b / 8] = std::uint8_t(mask[b / 8] | (1u << (b % 8)));
        not_measured_value = table.stored(c, i);
        values[i] = fill;
      } else {
        values[i] = fill = std::log1p(table.physical(c, i));
      }
    }
    const std::size_t n = zfp_channel(values.data(), tolerance, &streams[std::size_t(c)], false);
    if (n == 0) return error(ErrorCode::kInternal, "ZFP compression failed");
    streams[std::size_t(c)].resize(n);
    total += n;
  }
  CBRDF_ASSIGN_OR_RETURN(auto packed_mask, zstd_round_trip(mask, 19));
  r.compressed.encode_s = since(t0) - packed_mask.decode_s;
  // The file: three ZFP stream sizes (u32), the streams, the zstd mask, the not-measured value.
  std::vector<std::uint8_t>& file = r.compressed.bytes;
  file.reserve(total + packed_mask.bytes.size() + 3 * 4 + 8);
  auto put = [&](const void* p, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(p);
    file.insert(file.end(), b, b + n);
  };
  for (const auto& s : streams) {
    const auto n = std::uint32_t(s.size());
    put(&n, 4);
  }
  for (const auto& s : streams) put(s.data(), s.size());
  put(packed_mask.bytes.data(), packed_mask.bytes.size());
  put(&not_measured_value, 8);
  t0 = Clock::now();
  for (int c = 0; c < kChannels; ++c) {
    if (zfp_channel(values.data(), tolerance, &streams[std::size_t(c)], true) == 0)
      return error(ErrorCode::kInternal, "ZFP decompression failed");
    double* out = r.decoded.channel_data(c);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const std::size_t b = std::size_t(c) * kBinsPerChannel + i;
      if ((mask[b / 8] >> (b % 8)) & 1) {
        out[i] = not_measured_value;
      } else {
        out[i] = (values[i] > 0 ? std::expm1(values[i]) : 0.0) / kMerlScale[std::size_t(c)];
      }
    }
  }
  r.compressed.decode_s = since(t0) + packed_mask.decode_s;
  return r;
}

}  // namespace cbrdf::report
