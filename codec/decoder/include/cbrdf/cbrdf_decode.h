/* SPDX-License-Identifier: MIT */
/** @file
 * The cbrdf C API, decoder part (libcbrdf_decoder): open, describe, evaluate and sample .cbrdf
 * files from C (C99) or any language with a C foreign-function interface. The encoder part is
 * cbrdf/cbrdf_encode.h (libcbrdf_encoder); cbrdf/cbrdf_c.h includes both.
 *
 * Binary interface. These functions are cbrdf's stable ABI: the shared libraries export them and
 * nothing else. Within one SONAME major version a function is never removed and its signature
 * and meaning never change; structs only grow at their end (struct_size). The C++ headers are for
 * static linking only. The section behind CBRDF_EXPERIMENTAL_API (end of this file) is not
 * covered by that promise.
 *
 * Conventions (they hold for every function below unless its comment says otherwise):
 *
 * - Errors. Every function that can fail returns a cbrdf_status (or NULL for a handle) and
 *   records the failure as the calling thread's last error: cbrdf_last_error_code() and
 *   cbrdf_last_error_message() (a message naming the argument, file, chunk or byte offset). Every
 *   successful call of such a function clears the last error (code CBRDF_OK, message ""). The
 *   functions that cannot fail (version, names, the last error itself, the thread limit,
 *   cbrdf_merl_table_size, cbrdf_model_free, cbrdf_free) return no status and leave the last
 *   error as it is. No C++ exception crosses this API: running out of memory is reported as
 *   CBRDF_ERROR_INTERNAL with the message "out of memory".
 * - Arguments. Every pointer argument must be non-NULL unless its comment says otherwise; a NULL
 *   one fails with CBRDF_ERROR_INVALID_ARGUMENT, and so does any out-of-range index or count. A
 *   function that fails leaves its outputs unspecified unless its comment says otherwise.
 * - Directions are unit vectors in the surface's local frame, z the normal, as three doubles
 *   (x, y, z) (three floats in the _f32 calls). A direction with a non-finite component or whose
 *   squared length differs from 1 by more than 1e-3 fails with CBRDF_ERROR_INVALID_ARGUMENT; one
 *   within that tolerance is scaled to unit length before use (unless its squared length is 1 to
 *   within 4 ulp, when it is used as given), so |w| = 1.0004 gives the value at w / |w|. The
 *   calls that evaluate (cbrdf_model_eval*, cbrdf_model_sample_pdf, cbrdf_model_eval_pdf and
 *   cbrdf_model_pdf) also accept exactly (0, 0, 0), a rejected draw's wi, and give 0 for it.
 * - Argument order. A direction pair is passed as (wi, wo), incident direction first, the order
 *   of f(wi, wo) (as in cbrdf_model_eval and cbrdf_model_sample_pdf); inputs come before outputs.
 *   Sampling takes the given direction wo and returns wi. (cbrdf_model_pdf, deprecated, is the one
 *   exception: (wo, wi).) BRDF values are physical (1/sr), per colour channel R, G, B.
 * - Threads. Functions taking a `const cbrdf_model*` may be called concurrently from any number
 *   of threads on the same handle (evaluation and sampling are read-only after lazy, thread-safe
 *   initialization). cbrdf_model_free must not run concurrently with any other use of the handle.
 *   The last error is per thread. Batch calls take `threads`: the most threads the call may use,
 *   counting the calling thread; 1 runs it on the calling thread alone (call it so from a
 *   renderer's own worker threads, so that cbrdf's pool does not nest inside the renderer's);
 *   0 (or less) means up to cbrdf_thread_limit(). The results do not depend on it.
 * - Memory. Strings returned by cbrdf_version_string, cbrdf_status_name and cbrdf_family_name are
 *   static. Strings returned through a model handle live as long as the handle. Buffers returned
 *   by the encoder are freed with cbrdf_free.
 * - Cost (CPU time of opening the golden files, tests/data/golden, on a loaded 2-core machine;
 *   docs/renderer.md, Cost, has the benchmarks). Opening a file without a residual layer takes
 *   4 to 7 ms; the first open in a process 3 to 10 ms more (the decoder's below-horizon reference
 *   mask, built once). A file
 *   with a residual layer (info.residual_mode != CBRDF_RESIDUAL_NONE) holds one code per MERL bin,
 *   4,374,000 codes decoded at every open: 80 to 90 ms (_BOUNDED, _ROW_BOUNDED) and 190 to 250 ms
 *   (_INTERPOLATED, which also rebuilds each bin's residual); the handle keeps the codes (17 MB;
 *   _INTERPOLATED also the residuals, 35 MB more). Open such a file once and keep the handle.
 */
#ifndef CBRDF_CBRDF_DECODE_H_
#define CBRDF_CBRDF_DECODE_H_

#include <stddef.h>
#include <stdint.h>

#include "cbrdf/cbrdf_c_export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Version ----------------------------------------------------------------------------------
 */

/** The library's version, e.g. "1.2.0". Static; never NULL. */
CBRDF_C_API const char* cbrdf_version_string(void);
/** The same as major * 10000 + minor * 100 + patch (1.2.0 -> 10200), as zstd numbers its versions;
 * equal to CBRDF_VERSION of cbrdf/version.h. */
CBRDF_C_API int cbrdf_version_number(void);

/* ---- Errors -----------------------------------------------------------------------------------
 */

/** Stable numeric codes, equal to cbrdf::ErrorCode (cbrdf/status.h): never renumbered, only
 * appended to. */
typedef enum cbrdf_status {
  CBRDF_OK = 0,
  CBRDF_ERROR_IO = 1,               /**< the operating system refused a read or write */
  CBRDF_ERROR_NOT_FOUND = 2,        /**< a named file does not exist */
  CBRDF_ERROR_TRUNCATED = 3,        /**< the data ends before its declared content */
  CBRDF_ERROR_BAD_SIGNATURE = 4,    /**< not a file of the expected kind */
  CBRDF_ERROR_UNSUPPORTED = 5,      /**< a newer version or an unknown critical feature */
  CBRDF_ERROR_CORRUPT = 6,          /**< structurally invalid data */
  CBRDF_ERROR_CHECKSUM = 7,         /**< a checksum does not match */
  CBRDF_ERROR_LIMIT = 8,            /**< a declared size exceeds a documented maximum */
  CBRDF_ERROR_INVALID_ARGUMENT = 9, /**< a caller passed a value outside its domain */
  CBRDF_ERROR_NUMERIC = 10,         /**< NaN, Inf or a value outside a parameter's domain */
  CBRDF_ERROR_INTERNAL = 11,        /**< a bug in cbrdf, or out of memory */
  CBRDF_ERROR_CANCELLED = 12        /**< since 2.3: the caller cancelled (an encode's progress
                                         callback returned nonzero) */
} cbrdf_status;

/** The calling thread's last error: CBRDF_OK after a successful call. */
CBRDF_C_API cbrdf_status cbrdf_last_error_code(void);
/** Its message, "" after a successful call. Never NULL; owned by the library and valid until the
 * calling thread's next call of a function that sets or clears the last error. */
CBRDF_C_API const char* cbrdf_last_error_message(void);
/** A code's short name as `cbrdf` prints it ("ok", "io", "not-found", "truncated",
 * "bad-signature", "unsupported", "corrupt", "checksum", "limit", "invalid-argument", "numeric",
 * "internal", "cancelled"); "unknown" for any other value. Static; never NULL. */
CBRDF_C_API const char* cbrdf_status_name(cbrdf_status status);

/* ---- Threads ----------------------------------------------------------------------------------
 */

/** Caps the threads of every parallel loop in cbrdf (batch evaluation, fitting, tables) at n,
 * counting the calling thread; n <= 0 means one per core. The one global setting
 * (cbrdf/parallel.h); per-call requests (a batch call's `threads`, encode settings' threads) get
 * the smaller of theirs and this. Thread-safe; cannot fail. */
CBRDF_C_API void cbrdf_set_thread_limit(int n);
/** The limit in force, with "one per core" resolved to the core count (at least 1). */
CBRDF_C_API int cbrdf_thread_limit(void);

/* ---- Opening a model --------------------------------------------------------------------------
 */

/** A decoded .cbrdf file, ready for evaluation. Opaque. */
typedef struct cbrdf_model cbrdf_model;

/** Decodes a .cbrdf file held in memory, with the full validation of cbrdf::decode_model (every
 * chunk's checksum, bounds and content). The bytes are not referenced after the call returns.
 * Returns a new handle (free it with cbrdf_model_free), or NULL with the last error set:
 * CBRDF_ERROR_INVALID_ARGUMENT (data NULL), CBRDF_ERROR_TRUNCATED, CBRDF_ERROR_BAD_SIGNATURE,
 * CBRDF_ERROR_UNSUPPORTED, CBRDF_ERROR_CORRUPT, CBRDF_ERROR_CHECKSUM, CBRDF_ERROR_LIMIT,
 * CBRDF_ERROR_NUMERIC, CBRDF_ERROR_INTERNAL.
 * Cost: see Cost at the top of this file (milliseconds; tens of milliseconds with a residual
 * layer). */
CBRDF_C_API cbrdf_model* cbrdf_model_open_memory(const void* data, size_t size);
/** Reads and decodes a .cbrdf file (a regular file, or a path naming an open descriptor such as
 * /dev/stdin; at most 64 MiB). Returns a new handle or NULL with the last error set: the codes of
 * cbrdf_model_open_memory, and CBRDF_ERROR_INVALID_ARGUMENT (path NULL or empty),
 * CBRDF_ERROR_NOT_FOUND (no such file), CBRDF_ERROR_IO (a directory, FIFO or device, permission,
 * a failed read), CBRDF_ERROR_LIMIT (larger than 64 MiB). Messages start with the path. */
CBRDF_C_API cbrdf_model* cbrdf_model_open_file(const char* path);
/** Frees a handle and everything it owns (strings returned through it become invalid). NULL is
 * allowed and does nothing. Must not race with any other use of the handle. */
CBRDF_C_API void cbrdf_model_free(cbrdf_model* model);

/* ---- Describing a model -----------------------------------------------------------------------
 */

/** cbrdf_model_info.residual_mode: the residual layer (container 1.2, chunk RESD;
 * spec/container.md 4.6). */
typedef enum cbrdf_residual_mode {
  CBRDF_RESIDUAL_NONE = -1,    /**< no residual layer: the copula model alone */
  CBRDF_RESIDUAL_BOUNDED = 0,  /**< one error bound for every measured bin */
  CBRDF_RESIDUAL_LOSSLESS = 1, /**< the decoded table equals the source bit for bit */
  /** A bound per (theta_h, theta_d) row, coarser where a bin weighs less in rendering (written by
   * the rate control; cbrdf_encode_settings.max_error writes _BOUNDED, or with residual_steps
   * CBRDF_RESIDUAL_STEPS_VISIBILITY row bounds). */
  CBRDF_RESIDUAL_ROW_BOUNDED = 2,
  /** Since 1.5: row bounds, the codes correcting an interpolation of coarser bins; the finest level
   * (odd theta_d or phi_d) has a multiple of its row's bound (written by the rate control). */
  CBRDF_RESIDUAL_INTERPOLATED = 3,
  /** Since 2.2 (container 1.3): _INTERPOLATED with a multiple of the row's bound on every level
   * between the finest and the coarsest too (written by the rate control). */
  CBRDF_RESIDUAL_LEVEL_STEPS = 4
} cbrdf_residual_mode;

/** What a file holds. Fields are only ever appended: set struct_size to sizeof(cbrdf_model_info)
 * before the call, and a newer library fills only what the caller's version of the struct has. */
typedef struct cbrdf_model_info {
  uint32_t struct_size;       /**< in: sizeof(cbrdf_model_info); out: the bytes filled */
  int version_major;          /**< container version: 1 */
  int version_minor;          /**< the file's container minor version: 0 (the paper's model),
                                 1 (mixtures), 2 (a residual layer; the encoder writes 2 only
                                 for files with one, else the lowest that holds the model) */
  int slices;                 /**< theta_d slices, 1 to 90 */
  int max_components;         /**< most components in any slice and channel (1 unless a mixture) */
  int bits;                   /**< bits per quantized marginal value, 6 to 16 */
  uint64_t file_bytes;        /**< size of the .cbrdf file */
  uint64_t not_measured_bins; /**< (channel, bin) pairs marked not measured, over all channels */
  /* Since 1.4: the residual layer (container 1.2, chunk RESD; spec/container.md 4.6). */
  int residual_mode;         /**< a cbrdf_residual_mode value */
  double residual_max_error; /**< all but _LOSSLESS: every measured bin decodes within this
                                bound of the source, |log1p(decoded / k) - log1p(source / k)|
                                on stored values; 0 otherwise */
  double residual_min_error; /**< _ROW_BOUNDED, _INTERPOLATED: the finest row's bound (on the
                                coarser levels); _BOUNDED: max_error */
  double residual_knee;      /**< k of that bound, in stored units (0 without a bounded layer) */
  uint64_t residual_bytes;   /**< stored bytes of the RESD chunk (0 without one) */
} cbrdf_model_info;

/** Fills *info (see cbrdf_model_info). Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT when model
 * or info is NULL or info->struct_size is smaller than the first version of the struct. */
CBRDF_C_API cbrdf_status cbrdf_model_get_info(const cbrdf_model* model, cbrdf_model_info* info);

/** Slice `slice` (0 to info.slices - 1) covers theta_d bins [*theta_d_begin, *theta_d_end) of the
 * 90 MERL theta_d bins. Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, slice
 * out of range). */
CBRDF_C_API cbrdf_status cbrdf_model_get_slice(const cbrdf_model* model, int slice,
                                               int* theta_d_begin, int* theta_d_end);

/** The copula families (equal to cbrdf::CopulaFamily, as stored in files). CBRDF_FAMILY_AUTO is an
 * encoder setting only (fit every family, keep the best); a model never holds it. */
typedef enum cbrdf_family {
  CBRDF_FAMILY_AUTO = -1,
  CBRDF_FAMILY_INDEPENDENCE = 0, /**< the separable model; no parameter */
  CBRDF_FAMILY_FRANK = 1, /**< the paper's; its convention: theta < 0 is positive dependence */
  CBRDF_FAMILY_CLAYTON = 2,
  CBRDF_FAMILY_GUMBEL = 3, /**< Gumbel-Hougaard */
  CBRDF_FAMILY_JOE = 4
} cbrdf_family;

/** A family's name as the command line spells it ("independence", "frank", "clayton", "gumbel",
 * "joe", "auto"); "unknown" for any other value. Static; never NULL. */
CBRDF_C_API const char* cbrdf_family_name(int family);

/** Number of copula components (1, or up to 8 in a mixture) of slice `slice`, colour channel
 * `channel` (0 R, 1 G, 2 B). Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer,
 * slice or channel out of range). */
CBRDF_C_API cbrdf_status cbrdf_model_get_component_count(const cbrdf_model* model, int slice,
                                                         int channel, int* count);
/** Component `component` (0 to count - 1) of a slice and channel: its family (a cbrdf_family
 * value), its copula parameter theta (in the family's own convention) and its scale K (the term's
 * sum over the slice's bins, physical units). The slice's value is the sum over its components.
 * Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, slice, channel or component
 * out of range). */
CBRDF_C_API cbrdf_status cbrdf_model_get_component(const cbrdf_model* model, int slice, int channel,
                                                   int component, int* family, double* theta,
                                                   double* scale);

/** *count = the number of metadata entries (the ancillary mETA chunk: source, encoder, settings),
 * 0 when the file has none. Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (model or count
 * NULL). */
CBRDF_C_API cbrdf_status cbrdf_model_metadata_count(const cbrdf_model* model, size_t* count);
/** Entry i (0 to count - 1) in file order. *key and *value are NUL-terminated strings owned by the
 * handle and valid while it lives (a value holding a NUL byte is cut there). Returns CBRDF_OK, or
 * CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, i out of range). */
CBRDF_C_API cbrdf_status cbrdf_model_metadata_at(const cbrdf_model* model, size_t i,
                                                 const char** key, const char** value);

/* ---- Evaluation -------------------------------------------------------------------------------
 */

/** The model's value f(wi, wo) in RGB (1/sr): continuous in angle (trilinear between MERL bins),
 * 0 when wi or wo is at or below the horizon (z <= 0) or exactly (0, 0, 0) (a rejected draw's
 * wi), reciprocal up to rounding. Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL
 * pointer, any other direction that is not a finite unit vector; rgb is then unchanged). */
CBRDF_C_API cbrdf_status cbrdf_model_eval(const cbrdf_model* model, const double wi[3],
                                          const double wo[3], double rgb[3]);
/** n evaluations: wi, wo and rgb hold n interleaved (x, y, z) / (r, g, b) triples; rgb[3k..3k+2]
 * equals cbrdf_model_eval(wi + 3k, wo + 3k) bit for bit. Vectorized; on up to `threads` threads
 * (see Threads above). With n == 0 the pointers may be NULL. Every direction is checked before
 * anything is written: on CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, n too large for the arrays
 * to exist, a bad direction, the message naming its index) rgb is unchanged. */
CBRDF_C_API cbrdf_status cbrdf_model_eval_batch(const cbrdf_model* model, size_t n,
                                                const double* wi, const double* wo, double* rgb,
                                                int threads);
/** The same in structure-of-arrays form: pair k is wi = (wi_x[k], wi_y[k], wi_z[k]), wo likewise,
 * and its value goes to (r[k], g[k], b[k]), equal to cbrdf_model_eval bit for bit. The arrays
 * must not overlap. Errors as cbrdf_model_eval_batch's (outputs unchanged). */
CBRDF_C_API cbrdf_status cbrdf_model_eval_batch_soa(const cbrdf_model* model, size_t n,
                                                    const double* wi_x, const double* wi_y,
                                                    const double* wi_z, const double* wo_x,
                                                    const double* wo_y, const double* wo_z,
                                                    double* r, double* g, double* b, int threads);
/** Single precision, for renderers (cbrdf::ModelEvaluator::eval_f32): float directions in, float
 * RGB out, from tables rounded to float; its relative error against cbrdf_model_eval is about
 * 1e-5 where the value is not tiny. Errors as cbrdf_model_eval's. */
CBRDF_C_API cbrdf_status cbrdf_model_eval_f32(const cbrdf_model* model, const float wi[3],
                                              const float wo[3], float rgb[3]);
/** n of those: wi, wo and rgb hold n interleaved float triples; rgb[3k..3k+2] equals
 * cbrdf_model_eval_f32(wi + 3k, wo + 3k) bit for bit. Errors and threads as
 * cbrdf_model_eval_batch's. */
CBRDF_C_API cbrdf_status cbrdf_model_eval_batch_f32(const cbrdf_model* model, size_t n,
                                                    const float* wi, const float* wo, float* rgb,
                                                    int threads);

/* ---- Importance sampling ----------------------------------------------------------------------
 */

/* The sampler is cbrdf::BrdfSampler (cbrdf/sampling.h, default settings), built on the handle's
 * first sampling call (thread-safe); its per-theta_o tables fill in on first use, so the first
 * draws at a new elevation cost about a millisecond more. A rejected draw (wo at or below the
 * horizon, or wi reflected below it) has wi = (0, 0, 0), pdf = 0 and weight = 0; it still
 * returns CBRDF_OK. Drawn directions may be passed straight back, rejected ones included: the
 * evaluating calls give 0 for wi = (0, 0, 0), not an error.
 *     cbrdf_model_sample_batch(m, n, wo, u, wi, pdf, weight, 1);  // rejected: wi = 0, pdf = 0
 *     cbrdf_model_eval_batch(m, n, wi, wo, rgb, 1);               // CBRDF_OK; rgb = 0 there
 *     cbrdf_model_sample_pdf(m, wi + 3 * k, wo + 3 * k, &p);      // p == pdf[k] */

/** One draw: the incident direction wi (a unit vector) for the outgoing direction wo from the
 * uniform numbers u1, u2 (values outside [0, 1) are clamped into it), its density *pdf per unit
 * solid angle (equal to cbrdf_model_sample_pdf(wi, wo)) and weight = f(wi, wo) cos(theta_i) / pdf
 * in RGB. Equal bit for bit to draw k of cbrdf_model_sample_batch with the same wo, u1, u2.
 * Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, a wo that is not a finite
 * unit vector, a non-finite u1 or u2; outputs unchanged), or CBRDF_ERROR_INTERNAL (out of
 * memory). */
CBRDF_C_API cbrdf_status cbrdf_model_sample(const cbrdf_model* model, const double wo[3], double u1,
                                            double u2, double wi[3], double* pdf, double weight[3]);
/** n draws: wo (n triples) and u (n pairs u1, u2) in; wi (n triples), pdf (n) and weight (n RGB
 * triples) out, each draw as cbrdf_model_sample. Vectorized, with a cost proportional to n; on up
 * to `threads` threads. With n == 0 the pointers may be NULL. Returns CBRDF_OK, or
 * CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, n too large, a wo that is not a finite unit vector
 * or a non-finite u, checked before anything is written), or CBRDF_ERROR_INTERNAL. */
CBRDF_C_API cbrdf_status cbrdf_model_sample_batch(const cbrdf_model* model, size_t n,
                                                  const double* wo, const double* u, double* wi,
                                                  double* pdf, double* weight, int threads);
/** The sampler's density of drawing wi given wo (per unit solid angle), 0 when either is at or
 * below the horizon or exactly (0, 0, 0) (a rejected draw's wi). Returns CBRDF_OK, or
 * CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, any other direction that is not a finite unit
 * vector), or CBRDF_ERROR_INTERNAL (out of memory). */
CBRDF_C_API cbrdf_status cbrdf_model_sample_pdf(const cbrdf_model* model, const double wi[3],
                                                const double wo[3], double* pdf);
/** cbrdf_model_eval and cbrdf_model_sample_pdf in one call (one check of the arguments): for a
 * renderer's multiple importance sampling of a light sample. Errors as cbrdf_model_sample_pdf's
 * (outputs unchanged). */
CBRDF_C_API cbrdf_status cbrdf_model_eval_pdf(const cbrdf_model* model, const double wi[3],
                                              const double wo[3], double rgb[3], double* pdf);
/** Deprecated: cbrdf_model_sample_pdf with the arguments in the other order (wo, wi). */
CBRDF_C_API CBRDF_C_DEPRECATED("use cbrdf_model_sample_pdf(model, wi, wo, pdf)") cbrdf_status
    cbrdf_model_pdf(const cbrdf_model* model, const double wo[3], const double wi[3], double* pdf);

/* ---- Full MERL tables -------------------------------------------------------------------------
 */

/** Doubles in a full MERL table: 3 * 90 * 90 * 180 = 4,374,000. */
CBRDF_C_API size_t cbrdf_merl_table_size(void);

/** Writes the model's full MERL table as a .binary file stores it (cbrdf/merl_io.h): three channel
 * blocks R, G, B of 1,458,000 values, index phi_d + 180 * (theta_d + 90 * theta_h), each value the
 * physical value divided by the channel's MERL scale (1/1500, 1.15/1500, 1.66/1500); not-measured
 * bins hold the source's negative (or NaN) stored values bit for bit. count must be
 * cbrdf_merl_table_size(). Takes about a second and 35 MB of temporary memory. Returns CBRDF_OK,
 * or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, another count), or CBRDF_ERROR_INTERNAL (out
 * of memory). */
CBRDF_C_API cbrdf_status cbrdf_model_table(const cbrdf_model* model, double* stored_values,
                                           size_t count);
/** Writes that table as a MERL .binary file (34,992,012 bytes), atomically (cbrdf::write_merl: a
 * temporary beside the target renamed over it). Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT
 * (a NULL pointer), CBRDF_ERROR_IO (the write failed; an existing target is left untouched), or
 * CBRDF_ERROR_INTERNAL (out of memory). */
CBRDF_C_API cbrdf_status cbrdf_model_write_merl(const cbrdf_model* model, const char* path);

/** Frees a buffer returned by this library (cbrdf_encode_table). NULL is allowed. */
CBRDF_C_API void cbrdf_free(void* p);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* CBRDF_CBRDF_DECODE_H_ */

/* ---- Experimental ------------------------------------------------------------------------------
 * Calls whose signature or meaning may still change in a minor release: NOT covered by the ABI
 * promise above. Define CBRDF_EXPERIMENTAL_API before including this header to declare them, and
 * link the same version of the library you compiled against (as zstd's
 * ZSTD_STATIC_LINKING_ONLY). */
#if defined(CBRDF_EXPERIMENTAL_API) && !defined(CBRDF_CBRDF_DECODE_EXPERIMENTAL_H_)
#define CBRDF_CBRDF_DECODE_EXPERIMENTAL_H_

#ifdef __cplusplus
extern "C" {
#endif

/** The directional albedo at wo: the reflected fraction of light arriving from wo over the
 * hemisphere, rgb = integral of f(wi, wo) cos(theta_i) dwi, per channel (0 for wo at or below the
 * horizon); for a renderer's light-path decisions (Russian roulette, lobe selection). The model is
 * isotropic, so only wo's elevation matters. A deterministic quadrature over half vectors (180
 * theta_h cells with the MERL spacing by 720 phi_h cells: 129,600 evaluations, on up to `threads`
 * threads): within 0.5% of a brute-force integration, and of the mean weight of
 * cbrdf_model_sample's draws to about 1%. Costs milliseconds: tabulate it once
 * (cbrdf_model_albedo_table) rather than call it per path.
 * Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, a wo that is not a finite
 * unit vector), or CBRDF_ERROR_INTERNAL. */
CBRDF_C_API cbrdf_status cbrdf_model_albedo(const cbrdf_model* model, const double wo[3],
                                            double rgb[3], int threads);
/** The albedo at n elevations, uniform in theta_o: entry k (rgb[3k..3k+2]) is cbrdf_model_albedo
 * at theta_o = (k + 0.5) / n * 90 degrees (bit for bit); n from 1 to 256 (a 0.35 degree step,
 * finer than the albedo varies). A renderer interpolates it linearly in theta_o.
 * Cost: O(n) albedos, n x 129,600 evaluations: measured on one core (release build), about 33 ms
 * per entry for a file of 90 slices x 8 Frank components (n = 256: about 8.5 s), and for Clayton,
 * Gumbel or Joe components up to about 3.5x that for the first entries (their bins' densities are
 * computed on first use and kept), whatever the parameter; divide by the threads given.
 * Returns CBRDF_OK, or CBRDF_ERROR_INVALID_ARGUMENT (a NULL pointer, n out of range), or
 * CBRDF_ERROR_INTERNAL. */
CBRDF_C_API cbrdf_status cbrdf_model_albedo_table(const cbrdf_model* model, size_t n, double* rgb,
                                                  int threads);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* CBRDF_EXPERIMENTAL_API */
