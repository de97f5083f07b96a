// SPDX-License-Identifier: MIT
/* The cbrdf C API: open, describe, evaluate, sample and encode .cbrdf files from C (C99) or any
 * language with a C foreign-function interface.
 *
 * Conventions (they hold for every function below unless its comment says otherwise):
 *
 * - Errors. A function that can fail returns a cbrdf_status (or NULL for a handle) and records
 *   the failure as the calling thread's last error: cbrdf_last_error_code() and
 *   cbrdf_last_error_message() (a message naming the argument, file, chunk or byte offset). Every
 *   successful call of such a function clears the last error (code CBRDF_OK, message ""). The
 *   functions that cannot fail (version, names, the last error itself, cbrdf_merl_table_size,
 *   cbrdf_model_free, cbrdf_free) leave the last error as it is. No C++ exception crosses this
 *   API: running out of memory is reported as CBRDF_ERROR_INTERNAL with the message
 *   "out of memory".
 * - Arguments. Every pointer argument must be non-NULL unless its comment says otherwise; a NULL
 *   one fails with CBRDF_ERROR_INVALID_ARGUMENT, and so does any out-of-range index or count. A
 *   function that fails leaves its outputs unspecified unless its comment says otherwise.
 * - Directions are unit vectors in the surface's local frame, z the normal, as three doubles
 *   (x, y, z). A direction with a non-finite component or whose squared length differs from 1 by
 *   more than 1e-3 fails with CBRDF_ERROR_INVALID_ARGUMENT. BRDF values are physical (1/sr), per
 *   colour channel R, G, B.
 * - Threads. Functions taking a `const cbrdf_model*` may be called concurrently from any number
 *   of threads on the same handle (evaluation and sampling are read-only after lazy, thread-safe
 *   initialization). cbrdf_model_free must not run concurrently with any other use of the handle.
 *   The last error is per thread.
 * - Memory. Strings returned by cbrdf_version_string, cbrdf_status_name and cbrdf_family_name are
 *   static. Strings returned through a model handle live as long as the handle. Buffers returned
 *   by the encoder are freed with cbrdf_free.
 */
#ifndef CBRDF_CBRDF_C_H_
#define CBRDF_CBRDF_C_H_

#include <stddef.h>
#include <stdint.h>

#if defined(__GNUC__) || defined(__clang__)
#define CBRDF_C_API __attribute__((visibility("default")))
#else
#define CBRDF_C_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Version ----------------------------------------------------------------------------------
 */

/* The library's version, e.g. "1.2.0". Static; never NULL. */
CBRDF_C_API const char* cbrdf_version_string(void);
/* The same as major * 10000 + minor * 100 + patch (1.2.0 -> 10200), as zstd numbers its versions;
 * equal to CBRDF_VERSION of cbrdf/version.h. */
CBRDF_C_API int cbrdf_version_number(void);

/* ---- Errors -----------------------------------------------------------------------------------
 */

/* Stable numeric codes, equal to cbrdf::ErrorCode (cbrdf/status.h): never renumbered, only
 * appended to. */
typedef enum cbrdf_status {
  CBRDF_OK = 0,
  CBRDF_ERROR_IO = 1,               /* the operating system refused a read or write */
  CBRDF_ERROR_NOT_FOUND = 2,        /* a named file does not exist */
  CBRDF_ERROR_TRUNCATED = 3,        /* the data ends before its declared content */
  CBRDF_ERROR_BAD_SIGNATURE = 4,    /* not a file of the expected kind */
  CBRDF_ERROR_UNSUPPORTED = 5,      /* a newer version or an unknown critical feature */
  CBRDF_ERROR_CORRUPT = 6,          /* structurally invalid data */
  CBRDF_ERROR_CHECKSUM = 7,         /* a checksum does not match */
  CBRDF_ERROR_LIMIT = 8,            /* a declared size exceeds a documented maximum */
  CBRDF_ERROR_INVALID_ARGUMENT = 9, /* a caller passed a value outside its domain */
  CBRDF_ERROR_NUMERIC = 10,         /* NaN, Inf or a value outside a parameter's domain */
  CBRDF_ERROR_INTERNAL = 11         /* a bug in cbrdf, or out of memory */
} cbrdf_status;

/* The calling thread's last error: CBRDF_OK after a successful call. */
CBRDF_C_API cbrdf_status cbrdf_last_error_code(void);
/* Its message, "" after a successful call. Never NULL; owned by the library and valid until the
 * calling thread's next call of a function that sets or clears the last error. */
CBRDF_C_API const char* cbrdf_last_error_message(void);
/* A code's short name as `cbrdf` prints it ("ok", "io", "not-found", "truncated",
 * "bad-signature", "unsupported", "corrupt", "checksum", "limit", "invalid-argument", "numeric",
 * "internal"); "unknown" for any other value. Static; never NULL. */
CBRDF_C_API const char* cbrdf_status_name(cbrdf_status status);

/* ---- Threads ----------------------------------------------------------------------------------
 */

/* Caps the threads of every parallel loop in cbrdf (batch evaluation, fitting, tables) at n,
 * counting the calling thread; n <= 0 means one per core. The one global setting
 * (cbrdf/parallel.h); per-call requests (encode settings' threads) get the smaller of theirs and
 * this. Thread-safe; does not touch the last error. */
CBRDF_C_API void cbrdf_set_thread_limit(int n);
/* The limit in force, with "one per core" resolved to the core count (at least 1). */
CBRDF_C_API int cbrdf_thread_limit(void);

/* ---- Opening a model --------------------------------------------------------------------------
 */

/* A decoded .cbrdf file, ready for evaluation. Opaque. */
typedef struct cbrdf_model cbrdf_model;

/* Decodes a .cbrdf file held in memory, with the full validation of cbrdf::decode_model (every
 * chunk's checksum, bounds and content). The bytes are not referenced after the call returns.
 * Returns a new handle (free it with cbrdf_model_free), or NULL with the last error set:
 * CBRDF_ERROR_INVALID_ARGUMENT (data NULL), CBRDF_ERROR_TRUNCATED, CBRDF_ERROR_BAD_SIGNATURE,
 * CBRDF_ERROR_UNSUPPORTED, CBRDF_ERROR_CORRUPT, CBRDF_ERROR_CHECKSUM, CBRDF_ERROR_LIMIT,
 * CBRDF_ERROR_NUMERIC, CBRDF_ERROR_INTERNAL. */
CBRDF_C_API cbrdf_model* cbrdf_model_open_memory(const void* data, size_t size);
/* Reads and decodes a .cbrdf file (a regular file, or a path naming an open descriptor such as
 * /dev/stdin; at most 64 MiB). Returns a new handle or NULL with the last error set: the codes of
 * cbrdf_model_open_memory, and CBRDF_ERROR_NOT_FOUND (no such file), CBRDF_ERROR_IO (a directory,
 * FIFO or device, permission, a failed read), CBRDF_ERROR_LIMIT (larger than 64 MiB). Messages
 * start with the path. */
CBRDF_C_API cbrdf_model* cbrdf_model_open_file(const char* path);
/* Frees a handle and everything it owns (strings returned through it become invalid). NULL is
 * allowed and does nothing. Must not race with any other use of the handle. */
CBRDF_C_API void cbrdf_model_free(cbrdf_model* model);

/* ---- Describing a model -----------------------------------------------------------------------
 */

/* What a file holds. Fields are only ever appended: set struct_size to sizeof(cbrdf_model_info)
 * before the call, and a newer library fills only what the caller's version of the struct has. */
typedef struct cbrdf_model_info {
  uint32_t struct_size;       /* in: sizeof(cbrdf_model_info); out: the bytes filled */
  int version_major;          /* container version: 1 */
  int version_minor;          /* 0, or 1 for a file with mixtures */
  int slices;                 /* theta_d slices, 1 to 90 */
  int max_components;         /* most components in any slice and channel (1 unless a mixture) */
  int bits;                   /* bits per quantized marginal value, 6 to 16 */
  uint64_t file_bytes;        /* size of the .cbrdf file */
  uint64_t not_measured_bins; /* (channel, bin) pairs marked not measured, over all channels */
  /* Since 1.4: the residual layer (container 1.2, chunk RESD; spec/container.md 4.6). */
  int residual_mode; /* CBRDF_RESIDUAL_NONE, _BOUNDED, _LOSSLESS, _ROW_BOUNDED or _INTERPOLATED */
  double residual_max_error; /* all but _LOSSLESS: every measured bin decodes within this
                                bound of the source, |log1p(decoded / k) - log1p(source / k)|
                                on stored values; 0 otherwise */
  double residual_min_error; /* _ROW_BOUNDED, _INTERPOLATED: the finest row's bound (on the
                                coarser levels); _BOUNDED: max_error */
  double residual_knee;      /* k of that bound, in stored units (0 without a bounded layer) */
  uint64_t residual_bytes;   /* stored bytes of the RESD chunk (0 without one) */
} cbrdf_model_info;

/* cbrdf_model_info.residual_mode */
#define CBRDF_RESIDUAL_NONE (-1)
#define CBRDF_RESIDUAL_BOUNDED 0
#define CBRDF_RESIDUAL_LOSSLESS 1
/* A bound per (theta_h, theta_d) row, coarser where a bin weighs less in rendering (written by
 * the rate control: cbrdf_encode_settings.max_error always writes _BOUNDED). */
#define CBRDF_RESIDUAL_ROW_BOUNDED 2
/* Since 1.5: row bounds, the codes correcting an interpolation of coarser bins; the finest level
 * (odd theta_d or phi_d) has a multiple of its row's bound (written by the rate control). */
#define CBRDF_RESIDUAL_INTERPOLATED 3

/* Fills *info (see cbrdf_model_info). Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT when model
 * or info is NULL or info->struct_size is smaller than the first version of the struct. */
CBRDF_C_API cbrdf_status cbrdf_model_get_info(const cbrdf_model* model, cbrdf_model_info* info);

/* Slice `slice` (0 to info.slices - 1) covers theta_d bins [*theta_d_begin, *theta_d_end) of the
 * 90 MERL theta_d bins. Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, slice
 * out of range). */
CBRDF_C_API cbrdf_status cbrdf_model_get_slice(const cbrdf_model* model, int slice,
                                               int* theta_d_begin, int* theta_d_end);

/* The copula families (equal to cbrdf::CopulaFamily, as stored in files). CBRDF_FAMILY_AUTO is an
 * encoder setting only (fit every family, keep the best); a model never holds it. */
typedef enum cbrdf_family {
  CBRDF_FAMILY_AUTO = -1,
  CBRDF_FAMILY_INDEPENDENCE = 0, /* the separable model; no parameter */
  CBRDF_FAMILY_FRANK = 1,        /* the paper's; its convention: theta < 0 is positive dependence */
  CBRDF_FAMILY_CLAYTON = 2,
  CBRDF_FAMILY_GUMBEL = 3, /* Gumbel-Hougaard */
  CBRDF_FAMILY_JOE = 4
} cbrdf_family;

/* A family's name as the command line spells it ("independence", "frank", "clayton", "gumbel",
 * "joe", "auto"); "unknown" for any other value. Static; never NULL. */
CBRDF_C_API const char* cbrdf_family_name(int family);

/* Number of copula components (1, or up to 8 in a mixture) of slice `slice`, colour channel
 * `channel` (0 R, 1 G, 2 B). Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer,
 * slice or channel out of range). */
CBRDF_C_API cbrdf_status cbrdf_model_get_component_count(const cbrdf_model* model, int slice,
                                                         int channel, int* count);
/* Component `component` (0 to count - 1) of a slice and channel: its family (a cbrdf_family
 * value), its copula parameter theta (in the family's own convention) and its scale K (the term's
 * sum over the slice's bins, physical units). The slice's value is the sum over its components.
 * Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, slice, channel or component
 * out of range). */
CBRDF_C_API cbrdf_status cbrdf_model_get_component(const cbrdf_model* model, int slice, int channel,
                                                   int component, int* family, double* theta,
                                                   double* scale);

/* Number of metadata entries (the ancillary mETA chunk: source, encoder, settings), 0 when the
 * file has none. Returns 0 with CBRDF_ERROR_INVALID_ARGUMENT when model is NULL. */
CBRDF_C_API size_t cbrdf_model_metadata_count(const cbrdf_model* model);
/* Entry i (0 to count - 1) in file order. *key and *value are NUL-terminated strings owned by the
 * handle and valid while it lives (a value holding a NUL byte is cut there). Returns CBRDF_OK, or
 * CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, i out of range). */
CBRDF_C_API cbrdf_status cbrdf_model_metadata_at(const cbrdf_model* model, size_t i,
                                                 const char** key, const char** value);

/* ---- Evaluation -------------------------------------------------------------------------------
 */

/* The model's value f(wi, wo) in RGB (1/sr): continuous in angle (trilinear between MERL bins),
 * 0 when wi or wo is at or below the horizon (z <= 0), reciprocal up to rounding. Returns CBRDF_OK,
 * or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, a direction that is not a finite unit vector;
 * rgb is then unchanged). Thread-safe on one handle. */
CBRDF_C_API cbrdf_status cbrdf_model_eval(const cbrdf_model* model, const double wi[3],
                                          const double wo[3], double rgb[3]);
/* n evaluations: wi, wo and rgb hold n interleaved (x, y, z) / (r, g, b) triples; rgb[3k..3k+2]
 * equals cbrdf_model_eval(wi + 3k, wo + 3k) bit for bit. With n == 0 the pointers may be NULL.
 * Every direction is checked before anything is written: on CBRDF_ERROR_INVALID_ARGUMENT (a NULL
 * pointer, n too large for the arrays to exist, a bad direction, the message naming its index)
 * rgb is unchanged. */
CBRDF_C_API cbrdf_status cbrdf_model_eval_batch(const cbrdf_model* model, size_t n,
                                                const double* wi, const double* wo, double* rgb);
/* The same in structure-of-arrays form: pair k is wi = (wi_x[k], wi_y[k], wi_z[k]), wo likewise,
 * and its value goes to (r[k], g[k], b[k]), equal to cbrdf_model_eval bit for bit. Both batch
 * forms are vectorized and use up to cbrdf_thread_limit() threads; the arrays must not overlap.
 * Errors as cbrdf_model_eval_batch's (outputs unchanged). */
CBRDF_C_API cbrdf_status cbrdf_model_eval_batch_soa(const cbrdf_model* model, size_t n,
                                                    const double* wi_x, const double* wi_y,
                                                    const double* wi_z, const double* wo_x,
                                                    const double* wo_y, const double* wo_z,
                                                    double* r, double* g, double* b);

/* ---- Importance sampling ----------------------------------------------------------------------
 */

/* Draws n incident directions wi for the outgoing directions wo (n triples) from the uniform
 * numbers u (n pairs; values outside [0, 1) are clamped into it) with cbrdf::BrdfSampler
 * (cbrdf/sampling.h, default settings): per sample, wi (a unit vector), its density pdf (per unit
 * solid angle, equal to cbrdf_model_pdf(wo, wi)) and weight = f(wi, wo) * cos(theta_i) / pdf in
 * RGB. A rejected sample (wo at or below the horizon, or wi reflected below it) has wi = (0, 0, 0),
 * pdf = 0 and weight = 0. The sampler is built on the handle's first sampling call (thread-safe;
 * its tables fill in on first use), so that call costs more. With n == 0 the pointers may be NULL.
 * Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, n too large, a wo that is not
 * a finite unit vector or a non-finite u, checked before anything is written), or
 * CBRDF_ERROR_INTERNAL (out of memory). */
CBRDF_C_API cbrdf_status cbrdf_model_sample_batch(const cbrdf_model* model, size_t n,
                                                  const double* wo, const double* u, double* wi,
                                                  double* pdf, double* weight);
/* The sampler's density of drawing wi given wo (note the order: wo first, as
 * cbrdf::BrdfSampler::pdf), 0 when either is at or below the horizon. Returns CBRDF_OK, or
 * CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, a direction that is not a finite unit vector), or
 * CBRDF_ERROR_INTERNAL (out of memory). */
CBRDF_C_API cbrdf_status cbrdf_model_pdf(const cbrdf_model* model, const double wo[3],
                                         const double wi[3], double* pdf);

/* ---- Full MERL tables -------------------------------------------------------------------------
 */

/* Doubles in a full MERL table: 3 * 90 * 90 * 180 = 4,374,000. */
CBRDF_C_API size_t cbrdf_merl_table_size(void);

/* Writes the model's full MERL table as a .binary file stores it (cbrdf/merl_io.h): three channel
 * blocks R, G, B of 1,458,000 values, index phi_d + 180 * (theta_d + 90 * theta_h), each value the
 * physical value divided by the channel's MERL scale (1/1500, 1.15/1500, 1.66/1500); not-measured
 * bins hold the source's negative (or NaN) stored values bit for bit. count must be
 * cbrdf_merl_table_size(). Takes about a second and 35 MB of temporary memory. Returns CBRDF_OK,
 * or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, another count), or CBRDF_ERROR_INTERNAL (out
 * of memory). */
CBRDF_C_API cbrdf_status cbrdf_model_table(const cbrdf_model* model, double* stored_values,
                                           size_t count);
/* Writes that table as a MERL .binary file (34,992,012 bytes), atomically (cbrdf::write_merl: a
 * temporary beside the target renamed over it). Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT
 * (a NULL pointer), CBRDF_ERROR_IO (the write failed; an existing target is left untouched), or
 * CBRDF_ERROR_INTERNAL (out of memory). */
CBRDF_C_API cbrdf_status cbrdf_model_write_merl(const cbrdf_model* model, const char* path);

/* Frees a buffer returned by this library (cbrdf_encode_table). NULL is allowed. */
CBRDF_C_API void cbrdf_free(void* p);

/* ---- Encoding ---------------------------------------------------------------------------------
 */

/* cbrdf_encode_settings.bits: chosen from the data. */
#define CBRDF_BITS_AUTO 0

/* Encoder settings. Fields are only ever appended: fill the struct with
 * cbrdf_encode_settings_init, then change the fields you need. */
typedef struct cbrdf_encode_settings {
  uint32_t struct_size; /* sizeof(cbrdf_encode_settings), set by cbrdf_encode_settings_init */
  int bits;             /* bits per quantized marginal value, 6 to 16 (the quality knob), or
                           CBRDF_BITS_AUTO (the default): the fewest bits costing at most 0.05 dB
                           tone-mapped and 0.5 dB linear sphere PSNR against the unquantized
                           model */
  int zstd_level;       /* 1 to 22: the effort knob (19) */
  int slices;           /* uniform theta_d slices, 1 to 90 (6, the paper's) */
  int components;       /* copula components per slice and channel, 1 to 8 (1, the paper's) */
  int family;           /* a cbrdf_family, CBRDF_FAMILY_AUTO included (CBRDF_FAMILY_FRANK) */
  int threads;          /* fitting threads, 0 (one per core) to 256 (1); results are identical */
  /* Since 1.4: the residual layer (container 1.2; spec/container.md 4.6). */
  double max_error; /* > 0: every measured bin decodes within this bound of the source,
                       |log1p(decoded / k) - log1p(source / k)| <= max_error on stored values
                       with k = 1e-4 (a relative bound), 1e-6 to 16; 0 (the default): none */
  int lossless;     /* 1: the decoded table equals the source bit for bit (excludes
                       max_error); 0 (the default): not */
  /* Since 1.6. */
  int mixture_copulas; /* with components > 1: 1 (the default) fits each component's copula, 0
                          leaves them at independence (about half the fit's time and 6% fewer
                          bytes at the same bits, for about the same tone-mapped PSNR per byte) */
} cbrdf_encode_settings;

/* Sets every field to its default (as `cbrdf encode` without options, except threads = 1) and
 * struct_size to sizeof(cbrdf_encode_settings). Clears the last error; with settings NULL, sets
 * CBRDF_ERROR_INVALID_ARGUMENT and does nothing else. */
CBRDF_C_API void cbrdf_encode_settings_init(cbrdf_encode_settings* settings);

/* Fits the model to a full MERL table (layout of cbrdf_model_table; count must be
 * cbrdf_merl_table_size(); negative and NaN values mean not measured and are kept bit for bit)
 * and writes it as a .cbrdf file in a new buffer: *out_bytes (free it with cbrdf_free) of
 * *out_size bytes. settings may be NULL for the defaults. Takes seconds (mixtures: tens of
 * seconds). On failure *out_bytes is NULL and *out_size 0 (when those pointers are not NULL).
 * Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, another count,
 * settings->struct_size smaller than the first version of the struct, a setting out of its range:
 * the message names the field and the range), CBRDF_ERROR_NUMERIC (a +Inf value, or a channel
 * whose largest value is outside what the fit supports), CBRDF_ERROR_LIMIT, or
 * CBRDF_ERROR_INTERNAL. */
CBRDF_C_API cbrdf_status cbrdf_encode_table(const double* stored_values, size_t count,
                                            const cbrdf_encode_settings* settings, void** out_bytes,
                                            size_t* out_size);
/* Reads a MERL .binary (cbrdf::read_merl: 90x90x180, or 90x90x360 folded), encodes it as
 * cbrdf_encode_table does (the metadata records the input's file name) and writes the .cbrdf file
 * atomically. in_path and out_path may name the same file. Returns CBRDF_OK, or the codes of
 * cbrdf_encode_table, and CBRDF_ERROR_NOT_FOUND, CBRDF_ERROR_IO, CBRDF_ERROR_TRUNCATED,
 * CBRDF_ERROR_CORRUPT, CBRDF_ERROR_UNSUPPORTED (reading the input) or CBRDF_ERROR_IO (writing the
 * output; an existing output is left untouched). */
CBRDF_C_API cbrdf_status cbrdf_encode_merl_file(const char* in_path, const char* out_path,
                                                const cbrdf_encode_settings* settings);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* CBRDF_CBRDF_C_H_ */
