// SPDX-License-Identifier: MIT
/// @file
/// One-call encoding of whole tables: fit + quantize + container (decode_table, the way back, is
/// the decoder's: codec.h).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/codec.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/fit.h"
#include "cbrdf/model.h"
#include "cbrdf/progress.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// `--bits auto`: the fewest bits (6 to 16) whose quantization costs at most these losses of
/// sphere PSNR (metrics.h) against the unquantized model. On the 20 measured materials of
/// ../shared this chose 6 to 12 bits (the knee differs by material: 9 for most) at 55% of the
/// 12-bit bytes, losing 0.008 dB tone-mapped on average (0.049 at worst).
struct AutoBitsSettings {
  bool enabled = true;                   ///< when false, ContainerSettings::bits is used as it is
  double max_tonemapped_loss_db = 0.05;  ///< tone-mapped sphere PSNR
  double max_linear_loss_db = 0.5;       ///< linear sphere PSNR
};

/// The residual layer on top of the copula model (container 1.2, spec/container.md 4.6).
struct ResidualSettings {
  /// > 0: every measured bin decodes within this bound, |log1p(decoded / k) - log1p(source / k)|
  /// <= E with the values a MERL file stores (physical value / the MERL colour scale) and the knee
  /// k = 1e-4 (about 6.7e-8 physical): a relative error of at most e^E - 1 above the knee, an
  /// absolute one of about E k below; kMinResidualBound to kMaxResidualBound (encoder_settings.h).
  /// 0: no residual layer.
  double max_error = 0;
  bool lossless = false;  ///< the decoded table equal to the source bit for bit
  /// A coarser step where a bin counts less in rendered images (RESD mode 2): each theta_h,
  /// theta_d row's step and bound are those of max_error times a power of two from the row's
  /// solid-angle measure times cos(theta_i) cos(theta_o), so max_error bounds the most visible
  /// rows only. What --target-psnr and --target-bytes use; --max-error keeps one bound.
  bool row_steps = false;
  /// > 0: RESD mode 3, codes that correct a level-by-level interpolation of the residual (1..4
  /// levels, the coarsest every 2^levels-th theta_d and phi_d bin), so that smooth regions cost
  /// almost nothing; the finest level's (odd theta_d or phi_d) step and bound are
  /// fine_multiplier (1..64) times its row's. What --target-psnr and --target-bytes use.
  int levels = 0;
  int fine_multiplier = 1;  ///< mode 3: see levels
  /// The same for the levels between the finest and the coarsest, finer first: level l, from 1
  /// to levels minus 1, has middle_multipliers[l - 1], each from 1 to 64. Any other than 1
  /// writes RESD mode 4, which needs container 1.3 (a 1.2 file takes them as 1).
  std::array<int, 3> middle_multipliers{1, 1, 1};
  /// The finest level's multiplier where the middle ones cannot be written (a file whose base is
  /// 1.2: RESD mode 3), 1..64; 0: fine_multiplier. Mode 3 alone wants a finer one than mode 4.
  int mode3_fine_multiplier = 0;
};

/// The residual the rate control (--target-psnr, --target-bytes) and the report's ladder write at
/// bound E of the finest rows: row steps, 3 levels, the finest level's bound 32, 16 or 8 times its
/// row's (E from 1.5e-3, from 6e-4, below; at most 16 / E) and level 1's a quarter of that (in
/// container 1.3: RESD mode 4); in a 1.2 file (mode 3) the finest level's 8 times its row's.
ResidualSettings target_residual_settings(double max_error);

/// Everything encode_table() needs. The defaults are `cbrdf encode`'s without options: version
/// 1.3 where smaller, short metadata, bits chosen per material (`--bits auto`), one fitting thread
/// (the threads change the time, not the bytes). validate() (cbrdf/encoder_settings.h) checks them
/// as encode_table() does.
struct EncoderSettings {
  FitSettings fit;              ///< the model fit
  ContainerSettings container;  ///< quantization and compression
  ResidualSettings residual;    ///< the optional residual layer
  AutoBitsSettings auto_bits;   ///< `--bits auto`
  /// Called during the encode to report progress and allow a cancel (progress.h); empty: no
  /// calls.
  ProgressCallback progress;
};

/// What encode_table() produced.
struct EncodeResult {
  std::vector<std::uint8_t> bytes;  ///< the .cbrdf file
  Model model;                      ///< as fitted, before quantization
  FitReport report;                 ///< the fit's diagnostics
  int bits = 0;                     ///< bits per marginal code in the file (chosen when auto)
};

/// What choose_bits() picked.
struct AutoBitsChoice {
  int bits = 0;                     ///< the chosen bits, 6 to 16
  std::vector<std::uint8_t> bytes;  ///< the model written with `bits`
};

/// What `--bits auto` does after the fit: writes `model` (fitted to `source`) at the fewest bits
/// whose decoded sphere PSNR stays within the settings' losses of the unquantized model's, by
/// bisection over 6..16 (3 or 4 files written and decoded: quantization error falls with every
/// bit, so the first depth that passes is the knee). `container.bits` is ignored.
Expected<AutoBitsChoice> choose_bits(const BrdfTable& source, const Model& model,
                                     const ContainerSettings& container,
                                     const AutoBitsSettings& settings);

/// Fits the model to the table and writes it as a .cbrdf container. Settings that validate()
/// faults fail with kInvalidArgument naming each member ("fit.slices must be from 1 to 90, not
/// 0"); fit.threads 0 takes one thread per core (thread_limit()).
Expected<EncodeResult> encode_table(const BrdfTable& table, const EncoderSettings& settings);

/// What encode_table does after the fit: `result` holds a base file (bytes, bits, model) of
/// `table`, and receives the file with the residual layer of settings.residual (the bound checked
/// after decoding). One fit then serves several bounds (the report's ladder).
Status add_residual_layer(const BrdfTable& table, const EncoderSettings& settings,
                          EncodeResult* result);

}  // namespace cbrdf
