// SPDX-License-Identifier: MIT
/* Links only the installed decoder (found with pkg-config cbrdf-decoder), opens a golden file,
   describes and evaluates it. Usage: consumer_c FILE.cbrdf */
#include <cbrdf/cbrdf_c.h>
#include <math.h>
#include <stdio.h>

int main(int argc, char** argv) {
  cbrdf_model* model;
  cbrdf_model_info info;
  double wi[3] = {0.0, 0.6, 0.8}, wo[3] = {0.0, -0.6, 0.8}, rgb[3] = {0, 0, 0}, back[3];
  if (argc != 2) {
    fprintf(stderr, "usage: consumer_c FILE.cbrdf\n");
    return 2;
  }
  printf("cbrdf %s\n", cbrdf_version_string());
  model = cbrdf_model_open_file(argv[1]);
  if (!model) {
    fprintf(stderr, "open: %s\n", cbrdf_last_error_message());
    return 1;
  }
  info.struct_size = sizeof info;
  if (cbrdf_model_get_info(model, &info) != CBRDF_OK) {
    fprintf(stderr, "info: %s\n", cbrdf_last_error_message());
    return 1;
  }
  if (cbrdf_model_eval(model, wi, wo, rgb) != CBRDF_OK ||
      cbrdf_model_eval(model, wo, wi, back) != CBRDF_OK) {
    fprintf(stderr, "eval: %s\n", cbrdf_last_error_message());
    return 1;
  }
  printf("version %d.%d, %d slices, %d bits, eval %.6g %.6g %.6g\n", info.version_major,
         info.version_minor, info.slices, info.bits, rgb[0], rgb[1], rgb[2]);
  cbrdf_model_free(model);
  /* A real value, reciprocal, and a refused file names its error. */
  if (!(rgb[0] > 0 && isfinite(rgb[0])) || rgb[0] != back[0] || info.slices < 1) {
    printf("consumer_c: FAILED\n");
    return 1;
  }
  if (cbrdf_model_open_file("/nonexistent.cbrdf") != NULL ||
      cbrdf_last_error_code() != CBRDF_ERROR_NOT_FOUND) {
    printf("consumer_c: FAILED (missing file)\n");
    return 1;
  }
  printf("consumer_c: ok\n");
  return 0;
}
