// SPDX-License-Identifier: MIT
/// @file
/// One-call encoding of whole tables: fit + quantize + container (decode_table, the way back, is
/// the decoder's: codec.h).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/codec.h"
#include "cbrdf/fit.h"
#include "cbrdf/model.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// `--bits auto`: the fewest bits (6 to 16) whose quantization costs at most these losses of
/// sphere PSNR (metrics.h) against the unquantized model. On the 20 measured materials of
/// ../shared this chose 6 to 12 bits (the knee differs by material: 9 for most) at 55% of the
/// 12-bit bytes, losing 0.008 dB tone-mapped on average (0.049 at worst).
struct AutoBitsSettings {
  bool enabled = false;                  ///< when false, ContainerSettings::bits is used as it is
  double max_tonemapped_loss_db = 0.05;  ///< tone-mapped sphere PSNR
  double max_linear_loss_db = 0.5;       ///< linear sphere PSNR
};

/// The residual layer on top of the copula model (container 1.2, spec/container.md 4.6).
struct ResidualSettings {
  /// > 0: every measured bin decodes within this bound, |log1p(decoded / k) - log1p(source / k)|
  /// <= E with the values a MERL file stores (physical value / the MERL colour scale) and the knee
  /// k = 1e-4 (about 6.7e-8 physical): a relative error of at most e^E - 1 above the knee, an
  /// absolute one of about E k below; 1e-6 to 16. 0: no residual layer.
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
};

/// The residual the rate control (--target-psnr, --target-bytes) and the report's ladder write at
/// bound E of the finest rows: row steps, 3 levels, the finest level's bound 8 times its row's.
ResidualSettings target_residual_settings(double max_error);

/// Everything encode_table() needs; encoder_settings() makes one from the command's options.
struct EncoderSettings {
  FitSettings fit;              ///< the model fit
  ContainerSettings container;  ///< quantization and compression
  ResidualSettings residual;    ///< the optional residual layer
  AutoBitsSettings auto_bits;   ///< `--bits auto`
};

/// An "integer or auto" option value: `--slices N|auto`, `--components K|auto`, the report's
/// sweep lists.
struct CountOrAuto {
  int count = 0;         ///< meaningless when is_auto
  bool is_auto = false;  ///< "auto" was given
};

/// `text` as an integer from lo to hi or, when allow_auto, "auto"; nullopt for anything else (no
/// sign, spaces or fraction). Callers word the message: an option and a sweep list name it apart.
std::optional<CountOrAuto> parse_count_or_auto(std::string_view text, int lo, int hi,
                                               bool allow_auto);

/// EncoderOptions::bits for `--bits auto`.
inline constexpr int kAutoBits = 0;

/// The encoder's user-facing options, as `cbrdf encode` takes them (and `cbrdf report` sets them).
struct EncoderOptions {
  std::string slices = "6";           ///< 1 to 90, or auto (count and boundaries from the data)
  std::string placement = "uniform";  ///< uniform or adaptive
  std::string components = "1";       ///< 1 to kMaxComponents, or auto (up to kAutoMaxComponents)
  std::string family = "frank";       ///< frank, clayton, gumbel, joe, independence or auto
  /// Mixtures: fit or independence (FitSettings::mixture_copulas).
  std::string mixture_copulas = "fit";
  int bits = kAutoBits;  ///< 6 to 16, or kAutoBits (the default: see AutoBitsSettings)
  int level = ContainerSettings{}.zstd_level;  ///< zstd level, 1 to 22
  std::string loss = "linear";                 ///< linear, cosine or log
  int threads = 0;                             ///< fitting threads (0: one per core)
  bool naive_marginals = false;                ///< the paper's marginals (missing bins as 0)
  std::string source_name;                     ///< recorded in the container's metadata
  double max_error = 0;   ///< the residual layer's bound (ResidualSettings); 0: none
  bool lossless = false;  ///< the residual layer makes the decoded table exact
  /// auto (1.3 where smaller), 1.2 (the 1.0-1.2 chunks only) or 1.3 (ContainerSettings::Format)
  std::string format_version = "auto";
  std::string metadata = "short";  ///< none, short (source, encoder) or full (and bits, zstd level)
};

/// The settings the options stand for. kInvalidArgument names the option and its valid values in
/// one line ("--slices must be 1 to 90 or auto, not '0'"), the same wording for every caller.
Expected<EncoderSettings> encoder_settings(const EncoderOptions& options);

/// Sets a slice count (fixed: explicit boundaries cleared, auto_slices left as it is; auto: chosen
/// from the data) and a
/// component count (auto: up to kAutoMaxComponents) on `settings`: what encoder_settings does with
/// --slices and --components, and what rate control does for each candidate it tries.
void set_counts(CountOrAuto slices, CountOrAuto components, FitSettings* settings);

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

/// Fits the model to the table and writes it as a .cbrdf container.
Expected<EncodeResult> encode_table(const BrdfTable& table, const EncoderSettings& settings);

/// What encode_table does after the fit: `result` holds a base file (bytes, bits, model) of
/// `table`, and receives the file with the residual layer of settings.residual (the bound checked
/// after decoding). One fit then serves several bounds (the report's ladder).
Status add_residual_layer(const BrdfTable& table, const EncoderSettings& settings,
                          EncodeResult* result);

}  // namespace cbrdf
