// SPDX-License-Identifier: MIT
/* The C side of cbrdf.wasm: what cbrdf.mjs needs beyond the C API (cbrdf/cbrdf_c.h), whose
 * functions the module exports as they are. Kept to plain values, so that the JavaScript side
 * needs no struct layouts. */
#include <stddef.h>
#include <stdint.h>

#include "cbrdf/cbrdf_c.h"

#define CBRDF_WASM_EXPORT __attribute__((visibility("default"), used))

/* The module has no threads: every parallel loop runs on the calling thread. */
CBRDF_WASM_EXPORT void cbrdf_wasm_init(void) {
  cbrdf_set_thread_limit(1);
}

/* The fields of cbrdf_model_info as doubles, in cbrdf.mjs's order (CBRDF_WASM_INFO_FIELDS). The
 * 64-bit counts are exact as doubles below 2^53 (files are at most 64 MiB). */
#define CBRDF_WASM_INFO_FIELDS 12
CBRDF_WASM_EXPORT int cbrdf_wasm_info_fields(void) {
  return CBRDF_WASM_INFO_FIELDS;
}

CBRDF_WASM_EXPORT cbrdf_status cbrdf_wasm_info(const cbrdf_model* model, double* out) {
  cbrdf_model_info info;
  info.struct_size = (uint32_t)sizeof info;
  const cbrdf_status s = cbrdf_model_get_info(model, &info);
  if (s != CBRDF_OK || out == NULL) return s;
  const double fields[CBRDF_WASM_INFO_FIELDS] = {info.version_major,
                                                 info.version_minor,
                                                 info.slices,
                                                 info.max_components,
                                                 info.bits,
                                                 (double)info.file_bytes,
                                                 (double)info.not_measured_bins,
                                                 info.residual_mode,
                                                 info.residual_max_error,
                                                 info.residual_min_error,
                                                 info.residual_knee,
                                                 (double)info.residual_bytes};
  for (int i = 0; i < CBRDF_WASM_INFO_FIELDS; ++i) out[i] = fields[i];
  return CBRDF_OK;
}
