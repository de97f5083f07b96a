/* SPDX-License-Identifier: MIT */
/* The C side of the (wi, wo) convention and rejected-draw tests (issue 42), plain C99 on the C API.
 *
 *   convention_reference pairs MODEL.cbrdf
 *     The test pairs (grazing, below the horizon, (0, 0, 0), pairs whose density changes when
 *     swapped, random ones), one a line: wi (3), wo (3), f = cbrdf_model_eval (3) and
 *     pdf = cbrdf_model_sample_pdf(wi, wo), %.17g. The C++, Python and JavaScript tests read them
 *     and compare their own f and pdf. It checks first that the batch call equals the single one
 *     bit for bit, that cbrdf_model_eval_pdf and the deprecated cbrdf_model_pdf(wo, wi) agree,
 *     and that enough pairs change density when swapped for a swapped order to be caught.
 *   convention_reference draws N MODEL.cbrdf...
 *     N draws spread over the models and 16 elevations (theta_o 0 to 89 degrees, phi_o varied)
 *     through cbrdf_model_sample_batch, fed straight back into cbrdf_model_eval_batch and
 *     cbrdf_model_sample_pdf: every call CBRDF_OK, nothing NaN, a rejected draw exactly 0. Under
 *     a sanitizer N is divided by 100 (the suite runs there too).
 * Exits 0 when every check holds, 1 (saying which failed) otherwise, 2 on a usage error. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cbrdf/cbrdf_c.h"

#if defined(__SANITIZE_ADDRESS__)
#define CONVENTION_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
#define CONVENTION_SANITIZED 1
#endif
#endif
#ifndef CONVENTION_SANITIZED
#define CONVENTION_SANITIZED 0
#endif

static const double kPi = 3.14159265358979323846;
static int failures = 0;

static void fail(const char* what, long index) {
  if (failures < 20) {
    fprintf(stderr, "FAILED: %s (at %ld; last error: %s)\n", what, index,
            cbrdf_last_error_message());
  }
  ++failures;
}

static unsigned long long rng_state = 0x9E3779B97F4A7C15ull;
static double uniform01(void) {
  rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
  return (double)(rng_state >> 11) / 9007199254740992.0;
}

static void direction(double theta_deg, double phi_deg, double* w) {
  const double t = theta_deg * kPi / 180, p = phi_deg * kPi / 180;
  w[0] = sin(t) * cos(p);
  w[1] = sin(t) * sin(p);
  w[2] = cos(t);
}

static cbrdf_model* open_model(const char* path) {
  cbrdf_model* m = cbrdf_model_open_file(path);
  if (m == NULL) fprintf(stderr, "cannot open %s: %s\n", path, cbrdf_last_error_message());
  return m;
}

#define MAX_PAIRS 1024

/* The pairs: a grid of elevations with grazing ones (89.9 degrees and z = 1e-9), below the
 * horizon in wi and in wo, (0, 0, 0) as wi and as wo, and uniform random upper-hemisphere pairs. */
static int make_pairs(double* wi, double* wo) {
  static const double thetas[] = {0, 1, 15, 30, 45, 60, 75, 85, 89, 89.9};
  const int nt = (int)(sizeof thetas / sizeof thetas[0]);
  int n = 0, a, b, k;
  for (a = 0; a < nt; ++a) {
    for (b = 0; b < nt; ++b) {
      direction(thetas[a], 37.0 * a + 11.0 * b, wi + 3 * n);
      direction(thetas[b], 180.0 + 23.0 * b, wo + 3 * n);
      ++n;
    }
  }
  for (k = 0; k < 8; ++k) { /* z = 1e-9: as grazing as a unit vector gets */
    const double p = 45.0 * k * kPi / 180, s = sqrt(1 - 1e-18);
    double* i = wi + 3 * n;
    i[0] = s * cos(p);
    i[1] = s * sin(p);
    i[2] = 1e-9;
    direction(10.0 * k, 90.0 * k, wo + 3 * n);
    ++n;
  }
  for (k = 0; k < 12; ++k) { /* below the horizon: wi, wo, both */
    direction(k % 3 == 1 ? 40.0 : 95.0 + 7 * k, 30.0 * k, wi + 3 * n);
    direction(k % 3 == 0 ? 50.0 : 91.0 + 8 * k, 200.0 + 13 * k, wo + 3 * n);
    ++n;
  }
  for (k = 0; k < 6; ++k) { /* the rejected draw's (0, 0, 0): as wi, as wo, as both */
    memset(wi + 3 * n, 0, 3 * sizeof(double));
    direction(15.0 * k, 60.0 * k, wo + 3 * n);
    if (k >= 2) {
      direction(15.0 * k, 60.0 * k, wi + 3 * n);
      memset(wo + 3 * n, 0, 3 * sizeof(double));
    }
    if (k >= 4) memset(wi + 3 * n, 0, 3 * sizeof(double));
    ++n;
  }
  while (n < 400) { /* random pairs over the upper hemisphere */
    direction(acos(uniform01()) * 180 / kPi, 360 * uniform01(), wi + 3 * n);
    direction(acos(uniform01()) * 180 / kPi, 360 * uniform01(), wo + 3 * n);
    ++n;
  }
  return n;
}

static int run_pairs(const char* path) {
  static double wi[3 * MAX_PAIRS], wo[3 * MAX_PAIRS], f[3 * MAX_PAIRS], batch[3 * MAX_PAIRS],
      pdf[MAX_PAIRS];
  cbrdf_model* m = open_model(path);
  int n, k, swapped_differ = 0;
  if (m == NULL) return 1;
  n = make_pairs(wi, wo);
  for (k = 0; k < n; ++k) {
    double rgb[3], p = -1, q = -1, r = -1;
    if (cbrdf_model_eval(m, wi + 3 * k, wo + 3 * k, f + 3 * k) != CBRDF_OK) fail("eval", k);
    if (cbrdf_model_sample_pdf(m, wi + 3 * k, wo + 3 * k, pdf + k) != CBRDF_OK) {
      fail("sample_pdf", k);
    }
    if (cbrdf_model_eval_pdf(m, wi + 3 * k, wo + 3 * k, rgb, &p) != CBRDF_OK ||
        memcmp(rgb, f + 3 * k, sizeof rgb) != 0 || p != pdf[k]) {
      fail("eval_pdf differs from eval and sample_pdf", k);
    }
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
    if (cbrdf_model_pdf(m, wo + 3 * k, wi + 3 * k, &q) != CBRDF_OK || q != pdf[k]) {
      fail("the deprecated cbrdf_model_pdf(wo, wi) differs from sample_pdf(wi, wo)", k);
    }
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
    if (cbrdf_model_sample_pdf(m, wo + 3 * k, wi + 3 * k, &r) != CBRDF_OK) fail("swapped", k);
    if (fabs(r - pdf[k]) > 1e-6 * fabs(pdf[k])) ++swapped_differ;
    if (isnan(pdf[k]) || isnan(f[3 * k]) || isnan(f[3 * k + 1]) || isnan(f[3 * k + 2])) {
      fail("NaN", k);
    }
  }
  if (cbrdf_model_eval_batch(m, (size_t)n, wi, wo, batch, 1) != CBRDF_OK ||
      memcmp(batch, f, 3 * (size_t)n * sizeof(double)) != 0) {
    fail("eval_batch differs from eval", -1);
  }
  /* A language that swapped wi and wo must be caught: most pairs change density when swapped. */
  if (swapped_differ < n / 2) fail("too few pairs change density when swapped", swapped_differ);
  for (k = 0; k < n; ++k) {
    printf("%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", wi[3 * k],
           wi[3 * k + 1], wi[3 * k + 2], wo[3 * k], wo[3 * k + 1], wo[3 * k + 2], f[3 * k],
           f[3 * k + 1], f[3 * k + 2], pdf[k]);
  }
  fprintf(stderr, "%d pairs (%d change density when swapped), %d failures\n", n, swapped_differ,
          failures);
  cbrdf_model_free(m);
  return failures ? 1 : 0;
}

#define BLOCK 4096

static int run_draws(long total, int models, char** paths) {
  static double wo[3 * BLOCK], u[2 * BLOCK], wi[3 * BLOCK], pdf[BLOCK], weight[3 * BLOCK],
      f[3 * BLOCK];
  long draws = 0, rejected = 0;
  int mi, e;
  if (CONVENTION_SANITIZED) total /= 100;
  for (mi = 0; mi < models; ++mi) {
    cbrdf_model* m = open_model(paths[mi]);
    const long per_elevation = total / models / 16;
    if (m == NULL) return 1;
    for (e = 0; e < 16; ++e) {
      const double theta = 89.0 * e / 15;
      long done = 0;
      while (done < per_elevation) {
        const long left = per_elevation - done;
        const int n = (int)(left < BLOCK ? left : BLOCK);
        int k;
        for (k = 0; k < n; ++k) {
          direction(theta, 360 * uniform01(), wo + 3 * k);
          u[2 * k] = uniform01();
          u[2 * k + 1] = uniform01();
        }
        if (cbrdf_model_sample_batch(m, (size_t)n, wo, u, wi, pdf, weight, 0) != CBRDF_OK) {
          fail("sample_batch", draws);
        }
        if (cbrdf_model_eval_batch(m, (size_t)n, wi, wo, f, 0) != CBRDF_OK) {
          fail("eval_batch of the drawn directions", draws);
        }
        for (k = 0; k < n; ++k) {
          double p = -1;
          const double* i = wi + 3 * k;
          if (cbrdf_model_sample_pdf(m, i, wo + 3 * k, &p) != CBRDF_OK) {
            fail("sample_pdf of a drawn direction", draws + k);
          }
          if (isnan(p) || isnan(pdf[k]) || isnan(f[3 * k]) || isnan(f[3 * k + 1]) ||
              isnan(f[3 * k + 2])) {
            fail("NaN", draws + k);
          }
          if (pdf[k] == 0.0) {
            ++rejected;
            if (i[0] != 0.0 || i[1] != 0.0 || i[2] != 0.0 || p != 0.0 || f[3 * k] != 0.0 ||
                f[3 * k + 1] != 0.0 || f[3 * k + 2] != 0.0) {
              fail("a rejected draw is not exactly 0", draws + k);
            }
          } else if (p != pdf[k]) {
            fail("sample_pdf(wi, wo) differs from the drawn pdf", draws + k);
          }
        }
        done += n;
        draws += n;
      }
    }
    cbrdf_model_free(m);
  }
  printf("%ld draws over %d models and 16 elevations, %ld rejected, %d failures\n", draws, models,
         rejected, failures);
  if (draws == 0) fail("no draws", 0);
  return failures ? 1 : 0;
}

int main(int argc, char** argv) {
  if (argc == 3 && strcmp(argv[1], "pairs") == 0) return run_pairs(argv[2]);
  if (argc >= 4 && strcmp(argv[1], "draws") == 0) {
    return run_draws(strtol(argv[2], NULL, 10), argc - 3, argv + 3);
  }
  fprintf(stderr, "usage: %s pairs MODEL.cbrdf | draws N MODEL.cbrdf...\n", argv[0]);
  return 2;
}
