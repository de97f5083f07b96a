// SPDX-License-Identifier: MIT
/* Links only the installed whole-C-API library (found with pkg-config cbrdf: libcbrdf_encoder),
   rebuilds a golden file's table, encodes it again and evaluates the result: decoder and encoder
   halves from one library. Usage: consumer_c_encoder FILE.cbrdf */
#include <cbrdf/cbrdf_c.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int fail(const char* what) {
  fprintf(stderr, "%s: %s\n", what, cbrdf_last_error_message());
  printf("consumer_c_encoder: FAILED\n");
  return 1;
}

int main(int argc, char** argv) {
  const double wi[3] = {0.0, 0.6, 0.8}, wo[3] = {0.0, -0.6, 0.8};
  double original[3], again[3];
  cbrdf_encode_settings settings;
  cbrdf_model *model, *reencoded;
  double* table;
  void* bytes = NULL;
  size_t size = 0;
  if (argc != 2) {
    fprintf(stderr, "usage: consumer_c_encoder FILE.cbrdf\n");
    return 2;
  }
  model = cbrdf_model_open_file(argv[1]);
  if (!model) return fail("open");
  table = malloc(cbrdf_merl_table_size() * sizeof(double));
  if (!table) return fail("malloc");
  if (cbrdf_model_table(model, table, cbrdf_merl_table_size()) != CBRDF_OK) return fail("table");
  cbrdf_encode_settings_init(&settings);
  if (cbrdf_encode_table(table, cbrdf_merl_table_size(), &settings, &bytes, &size) != CBRDF_OK) {
    return fail("encode");
  }
  reencoded = cbrdf_model_open_memory(bytes, size);
  if (!reencoded) return fail("open the encoded bytes");
  if (cbrdf_model_eval(model, wi, wo, original) != CBRDF_OK ||
      cbrdf_model_eval(reencoded, wi, wo, again) != CBRDF_OK) {
    return fail("eval");
  }
  printf("re-encoded into %zu bytes; eval %.6g against %.6g\n", size, again[0], original[0]);
  cbrdf_model_free(reencoded);
  cbrdf_model_free(model);
  cbrdf_free(bytes);
  free(table);
  /* Refitting a single-component model from its own table reproduces it closely. */
  if (!(size > 0 && isfinite(again[0]) && fabs(again[0] - original[0]) <= 0.1 * original[0])) {
    printf("consumer_c_encoder: FAILED\n");
    return 1;
  }
  printf("consumer_c_encoder: ok\n");
  return 0;
}
