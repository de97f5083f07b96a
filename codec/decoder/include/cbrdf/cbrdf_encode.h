/* SPDX-License-Identifier: MIT */
/** @file
 * The cbrdf C API, encoder part: fit MERL tables and write .cbrdf files. These functions live in
 * libcbrdf_encoder (pkg-config cbrdf, CMake cbrdf::encoder), not in the decoder library: a program
 * linked against libcbrdf_decoder alone cannot call them. libcbrdf_encoder.so contains the
 * decoder's code itself (it does not depend on libcbrdf_decoder.so), so everything of
 * cbrdf/cbrdf_decode.h (included here) is available from it alone: a program links one of the
 * two. Statically, libcbrdf_encoder.a sits on libcbrdf_decoder.a (pkg-config and CMake add both).
 * Conventions and the ABI promise are those of cbrdf/cbrdf_decode.h. */
#ifndef CBRDF_CBRDF_ENCODE_H_
#define CBRDF_CBRDF_ENCODE_H_

#include <stddef.h>
#include <stdint.h>

#include "cbrdf/cbrdf_c_export.h"
#include "cbrdf/cbrdf_decode.h"

#ifdef __cplusplus
extern "C" {
#endif

/** cbrdf_encode_settings.bits: chosen from the data. */
#define CBRDF_BITS_AUTO 0
/** cbrdf_encode_settings.format_version: 1.3 where smaller (the default). */
#define CBRDF_FORMAT_AUTO 0
/** cbrdf_encode_settings.format_version: the 1.0-1.2 chunks only. */
#define CBRDF_FORMAT_1_2 12
/** cbrdf_encode_settings.format_version: version 1.3 whenever the model allows it. */
#define CBRDF_FORMAT_1_3 13
/** cbrdf_encode_settings.metadata: no metadata chunk. */
#define CBRDF_METADATA_NONE 0
/** cbrdf_encode_settings.metadata: the source's name and the encoder (the default). */
#define CBRDF_METADATA_SHORT 1
/** cbrdf_encode_settings.metadata: also the bits and the zstd level. */
#define CBRDF_METADATA_FULL 2

/** cbrdf_encode_settings.residual_steps: every measured bin within max_error (the default). */
#define CBRDF_RESIDUAL_STEPS_ONE 0
/** cbrdf_encode_settings.residual_steps: max_error bounds the most visible rows; rows that count
 * less in rendered images get coarser steps (as `cbrdf encode --residual-steps visibility`). */
#define CBRDF_RESIDUAL_STEPS_VISIBILITY 1

/** Encoder settings. Fields are only ever appended: fill the struct with
 * cbrdf_encode_settings_init, then change the fields you need. */
typedef struct cbrdf_encode_settings {
  uint32_t struct_size; /**< sizeof(cbrdf_encode_settings), set by cbrdf_encode_settings_init */
  int bits;             /**< bits per quantized marginal value, 6 to 16 (the quality knob), or
                           CBRDF_BITS_AUTO (the default): the fewest bits costing at most 0.05 dB
                           tone-mapped and 0.5 dB linear sphere PSNR against the unquantized
                           model */
  int zstd_level;       /**< 1 to 22: the effort knob (19) */
  int slices;           /**< uniform theta_d slices, 1 to 90 (6, the paper's) */
  int components;       /**< copula components per slice and channel, 1 to 8 (1, the paper's) */
  int family;           /**< a cbrdf_family, CBRDF_FAMILY_AUTO included (CBRDF_FAMILY_FRANK) */
  int threads;          /**< fitting threads, 0 (one per core) to 256 (1); results are identical */
  /* Since 1.4: the residual layer (container 1.2; spec/container.md 4.6). */
  double max_error; /**< > 0: every measured bin decodes within this bound of the source,
                       |log1p(decoded / k) - log1p(source / k)| <= max_error on stored values
                       with k = 1e-4 (a relative bound), 1e-6 to 16; 0 (the default): none */
  int lossless;     /**< 1: the decoded table equals the source bit for bit (excludes
                       max_error); 0 (the default): not */
  /* Since 1.6. */
  int mixture_copulas; /**< with components > 1: 1 (the default) fits each component's copula, 0
                          leaves them at independence (about half the fit's time and, in the 1.2
                          coding the C API writes, 6% fewer bytes at the same bits, for about the
                          same tone-mapped PSNR per byte) */
  /* Since 2.2. A caller built against an older struct (a smaller struct_size) gets what older
     releases wrote: CBRDF_FORMAT_1_2 and CBRDF_METADATA_FULL. */
  int format_version; /**< the container's coding: CBRDF_FORMAT_AUTO (the default: version 1.3
                         where it is smaller, as `cbrdf encode`), CBRDF_FORMAT_1_2 (the 1.0-1.2
                         chunks, for readers older than 2.1) or CBRDF_FORMAT_1_3 */
  int metadata;       /**< the metadata chunk: CBRDF_METADATA_NONE, CBRDF_METADATA_SHORT (the
                         default: source and encoder) or CBRDF_METADATA_FULL (also bits and
                         zstd level) */
  int residual_steps; /**< how max_error bounds the residual layer: CBRDF_RESIDUAL_STEPS_ONE (the
                         default: every measured bin within it) or
                         CBRDF_RESIDUAL_STEPS_VISIBILITY (the most visible rows within it, the
                         others coarser: fewer bytes for the same picture; needs max_error > 0) */
  /* Since 2.3. A caller built against an older struct (a smaller struct_size) gets no callback. */
  /** NULL (the default), or called on the calling thread at least every 50 ms of encoder work
      with the share of the encode done (0 to 1, never decreasing; negative when it cannot be
      estimated) and progress_user. Returning nonzero cancels: the work stops at its next
      checkpoint (usually tens of milliseconds; up to a few hundred while a residual layer is
      compressed) and the call fails with CBRDF_ERROR_CANCELLED ("cancelled"). Must not call the
      encoder. */
  int (*progress)(void* user, double fraction);
  void* progress_user; /**< passed to progress as it is (NULL by default) */
} cbrdf_encode_settings;

/** Sets every field to its default (as `cbrdf encode` without options, except threads = 1) and
 * struct_size to sizeof(cbrdf_encode_settings). Returns CBRDF_OK, or
 * CBRDF_ERROR_INVALID_ARGUMENT (settings NULL). */
CBRDF_C_API cbrdf_status cbrdf_encode_settings_init(cbrdf_encode_settings* settings);

/** Fits the model to a full MERL table (layout of cbrdf_model_table; count must be
 * cbrdf_merl_table_size(); negative and NaN values mean not measured and are kept bit for bit)
 * and writes it as a .cbrdf file in a new buffer: *out_bytes (free it with cbrdf_free) of
 * *out_size bytes. settings may be NULL for the defaults. Takes seconds (mixtures: tens of
 * seconds). On failure *out_bytes is NULL and *out_size 0 (when those pointers are not NULL).
 * Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, another count,
 * settings->struct_size smaller than the first version of the struct, a setting out of its range:
 * the message names the field and the range), CBRDF_ERROR_NUMERIC (a +Inf value, or a channel
 * whose largest value is outside what the fit supports), CBRDF_ERROR_LIMIT,
 * CBRDF_ERROR_CANCELLED (settings->progress returned nonzero), or CBRDF_ERROR_INTERNAL. */
CBRDF_C_API cbrdf_status cbrdf_encode_table(const double* stored_values, size_t count,
                                            const cbrdf_encode_settings* settings, void** out_bytes,
                                            size_t* out_size);
/** Reads a MERL .binary (cbrdf::read_merl: 90x90x180, or 90x90x360 folded), encodes it as
 * cbrdf_encode_table does (the metadata records the input's file name) and writes the .cbrdf file
 * atomically. in_path and out_path may name the same file. Returns CBRDF_OK, or the codes of
 * cbrdf_encode_table, and CBRDF_ERROR_NOT_FOUND, CBRDF_ERROR_IO, CBRDF_ERROR_TRUNCATED,
 * CBRDF_ERROR_CORRUPT, CBRDF_ERROR_UNSUPPORTED (reading the input) or CBRDF_ERROR_IO (writing the
 * output; an existing output is left untouched). When cancelled (CBRDF_ERROR_CANCELLED) nothing
 * is written: an existing output is left untouched. */
CBRDF_C_API cbrdf_status cbrdf_encode_merl_file(const char* in_path, const char* out_path,
                                                const cbrdf_encode_settings* settings);

/** Since 2.1: the measurement noise of a table, estimated from the table alone (cbrdf/noise.h).
 * The number of theta_d bands: 15 bins each, 0-14 deg to 75-89 deg. */
#define CBRDF_NOISE_BANDS 6

/** The noise estimate. Fields are only ever appended: set struct_size to
 * sizeof(cbrdf_noise_estimate) before the call, and a newer library fills only what the caller's
 * version of the struct has. */
typedef struct cbrdf_noise_estimate {
  uint32_t struct_size; /**< in: sizeof(cbrdf_noise_estimate); out: the bytes filled */
  double sigma[3];      /**< relative noise per channel R, G, B: the deviation of log(value), so
                             0.03 is 3%; near 0 (below 0.002) for a smooth table */
  double band_sigma[CBRDF_NOISE_BANDS][3]; /**< the same per theta_d band and channel */
  double grazing_growth;          /**< last band's sigma over the first's, mean over channels */
  double psnr_ceiling_tonemapped; /**< the tone-mapped sphere PSNR (dB) of the table against
                                       itself with another draw of its noise: beyond it a coder
                                       reproduces noise; 100 for a smooth table; NaN (test with
                                       isnan) when not measurable: noise of many decades per bin
                                       takes that draw's renders past their range */
  double psnr_ceiling_linear;     /**< the same ceiling in linear sphere PSNR (dB), NaN when not
                                       measurable (values log-uniform over 1e-30..1e30: a finite
                                       tone-mapped ceiling, NaN here); never an infinity */
  int noisy;                      /**< 1: some channel's sigma is above 0.002; 0: a smooth table */
} cbrdf_noise_estimate;

/** Estimates the noise of a full MERL table (layout and count as cbrdf_encode_table; negative and
 * NaN values are not measured and ignored). Takes about half a second (three sphere renders).
 * Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, another count, or
 * out->struct_size smaller than the struct's first version). */
CBRDF_C_API cbrdf_status cbrdf_estimate_noise(const double* stored_values, size_t count,
                                              cbrdf_noise_estimate* out);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* CBRDF_CBRDF_ENCODE_H_ */
