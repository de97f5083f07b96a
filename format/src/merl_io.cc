// SPDX-License-Identifier: MIT
#include "cbrdf/merl_io.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "cbrdf/coords.h"
#include "cbrdf/file_io.h"

namespace cbrdf {
namespace fs = std::filesystem;

// MERL files are little-endian and values are copied as raw bytes (see merl_io.h).
static_assert(std::endian::native == std::endian::little,
              "cbrdf reads and writes MERL files with plain copies: little-endian hosts only");

namespace {

constexpr std::array<char, 3> kChannelNames = {'R', 'G', 'B'};

// Bytes already in memory, read with the same interface as FileReader.
class SpanSource {
 public:
  SpanSource(std::span<const std::uint8_t> bytes, std::string_view name)
      : bytes_(bytes), name_(name) {}
  std::uint64_t size() const { return bytes_.size(); }
  Status read_exact(void* dst, std::size_t n) {
    if (n > bytes_.size() - pos_) {
      return error(ErrorCode::kTruncated,
                   std::string(name_) + ": data ends at byte offset " +
                       std::to_string(bytes_.size()) + ", but " + std::to_string(n) +
                       " bytes were needed from offset " + std::to_string(pos_));
    }
    if (n > 0) std::memcpy(dst, bytes_.data() + pos_, n);
    pos_ += n;
    return ok_status();
  }

 private:
  std::span<const std::uint8_t> bytes_;
  std::string_view name_;
  std::size_t pos_ = 0;
};

std::string dims_text(const std::array<std::int32_t, 3>& d) {
  return "(" + std::to_string(d[0]) + ", " + std::to_string(d[1]) + ", " + std::to_string(d[2]) +
         ")";
}

std::int32_t byte_swapped(std::int32_t v) {
  const auto u = std::uint32_t(v);
  return std::int32_t((u >> 24) | ((u >> 8) & 0xff00u) | ((u << 8) & 0xff0000u) | (u << 24));
}

bool accepted_dims(const std::array<std::int32_t, 3>& d, int phi) {
  return d[0] == kThetaHBins && d[1] == kThetaDBins && d[2] == phi;
}

// Dims are checked in this order so that each message names the most likely cause.
Status check_dims(const std::array<std::int32_t, 3>& dims, std::uint64_t file_bytes,
                  const std::string& name, const MerlReadOptions& options) {
  const bool plausible = std::all_of(dims.begin(), dims.end(),
                                     [](std::int32_t d) { return d >= 1 && d <= kMerlMaxDim; });
  if (!plausible) {
    std::string msg = name + ": MERL header dims " + dims_text(dims) +
                      " are not plausible: each must be in 1.." + std::to_string(kMerlMaxDim);
    std::array<std::int32_t, 3> swapped{};
    for (int i = 0; i < 3; ++i) swapped[i] = byte_swapped(dims[i]);
    if (accepted_dims(swapped, 180) || accepted_dims(swapped, 360)) {
      msg += "; byte-swapped they read " + dims_text(swapped) +
             ", so this looks like a big-endian file (MERL files are little-endian)";
    }
    return error(ErrorCode::kCorrupt, msg);
  }
  const std::uint64_t bins =
      std::uint64_t(dims[0]) * std::uint64_t(dims[1]) * std::uint64_t(dims[2]);
  if (bins > kMerlMaxBinsPerChannel) {
    return error(ErrorCode::kLimit, name + ": MERL header dims " + dims_text(dims) + " give " +
                                        std::to_string(bins) + " bins per channel, more than the " +
                                        std::to_string(kMerlMaxBinsPerChannel) + " allowed");
  }
  const bool is180 = accepted_dims(dims, kPhiDBins);
  const bool is360 = accepted_dims(dims, 2 * kPhiDBins);
  if (!is180 && !(is360 && options.fold_phi_360)) {
    std::string msg = name + ": MERL dims " + dims_text(dims) + " are not supported: cbrdf reads ";
    msg += options.fold_phi_360 ? "(90, 90, 180), and (90, 90, 360) folded to 180 phi_d bins"
                                : "(90, 90, 180) (folding of (90, 90, 360) is switched off)";
    return error(ErrorCode::kUnsupported, msg);
  }
  const std::uint64_t expected = kMerlHeaderBytes + kChannels * bins * sizeof(double);
  if (file_bytes != expected) {
    const bool short_file = file_bytes < expected;
    return error(short_file ? ErrorCode::kTruncated : ErrorCode::kCorrupt,
                 name + ": too " + (short_file ? "short" : "long") + " for its dims " +
                     dims_text(dims) + ": expected " + std::to_string(expected) + " bytes, found " +
                     std::to_string(file_bytes));
  }
  return ok_status();
}

// Tracks +Inf values in file order, so the error can name the first one. NaN and negative values
// (-Inf included) are "not measured" and kept as they are: every table cbrdf writes, it reads.
struct NonFinite {
  std::size_t count = 0;
  std::size_t first = 0;  // index among the file's doubles

  void scan(const double* values, std::size_t n, std::size_t file_index) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!(values[i] == std::numeric_limits<double>::infinity())) continue;
      if (count++ == 0) first = file_index + i;
    }
  }

  Status status(const std::string& name, int phi_bins) const {
    if (count == 0) return ok_status();
    const std::size_t per_channel = std::size_t{kThetaHBins} * kThetaDBins * std::size_t(phi_bins);
    const std::size_t channel = first / per_channel;
    const std::size_t index = first % per_channel;
    const std::size_t phi = index % std::size_t(phi_bins);
    const std::size_t theta_d = (index / std::size_t(phi_bins)) % kThetaDBins;
    const std::size_t theta_h = index / (std::size_t(phi_bins) * kThetaDBins);
    return error(ErrorCode::kNumeric,
                 name + ": " + std::to_string(count) + " +Inf value" + (count == 1 ? "" : "s") +
                     " (a measurement must be finite); the first at channel " +
                     kChannelNames[channel] + ", bin (theta_h " + std::to_string(theta_h) +
                     ", theta_d " + std::to_string(theta_d) + ", phi_d " + std::to_string(phi) +
                     "), byte offset " + std::to_string(kMerlHeaderBytes + first * sizeof(double)));
  }
};

// Reads the 360-bin body one theta_h slab at a time (a quarter megabyte), folding into the table.
template <typename Source>
Status read_folded_360(Source& src, const std::string& name, BrdfTable& table, MerlInfo& info) {
  constexpr std::size_t kPhi360 = 2 * kPhiDBins;
  constexpr std::size_t kSlab = std::size_t{kThetaDBins} * kPhi360;
  std::vector<double> slab(kSlab);
  NonFinite bad;
  for (int c = 0; c < kChannels; ++c) {
    double* out = table.channel_data(c);
    for (int h = 0; h < kThetaHBins; ++h) {
      CBRDF_RETURN_IF_ERROR(src.read_exact(slab.data(), kSlab * sizeof(double)));
      bad.scan(slab.data(), kSlab, (std::size_t(c) * kThetaHBins + std::size_t(h)) * kSlab);
      for (int d = 0; d < kThetaDBins; ++d) {
        const double* row = slab.data() + std::size_t(d) * kPhi360;
        for (int k = 0; k < kPhiDBins; ++k) {
          const double a = row[k], b = row[k + kPhiDBins];
          const bool am = a >= 0.0, bm = b >= 0.0;
          double v = a;  // neither measured: bin k's stored value is kept
          if (am && bm) {
            v = a + (b - a) * 0.5;  // cannot overflow for non-negative a, b; exact when a == b
            ++info.fold_averaged;
            const double m = std::max(a, b);
            if (m > 0.0)
              info.fold_max_rel_diff = std::max(info.fold_max_rel_diff, std::abs(a - b) / m);
          } else if (am || bm) {
            v = am ? a : b;
            ++info.fold_one_side;
          } else {
            ++info.fold_neither;
          }
          out[merl_index(h, d, k)] = v;
        }
      }
    }
  }
  return bad.status(name, int(kPhi360));
}

template <typename Source>
Expected<BrdfTable> read_merl_from(Source& src, const std::string& name,
                                   const MerlReadOptions& options, MerlInfo* info_out) {
  MerlInfo info;
  info.file_bytes = src.size();
  if (src.size() < kMerlHeaderBytes) {
    return error(ErrorCode::kTruncated,
                 name + ": " + std::to_string(src.size()) + " bytes, shorter than the " +
                     std::to_string(kMerlHeaderBytes) + "-byte MERL header (three int32 dims)");
  }
  CBRDF_RETURN_IF_ERROR(src.read_exact(info.dims.data(), kMerlHeaderBytes));
  CBRDF_RETURN_IF_ERROR(check_dims(info.dims, src.size(), name, options));

  BrdfTable table;  // the one table-sized allocation
  if (info.dims[2] == kPhiDBins) {
    std::vector<double>& values = table.stored_values();
    CBRDF_RETURN_IF_ERROR(src.read_exact(values.data(), values.size() * sizeof(double)));
    NonFinite bad;
    bad.scan(values.data(), values.size(), 0);
    CBRDF_RETURN_IF_ERROR(bad.status(name, kPhiDBins));
  } else {
    info.folded_from_360 = true;
    CBRDF_RETURN_IF_ERROR(read_folded_360(src, name, table, info));
  }
  if (info_out) *info_out = info;
  return table;
}

}  // namespace

Expected<BrdfTable> read_merl(const fs::path& path, const MerlReadOptions& options,
                              MerlInfo* info) {
  Expected<FileReader> reader = FileReader::open(path);
  if (!reader) return reader.status();
  return read_merl_from(*reader, path.string(), options, info);
}

namespace {
// A caller's reader, with the interface read_merl_from takes.
class FunctionSource {
 public:
  FunctionSource(std::uint64_t size, const MerlReadExact& read) : size_(size), read_(read) {}
  std::uint64_t size() const { return size_; }
  Status read_exact(void* dst, std::size_t n) { return read_(dst, n); }

 private:
  std::uint64_t size_;
  const MerlReadExact& read_;
};
}  // namespace

Expected<BrdfTable> read_merl_stream(std::uint64_t size, const MerlReadExact& read_exact,
                                     std::string_view name_for_errors,
                                     const MerlReadOptions& options, MerlInfo* info) {
  FunctionSource src(size, read_exact);
  return read_merl_from(src, std::string(name_for_errors), options, info);
}

Expected<BrdfTable> parse_merl(std::span<const std::uint8_t> bytes,
                               std::string_view name_for_errors, const MerlReadOptions& options,
                               MerlInfo* info) {
  SpanSource src(bytes, name_for_errors);
  return read_merl_from(src, std::string(name_for_errors), options, info);
}

namespace {
constexpr std::array<std::int32_t, 3> kDims180 = {kThetaHBins, kThetaDBins, kPhiDBins};

static_assert(sizeof(kDims180) == kMerlHeaderBytes);

std::span<const std::uint8_t> header_bytes() {
  return {reinterpret_cast<const std::uint8_t*>(kDims180.data()), kMerlHeaderBytes};
}

std::span<const std::uint8_t> body_bytes(const BrdfTable& table) {
  const std::vector<double>& v = table.stored_values();
  return {reinterpret_cast<const std::uint8_t*>(v.data()), v.size() * sizeof(double)};
}
}  // namespace

Status write_merl(const BrdfTable& table, const ChunkSink& sink) {
  CBRDF_RETURN_IF_ERROR(sink(header_bytes()));
  return sink(body_bytes(table));
}

Status write_merl(const fs::path& path, const BrdfTable& table) {
  return write_file_atomic(path,
                           [&table](const ChunkSink& sink) { return write_merl(table, sink); });
}

std::vector<std::uint8_t> serialize_merl(const BrdfTable& table) {
  std::vector<std::uint8_t> bytes(kMerlFileBytes);
  const auto header = header_bytes();
  const auto body = body_bytes(table);
  std::memcpy(bytes.data(), header.data(), header.size());
  std::memcpy(bytes.data() + header.size(), body.data(), body.size());
  return bytes;
}

MerlStats merl_stats(const BrdfTable& table) {
  MerlStats stats;
  for (int c = 0; c < kChannels; ++c) {
    MerlChannelStats& s = stats.channel[std::size_t(c)];
    const double* v = table.channel_data(c);
    double lo = 0.0, hi = 0.0, sum = 0.0;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (!(v[i] >= 0.0)) {
        ++s.not_measured;
        continue;
      }
      const double p = v[i] * kMerlScale[std::size_t(c)];
      if (s.measured++ == 0) lo = hi = p;
      lo = std::min(lo, p);
      hi = std::max(hi, p);
      sum += p;
      if (v[i] == 0.0) ++s.zeros;
    }
    if (s.measured > 0) {
      s.min = lo;
      s.max = hi;
      s.mean = sum / double(s.measured);
    }
  }
  return stats;
}

HorizonMaskCheck check_horizon_mask(const BrdfTable& table) {
  HorizonMaskCheck check;
  std::vector<bool> below(kBinsPerChannel);
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    const BinIndex b = merl_bin(i);
    below[i] = bin_below_horizon(b.theta_h, b.theta_d, b.phi_d);
  }
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (table.measured(c, i) != below[i]) continue;
      if (check.mismatches++ == 0) {
        check.first_channel = c;
        check.first_index = i;
      }
    }
  }
  return check;
}

}  // namespace cbrdf
