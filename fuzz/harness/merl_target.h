// SPDX-License-Identifier: MIT
// fuzz_merl: parse_merl, in two modes chosen by the input's first bytes.
//
// Raw mode (any input not starting with "TPL"): the input is the file. Fuzzer inputs are small,
// so this reaches the header and size checks.
//
// Template mode ("TPL", then the fields below): the input PATCHES a valid 35 MB (90x90x180) or
// 70 MB (90x90x360) MERL file built once per process, so that value validation (NaN, Inf,
// negative "not measured" values) and the 360-bin fold are reached at fuzzing speed:
//   u8   flags: 1 = the 360-bin template, 2 = folding switched off, 4 = patch the 12 header
//        bytes with the next 12, 8 = change the file size by the next i16 (clamped to the buffer)
//   [12 bytes of header]  [i16 size change]
//   u32  window offset into the values (modulo their size)
//   ...  window: the remaining bytes overwrite the file from that offset on
// The template is patched in place and restored after the call (no 35 MB copy per input).
// Oracle: the file is accepted exactly when its dims are supported, its size is exact and no value
// is +Inf; an accepted 180-bin file is byte-exact, an accepted 360-bin file is checked bin by bin
// against the fold rule of merl_io.h.
//
// Reading a whole file allocates and fills the 35 MB table (70 MB read for 360 bins): about 70 ms
// under ASan, which held this target to 14 inputs per second. A patch whose header and size the
// reader must accept is read in full for one input in kMerlFullReadEvery (chosen by a hash of the
// input, so replays take the same path; the replay test reads every one); for the others the
// same header is read with the size one byte short and one value long, which the reader must
// refuse (kTruncated, kCorrupt) before it allocates anything. Every other patch (dims, sizes) is
// refused by the header check and costs nothing, so it is always run.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "cbrdf/coords.h"
#include "cbrdf/merl_io.h"
#include "common.h"

namespace cbrdf::fuzz {

inline constexpr char kMerlName[] = "fuzz.binary";
inline constexpr std::size_t kTemplateSlack = 64;  // bytes a template may grow by

inline double read_f64(const std::uint8_t* p) {
  double v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// A plausible MERL file: the standard below-horizon mask (stored -1), smooth positive values,
// and for 360 bins a mirrored half that differs slightly, with some bins measured on one side only.
inline std::vector<std::uint8_t> make_merl_template(int phi_bins) {
  static const std::vector<bool> below = [] {
    std::vector<bool> v(kBinsPerChannel);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const BinIndex b = merl_bin(i);
      v[i] = bin_below_horizon(b.theta_h, b.theta_d, b.phi_d);
    }
    return v;
  }();
  const std::size_t per_channel = std::size_t{kThetaHBins} * kThetaDBins * std::size_t(phi_bins);
  std::vector<std::uint8_t> out(kMerlHeaderBytes + kChannels * per_channel * 8 + kTemplateSlack);
  const std::int32_t dims[3] = {kThetaHBins, kThetaDBins, phi_bins};
  std::memcpy(out.data(), dims, sizeof dims);
  std::uint8_t* p = out.data() + kMerlHeaderBytes;
  for (int c = 0; c < kChannels; ++c) {
    for (int h = 0; h < kThetaHBins; ++h) {
      for (int d = 0; d < kThetaDBins; ++d) {
        for (int k = 0; k < phi_bins; ++k, p += 8) {
          const int k180 = k % kPhiDBins;
          double v = 1.0 + ((h * 7 + d * 3 + k180 * 5 + c) % 97) * 0.01;
          if (k >= kPhiDBins) v *= 1.01;
          if (below[merl_index(h, d, k180)]) v = -1.0;
          if (phi_bins > kPhiDBins && k >= kPhiDBins && (h + d + k) % 211 == 0) v = -2.0;
          std::memcpy(p, &v, 8);
        }
      }
    }
  }
  return out;
}

inline std::vector<std::uint8_t>& merl_template(bool phi360) {
  static std::vector<std::uint8_t> t180, t360;
  std::vector<std::uint8_t>& t = phi360 ? t360 : t180;
  if (t.empty()) t = make_merl_template(phi360 ? 2 * kPhiDBins : kPhiDBins);
  return t;
}

// Checks an accepted 360-bin file against the fold rule, bin by bin.
inline void check_fold(const BrdfTable& table, const MerlInfo& info, const std::uint8_t* file,
                       Result* r) {
  std::size_t averaged = 0, one_side = 0, neither = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (int h = 0; h < kThetaHBins; ++h) {
      for (int d = 0; d < kThetaDBins; ++d) {
        const std::uint8_t* row =
            file + kMerlHeaderBytes +
            8 * ((std::size_t(c) * kThetaHBins + std::size_t(h)) * kThetaDBins + std::size_t(d)) *
                (2 * kPhiDBins);
        for (int k = 0; k < kPhiDBins; ++k) {
          const double a = read_f64(row + 8 * k), b = read_f64(row + 8 * (k + kPhiDBins));
          const double got = table.stored(c, merl_index(h, d, k));
          bool ok = true;
          if (a >= 0.0 && b >= 0.0) {
            ++averaged;
            const double lo = std::min(a, b), hi = std::max(a, b);
            ok = got >= lo && got <= hi &&
                 std::abs(got - (0.5 * a + 0.5 * b)) <= 0x1p-52 * hi + 0x1p-1073;
          } else if (a >= 0.0 || b >= 0.0) {
            ++one_side;
            const double want = a >= 0.0 ? a : b;
            ok = std::memcmp(&got, &want, 8) == 0;
          } else {
            ++neither;
            ok = std::memcmp(&got, &a, 8) == 0;
          }
          if (!ok) {
            r->check(false, "fold of channel " + std::to_string(c) + " bin (" + std::to_string(h) +
                                ", " + std::to_string(d) + ", " + std::to_string(k) +
                                "): " + std::to_string(a) + " and " + std::to_string(b) + " gave " +
                                std::to_string(got));
            return;
          }
        }
      }
    }
  }
  r->check(info.folded_from_360, "a 360-bin file was not reported as folded");
  r->check(info.fold_averaged == averaged && info.fold_one_side == one_side &&
               info.fold_neither == neither,
           "MerlInfo fold counts differ from the file");
}

inline Result run_merl_raw(Bytes bytes) {
  Result r;
  MerlInfo info;
  Expected<BrdfTable> t = parse_merl(bytes, kMerlName, {}, &info);
  if (!t.ok()) {
    r.reject(t.status(), "parse_merl");
    r.check(t.status().message().rfind(kMerlName, 0) == 0, "the message does not name the file");
    return r;
  }
  r.accept();
  r.check(bytes.size() == kMerlFileBytes || bytes.size() == 2 * kMerlFileBytes - kMerlHeaderBytes,
          "accepted a file of " + std::to_string(bytes.size()) + " bytes");
  if (!info.folded_from_360 && bytes.size() == kMerlFileBytes) {
    r.check(std::memcmp(t->stored_values().data(), bytes.data() + kMerlHeaderBytes,
                        kMerlFileBytes - kMerlHeaderBytes) == 0,
            "a 180-bin file was not read byte for byte");
  }
  return r;
}

// parse_merl on the patched file against the oracle.
inline void check_full_read(const std::vector<std::uint8_t>& buf, std::size_t size,
                            const MerlReadOptions& options, const std::int32_t dims[3],
                            bool supported, std::size_t needed, bool finite, Result* rp) {
  Result& r = *rp;
  MerlInfo info;
  const Expected<BrdfTable> t = parse_merl(Bytes(buf.data(), size), kMerlName, options, &info);
  if (!t.ok()) {
    r.reject(t.status(), "parse_merl");
    r.check(t.status().message().rfind(kMerlName, 0) == 0, "the message does not name the file");
    r.check(!(supported && size == needed && finite),
            "refused a valid file: " + t.status().message());
    if (supported && size < needed) r.check(r.code == ErrorCode::kTruncated, "short file: code");
    if (supported && size > needed) r.check(r.code == ErrorCode::kCorrupt, "long file: code");
    if (supported && size == needed && !finite)
      r.check(r.code == ErrorCode::kNumeric, "+Inf: code");
    return;
  }
  r.accept();
  r.check(supported && size == needed && finite, "accepted an invalid file");
  r.check(std::memcmp(info.dims.data(), dims, 3 * sizeof(std::int32_t)) == 0,
          "MerlInfo dims differ");
  r.check(info.file_bytes == size, "MerlInfo file_bytes differs");
  if (dims[2] == kPhiDBins) {
    r.check(!info.folded_from_360, "a 180-bin file was reported as folded");
    r.check(std::memcmp(t->stored_values().data(), buf.data() + kMerlHeaderBytes,
                        size - kMerlHeaderBytes) == 0,
            "a 180-bin file was not read byte for byte");
  } else {
    check_fold(*t, info, buf.data(), &r);
  }
}

inline constexpr std::uint64_t kMerlFullReadEvery = 64;

struct MerlOptions {
  bool always_full_read = false;  // the regression test reads every valid-size patch in full
};

// A patch with a valid header and size, not read in full: the same header must be refused one
// byte short and one value long (the size checks a truncated or padded download meets).
inline void check_size_refusals(const std::vector<std::uint8_t>& buf, std::size_t size,
                                const MerlReadOptions& options, Result* r) {
  const Expected<BrdfTable> shorter = parse_merl(Bytes(buf.data(), size - 1), kMerlName, options);
  if (shorter.ok()) {
    r->check(false, "accepted a file one byte short");
  } else {
    r->reject(shorter.status(), "parse_merl");
    r->check(r->code == ErrorCode::kTruncated, "one byte short: code");
  }
  const Expected<BrdfTable> longer = parse_merl(Bytes(buf.data(), size + 8), kMerlName, options);
  r->check(!longer.ok() && longer.status().code() == ErrorCode::kCorrupt &&
               longer.status().message().rfind(kMerlName, 0) == 0,
           "one value long: not refused as kCorrupt naming the file");
}

inline Result run_merl_template(ByteSource in, std::uint64_t hash, const MerlOptions& opts) {
  const std::uint8_t flags = in.u8();
  const bool phi360 = flags & 1;
  MerlReadOptions options;
  options.fold_phi_360 = !(flags & 2);
  std::vector<std::uint8_t>& buf = merl_template(phi360);
  const std::size_t base_size = buf.size() - kTemplateSlack;

  std::uint8_t header[kMerlHeaderBytes];
  std::memcpy(header, buf.data(), kMerlHeaderBytes);
  if (flags & 4) {
    for (std::uint8_t& b : header) b = in.u8();
  }
  std::size_t size = base_size;
  if (flags & 8) {
    const auto delta = std::int64_t(std::int16_t(in.u16()));
    size = std::size_t(
        std::clamp<std::int64_t>(std::int64_t(base_size) + delta, 0, std::int64_t(buf.size())));
  }
  const std::size_t body = base_size - kMerlHeaderBytes;
  const std::size_t window_at = kMerlHeaderBytes + in.u32() % body;
  const Bytes window = in.rest();
  const std::size_t window_len = std::min(window.size(), buf.size() - window_at);

  // Patch in place, remembering what to restore.
  const std::vector<std::uint8_t> saved_header(buf.begin(), buf.begin() + kMerlHeaderBytes);
  const std::vector<std::uint8_t> saved_window(
      buf.begin() + std::ptrdiff_t(window_at),
      buf.begin() + std::ptrdiff_t(window_at + window_len));
  if (window_len > 0) std::memcpy(buf.data() + window_at, window.data(), window_len);
  std::memcpy(buf.data(), header, kMerlHeaderBytes);

  // The oracle.
  std::int32_t dims[3];
  std::memcpy(dims, header, sizeof dims);
  const bool supported =
      dims[0] == kThetaHBins && dims[1] == kThetaDBins &&
      (dims[2] == kPhiDBins || (dims[2] == 2 * kPhiDBins && options.fold_phi_360));
  const std::size_t needed = supported ? kMerlHeaderBytes + kChannels * kBinsPerChannel * 8 *
                                                                std::size_t(dims[2] / kPhiDBins)
                                       : 0;
  bool finite = true;
  if (supported && size == needed) {
    // Only the window can hold a non-finite value (the template's values are finite): the values
    // it overlaps, from the one holding its first byte.
    const std::size_t end = std::min(window_at + window_len, size);
    for (std::size_t at = window_at - (window_at - kMerlHeaderBytes) % 8; at < end && finite;
         at += 8) {
      // NaN and -Inf are not-measured values; only +Inf is refused.
      if (at + 8 <= size)
        finite = read_f64(buf.data() + at) != std::numeric_limits<double>::infinity();
    }
  }

  Result r;
  const bool full_read =
      !(supported && size == needed) || opts.always_full_read || hash % kMerlFullReadEvery == 0;
  if (full_read) {
    check_full_read(buf, size, options, dims, supported, needed, finite, &r);
  } else {
    check_size_refusals(buf, size, options, &r);
  }

  if (window_len > 0) std::memcpy(buf.data() + window_at, saved_window.data(), window_len);
  std::memcpy(buf.data(), saved_header.data(), kMerlHeaderBytes);
  return r;
}

inline Result run_merl(Bytes bytes, const MerlOptions& options = {}) {
  if (bytes.size() >= 3 && bytes[0] == 'T' && bytes[1] == 'P' && bytes[2] == 'L') {
    return run_merl_template(ByteSource(bytes.subspan(3)), input_hash(bytes), options);
  }
  return run_merl_raw(bytes);
}

}  // namespace cbrdf::fuzz
