// SPDX-License-Identifier: MIT
/// @file
/// MERL .binary files: reading (validated), writing (atomic, byte-exact), statistics.
///
/// Layout: int32 dims {theta_h, theta_d, phi_d} = {90, 90, 180}, then three blocks (R, G, B) of
/// 90*90*180 = 1,458,000 float64, index = phi_d + 180 * (theta_d + 90 * theta_h). All numbers are
/// little-endian, as the MERL database writes them; cbrdf targets little-endian hosts only (the
/// build refuses others) and reads and writes the values with plain copies.
///
/// Values are kept as stored (physical / kMerlScale). A value is a measurement when it is >= 0 and
/// finite; negative values (-Inf included) and NaN mean "not measured" (below the horizon) and are
/// preserved bit for bit, NaN payloads included; so is -0.0 (which counts as a measured 0). +Inf is
/// refused. Reading then writing a file reproduces it byte for byte, and every table cbrdf writes
/// (a decoded container may hold NaN or -Inf not-measured values) it reads back.
///
/// 90x90x360 files (phi_d over the full [0, 360) range) are folded to 180 bins by reciprocity:
/// phi_d bins k and k+180 are the same configuration with the two directions swapped, so for k in
/// [0, 180) the folded value is the mean of the measured values among bins k and k+180; when only
/// one is measured it is that value; when neither is, bin k's stored (negative) value is kept.
/// MerlInfo reports that a fold happened and how many bins fell in each case.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/file_io.h"  // ChunkSink
#include "cbrdf/status.h"

namespace cbrdf {

/// Three int32 dims (theta_h, theta_d, phi_d bins).
inline constexpr std::size_t kMerlHeaderBytes = 3 * sizeof(std::int32_t);
inline constexpr std::size_t kMerlFileBytes =
    kMerlHeaderBytes + kChannels * kBinsPerChannel * sizeof(double);  ///< 34,992,012
/// Sanity limits on the dims of a header, checked before anything is sized from them.
inline constexpr std::int32_t kMerlMaxDim = 10000;                    ///< largest dim
inline constexpr std::uint64_t kMerlMaxBinsPerChannel = 100'000'000;  ///< largest product of dims

/// How read_merl() treats files other than 90x90x180.
struct MerlReadOptions {
  /// Accept 90x90x360 files and fold them to 180 phi_d bins (see above); when false they are
  /// refused.
  bool fold_phi_360 = true;
};

/// What a read found, for `cbrdf info` and for callers that want to know a fold happened.
struct MerlInfo {
  std::array<std::int32_t, 3> dims{};  ///< as written in the file's header
  std::uint64_t file_bytes = 0;        ///< the file's size
  bool folded_from_360 = false;        ///< a 90x90x360 file folded to 180 phi_d bins
  /// Counts over (channel, folded bin), filled only when folded_from_360:
  std::size_t fold_averaged = 0;   ///< both k and k+180 measured: their mean
  std::size_t fold_one_side = 0;   ///< exactly one measured: its value
  std::size_t fold_neither = 0;    ///< neither: bin k's stored value kept
  double fold_max_rel_diff = 0.0;  ///< largest |a - b| / max(a, b) among averaged pairs
};

/// Reads a MERL .binary with one allocation (the table itself): a small header read, then the body
/// is read straight into the table (or, for a 360-bin file, folded into it slab by slab). Errors
/// name the file: kNotFound, kIo, kTruncated (shorter than the header or its dims need), kCorrupt
/// (implausible dims, longer than its dims need), kUnsupported (dims other than 90x90x180 or
/// 90x90x360), kNumeric (+Inf: the count and the first one's channel and bin).
/// Regular files only (cbrdf/file_io.h).
Expected<BrdfTable> read_merl(const std::filesystem::path& path,
                              const MerlReadOptions& options = {}, MerlInfo* info = nullptr);
/// The same from bytes in memory; name_for_errors prefixes every message.
Expected<BrdfTable> parse_merl(std::span<const std::uint8_t> bytes,
                               std::string_view name_for_errors,
                               const MerlReadOptions& options = {}, MerlInfo* info = nullptr);

/// From any reader: size is the number of bytes the source holds and read_exact(dst, n) reads the
/// next n of them (kTruncated when the source ends first). For readers of one's own (the `cbrdf`
/// command reads standard input and pipes this way).
using MerlReadExact = std::function<Status(void* dst, std::size_t n)>;
/// A .binary read through read_exact; errors as read_merl().
Expected<BrdfTable> read_merl_stream(std::uint64_t size, const MerlReadExact& read_exact,
                                     std::string_view name_for_errors,
                                     const MerlReadOptions& options = {}, MerlInfo* info = nullptr);

/// Streams a 90x90x180 .binary's bytes to sink (the header, then the table's memory, no copy).
Status write_merl(const BrdfTable& table, const ChunkSink& sink);
/// Writes a 90x90x180 .binary (write_file_atomic of cbrdf/file_io.h), straight from the table's
/// memory.
Status write_merl(const std::filesystem::path& path, const BrdfTable& table);
/// The file's bytes (kMerlFileBytes of them).
std::vector<std::uint8_t> serialize_merl(const BrdfTable& table);

/// One channel's statistics (merl_stats).
struct MerlChannelStats {
  std::size_t measured = 0;      ///< stored values >= 0
  std::size_t not_measured = 0;  ///< negative stored values
  std::size_t zeros = 0;         ///< measured bins holding 0 (or -0.0)
  /** Of the measured physical values (1/sr); all 0 when nothing is measured. */
  ///@{
  double min = 0.0, max = 0.0, mean = 0.0;
  ///@}
};
/// A table's statistics per channel, as `cbrdf info` prints them.
struct MerlStats {
  std::array<MerlChannelStats, kChannels> channel;  ///< R, G, B
};
/// Counts and value range of each channel.
MerlStats merl_stats(const BrdfTable& table);

/// How a table's not-measured mask compares with the geometric below-horizon bins (coords.h
/// bin_below_horizon): a mismatch is a (channel, bin) measured below the horizon or not measured
/// above it.
struct HorizonMaskCheck {
  std::size_t mismatches = 0;   ///< (channel, bin) pairs that differ
  int first_channel = -1;       ///< of the first mismatch in file order, when there is one
  std::size_t first_index = 0;  ///< MERL index within the channel
  bool matches() const { return mismatches == 0; }  ///< No mismatch.
};
/// Compares the table's mask with bin_below_horizon().
HorizonMaskCheck check_horizon_mask(const BrdfTable& table);

}  // namespace cbrdf
