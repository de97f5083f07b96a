// SPDX-License-Identifier: MIT
// The payloads of the version-1 chunks (spec/container.md section 4), the reader's side: one file
// per chunk (head.cc, modl.cc, marg.cc, mask.cc, meta.cc, base.cc, resd.cc), the constants and
// rules reader and writer share (params.cc), and the model-level reader (read_model.cc). The
// writers are the encoder's (codec/encoder/src/bitstream/chunk_writers.h), so that a program
// linking only the decoder carries none. Readers' messages carry no location: read_model.cc
// prefixes the chunk tag and offset.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "byte_reader.h"
#include "cbrdf/codec.h"
#include "cbrdf/model.h"
#include "cbrdf/status.h"
#include "quantize.h"
#include "range_coder.h"

namespace cbrdf {

inline constexpr std::uint8_t kThetaHMappingMerlSqrt = 0;
// Version 1.3's HEAD names the grid by number: 0 is MERL's (90x90x180, square-root theta_h
// mapping, RGB with MERL's scales), the only one version 1 holds.
inline constexpr std::uint8_t kGridMerl = 0;
// BASE's flags: bit 0, the further-component counts follow the slice ends; bit 1, every K is a
// binary64 (spec 4.8: the writer sets it only where some K has no normal binary32, so that a
// table's scale survives anywhere in the supported range, 1e-250 to 1e250).
inline constexpr std::uint8_t kBaseFlagComponents = 1;
inline constexpr std::uint8_t kBaseFlagWideScales = 2;
inline constexpr const char* kChannelNames[kChannels] = {"R", "G", "B"};
inline constexpr std::size_t kMaskBits = std::size_t{kChannels} * kBinsPerChannel;
inline constexpr std::size_t kMaskBytes = kMaskBits / 8;  // 4,374,000 bits: no padding
static_assert(kMaskBits % 8 == 0);

// Metadata limits keep the key=value parser bounded.
inline constexpr std::size_t kMaxMetadataEntries = 64;
inline constexpr std::size_t kMaxMetadataKeyBytes = 32;
inline constexpr std::size_t kMaxMetadataValueBytes = 1024;

struct HeaderFields {
  std::array<double, kChannels> colour_scale{};
  int slice_count = 0;
};

enum class MaskReference : std::uint8_t { kNone = 0, kBelowHorizon = 1 };
enum class MaskForm : std::uint8_t { kBitmap = 0, kRuns = 1 };
enum class MaskValues : std::uint8_t { kSingle = 0, kPerBin = 1 };

struct MaskFields {
  MaskReference reference = MaskReference::kNone;
  MaskForm form = MaskForm::kBitmap;
  MaskValues values = MaskValues::kSingle;
};

// MARG's second byte: reserved (0) in version 1.0; in 1.1 the table layout, 1 when the model has
// further components (their tables follow each slice channel's first component's).
inline constexpr std::uint8_t kMarginalLayoutSingle = 0;
inline constexpr std::uint8_t kMarginalLayoutComponents = 1;
// At most this many further components per slice and channel (kMaxComponents - 1 in fit.h).
inline constexpr int kMaxExtraComponents = 7;

// RESD (spec 4.6, version 1.2): the residual layer's modes, predictor and limits.
inline constexpr std::uint8_t kResidualModeLog = 0;         // bounded log1p residual
inline constexpr std::uint8_t kResidualModeExact = 1;       // the exact table (lossless)
inline constexpr std::uint8_t kResidualModeRows = 2;        // mode 0 with a step per row
inline constexpr std::uint8_t kResidualModeInterp = 3;      // mode 2, interpolated levels
inline constexpr std::uint8_t kResidualModeLevelSteps = 4;  // mode 3, a step per level (1.3)
inline constexpr int kMaxResidualLevels = 4;  // coarsest spacing 16: phi_d + h stays <= 180
inline constexpr int kMaxFineMultiplier = 64;
inline constexpr std::uint8_t kResidualPredictorNone = 0;  // codes as they are
inline constexpr std::uint8_t kResidualPredictorPhi = 1;   // from the previous phi_d bin
// Version 1.3: the codes range coded with contexts (residual_codes.h), in files of minor >= 3.
inline constexpr std::uint8_t kResidualPredictorRange = 2;
// Version 1.3: the range-coded codes after a prediction from the previous slab and channel
// (residual_prediction.h), in files of minor >= 3.
inline constexpr std::uint8_t kResidualPredictorRangePredicted = 3;
inline constexpr double kMinResidualError = 1e-6;
inline constexpr double kMaxResidualError = 16.0;
// Down to 1e-300 so that a table at any scale has a knee below its values (with a 1e-12 floor, a
// table scaled by 1e-30 would have every value below the knee: an absolute bound, not relative).
inline constexpr double kMinResidualKnee = 1e-300;
inline constexpr double kMaxResidualKnee = 1e12;
// The reference encoder's knee, stored units (about 6.7e-8 physical): a bound relative down to
// there serves dark specular materials far better than the knee 1 (log1p of stored values) at the
// same bytes, and costs diffuse ones nothing.
inline constexpr double kResidualKnee = 1e-4;
inline constexpr std::int64_t kMaxResidualCode = std::int64_t{1} << 28;
// The largest residual a bin may carry, |code x step'| (modes 0, 2) or |R| (mode 3, every bin), in
// log1p units: a decoded value is then at most e^64 (base + knee), so every accepted file
// evaluates and samples finite. The reference writer clamps its targets to +-(64 - 16) and stores
// bins beyond that exactly (escapes); real materials stay within about +-30.
inline constexpr double kMaxResidualValue = 64.0;
inline constexpr std::uint32_t kMaxResidualEscapes = 65536;
// Mode 2: rows (90 theta_h + theta_d) and the largest shift of a row's step (x 2^24).
inline constexpr std::size_t kResidualRows = std::size_t{kThetaHBins} * kThetaDBins;
inline constexpr std::uint8_t kMaxResidualShift = 24;
// Up to 4.4 million varints: zstd's top levels cost seconds there for little (measured).
inline constexpr int kResidualZstdLevel = 19;

// RESD predictors 0 and 1: the prediction of code (c, i) from codes already decoded: 0 (predictor
// 0), or the previous phi_d bin's code of the same channel (predictor 1; 0 at phi_d = 0).
// Not-measured bins hold code 0. i is a MERL index, phi_d = i mod 180. (Measured on real materials:
// the previous phi_d bin wins where the residual is quantized finely, no prediction where it is
// coarse and mostly 0; the channel before, Lorenzo across theta_d and both lost to these.)
inline std::int64_t varint_code_prediction(const std::int32_t* q, int c, std::size_t i,
                                           std::uint8_t predictor) {
  if (predictor == kResidualPredictorNone || i % kPhiDBins == 0) return 0;
  return q[std::size_t(c) * kBinsPerChannel + i - 1];
}

// Bit b of a mask held as 64-bit words, least significant bit first.
inline bool mask_bit(const std::vector<std::uint64_t>& bits, std::size_t b) {
  return (bits[b >> 6] >> (b & 63)) & 1u;
}

// Set bits of a mask. The bit trick, not std::popcount: without a popcount instruction in the
// target (the default x86-64 build, Emscripten) std::popcount is a library call per word, which
// made counting the mask's 68,344 words about a fifth of decode_model's time (measured); this
// loop vectorizes.
inline std::size_t count_set_bits(std::span<const std::uint64_t> words) {
  std::uint64_t n = 0;
  for (std::uint64_t x : words) {
    x = x - ((x >> 1) & 0x5555555555555555ull);
    x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
    x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
    n += (x * 0x0101010101010101ull) >> 56;
  }
  return std::size_t(n);
}

// Payload offsets are named as such in messages.
inline ByteReader payload_reader(std::span<const std::uint8_t> payload) {
  return ByteReader(payload, 0, "payload offset");
}

// Trailing bytes after the known fields are allowed only in a file of a newer minor version
// (which may append fields); otherwise they are corruption.
Status check_trailing(std::size_t trailing, std::uint16_t file_minor);

// %.17g: every double in a message round-trips.
std::string number_text(double v);

// The parameter rules shared by encoder and decoder; the message names the problem.
Status check_channel_params(std::uint8_t family, double theta, double scale);

// The slice ends (one u8 each) that MODL and BASE both hold: slice_count slices, non-empty,
// contiguous from theta_d bin 0 to 90; sets each slice's bounds in `slices` (resized).
Status read_slice_bounds(ByteReader& r, int slice_count, std::vector<Slice>* slices);

// The further-component counts (one u8 per slice and channel, at most kMaxExtraComponents) that
// MODL 1.1+ and BASE with its components flag both hold; sizes each channel's `extra`.
Status read_component_counts(ByteReader& r, std::vector<Slice>* slices);

// compact: the 2-byte form of a file that holds BASE (version 1.3), else the 34-byte one.
Status decode_header_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                           bool compact, HeaderFields* out);
// Fills slices' bounds, families, parameters and scales.
Status decode_model_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                          int slice_count, std::vector<Slice>* slices);
// Fills the marginal tables of slices whose bounds are already known.
Status decode_marginals_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                              std::vector<Slice>* slices, int* bits);
// Version 1.3: the BASE chunk, MODL's and MARG's content (slices' bounds, parameters, tables).
Status decode_base_chunk(std::span<const std::uint8_t> payload, int slice_count,
                         std::vector<Slice>* slices, int* bits);
Status decode_mask_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                         NotMeasured* out, MaskFields* fields);
// Needs the mask (decoded before): codes are stored for measured bins only. `predictor`, when
// given, receives the chunk's predictor byte (modes 0, 2-4; untouched in mode 1).
Status decode_residual_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                             const NotMeasured& mask, Residual* out,
                             std::uint8_t* predictor_out = nullptr);
Status decode_metadata_chunk(std::span<const std::uint8_t> payload,
                             std::vector<std::pair<std::string, std::string>>* out);

// The below-horizon mask of one channel (bit i = bin_below_horizon(merl_bin(i))), computed once.
const std::vector<std::uint64_t>& below_horizon_bits();
// Flips every channel's below-horizon bins: the mask relative to the below-horizon reference, and
// back (MASK's reference 1, spec 4.4).
void xor_below_horizon(std::vector<std::uint64_t>* bits);
// XXH64 of the mask's 4,374,000 bits as LSB-first bytes (the words' little-endian bytes).
std::uint64_t mask_hash(const std::vector<std::uint64_t>& bits);

}  // namespace cbrdf
