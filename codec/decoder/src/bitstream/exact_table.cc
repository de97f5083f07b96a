// SPDX-License-Identifier: MIT
// Exact table coding (spec: "Exact table coding"). Why this shape: the tables are smooth functions
// sampled on a grid, so integer differences of neighbouring bit patterns (which are nearly
// log-linear in the value) leave residuals of ~20 bits instead of 64; the high bits of a residual
// (its size) are predictable from the neighbours' sizes and go to zstd split by context, while the
// low bits are noise and are stored as they are.
#include "exact_table.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <string>

#include "byte_reader.h"
#include "exact_table_coding.h"
#include "parallel_for.h"
#include "zstd_util.h"

namespace cbrdf::internal {
namespace {

using namespace exact_coding;

bool bit_set(std::span<const std::uint8_t> bitmap, std::size_t b) {
  return ((bitmap[b >> 3] >> (b & 7)) & 1) != 0;
}

std::uint64_t binomial(int n, int k) {
  std::uint64_t r = 1;
  for (int i = 1; i <= k; ++i) r = r * std::uint64_t(n - k + i) / std::uint64_t(i);
  return r;
}

// The neighbour terms of one prediction: pred = sum of coef * w[index - offset] (mod 2^64).
struct Term {
  std::size_t offset;
  std::uint64_t coef;
};
using Terms = std::vector<Term>;

// Terms of (1-z_h)^mh (1-z_d)^md (1-z_p)^mp without its centre, negated: the prediction that
// makes the residual that difference.
Terms terms_for(int mh, int md, int mp) {
  Terms t;
  for (int a = 0; a <= mh; ++a) {
    for (int b = 0; b <= md; ++b) {
      for (int c = 0; c <= mp; ++c) {
        if (a + b + c == 0) continue;
        std::uint64_t coef = binomial(mh, a) * binomial(md, b) * binomial(mp, c);
        if ((a + b + c) % 2 == 0) coef = std::uint64_t{0} - coef;  // minus the signed coefficient
        t.push_back(
            {std::size_t(a) * kPlaneStride + std::size_t(b) * kPhiDBins + std::size_t(c), coef});
      }
    }
  }
  return t;
}

// Terms per predictor, per effective order (orders are cut to the available history at edges).
const std::vector<Terms>& terms_table() {
  static const std::vector<Terms> table = [] {
    std::vector<Terms> t(kPredictors.size() * 125);
    for (std::size_t p = 0; p < kPredictors.size(); ++p) {
      for (int a = 0; a <= kPredictors[p].h; ++a)
        for (int b = 0; b <= kPredictors[p].d; ++b)
          for (int c = 0; c <= kPredictors[p].p; ++c)
            t[p * 125 + std::size_t(a * 25 + b * 5 + c)] = terms_for(a, b, c);
    }
    return t;
  }();
  return table;
}
static_assert(kMaxOrder < 5);

// ---- bits: LSB first, at most 32 per call ----------------------------------------------------

class BitReader {
 public:
  explicit BitReader(std::span<const std::uint8_t> data) : data_(data) {}
  bool get(int n, std::uint64_t* out) {
    std::uint64_t v = 0;
    int shift = 0;
    while (n > 0) {
      const int take = n > 32 ? 32 : n;
      std::uint64_t part = 0;
      if (!get32(take, &part)) return false;
      v |= part << shift;
      shift += take;
      n -= take;
    }
    *out = v;
    return true;
  }
  // Every byte used and the padding bits of the last one zero: one encoding per table.
  bool finished() const { return pos_ == data_.size() && acc_ == 0; }

 private:
  bool get32(int n, std::uint64_t* out) {
    while (bits_ < n && pos_ < data_.size()) {
      acc_ |= std::uint64_t(data_[pos_++]) << bits_;
      bits_ += 8;
    }
    if (bits_ < n) return false;
    *out = acc_ & ((std::uint64_t{1} << n) - 1);
    acc_ >>= n;
    bits_ -= n;
    return true;
  }
  std::span<const std::uint8_t> data_;
  std::size_t pos_ = 0;
  std::uint64_t acc_ = 0;
  int bits_ = 0;
};

// ---- streams: u8 form (0 stored, 1 zstd), u32 content bytes, u32 stored bytes, bytes ----------

// A stream's content; `exact` says whether its size must equal `max_bytes` or may be below it.
Expected<std::vector<std::uint8_t>> get_stream(ByteReader* r, const std::string& name,
                                               std::size_t max_bytes, bool exact) {
  std::uint8_t form = 0;
  std::uint32_t content = 0, stored = 0;
  CBRDF_RETURN_IF_ERROR(r->u8(&form, name.c_str()));
  CBRDF_RETURN_IF_ERROR(r->u32(&content, name.c_str()));
  CBRDF_RETURN_IF_ERROR(r->u32(&stored, name.c_str()));
  if (form > 1) {
    return error(ErrorCode::kCorrupt,
                 name + ": unknown stream form " + std::to_string(form) + " (0 or 1 expected)");
  }
  if (exact ? content != max_bytes : content > max_bytes) {
    return error(ErrorCode::kCorrupt, name + ": declares " + std::to_string(content) +
                                          " bytes where " + (exact ? "" : "at most ") +
                                          std::to_string(max_bytes) + " are possible");
  }
  if (form == 0 && stored != content) {
    return error(ErrorCode::kCorrupt, name + ": a stored stream of " + std::to_string(content) +
                                          " bytes declares " + std::to_string(stored));
  }
  std::span<const std::uint8_t> bytes;
  CBRDF_RETURN_IF_ERROR(r->bytes(stored, &bytes, name.c_str()));
  if (form == 0) return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
  auto out = zstd_decompress_exact(bytes, content);
  if (!out.ok()) return out.status().with_context(name);
  return out;
}

std::string channel_stream(int c, const char* what, int ctx = -1) {
  std::string s = std::string("exact table channel ") + "RGB"[c] + " " + what;
  if (ctx >= 0) s += " " + std::to_string(ctx);
  return s;
}

// ---- decoder ----------------------------------------------------------------------------------

struct ChannelStreams {
  std::array<std::vector<std::uint8_t>, kContexts> symbols;
  std::vector<std::uint8_t> bits;
};

// `coded` is the channel's bins that are not exceptions: each holds exactly one symbol, so a
// symbol stream is refused before it is decompressed when it would pass what the earlier ones
// leave (a hostile table was otherwise sized 8 x 1.46 MB of symbols per channel; spec 7, the
// decode peak). Too few symbols are found while decoding ("ends early").
Expected<ChannelStreams> read_channel_streams(ByteReader* r, int c, std::size_t coded) {
  ChannelStreams s;
  std::size_t left = coded;
  for (int ctx = 0; ctx < kContexts; ++ctx) {
    CBRDF_ASSIGN_OR_RETURN(auto sym,
                           get_stream(r, channel_stream(c, "symbol stream", ctx), left, false));
    left -= sym.size();
    s.symbols[std::size_t(ctx)] = std::move(sym);
  }
  // At most 62 low bits per coded bin.
  CBRDF_ASSIGN_OR_RETURN(
      auto bits, get_stream(r, channel_stream(c, "low-bit stream"), (coded * 62 + 7) / 8, false));
  s.bits = std::move(bits);
  return s;
}

struct SharedStreams {
  std::vector<std::uint8_t> bitmap;
  std::vector<std::uint8_t> values;
  std::vector<std::uint8_t> choices;
};

Status corrupt_at(int c, std::size_t index, const std::string& what) {
  const BinIndex b = merl_bin(index);
  return error(ErrorCode::kCorrupt, "exact table channel " + std::string(1, "RGB"[c]) +
                                        " bin (theta_h " + std::to_string(b.theta_h) +
                                        ", theta_d " + std::to_string(b.theta_d) + ", phi_d " +
                                        std::to_string(b.phi_d) + "): " + what);
}

// The residuals of one channel in coding order: symbols from the context's stream, then low bits.
class ResidualReader {
 public:
  explicit ResidualReader(const ChannelStreams& s) : s_(s), bits_(s.bits) {}

  // The residual's zigzag value and size; false with *why set when a stream is malformed.
  bool next(std::size_t ctx, std::uint64_t* z, int* len, std::string* why) {
    if (used_[ctx] == s_.symbols[ctx].size()) {
      *why = "symbol stream " + std::to_string(ctx) + " ends early";
      return false;
    }
    const int sym = s_.symbols[ctx][used_[ctx]++];
    if (sym >= kSymbols) {
      *why = "symbol " + std::to_string(sym) + " is above 127";
      return false;
    }
    *z = std::uint64_t(sym);
    *len = sym;
    if (sym < 2) return true;
    *len = sym / 2 + 1;
    std::uint64_t low = 0;
    if (!bits_.get(*len - 2, &low)) {
      *why = "the low-bit stream ends early";
      return false;
    }
    *z = (std::uint64_t{1} << (*len - 1)) | (std::uint64_t(sym & 1) << (*len - 2)) | low;
    return true;
  }

  Status check_used_up(int c) const {
    for (std::size_t ctx = 0; ctx < kContexts; ++ctx) {
      if (used_[ctx] != s_.symbols[ctx].size())
        return error(ErrorCode::kCorrupt, channel_stream(c, "symbol stream", int(ctx)) +
                                              " holds more symbols than the channel uses");
    }
    if (!bits_.finished())
      return error(ErrorCode::kCorrupt,
                   channel_stream(c, "low-bit stream") + " holds more bits than the channel uses");
    return ok_status();
  }

 private:
  const ChannelStreams& s_;
  BitReader bits_;
  std::array<std::size_t, kContexts> used_{};
};

std::uint64_t exception_value(const SharedStreams& shared, std::size_t e) {
  std::uint64_t v = 0;
  for (std::size_t b = 0; b < 8; ++b) v |= std::uint64_t(shared.values[8 * e + b]) << (8 * b);
  return v;
}

// Decodes channel c into out; `exception` is the index of its first value in the value stream.
Status decode_channel(int c, const SharedStreams& shared, std::size_t exception,
                      const ChannelStreams& s, double* out) {
  std::vector<std::uint64_t> w(kBinsPerChannel);
  std::vector<std::uint8_t> size(kBinsPerChannel, 0);
  ResidualReader reader(s);
  std::string why;
  const std::vector<Terms>& table = terms_table();
  const std::size_t bitmap_base = std::size_t(c) * kBinsPerChannel;
  for (int h = 0; h < kThetaHBins; ++h) {
    for (int d = 0; d < kThetaDBins; ++d) {
      const std::size_t row = std::size_t(h) * kThetaDBins + std::size_t(d);
      const int p = shared.choices[std::size_t(c) * kRowsPerChannel + row];
      const Order o = kPredictors[std::size_t(p)];
      const std::size_t order_base = std::size_t(p) * 125 + std::size_t(std::min(o.h, h) * 25) +
                                     std::size_t(std::min(o.d, d) * 5);
      for (int k = 0; k < kPhiDBins; ++k) {
        const std::size_t i = row * kPhiDBins + std::size_t(k);
        if (bit_set(shared.bitmap, bitmap_base + i)) {
          w[i] = i > 0 ? w[i - 1] : 0;
          out[i] = std::bit_cast<double>(exception_value(shared, exception++));
          continue;
        }
        std::uint64_t pred = 0;
        for (const Term& t : table[order_base + std::size_t(std::min(o.p, k))])
          pred += t.coef * w[i - t.offset];
        const int a = i > 0 ? size[i - 1] : 0;
        const int b = i >= kPlaneStride ? size[i - kPlaneStride] : 0;
        std::uint64_t z = 0;
        int len = 0;
        if (!reader.next(std::size_t(context_of(a, b)), &z, &len, &why))
          return corrupt_at(c, i, why);
        w[i] = pred + unzigzag(z);
        if (is_exception(w[i]))
          return corrupt_at(c, i, "a measured bin decodes to a value with the sign bit set");
        size[i] = std::uint8_t(len);
        out[i] = std::bit_cast<double>(w[i]);
      }
    }
  }
  return reader.check_used_up(c);
}

Expected<SharedStreams> read_shared_streams(ByteReader* r) {
  std::uint8_t method = 0;
  std::uint32_t count = 0;
  CBRDF_RETURN_IF_ERROR(r->u8(&method, "exact table method"));
  if (method != kMethodPredictive) {
    return error(ErrorCode::kCorrupt,
                 "exact table: unknown method " + std::to_string(method) + " (only 1 is defined)");
  }
  CBRDF_RETURN_IF_ERROR(r->u32(&count, "exact table exception count"));
  if (count > kTotalBins) {
    return error(ErrorCode::kCorrupt, "exact table: " + std::to_string(count) +
                                          " exceptions in a table of " +
                                          std::to_string(kTotalBins) + " bins");
  }
  SharedStreams s;
  CBRDF_ASSIGN_OR_RETURN(auto bitmap,
                         get_stream(r, "exact table exception bitmap", kBitmapBytes, true));
  s.bitmap = std::move(bitmap);
  std::size_t set = 0;
  for (std::uint8_t byte : s.bitmap) set += std::size_t(std::popcount(byte));
  if (set != count) {
    return error(ErrorCode::kCorrupt, "exact table: the exception bitmap marks " +
                                          std::to_string(set) + " bins but the header declares " +
                                          std::to_string(count));
  }
  CBRDF_ASSIGN_OR_RETURN(
      auto values, get_stream(r, "exact table exception values", std::size_t{8} * count, true));
  s.values = std::move(values);
  for (std::size_t i = 0; i < count; ++i) {
    if ((s.values[8 * i + 7] & 0x80) == 0) {
      return error(ErrorCode::kCorrupt, "exact table: exception value " + std::to_string(i) +
                                            " lacks the sign bit of a not-measured value");
    }
  }
  CBRDF_ASSIGN_OR_RETURN(auto choices, get_stream(r, "exact table predictor choices",
                                                  std::size_t{kChannels} * kRowsPerChannel, true));
  s.choices = std::move(choices);
  for (std::size_t i = 0; i < s.choices.size(); ++i) {
    if (s.choices[i] >= kPredictors.size()) {
      return error(ErrorCode::kCorrupt, "exact table: predictor " + std::to_string(s.choices[i]) +
                                            " of row " + std::to_string(i) + " is not below 16");
    }
  }
  return s;
}

Expected<BrdfTable> decode_streams(std::span<const std::uint8_t> bytes) {
  ByteReader r(bytes, 0, "exact table offset");
  CBRDF_ASSIGN_OR_RETURN(auto shared, read_shared_streams(&r));
  // Each channel's exceptions: where its values start, and how many bins it codes.
  std::array<std::size_t, kChannels + 1> first{};
  for (int c = 0; c < kChannels; ++c) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i)
      n += bit_set(shared.bitmap, std::size_t(c) * kBinsPerChannel + i) ? 1 : 0;
    first[std::size_t(c) + 1] = first[std::size_t(c)] + n;
  }
  std::array<ChannelStreams, kChannels> streams;
  for (int c = 0; c < kChannels; ++c) {
    const std::size_t exceptions = first[std::size_t(c) + 1] - first[std::size_t(c)];
    CBRDF_ASSIGN_OR_RETURN(streams[std::size_t(c)],
                           read_channel_streams(&r, c, kBinsPerChannel - exceptions));
  }
  if (!r.at_end()) {
    return error(ErrorCode::kCorrupt,
                 "exact table: " + std::to_string(r.remaining()) + " bytes follow the last stream");
  }
  BrdfTable table;
  std::array<Status, kChannels> status;
  parallel_for(kChannels, 0, [&](int c) {
    status[std::size_t(c)] = decode_channel(c, shared, first[std::size_t(c)],
                                            streams[std::size_t(c)], table.channel_data(c));
  });
  for (const Status& s : status) CBRDF_RETURN_IF_ERROR(s);
  return table;
}

}  // namespace

Expected<BrdfTable> decode_exact_table(std::span<const std::uint8_t> bytes) {
  auto table = decode_streams(bytes);
  // The payload's length is the chunk's: data ending early is damage, not a short read.
  if (table.status().code() == ErrorCode::kTruncated)
    return error(ErrorCode::kCorrupt, table.status().message());
  return table;
}

}  // namespace cbrdf::internal
