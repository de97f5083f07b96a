// SPDX-License-Identifier: MIT
/* The C API (cbrdf/cbrdf_c.h), compiled as C99: every function, every error path, and results
 * checked against the golden files' recorded contents (`cbrdf info --json`), against each other
 * (eval and eval_batch bit for bit, sample_batch and pdf, table and write_merl) and against the
 * BRDF's properties (reciprocity, zero below the horizon). Prints "N passed, M failed" last and
 * exits nonzero on any failure. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The experimental section is tested too. */
#define CBRDF_EXPERIMENTAL_API 1
#include "cbrdf/cbrdf_c.h"
#include "cbrdf/version.h"

#ifndef CBRDF_TEST_DATA_DIR
#error "CBRDF_TEST_DATA_DIR must name tests/data"
#endif
#ifndef CBRDF_TEST_TMP_DIR
#error "CBRDF_TEST_TMP_DIR must name a writable directory"
#endif

#define GOLDEN_DIR CBRDF_TEST_DATA_DIR "/golden/"
#define PI 3.14159265358979323846

static int g_passed = 0;
static int g_failed = 0;

static void check_impl(int ok, const char* what, const char* file, int line) {
  if (ok) {
    ++g_passed;
    return;
  }
  ++g_failed;
  fprintf(stderr, "%s:%d: FAILED: %s (last error %d %s: %s)\n", file, line, what,
          (int)cbrdf_last_error_code(), cbrdf_status_name(cbrdf_last_error_code()),
          cbrdf_last_error_message());
}
#define CHECK(cond) check_impl((cond) ? 1 : 0, #cond, __FILE__, __LINE__)

/* A call's status, the thread's last error code and its message agree: "" for success, a message
 * for a failure. */
static void check_status_impl(cbrdf_status got, cbrdf_status want, const char* what,
                              const char* file, int line) {
  const cbrdf_status last = cbrdf_last_error_code();
  const char* msg = cbrdf_last_error_message();
  int ok = got == want && last == want && msg != NULL;
  if (ok) ok = want == CBRDF_OK ? msg[0] == '\0' : msg[0] != '\0';
  if (!ok) {
    fprintf(stderr, "%s:%d: %s returned %s (last error %s), want %s; message: %s\n", file, line,
            what, cbrdf_status_name(got), cbrdf_status_name(last), cbrdf_status_name(want),
            msg ? msg : "(null)");
  }
  check_impl(ok, what, file, line);
}
#define CHECK_STATUS(expr, want) check_status_impl((expr), (want), #expr, __FILE__, __LINE__)

/* The last error's message contains `part`. */
#define CHECK_MESSAGE_HAS(part) CHECK(strstr(cbrdf_last_error_message(), (part)) != NULL)

/* ---- Helpers ----------------------------------------------------------------------------------
 */

static unsigned char* read_whole_file(const char* path, size_t* size) {
  FILE* f = fopen(path, "rb");
  unsigned char* data = NULL;
  long n;
  *size = 0;
  if (f == NULL) return NULL;
  if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
    data = (unsigned char*)malloc((size_t)n + 1);
    if (data != NULL && fread(data, 1, (size_t)n, f) == (size_t)n) {
      *size = (size_t)n;
    } else {
      free(data);
      data = NULL;
    }
  }
  fclose(f);
  return data;
}

static void direction(double theta_deg, double phi_deg, double out[3]) {
  const double t = theta_deg * PI / 180.0, p = phi_deg * PI / 180.0;
  out[0] = sin(t) * cos(p);
  out[1] = sin(t) * sin(p);
  out[2] = cos(t);
}

static int close_rel(double a, double b, double rel) {
  return fabs(a - b) <= rel * fmax(fabs(a), fabs(b)) || a == b;
}

/* A small deterministic generator of numbers in [0, 1). */
static uint64_t g_rng = 0x9E3779B97F4A7C15ull;
static double uniform01(void) {
  g_rng ^= g_rng << 13;
  g_rng ^= g_rng >> 7;
  g_rng ^= g_rng << 17;
  return (double)(g_rng >> 11) * (1.0 / 9007199254740992.0);
}

static void tmp_path(char* out, size_t size, const char* name) {
  snprintf(out, size, "%s/c_api_test_%ld_%s", CBRDF_TEST_TMP_DIR, (long)getpid(), name);
}

static const double kMerlScale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};
#define BINS_PER_CHANNEL ((size_t)90 * 90 * 180)

/* ---- Version, names, errors -------------------------------------------------------------------
 */

static void test_version_and_names(void) {
  int major = -1, minor = -1, patch = -1;
  /* The run-time library agrees with the headers it was built with (cbrdf/version.h). */
  CHECK(strcmp(cbrdf_version_string(), CBRDF_VERSION_STRING) == 0);
  CHECK(cbrdf_version_number() == CBRDF_VERSION);
  /* The global thread limit: a cap, then one per core again. */
  cbrdf_set_thread_limit(1);
  CHECK(cbrdf_thread_limit() == 1);
  cbrdf_set_thread_limit(0);
  CHECK(cbrdf_thread_limit() >= 1);
  CHECK(sscanf(cbrdf_version_string(), "%d.%d.%d", &major, &minor, &patch) == 3);
  CHECK(cbrdf_version_number() == major * 10000 + minor * 100 + patch);

  CHECK(strcmp(cbrdf_status_name(CBRDF_OK), "ok") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_IO), "io") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_NOT_FOUND), "not-found") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_TRUNCATED), "truncated") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_BAD_SIGNATURE), "bad-signature") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_UNSUPPORTED), "unsupported") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_CORRUPT), "corrupt") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_CHECKSUM), "checksum") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_LIMIT), "limit") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_INVALID_ARGUMENT), "invalid-argument") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_NUMERIC), "numeric") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_INTERNAL), "internal") == 0);
  CHECK(strcmp(cbrdf_status_name(CBRDF_ERROR_CANCELLED), "cancelled") == 0);
  CHECK(strcmp(cbrdf_status_name((cbrdf_status)13), "unknown") == 0);
  CHECK(strcmp(cbrdf_status_name((cbrdf_status)-1), "unknown") == 0);
  /* The numeric values are the stable codes of cbrdf::ErrorCode. */
  CHECK(CBRDF_OK == 0 && CBRDF_ERROR_IO == 1 && CBRDF_ERROR_NOT_FOUND == 2);
  CHECK(CBRDF_ERROR_CHECKSUM == 7 && CBRDF_ERROR_INVALID_ARGUMENT == 9);
  CHECK(CBRDF_ERROR_INTERNAL == 11 && CBRDF_ERROR_CANCELLED == 12);

  CHECK(strcmp(cbrdf_family_name(CBRDF_FAMILY_INDEPENDENCE), "independence") == 0);
  CHECK(strcmp(cbrdf_family_name(CBRDF_FAMILY_FRANK), "frank") == 0);
  CHECK(strcmp(cbrdf_family_name(CBRDF_FAMILY_CLAYTON), "clayton") == 0);
  CHECK(strcmp(cbrdf_family_name(CBRDF_FAMILY_GUMBEL), "gumbel") == 0);
  CHECK(strcmp(cbrdf_family_name(CBRDF_FAMILY_JOE), "joe") == 0);
  CHECK(strcmp(cbrdf_family_name(CBRDF_FAMILY_AUTO), "auto") == 0);
  CHECK(strcmp(cbrdf_family_name(5), "unknown") == 0);
  CHECK(strcmp(cbrdf_family_name(-2), "unknown") == 0);
  CHECK(strcmp(cbrdf_family_name(256 + 1), "unknown") == 0);

  CHECK(cbrdf_merl_table_size() == 4374000u);
}

/* Failing calls set the last error; successful ones clear it; the functions that cannot fail
 * leave it alone. */
static void test_last_error_lifecycle(void) {
  cbrdf_model* m;
  CHECK(cbrdf_model_open_file(NULL) == NULL);
  CHECK(cbrdf_last_error_code() == CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK(cbrdf_last_error_message()[0] != '\0');
  /* Not cleared by the functions that cannot fail. */
  (void)cbrdf_version_string();
  (void)cbrdf_version_number();
  (void)cbrdf_status_name(CBRDF_OK);
  (void)cbrdf_family_name(1);
  (void)cbrdf_merl_table_size();
  cbrdf_model_free(NULL);
  cbrdf_free(NULL);
  CHECK(cbrdf_last_error_code() == CBRDF_ERROR_INVALID_ARGUMENT);
  /* Cleared by a success. */
  m = cbrdf_model_open_file(GOLDEN_DIR "v1.0-frank6-b10.cbrdf");
  CHECK(m != NULL);
  CHECK(cbrdf_last_error_code() == CBRDF_OK);
  CHECK(strcmp(cbrdf_last_error_message(), "") == 0);
  /* And set again by the next failure, cleared by the next success of another function. */
  CHECK_STATUS(cbrdf_model_get_slice(m, 99, NULL, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
  {
    /* A count and its failure are told apart by the status, not by a count of 0. */
    size_t count = 99;
    CHECK_STATUS(cbrdf_model_metadata_count(m, &count), CBRDF_OK);
    CHECK(count == 4);
    CHECK_STATUS(cbrdf_model_metadata_count(NULL, &count), CBRDF_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(cbrdf_model_metadata_count(m, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
  }
#ifndef CBRDF_C_TEST_DECODER_ONLY
  /* cbrdf_encode_settings_init can fail, and says so by its status. */
  CHECK_STATUS(cbrdf_encode_settings_init(NULL), CBRDF_ERROR_INVALID_ARGUMENT);
  {
    cbrdf_encode_settings s;
    CHECK_STATUS(cbrdf_encode_settings_init(&s), CBRDF_OK);
  }
#endif
  cbrdf_model_free(m);
}

/* ---- Opening ----------------------------------------------------------------------------------
 */

static void test_open_errors(void) {
  size_t size = 0;
  unsigned char* bytes = read_whole_file(GOLDEN_DIR "v1.0-frank6-b10.cbrdf", &size);
  unsigned char zeros[64];
  CHECK(bytes != NULL && size == 3354);
  if (bytes == NULL) return;

  CHECK(cbrdf_model_open_memory(NULL, 10) == NULL);
  CHECK_STATUS(cbrdf_last_error_code(), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK(cbrdf_model_open_file(NULL) == NULL);
  CHECK_STATUS(cbrdf_last_error_code(), CBRDF_ERROR_INVALID_ARGUMENT);

  CHECK(cbrdf_model_open_file(GOLDEN_DIR "no-such-file.cbrdf") == NULL);
  CHECK_STATUS(cbrdf_last_error_code(), CBRDF_ERROR_NOT_FOUND);
  CHECK_MESSAGE_HAS("no-such-file.cbrdf");
  CHECK(cbrdf_model_open_file(CBRDF_TEST_DATA_DIR) == NULL); /* a directory */
  CHECK_STATUS(cbrdf_last_error_code(), CBRDF_ERROR_IO);
  /* An empty path says so (it used to read ": no such file"). */
  CHECK(cbrdf_model_open_file("") == NULL);
  CHECK_STATUS(cbrdf_last_error_code(), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("path is empty");

  /* One flipped bit inside the marginals chunk's stored bytes (at offset 406 + 16 + 100): the
   * chunk's XXH64 no longer matches. */
  bytes[406 + 16 + 100] ^= 0x10;
  CHECK(cbrdf_model_open_memory(bytes, size) == NULL);
  CHECK_STATUS(cbrdf_last_error_code(), CBRDF_ERROR_CHECKSUM);
  CHECK(cbrdf_last_error_code() == 7);
  CHECK_MESSAGE_HAS("MARG");
  bytes[406 + 16 + 100] ^= 0x10;

  /* Cut short, empty, not a container at all. */
  CHECK(cbrdf_model_open_memory(bytes, size - 100) == NULL);
  CHECK_STATUS(cbrdf_last_error_code(), CBRDF_ERROR_TRUNCATED);
  CHECK(cbrdf_model_open_memory(bytes, 0) == NULL);
  CHECK_STATUS(cbrdf_last_error_code(), CBRDF_ERROR_TRUNCATED);
  memset(zeros, 0, sizeof zeros);
  CHECK(cbrdf_model_open_memory(zeros, sizeof zeros) == NULL);
  CHECK_STATUS(cbrdf_last_error_code(), CBRDF_ERROR_BAD_SIGNATURE);

  /* Restored, it opens again. */
  {
    cbrdf_model* m = cbrdf_model_open_memory(bytes, size);
    CHECK(m != NULL);
    CHECK(cbrdf_last_error_code() == CBRDF_OK);
    cbrdf_model_free(m);
  }
  free(bytes);
}

/* ---- Describing -------------------------------------------------------------------------------
 */

struct expected_component {
  int family;
  double theta, scale;
  int count;
};

struct expected_model {
  const char* file;
  int version_minor, slices, max_components, bits;
  uint64_t file_bytes, not_measured_bins;
  int bounds[7];
  struct expected_component first[6][3]; /* component 0 of each slice and channel */
  const char* bits_text;
};

/* From `cbrdf info --json` of the two files. */
static const struct expected_model kFrank6 = {"v1.0-frank6-b10.cbrdf",
                                              0,
                                              6,
                                              1,
                                              10,
                                              3354,
                                              1039704,
                                              {0, 6, 15, 30, 50, 70, 90},
                                              {{{1, -7.487472690779502, 748.7472690779502, 1},
                                                {1, -8.0572107147594, 805.7210714759399, 1},
                                                {1, -1.4245683699359812, 142.45683699359813, 1}},
                                               {{1, -2.524576549340574, 252.45765493405742, 1},
                                                {1, -3.8719776521803966, 387.19776521803965, 1},
                                                {1, -2.2472692192806103, 224.72692192806102, 1}},
                                               {{1, -6.836554546241433, 683.6554546241433, 1},
                                                {1, -7.043917499011666, 704.3917499011666, 1},
                                                {1, -4.794431153496154, 479.44311534961537, 1}},
                                               {{1, -3.657785630841655, 365.7785630841655, 1},
                                                {1, -9.24536716533451, 924.5367165334511, 1},
                                                {1, -1.6050029918004012, 160.50029918004012, 1}},
                                               {{1, -10.08281509164725, 1008.281509164725, 1},
                                                {1, -9.71316630092171, 971.3166300921711, 1},
                                                {1, -7.202684660070182, 720.2684660070182, 1}},
                                               {{1, -3.9748671156917634, 397.48671156917635, 1},
                                                {1, -6.83269725562334, 683.269725562334, 1},
                                                {1, -7.708885780323758, 770.8885780323758, 1}}},
                                              "10"};

static const struct expected_model kMixture3 = {"v1.1-mixture3-b12.cbrdf",
                                                1,
                                                3,
                                                4,
                                                12,
                                                6807,
                                                1039704,
                                                {0, 20, 50, 90},
                                                {{{1, -1.579832006646571, 332.3330674129784, 1},
                                                  {2, 0.7608509468871054, 928.0716078049443, 2},
                                                  {3, 2.66979832532322, 579.877958945556, 3}},
                                                 {{4, 2.9842542164001085, 138.47771575829466, 2},
                                                  {0, 0.0, 51.890368164240165, 3},
                                                  {1, -16.79481390540814, 405.91687947266627, 4}},
                                                 {{2, 1.8022628380746621, 371.25698492174484, 3},
                                                  {3, 2.7383083156709236, 722.8801956386344, 4},
                                                  {4, 1.2470998885501026, 790.5112547527069, 1}}},
                                                "12"};

static void test_info(const cbrdf_model* m, const struct expected_model* e) {
  cbrdf_model_info info;
  struct {
    cbrdf_model_info info;
    unsigned char future[16];
  } bigger;
  const size_t first_size = offsetof(cbrdf_model_info, not_measured_bins) + sizeof(uint64_t);
  size_t k;

  memset(&info, 0xAB, sizeof info);
  info.struct_size = sizeof info;
  CHECK_STATUS(cbrdf_model_get_info(m, &info), CBRDF_OK);
  CHECK(info.struct_size == sizeof info);
  CHECK(info.version_major == 1);
  CHECK(info.version_minor == e->version_minor);
  CHECK(info.slices == e->slices);
  CHECK(info.max_components == e->max_components);
  CHECK(info.bits == e->bits);
  CHECK(info.file_bytes == e->file_bytes);
  CHECK(info.not_measured_bins == e->not_measured_bins);
  CHECK(info.residual_mode == CBRDF_RESIDUAL_NONE && info.residual_bytes == 0);
  CHECK(info.residual_max_error == 0 && info.residual_min_error == 0 && info.residual_knee == 0);

  /* A caller with a newer, longer struct: this version's fields are filled, the rest untouched. */
  memset(&bigger, 0xCD, sizeof bigger);
  bigger.info.struct_size = (uint32_t)sizeof bigger;
  CHECK_STATUS(cbrdf_model_get_info(m, &bigger.info), CBRDF_OK);
  CHECK(bigger.info.struct_size == sizeof(cbrdf_model_info));
  CHECK(bigger.info.slices == e->slices && bigger.info.file_bytes == e->file_bytes);
  for (k = 0; k < sizeof bigger.future; ++k) CHECK(bigger.future[k] == 0xCD);

  /* Too small for the first version, zero, NULL. */
  info.struct_size = (uint32_t)(first_size - 1);
  CHECK_STATUS(cbrdf_model_get_info(m, &info), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("struct_size");
  info.struct_size = 0;
  CHECK_STATUS(cbrdf_model_get_info(m, &info), CBRDF_ERROR_INVALID_ARGUMENT);
  info.struct_size = sizeof info;
  CHECK_STATUS(cbrdf_model_get_info(NULL, &info), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_info(m, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
}

static void test_slices_and_components(const cbrdf_model* m, const struct expected_model* e) {
  int s, c, r, begin = -1, end = -1, count = -1, family = -1;
  double theta = 0, scale = 0;
  for (s = 0; s < e->slices; ++s) {
    CHECK_STATUS(cbrdf_model_get_slice(m, s, &begin, &end), CBRDF_OK);
    CHECK(begin == e->bounds[s] && end == e->bounds[s + 1]);
    for (c = 0; c < 3; ++c) {
      const struct expected_component* x = &e->first[s][c];
      CHECK_STATUS(cbrdf_model_get_component_count(m, s, c, &count), CBRDF_OK);
      CHECK(count == x->count);
      CHECK_STATUS(cbrdf_model_get_component(m, s, c, 0, &family, &theta, &scale), CBRDF_OK);
      CHECK(family == x->family);
      CHECK(theta == x->theta); /* the file stores them as doubles, bit for bit */
      CHECK(scale == x->scale);
      /* The mixture's further components (tests/support/synthetic_model.h make_mixture_model):
       * Frank, Clayton, Frank in turn, each with a smaller scale than the first. */
      for (r = 1; r < count; ++r) {
        double first_scale = scale, t = 0, k = 0;
        int f = -1;
        CHECK_STATUS(cbrdf_model_get_component(m, s, c, r, &f, &t, &k), CBRDF_OK);
        if (r % 2 == 1) {
          CHECK(f == CBRDF_FAMILY_FRANK && t <= -0.5 && t >= -5.5);
        } else {
          CHECK(f == CBRDF_FAMILY_CLAYTON && t >= 0.2 && t <= 1.2);
        }
        CHECK(k > 0.04 * first_scale && k < 0.36 * first_scale);
      }
      CHECK_STATUS(cbrdf_model_get_component(m, s, c, count, &family, &theta, &scale),
                   CBRDF_ERROR_INVALID_ARGUMENT);
      CHECK_MESSAGE_HAS("component");
    }
  }
  /* Out of range and NULL. */
  CHECK_STATUS(cbrdf_model_get_slice(m, -1, &begin, &end), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_slice(m, e->slices, &begin, &end), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("slice");
  CHECK_STATUS(cbrdf_model_get_slice(NULL, 0, &begin, &end), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_slice(m, 0, NULL, &end), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_slice(m, 0, &begin, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component_count(m, 0, -1, &count), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component_count(m, 0, 3, &count), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("channel");
  CHECK_STATUS(cbrdf_model_get_component_count(m, e->slices, 0, &count),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component_count(NULL, 0, 0, &count), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component_count(m, 0, 0, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component(m, 0, 0, -1, &family, &theta, &scale),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component(m, -1, 0, 0, &family, &theta, &scale),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component(m, 0, 3, 0, &family, &theta, &scale),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component(NULL, 0, 0, 0, &family, &theta, &scale),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component(m, 0, 0, 0, NULL, &theta, &scale),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component(m, 0, 0, 0, &family, NULL, &scale),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_get_component(m, 0, 0, 0, &family, &theta, NULL),
               CBRDF_ERROR_INVALID_ARGUMENT);
}

/* Value of a metadata key, or NULL. */
static const char* metadata_value(const cbrdf_model* m, const char* key) {
  size_t i, n = 0;
  if (cbrdf_model_metadata_count(m, &n) != CBRDF_OK) return NULL;
  for (i = 0; i < n; ++i) {
    const char *k = NULL, *v = NULL;
    if (cbrdf_model_metadata_at(m, i, &k, &v) != CBRDF_OK) return NULL;
    if (strcmp(k, key) == 0) return v;
  }
  return NULL;
}

static void test_metadata(const cbrdf_model* m, const struct expected_model* e) {
  const char *key = NULL, *value = NULL;
  const char* v;
  size_t count = 0;
  CHECK_STATUS(cbrdf_model_metadata_count(m, &count), CBRDF_OK);
  CHECK(count == 4);
  v = metadata_value(m, "bits");
  CHECK(v != NULL && strcmp(v, e->bits_text) == 0);
  v = metadata_value(m, "zstd_level");
  CHECK(v != NULL && strcmp(v, "19") == 0);
  v = metadata_value(m, "source");
  CHECK(v != NULL && strcmp(v, e->file) == 0);
  v = metadata_value(m, "encoder");
  CHECK(v != NULL && strncmp(v, "cbrdf ", 6) == 0);
  CHECK(metadata_value(m, "no-such-key") == NULL);

  CHECK_STATUS(cbrdf_model_metadata_at(m, 4, &key, &value), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("metadata index 4");
  CHECK_STATUS(cbrdf_model_metadata_at(m, (size_t)-1, &key, &value), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_metadata_at(NULL, 0, &key, &value), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_metadata_at(m, 0, NULL, &value), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_metadata_at(m, 0, &key, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
}

/* ---- Evaluation -------------------------------------------------------------------------------
 */

#define N_DIRS 40

/* cbrdf_model_eval_batch_soa: the same values bit for bit from separate coordinate arrays, and
 * its errors (outputs unchanged). wi, wo: N_DIRS triples; rgb: their cbrdf_model_eval values. */
static void test_eval_batch_soa(const cbrdf_model* m, const double* wi, const double* wo,
                                const double* rgb) {
  double x[6][N_DIRS], out[3][N_DIRS], keep[3][N_DIRS];
  int k, c, same = 1;
  for (k = 0; k < N_DIRS; ++k) {
    for (c = 0; c < 3; ++c) {
      x[c][k] = wi[3 * k + c];
      x[3 + c][k] = wo[3 * k + c];
    }
  }
  memset(out, 0xEE, sizeof out);
  CHECK_STATUS(cbrdf_model_eval_batch_soa(m, N_DIRS, x[0], x[1], x[2], x[3], x[4], x[5], out[0],
                                          out[1], out[2], 0),
               CBRDF_OK);
  for (k = 0; k < N_DIRS; ++k) {
    for (c = 0; c < 3; ++c) same &= memcmp(&out[c][k], &rgb[3 * k + c], sizeof(double)) == 0;
  }
  CHECK(same);
  /* Errors: a bad element (named by its index), NULL arrays, a NULL model, n too large. */
  memcpy(keep, out, sizeof out);
  x[1][5] = 2.0;
  CHECK_STATUS(cbrdf_model_eval_batch_soa(m, N_DIRS, x[0], x[1], x[2], x[3], x[4], x[5], out[0],
                                          out[1], out[2], 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wi[5]");
  x[1][5] = wi[3 * 5 + 1];
  x[5][11] = NAN;
  CHECK_STATUS(cbrdf_model_eval_batch_soa(m, N_DIRS, x[0], x[1], x[2], x[3], x[4], x[5], out[0],
                                          out[1], out[2], 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wo[11]");
  x[5][11] = wo[3 * 11 + 2];
  CHECK(memcmp(keep, out, sizeof out) == 0);
  for (k = 0; k < 9; ++k) {
    const double* in[6];
    double* o[3];
    for (c = 0; c < 6; ++c) in[c] = k == c ? NULL : x[c];
    for (c = 0; c < 3; ++c) o[c] = k == 6 + c ? NULL : out[c];
    CHECK_STATUS(cbrdf_model_eval_batch_soa(m, 1, in[0], in[1], in[2], in[3], in[4], in[5], o[0],
                                            o[1], o[2], 0),
                 CBRDF_ERROR_INVALID_ARGUMENT);
    CHECK_MESSAGE_HAS("NULL");
  }
  CHECK_STATUS(
      cbrdf_model_eval_batch_soa(m, 0, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL, 0),
      CBRDF_OK);
  CHECK_STATUS(cbrdf_model_eval_batch_soa(NULL, 1, x[0], x[1], x[2], x[3], x[4], x[5], out[0],
                                          out[1], out[2], 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_batch_soa(m, SIZE_MAX, x[0], x[1], x[2], x[3], x[4], x[5], out[0],
                                          out[1], out[2], 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("too large");
  CHECK(memcmp(keep, out, sizeof out) == 0);
}

static void test_eval(const cbrdf_model* m) {
  double wi[N_DIRS * 3], wo[N_DIRS * 3], rgb[N_DIRS * 3], batch[N_DIRS * 3];
  double one[3], back[3], below[3], up[3], n[3] = {0, 0, 1}, bad[3], saved;
  int k, c, positive = 0;

  for (k = 0; k < N_DIRS; ++k) {
    /* Spread over the hemisphere, including near-normal and grazing angles and the mirror. */
    const double ti = 85.0 * uniform01(), to = k % 5 == 0 ? ti : 85.0 * uniform01();
    const double pi = 360.0 * uniform01(), po = k % 5 == 0 ? pi + 180.0 : 360.0 * uniform01();
    direction(ti, pi, wi + 3 * k);
    direction(to, po, wo + 3 * k);
  }
  for (k = 0; k < N_DIRS; ++k) {
    CHECK_STATUS(cbrdf_model_eval(m, wi + 3 * k, wo + 3 * k, rgb + 3 * k), CBRDF_OK);
    for (c = 0; c < 3; ++c) {
      CHECK(isfinite(rgb[3 * k + c]) && rgb[3 * k + c] >= 0.0);
      if (rgb[3 * k + c] > 0) ++positive;
    }
    /* Reciprocity: swapping the directions reaches the same bins (phi_d + pi), so the value is
     * the same up to rounding in the coordinate transform. */
    CHECK_STATUS(cbrdf_model_eval(m, wo + 3 * k, wi + 3 * k, back), CBRDF_OK);
    for (c = 0; c < 3; ++c) CHECK(close_rel(back[c], rgb[3 * k + c], 1e-9));
  }
  CHECK(positive > 3 * N_DIRS / 2);

  /* The batch is the same computation, bit for bit. */
  memset(batch, 0xEE, sizeof batch);
  CHECK_STATUS(cbrdf_model_eval_batch(m, N_DIRS, wi, wo, batch, 0), CBRDF_OK);
  CHECK(memcmp(batch, rgb, sizeof rgb) == 0);
  test_eval_batch_soa(m, wi, wo, rgb);

  /* Zero at and below the horizon, on either side. */
  direction(60, 30, up);
  direction(120, 30, below);
  CHECK_STATUS(cbrdf_model_eval(m, below, up, one), CBRDF_OK);
  CHECK(one[0] == 0.0 && one[1] == 0.0 && one[2] == 0.0);
  CHECK_STATUS(cbrdf_model_eval(m, up, below, one), CBRDF_OK);
  CHECK(one[0] == 0.0 && one[1] == 0.0 && one[2] == 0.0);
  below[0] = 1;
  below[1] = 0;
  below[2] = 0; /* exactly on the horizon */
  CHECK_STATUS(cbrdf_model_eval(m, below, up, one), CBRDF_OK);
  CHECK(one[0] == 0.0 && one[1] == 0.0 && one[2] == 0.0);

  /* At normal incidence and exitance the position is exactly MERL bin (0, 0, 0). */
  CHECK_STATUS(cbrdf_model_eval(m, n, n, one), CBRDF_OK);
  CHECK(one[0] > 0 && one[1] > 0 && one[2] > 0);

  /* Errors leave rgb alone. */
  one[0] = one[1] = one[2] = 42.0;
  bad[0] = 2;
  bad[1] = 0;
  bad[2] = 0;
  CHECK_STATUS(cbrdf_model_eval(m, bad, up, one), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wi");
  CHECK_STATUS(cbrdf_model_eval(m, up, bad, one), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wo");
  bad[0] = 0;
  bad[2] = NAN;
  CHECK_STATUS(cbrdf_model_eval(m, bad, up, one), CBRDF_ERROR_INVALID_ARGUMENT);
  bad[2] = INFINITY;
  CHECK_STATUS(cbrdf_model_eval(m, up, bad, one), CBRDF_ERROR_INVALID_ARGUMENT);
  bad[2] = 1e-3; /* short of unit length, and not the zero vector */
  CHECK_STATUS(cbrdf_model_eval(m, bad, up, one), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("or (0, 0, 0)");
  CHECK(one[0] == 42.0 && one[1] == 42.0 && one[2] == 42.0);
  bad[2] = 0; /* the zero vector, a rejected draw's wi: 0, not an error */
  CHECK_STATUS(cbrdf_model_eval(m, bad, up, one), CBRDF_OK);
  CHECK(one[0] == 0.0 && one[1] == 0.0 && one[2] == 0.0);
  one[0] = one[1] = one[2] = 42.0;
  CHECK_STATUS(cbrdf_model_eval(NULL, up, up, one), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval(m, NULL, up, one), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval(m, up, NULL, one), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval(m, up, up, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
  /* Slightly off unit length (float rounding) is accepted. */
  up[2] *= 1.0 + 1e-6;
  CHECK_STATUS(cbrdf_model_eval(m, up, up, one), CBRDF_OK);

  /* A bad element anywhere fails the whole batch before anything is written. */
  memset(batch, 0xEE, sizeof batch);
  memcpy(back, batch, sizeof back);
  saved = wi[3 * 7 + 2];
  wi[3 * 7 + 2] = NAN;
  CHECK_STATUS(cbrdf_model_eval_batch(m, N_DIRS, wi, wo, batch, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wi[7]");
  CHECK(memcmp(batch, back, sizeof back) == 0);
  wi[3 * 7 + 2] = saved;
  wo[3 * 9] = 3;
  CHECK_STATUS(cbrdf_model_eval_batch(m, N_DIRS, wi, wo, batch, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wo[9]");
  CHECK_STATUS(cbrdf_model_eval_batch(m, 0, NULL, NULL, NULL, 0), CBRDF_OK);
  CHECK_STATUS(cbrdf_model_eval_batch(NULL, 1, wi, wo, batch, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_batch(NULL, 0, wi, wo, batch, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_batch(m, 1, NULL, wo, batch, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_batch(m, 1, wi, NULL, batch, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_batch(m, 1, wi, wo, NULL, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_batch(m, SIZE_MAX, wi, wo, batch, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("too large");
}

/* ---- Sampling ---------------------------------------------------------------------------------
 */

#define N_SAMPLES 512

static void test_sampling(const cbrdf_model* m) {
  static double wo[N_SAMPLES * 3], u[N_SAMPLES * 2], wi[N_SAMPLES * 3], pdf[N_SAMPLES],
      weight[N_SAMPLES * 3];
  double p = -1, f[3], up[3], down[3], bad[3] = {0, 0, 2};
  int k, c, valid = 0;

  for (k = 0; k < N_SAMPLES; ++k) {
    /* The last eighth below the horizon: those samples are rejected. */
    const double theta_o = k < N_SAMPLES * 7 / 8 ? 80.0 * uniform01() : 95.0 + 80.0 * uniform01();
    direction(theta_o, 360.0 * uniform01(), wo + 3 * k);
    u[2 * k] = uniform01();
    u[2 * k + 1] = uniform01();
  }
  CHECK_STATUS(cbrdf_model_sample_batch(m, N_SAMPLES, wo, u, wi, pdf, weight, 0), CBRDF_OK);
  for (k = 0; k < N_SAMPLES; ++k) {
    const double* i = wi + 3 * k;
    const double* w = weight + 3 * k;
    if (pdf[k] == 0.0) {
      CHECK(i[0] == 0.0 && i[1] == 0.0 && i[2] == 0.0);
      CHECK(w[0] == 0.0 && w[1] == 0.0 && w[2] == 0.0);
      continue;
    }
    ++valid;
    CHECK(k < N_SAMPLES * 7 / 8); /* never valid below the horizon */
    CHECK(isfinite(pdf[k]) && pdf[k] > 0.0);
    CHECK(fabs(i[0] * i[0] + i[1] * i[1] + i[2] * i[2] - 1.0) < 1e-9);
    CHECK(i[2] > 0.0);
    /* The density reported is the one pdf() gives, and the weight f cos / pdf. */
    CHECK_STATUS(cbrdf_model_sample_pdf(m, i, wo + 3 * k, &p), CBRDF_OK);
    CHECK(p == pdf[k]);
    CHECK_STATUS(cbrdf_model_eval(m, i, wo + 3 * k, f), CBRDF_OK);
    for (c = 0; c < 3; ++c) {
      CHECK(isfinite(w[c]) && w[c] >= 0.0);
      CHECK(close_rel(w[c], f[c] * i[2] / pdf[k], 1e-12));
    }
  }
  CHECK(valid > N_SAMPLES / 2);

  /* pdf: zero at or below the horizon, positive above it (the cosine-weighted share). */
  direction(30, 0, up);
  direction(100, 0, down);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, down, up, &p), CBRDF_OK);
  CHECK(p == 0.0);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, up, down, &p), CBRDF_OK);
  CHECK(p == 0.0);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, up, up, &p), CBRDF_OK);
  CHECK(p > 0.0 && isfinite(p));

  /* The draws passed straight back, rejected ones (wi = (0, 0, 0)) included: 0, not an error. */
  {
    static double rgb[N_SAMPLES * 3];
    static float fwi[N_SAMPLES * 3], fwo[N_SAMPLES * 3], frgb[N_SAMPLES * 3];
    const double zero[3] = {0.0, 0.0, 0.0};
    int rejected = 0;
    CHECK_STATUS(cbrdf_model_eval_batch(m, N_SAMPLES, wi, wo, rgb, 0), CBRDF_OK);
    for (k = 0; k < 3 * N_SAMPLES; ++k) {
      fwi[k] = (float)wi[k];
      fwo[k] = (float)wo[k];
    }
    CHECK_STATUS(cbrdf_model_eval_batch_f32(m, N_SAMPLES, fwi, fwo, frgb, 0), CBRDF_OK);
    for (k = 0; k < N_SAMPLES; ++k) {
      if (pdf[k] != 0.0) continue;
      ++rejected;
      CHECK_STATUS(cbrdf_model_sample_pdf(m, wi + 3 * k, wo + 3 * k, &p), CBRDF_OK);
      CHECK(p == 0.0);
      for (c = 0; c < 3; ++c) CHECK(rgb[3 * k + c] == 0.0 && frgb[3 * k + c] == 0.0f);
    }
    CHECK(rejected >= N_SAMPLES / 8);
    p = 1.0;
    f[0] = f[1] = f[2] = 1.0;
    CHECK_STATUS(cbrdf_model_eval_pdf(m, zero, up, f, &p), CBRDF_OK);
    CHECK(p == 0.0 && f[0] == 0.0 && f[1] == 0.0 && f[2] == 0.0);
    CHECK_STATUS(cbrdf_model_sample_pdf(m, up, zero, &p), CBRDF_OK);
    CHECK(p == 0.0);
    /* Only exactly (0, 0, 0): a short vector is refused, naming what is accepted. */
    CHECK_STATUS(cbrdf_model_sample_pdf(m, up, bad, &p), CBRDF_ERROR_INVALID_ARGUMENT);
    CHECK_MESSAGE_HAS("or (0, 0, 0) (a rejected draw)");
  }

  /* Errors, checked before anything is written. */
  pdf[0] = 42.0;
  u[2 * 5 + 1] = NAN;
  CHECK_STATUS(cbrdf_model_sample_batch(m, N_SAMPLES, wo, u, wi, pdf, weight, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("u pair 5 (u[10], u[11])");
  CHECK(pdf[0] == 42.0);
  u[2 * 5 + 1] = 0.5;
  wo[3 * 6 + 1] = 5.0;
  CHECK_STATUS(cbrdf_model_sample_batch(m, N_SAMPLES, wo, u, wi, pdf, weight, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wo[6]");
  CHECK_STATUS(cbrdf_model_sample_batch(m, 0, NULL, NULL, NULL, NULL, NULL, 0), CBRDF_OK);
  CHECK_STATUS(cbrdf_model_sample_batch(NULL, 1, wo, u, wi, pdf, weight, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_batch(m, 1, NULL, u, wi, pdf, weight, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_batch(m, 1, wo, NULL, wi, pdf, weight, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_batch(m, 1, wo, u, NULL, pdf, weight, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_batch(m, 1, wo, u, wi, NULL, weight, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_batch(m, 1, wo, u, wi, pdf, NULL, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_batch(m, SIZE_MAX, wo, u, wi, pdf, weight, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_pdf(NULL, up, up, &p), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, up, NULL, &p), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, NULL, up, &p), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, up, up, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, up, bad, &p), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, bad, up, &p), CBRDF_ERROR_INVALID_ARGUMENT);
}

/* Several threads sample and evaluate one freshly opened handle at once (the sampler is built by
 * whichever comes first): every thread gets what one thread alone gets. */
#define N_THREADS 4
#define N_THREAD_SAMPLES 64

struct thread_job {
  const cbrdf_model* model;
  const double *wo, *u;
  double wi[N_THREAD_SAMPLES * 3], pdf[N_THREAD_SAMPLES], weight[N_THREAD_SAMPLES * 3];
  double rgb[N_THREAD_SAMPLES * 3];
  cbrdf_status sample_status, eval_status;
};

static void* thread_main(void* arg) {
  struct thread_job* job = (struct thread_job*)arg;
  job->sample_status = cbrdf_model_sample_batch(job->model, N_THREAD_SAMPLES, job->wo, job->u,
                                                job->wi, job->pdf, job->weight, 0);
  /* On the calling thread alone, as a renderer's own worker thread calls it. */
  job->eval_status =
      cbrdf_model_eval_batch(job->model, N_THREAD_SAMPLES, job->wo, job->wo, job->rgb, 1);
  return NULL;
}

static void test_threads(void) {
  static struct thread_job jobs[N_THREADS + 1];
  double wo[N_THREAD_SAMPLES * 3], u[N_THREAD_SAMPLES * 2];
  pthread_t threads[N_THREADS];
  cbrdf_model* m = cbrdf_model_open_file(GOLDEN_DIR "v1.1-mixture3-b12.cbrdf");
  int k, started = 0;
  CHECK(m != NULL);
  if (m == NULL) return;
  for (k = 0; k < N_THREAD_SAMPLES; ++k) {
    direction(85.0 * uniform01(), 360.0 * uniform01(), wo + 3 * k);
    u[2 * k] = uniform01();
    u[2 * k + 1] = uniform01();
  }
  for (k = 0; k <= N_THREADS; ++k) {
    jobs[k].model = m;
    jobs[k].wo = wo;
    jobs[k].u = u;
  }
  for (k = 0; k < N_THREADS; ++k) {
    if (pthread_create(&threads[k], NULL, thread_main, &jobs[k]) == 0) ++started;
  }
  CHECK(started == N_THREADS);
  for (k = 0; k < started; ++k) pthread_join(threads[k], NULL);
  thread_main(&jobs[N_THREADS]); /* the reference, after the others */
  for (k = 0; k < started; ++k) {
    CHECK(jobs[k].sample_status == CBRDF_OK && jobs[k].eval_status == CBRDF_OK);
    CHECK(memcmp(jobs[k].wi, jobs[N_THREADS].wi, sizeof jobs[k].wi) == 0);
    CHECK(memcmp(jobs[k].pdf, jobs[N_THREADS].pdf, sizeof jobs[k].pdf) == 0);
    CHECK(memcmp(jobs[k].weight, jobs[N_THREADS].weight, sizeof jobs[k].weight) == 0);
    CHECK(memcmp(jobs[k].rgb, jobs[N_THREADS].rgb, sizeof jobs[k].rgb) == 0);
  }
  cbrdf_model_free(m);
}

/* ---- Tables -----------------------------------------------------------------------------------
 */

/* Reads a 90x90x180 MERL .binary written by write_merl into values (4,374,000 doubles). */
static int read_merl_c(const char* path, double* values) {
  FILE* f = fopen(path, "rb");
  int32_t dims[3] = {0, 0, 0};
  int ok = 0;
  if (f == NULL) return 0;
  if (fread(dims, sizeof(int32_t), 3, f) == 3 && dims[0] == 90 && dims[1] == 90 && dims[2] == 180 &&
      fread(values, sizeof(double), 3 * BINS_PER_CHANNEL, f) == 3 * BINS_PER_CHANNEL &&
      fgetc(f) == EOF) {
    ok = 1;
  }
  fclose(f);
  return ok;
}

/* Returns the model's table (4,374,000 doubles; the caller frees it), or NULL. */
static double* test_table(const cbrdf_model* m, const struct expected_model* e) {
  const size_t count = cbrdf_merl_table_size();
  double* table = (double*)malloc(count * sizeof(double));
  double* file = (double*)malloc(count * sizeof(double));
  double n[3] = {0, 0, 1}, rgb[3];
  char path[512];
  size_t i, negative = 0;
  int c;
  CHECK(table != NULL && file != NULL);
  if (table == NULL || file == NULL) {
    free(table);
    free(file);
    return NULL;
  }
  table[0] = 42.0;
  CHECK_STATUS(cbrdf_model_table(m, table, count - 1), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("count");
  CHECK_STATUS(cbrdf_model_table(m, table, count + 1), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_table(m, table, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK(table[0] == 42.0);
  CHECK_STATUS(cbrdf_model_table(NULL, table, count), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_table(m, NULL, count), CBRDF_ERROR_INVALID_ARGUMENT);

  CHECK_STATUS(cbrdf_model_table(m, table, count), CBRDF_OK);
  /* The not-measured bins are the negative ones (-1 in these files), as many as the mask has. */
  for (i = 0; i < count; ++i) {
    if (table[i] < 0) {
      ++negative;
      if (table[i] != -1.0) break;
    } else if (!isfinite(table[i])) {
      break;
    }
  }
  CHECK(i == count);
  CHECK(negative == e->not_measured_bins);
  /* eval at the normal reads bin (0, 0, 0), the first value of each channel block. */
  CHECK_STATUS(cbrdf_model_eval(m, n, n, rgb), CBRDF_OK);
  for (c = 0; c < 3; ++c) {
    CHECK(close_rel(rgb[c], table[(size_t)c * BINS_PER_CHANNEL] * kMerlScale[c], 1e-12));
  }

  /* write_merl writes exactly that table. */
  tmp_path(path, sizeof path, "table.binary");
  CHECK_STATUS(cbrdf_model_write_merl(m, path), CBRDF_OK);
  memset(file, 0, count * sizeof(double));
  CHECK(read_merl_c(path, file));
  CHECK(memcmp(file, table, count * sizeof(double)) == 0);
  remove(path);
  CHECK_STATUS(cbrdf_model_write_merl(m, CBRDF_TEST_DATA_DIR), CBRDF_ERROR_IO); /* a directory */
  CHECK_STATUS(cbrdf_model_write_merl(m, CBRDF_TEST_TMP_DIR "/no-such-dir/x.binary"),
               CBRDF_ERROR_IO);
  CHECK_STATUS(cbrdf_model_write_merl(NULL, path), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_write_merl(m, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
  free(file);
  return table;
}

/* ---- Encoding ---------------------------------------------------------------------------------
 */

#ifndef CBRDF_C_TEST_DECODER_ONLY
static void test_encode_settings(const double* table) {
  cbrdf_encode_settings s;
  void* out = (void*)&s;
  size_t size = 123;
  struct {
    const char* field;
    size_t offset;
    int bad_low, bad_high;
    const char* range;
  } fields[] = {
      {"bits", offsetof(cbrdf_encode_settings, bits), 5, 17, "6 to 16"},
      {"zstd_level", offsetof(cbrdf_encode_settings, zstd_level), 0, 23, "1 to 22"},
      {"slices", offsetof(cbrdf_encode_settings, slices), 0, 91, "1 to 90"},
      {"components", offsetof(cbrdf_encode_settings, components), 0, 9, "1 to 8"},
      {"family", offsetof(cbrdf_encode_settings, family), -2, 5,
       "(0 to 4) or CBRDF_FAMILY_AUTO (-1)"},
      {"threads", offsetof(cbrdf_encode_settings, threads), -1, 257, "to 256"},
      {"mixture_copulas", offsetof(cbrdf_encode_settings, mixture_copulas), -1, 2, "0 or 1"},
      {"format_version", offsetof(cbrdf_encode_settings, format_version), -1, 14,
       "CBRDF_FORMAT_1_3 (13)"},
      {"metadata", offsetof(cbrdf_encode_settings, metadata), -1, 3, "CBRDF_METADATA_FULL (2)"},
  };
  size_t f;

  memset(&s, 0x5A, sizeof s);
  cbrdf_encode_settings_init(&s);
  CHECK(s.struct_size == sizeof s);
  CHECK(s.bits == CBRDF_BITS_AUTO && s.zstd_level == 19 && s.slices == 6 && s.components == 1);
  CHECK(s.family == CBRDF_FAMILY_FRANK && s.threads == 1 && s.mixture_copulas == 1);
  CHECK(s.format_version == CBRDF_FORMAT_AUTO && s.metadata == CBRDF_METADATA_SHORT);

  /* Each field out of its range on either side: refused before any work, naming field and
   * range. */
  for (f = 0; f < sizeof fields / sizeof fields[0]; ++f) {
    int* field = (int*)((char*)&s + fields[f].offset);
    int bad[2];
    int b;
    bad[0] = fields[f].bad_low;
    bad[1] = fields[f].bad_high;
    for (b = 0; b < 2; ++b) {
      cbrdf_encode_settings_init(&s);
      *field = bad[b];
      out = (void*)&s;
      size = 123;
      CHECK_STATUS(cbrdf_encode_table(table, cbrdf_merl_table_size(), &s, &out, &size),
                   CBRDF_ERROR_INVALID_ARGUMENT);
      CHECK_MESSAGE_HAS(fields[f].field);
      CHECK_MESSAGE_HAS(fields[f].range);
      CHECK(out == NULL && size == 0);
      CHECK_STATUS(cbrdf_encode_merl_file("unused.binary", "unused.cbrdf", &s),
                   CBRDF_ERROR_INVALID_ARGUMENT);
      CHECK_MESSAGE_HAS(fields[f].field);
    }
  }
  cbrdf_encode_settings_init(&s);
  s.struct_size = (uint32_t)offsetof(cbrdf_encode_settings, threads);
  CHECK_STATUS(cbrdf_encode_table(table, cbrdf_merl_table_size(), &s, &out, &size),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("struct_size");
  s.struct_size = 0;
  CHECK_STATUS(cbrdf_encode_merl_file("unused.binary", "unused.cbrdf", &s),
               CBRDF_ERROR_INVALID_ARGUMENT);

  /* NULL pointers and a wrong count. */
  cbrdf_encode_settings_init(&s);
  CHECK_STATUS(cbrdf_encode_table(NULL, cbrdf_merl_table_size(), &s, &out, &size),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_encode_table(table, cbrdf_merl_table_size(), &s, NULL, &size),
               CBRDF_ERROR_INVALID_ARGUMENT);
  out = (void*)&s;
  CHECK_STATUS(cbrdf_encode_table(table, cbrdf_merl_table_size(), &s, &out, NULL),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK(out == NULL);
  CHECK_STATUS(cbrdf_encode_table(table, cbrdf_merl_table_size() - 3, &s, &out, &size),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("count");
  CHECK_STATUS(cbrdf_encode_merl_file(NULL, "x.cbrdf", &s), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_encode_merl_file("x.binary", NULL, &s), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(
      cbrdf_encode_merl_file(GOLDEN_DIR "no-such.binary", CBRDF_TEST_TMP_DIR "/x.cbrdf", &s),
      CBRDF_ERROR_NOT_FOUND);
  CHECK_MESSAGE_HAS("no-such.binary");
  /* A .cbrdf file is no MERL table. */
  CHECK(cbrdf_encode_merl_file(GOLDEN_DIR "v1.0-frank6-b10.cbrdf", CBRDF_TEST_TMP_DIR "/x.cbrdf",
                               &s) != CBRDF_OK);
  CHECK(cbrdf_last_error_code() != CBRDF_OK && cbrdf_last_error_message()[0] != '\0');
}

/* Re-encodes the golden model's table from memory and from a file, and opens the results. */
static void test_encode(const double* table) {
  const size_t count = cbrdf_merl_table_size();
  double* copy = (double*)malloc(count * sizeof(double));
  double* decoded = (double*)malloc(count * sizeof(double));
  double* decoded_file = (double*)malloc(count * sizeof(double));
  cbrdf_encode_settings s;
  void* bytes = NULL;
  size_t size = 0, i;
  char merl_path[512], cbrdf_path[512];
  cbrdf_model* m;
  cbrdf_model_info info;
  const char* v;
  int k, begin = -1, end = -1, family = -1;
  double err = 0, ref = 0, theta = 0, scale = 0;
  CHECK(copy != NULL && decoded != NULL && decoded_file != NULL);
  if (copy == NULL || decoded == NULL || decoded_file == NULL) {
    free(copy);
    free(decoded);
    free(decoded_file);
    return;
  }
  memcpy(copy, table, count * sizeof(double));

  cbrdf_encode_settings_init(&s);
  s.bits = 10;
  s.zstd_level = 3;
  s.threads = 2;
  s.format_version = CBRDF_FORMAT_1_2; /* the checks below read the 1.0 file's full metadata */
  s.metadata = CBRDF_METADATA_FULL;

  /* +Inf is neither a measurement nor the not-measured mark. */
  copy[BINS_PER_CHANNEL + 12345] = INFINITY;
  CHECK_STATUS(cbrdf_encode_table(copy, count, &s, &bytes, &size), CBRDF_ERROR_NUMERIC);
  CHECK_MESSAGE_HAS("+Inf");
  CHECK(bytes == NULL && size == 0);
  copy[BINS_PER_CHANNEL + 12345] = table[BINS_PER_CHANNEL + 12345];

  CHECK_STATUS(cbrdf_encode_table(copy, count, &s, &bytes, &size), CBRDF_OK);
  CHECK(bytes != NULL && size > 500 && size < 20000);
  m = bytes != NULL ? cbrdf_model_open_memory(bytes, size) : NULL;
  CHECK(m != NULL);
  if (m != NULL) {
    info.struct_size = sizeof info;
    CHECK_STATUS(cbrdf_model_get_info(m, &info), CBRDF_OK);
    CHECK(info.version_major == 1 && info.version_minor == 0);
    CHECK(info.slices == 6 && info.max_components == 1 && info.bits == 10);
    CHECK(info.file_bytes == size);
    CHECK(info.not_measured_bins == kFrank6.not_measured_bins);
    for (k = 0; k < 6; ++k) { /* uniform slices, Frank */
      CHECK_STATUS(cbrdf_model_get_slice(m, k, &begin, &end), CBRDF_OK);
      CHECK(begin == 15 * k && end == 15 * (k + 1));
      CHECK_STATUS(cbrdf_model_get_component(m, k, 1, 0, &family, &theta, &scale), CBRDF_OK);
      CHECK(family == CBRDF_FAMILY_FRANK && isfinite(theta) && scale > 0);
    }
    v = metadata_value(m, "bits");
    CHECK(v != NULL && strcmp(v, "10") == 0);
    v = metadata_value(m, "zstd_level");
    CHECK(v != NULL && strcmp(v, "3") == 0);
    CHECK(metadata_value(m, "source") == NULL); /* from memory: no source name */
    /* The mask and its values come back bit for bit; the values approximately (the golden
     * model's slices are not uniform, so a uniform refit cannot be exact: `cbrdf encode` of the
     * same table reports about 61 dB tone-mapped sphere PSNR). */
    CHECK_STATUS(cbrdf_model_table(m, decoded, count), CBRDF_OK);
    for (i = 0; i < count; ++i) {
      if (table[i] < 0) {
        if (memcmp(&table[i], &decoded[i], sizeof(double)) != 0) break;
        continue;
      }
      if (!(decoded[i] >= 0) || !isfinite(decoded[i])) break;
      err += fabs(decoded[i] - table[i]);
      ref += table[i];
    }
    CHECK(i == count);
    printf("re-encoded %s from memory: %lu bytes, mean absolute error / mean value %.4f\n",
           kFrank6.file, (unsigned long)size, ref > 0 ? err / ref : -1.0);
    CHECK(ref > 0 && err / ref < 1.0);
    cbrdf_model_free(m);
  }
  cbrdf_free(bytes);

  /* The coding and the metadata (since 2.2): the defaults are the command's (1.3 where smaller,
   * short metadata); none leaves the chunk out; a caller built against the struct before 2.2 (a
   * smaller struct_size) keeps the 1.2 coding with full metadata. */
  {
    struct {
      int format_version, metadata;
      uint32_t struct_size;
      int minor;
      int has_bits, has_metadata;
    } cases[] = {
        {CBRDF_FORMAT_AUTO, CBRDF_METADATA_SHORT, (uint32_t)sizeof s, 3, 0, 1},
        {CBRDF_FORMAT_1_3, CBRDF_METADATA_NONE, (uint32_t)sizeof s, 3, 0, 0},
        {CBRDF_FORMAT_1_2, CBRDF_METADATA_SHORT, (uint32_t)sizeof s, 0, 0, 1},
        {CBRDF_FORMAT_AUTO, CBRDF_METADATA_SHORT,
         (uint32_t)offsetof(cbrdf_encode_settings, format_version), 0, 1, 1},
    };
    size_t c;
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
      size_t n = 0;
      s.format_version = cases[c].format_version;
      s.metadata = cases[c].metadata;
      s.struct_size = cases[c].struct_size;
      bytes = NULL;
      CHECK_STATUS(cbrdf_encode_table(copy, count, &s, &bytes, &size), CBRDF_OK);
      m = bytes != NULL ? cbrdf_model_open_memory(bytes, size) : NULL;
      CHECK(m != NULL);
      if (m != NULL) {
        info.struct_size = sizeof info;
        CHECK_STATUS(cbrdf_model_get_info(m, &info), CBRDF_OK);
        CHECK(info.version_major == 1 && info.version_minor == cases[c].minor);
        CHECK((metadata_value(m, "bits") != NULL) == cases[c].has_bits);
        CHECK_STATUS(cbrdf_model_metadata_count(m, &n), CBRDF_OK);
        CHECK((n > 0) == cases[c].has_metadata);
        cbrdf_model_free(m);
      }
      cbrdf_free(bytes);
    }
    s.struct_size = (uint32_t)sizeof s;
    s.format_version = CBRDF_FORMAT_1_2;
    s.metadata = CBRDF_METADATA_FULL;
  }

  /* The same through files (MERL .binary in, .cbrdf out, the input's name recorded) is the same
   * model: its table is bit for bit the one encoded from memory. */
  tmp_path(merl_path, sizeof merl_path, "frank6.binary");
  tmp_path(cbrdf_path, sizeof cbrdf_path, "frank6.cbrdf");
  m = cbrdf_model_open_file(GOLDEN_DIR "v1.0-frank6-b10.cbrdf");
  CHECK(m != NULL);
  CHECK_STATUS(cbrdf_model_write_merl(m, merl_path), CBRDF_OK);
  cbrdf_model_free(m);
  CHECK_STATUS(cbrdf_encode_merl_file(merl_path, cbrdf_path, &s), CBRDF_OK);
  m = cbrdf_model_open_file(cbrdf_path);
  CHECK(m != NULL);
  if (m != NULL) {
    info.struct_size = sizeof info;
    CHECK_STATUS(cbrdf_model_get_info(m, &info), CBRDF_OK);
    CHECK(info.slices == 6 && info.bits == 10 && info.version_minor == 0);
    v = metadata_value(m, "source");
    CHECK(v != NULL && strstr(merl_path, v) != NULL && strstr(v, "frank6.binary") != NULL);
    CHECK_STATUS(cbrdf_model_table(m, decoded_file, count), CBRDF_OK);
    CHECK(memcmp(decoded_file, decoded, count * sizeof(double)) == 0);
    cbrdf_model_free(m);
  }
  /* Other settings reach the encoder: 3 Clayton slices. */
  s.slices = 3;
  s.family = CBRDF_FAMILY_CLAYTON;
  CHECK_STATUS(cbrdf_encode_merl_file(merl_path, cbrdf_path, &s), CBRDF_OK);
  m = cbrdf_model_open_file(cbrdf_path);
  CHECK(m != NULL);
  if (m != NULL) {
    info.struct_size = sizeof info;
    CHECK_STATUS(cbrdf_model_get_info(m, &info), CBRDF_OK);
    CHECK(info.slices == 3 && info.bits == 10 && info.version_minor == 0);
    for (k = 0; k < 3; ++k) {
      CHECK_STATUS(cbrdf_model_get_slice(m, k, &begin, &end), CBRDF_OK);
      CHECK(begin == 30 * k && end == 30 * (k + 1));
      CHECK_STATUS(cbrdf_model_get_component(m, k, 2, 0, &family, &theta, &scale), CBRDF_OK);
      CHECK(family == CBRDF_FAMILY_CLAYTON && scale > 0);
    }
    cbrdf_model_free(m);
  }
  /* Two components with their copulas left at independence: every mixture's thetas are 0. */
  s.family = CBRDF_FAMILY_FRANK;
  s.components = 2;
  s.mixture_copulas = 0;
  CHECK_STATUS(cbrdf_encode_merl_file(merl_path, cbrdf_path, &s), CBRDF_OK);
  m = cbrdf_model_open_file(cbrdf_path);
  CHECK(m != NULL);
  if (m != NULL) {
    int mixtures = 0, c, n = 0, r;
    for (k = 0; k < 3; ++k) {
      for (c = 0; c < 3; ++c) {
        CHECK_STATUS(cbrdf_model_get_component_count(m, k, c, &n), CBRDF_OK);
        if (n < 2) continue;
        ++mixtures;
        for (r = 0; r < n; ++r) {
          CHECK_STATUS(cbrdf_model_get_component(m, k, c, r, &family, &theta, &scale), CBRDF_OK);
          CHECK(family == CBRDF_FAMILY_FRANK && theta == 0.0 && scale > 0);
        }
      }
    }
    CHECK(mixtures > 0);
    cbrdf_model_free(m);
  }
  s.components = 1;
  s.mixture_copulas = 1;
  /* Settings NULL: the defaults, the command's (6 slices, bits from the data, version 1.3 where
   * smaller, short metadata: the source's name but not the zstd level). */
  CHECK_STATUS(cbrdf_encode_merl_file(merl_path, cbrdf_path, NULL), CBRDF_OK);
  m = cbrdf_model_open_file(cbrdf_path);
  CHECK(m != NULL);
  if (m != NULL) {
    info.struct_size = sizeof info;
    CHECK_STATUS(cbrdf_model_get_info(m, &info), CBRDF_OK);
    CHECK(info.slices == 6 && info.bits >= 6 && info.bits <= 16 && info.version_minor == 3);
    CHECK(metadata_value(m, "zstd_level") == NULL);
    v = metadata_value(m, "source");
    CHECK(v != NULL && strstr(v, "frank6.binary") != NULL);
    cbrdf_model_free(m);
  }
  /* An output that cannot be written. */
  CHECK_STATUS(cbrdf_encode_merl_file(merl_path, CBRDF_TEST_DATA_DIR, &s), CBRDF_ERROR_IO);
  remove(merl_path);
  remove(cbrdf_path);
  free(copy);
  free(decoded);
  free(decoded_file);
}

#endif /* CBRDF_C_TEST_DECODER_ONLY */

/* ---- What a renderer calls ---------------------------------------------------------------------
 */

/* Directions scaled off unit length within the 1e-3 tolerance are rescaled before use: the value
 * is the unit vector's (before, |w| = 1.0004 at the mirror direction changed f by 0.65%). */
static void test_renormalized(const cbrdf_model* m) {
  double wi[3], wo[3], wi_long[3], wo_long[3], a[3], b[3], batch[6], pa = 0, pb = 0;
  double two_wi[6], two_wo[6];
  int c;
  direction(30, 0, wi);
  direction(30, 180, wo); /* the mirror direction: the specular peak */
  for (c = 0; c < 3; ++c) {
    wi_long[c] = wi[c] * 1.0004;
    wo_long[c] = wo[c] * 0.9997;
  }
  CHECK_STATUS(cbrdf_model_eval(m, wi, wo, a), CBRDF_OK);
  CHECK_STATUS(cbrdf_model_eval(m, wi_long, wo_long, b), CBRDF_OK);
  for (c = 0; c < 3; ++c) CHECK(a[c] > 0 && close_rel(a[c], b[c], 1e-12));
  /* The batch rescales as eval does, one pair unit and one not. */
  memcpy(two_wi, wi, sizeof wi);
  memcpy(two_wi + 3, wi_long, sizeof wi);
  memcpy(two_wo, wo, sizeof wo);
  memcpy(two_wo + 3, wo_long, sizeof wo);
  CHECK_STATUS(cbrdf_model_eval_batch(m, 2, two_wi, two_wo, batch, 1), CBRDF_OK);
  CHECK(memcmp(batch, a, sizeof a) == 0 && memcmp(batch + 3, b, sizeof b) == 0);
  /* So does the sampler's density. */
  CHECK_STATUS(cbrdf_model_sample_pdf(m, wi, wo, &pa), CBRDF_OK);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, wi_long, wo_long, &pb), CBRDF_OK);
  CHECK(pa > 0 && close_rel(pa, pb, 1e-12));
}

/* One draw: cbrdf_model_sample equals the batch's draw bit for bit, for valid, rejected and
 * below-horizon draws, with any thread count; weight = f cos / pdf. */
#define N_SINGLE 300
static void test_single_sample(const cbrdf_model* m) {
  static double wo[N_SINGLE * 3], u[N_SINGLE * 2], wi[N_SINGLE * 3], pdf[N_SINGLE],
      weight[N_SINGLE * 3], wi1[N_SINGLE * 3], pdf1[N_SINGLE], weight1[N_SINGLE * 3];
  double one_wi[3], one_pdf, one_w[3], f[3], p;
  double up[3], bad[3] = {0.5, 0.5, 0.5};
  int k, c, same = 1, rejected = 0, valid = 0;
  for (k = 0; k < N_SINGLE; ++k) {
    const double theta_o = k % 10 == 9 ? 100.0 : 88.0 * uniform01();
    direction(theta_o, 360.0 * uniform01(), wo + 3 * k);
    u[2 * k] = k == 3 ? -0.5 : uniform01(); /* clamped into [0, 1) */
    u[2 * k + 1] = k == 4 ? 7.0 : uniform01();
  }
  CHECK_STATUS(cbrdf_model_sample_batch(m, N_SINGLE, wo, u, wi, pdf, weight, 0), CBRDF_OK);
  CHECK_STATUS(cbrdf_model_sample_batch(m, N_SINGLE, wo, u, wi1, pdf1, weight1, 1), CBRDF_OK);
  CHECK(memcmp(wi, wi1, sizeof wi) == 0 && memcmp(pdf, pdf1, sizeof pdf) == 0 &&
        memcmp(weight, weight1, sizeof weight) == 0);
  for (k = 0; k < N_SINGLE; ++k) {
    CHECK_STATUS(cbrdf_model_sample(m, wo + 3 * k, u[2 * k], u[2 * k + 1], one_wi, &one_pdf, one_w),
                 CBRDF_OK);
    same &= memcmp(one_wi, wi + 3 * k, sizeof one_wi) == 0;
    same &= memcmp(&one_pdf, pdf + k, sizeof one_pdf) == 0;
    same &= memcmp(one_w, weight + 3 * k, sizeof one_w) == 0;
    if (one_pdf == 0) {
      ++rejected;
      CHECK(one_wi[0] == 0 && one_wi[1] == 0 && one_wi[2] == 0 && one_w[0] == 0);
      continue;
    }
    ++valid;
    CHECK_STATUS(cbrdf_model_eval(m, one_wi, wo + 3 * k, f), CBRDF_OK);
    CHECK_STATUS(cbrdf_model_sample_pdf(m, one_wi, wo + 3 * k, &p), CBRDF_OK);
    CHECK(p == one_pdf);
    for (c = 0; c < 3; ++c) CHECK(one_w[c] == f[c] * one_wi[2] / one_pdf);
  }
  CHECK(same);
  CHECK(valid > N_SINGLE / 2 && rejected >= N_SINGLE / 10);
  /* Small batches are each draw's own: a batch of 1 and of 5 from the middle of the arrays. */
  CHECK_STATUS(cbrdf_model_sample_batch(m, 1, wo + 3 * 17, u + 2 * 17, wi1, pdf1, weight1, 1),
               CBRDF_OK);
  CHECK(memcmp(wi1, wi + 3 * 17, 3 * sizeof(double)) == 0 && pdf1[0] == pdf[17]);
  CHECK_STATUS(cbrdf_model_sample_batch(m, 5, wo + 3 * 40, u + 2 * 40, wi1, pdf1, weight1, 1),
               CBRDF_OK);
  CHECK(memcmp(wi1, wi + 3 * 40, 15 * sizeof(double)) == 0 &&
        memcmp(weight1, weight + 3 * 40, 15 * sizeof(double)) == 0);
  /* Errors leave the outputs alone. */
  direction(20, 0, up);
  one_pdf = 42.0;
  one_wi[0] = 42.0;
  CHECK_STATUS(cbrdf_model_sample(m, bad, 0.5, 0.5, one_wi, &one_pdf, one_w),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wo");
  CHECK_STATUS(cbrdf_model_sample(m, up, NAN, 0.5, one_wi, &one_pdf, one_w),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("u1, u2");
  CHECK_STATUS(cbrdf_model_sample(m, up, 0.5, INFINITY, one_wi, &one_pdf, one_w),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK(one_pdf == 42.0 && one_wi[0] == 42.0);
  CHECK_STATUS(cbrdf_model_sample(NULL, up, 0.5, 0.5, one_wi, &one_pdf, one_w),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample(m, NULL, 0.5, 0.5, one_wi, &one_pdf, one_w),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample(m, up, 0.5, 0.5, NULL, &one_pdf, one_w),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample(m, up, 0.5, 0.5, one_wi, NULL, one_w),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_sample(m, up, 0.5, 0.5, one_wi, &one_pdf, NULL),
               CBRDF_ERROR_INVALID_ARGUMENT);
}

/* The argument order: cbrdf_model_sample_pdf(wi, wo) is the deprecated cbrdf_model_pdf(wo, wi),
 * and cbrdf_model_eval_pdf(wi, wo) is eval and sample_pdf at once. */
static void test_eval_pdf(const cbrdf_model* m) {
  double wi[3], wo[3], rgb[3], f[3], p = -1, q = -1, r = -1, bad[3] = {0, 0, 1.01};
  const double zero[3] = {0.0, 0.0, 0.0};
  direction(50, 30, wi);
  direction(20, 250, wo);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, wi, wo, &p), CBRDF_OK);
  CHECK_STATUS(cbrdf_model_sample_pdf(m, wo, wi, &r), CBRDF_OK);
  CHECK(p > 0 && r > 0 && p != r); /* not symmetric: the order matters */
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
  CHECK_STATUS(cbrdf_model_pdf(m, wo, wi, &q), CBRDF_OK);
  r = 1.0; /* a rejected draw's wi, (0, 0, 0): 0 as in cbrdf_model_sample_pdf */
  CHECK_STATUS(cbrdf_model_pdf(m, wo, zero, &r), CBRDF_OK);
  CHECK(r == 0.0);
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
  CHECK(p == q);
  CHECK_STATUS(cbrdf_model_eval_pdf(m, wi, wo, rgb, &q), CBRDF_OK);
  CHECK_STATUS(cbrdf_model_eval(m, wi, wo, f), CBRDF_OK);
  CHECK(q == p && memcmp(rgb, f, sizeof f) == 0);
  q = 42;
  rgb[0] = 42;
  CHECK_STATUS(cbrdf_model_eval_pdf(m, bad, wo, rgb, &q), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wi");
  CHECK_STATUS(cbrdf_model_eval_pdf(m, wi, bad, rgb, &q), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wo");
  CHECK(q == 42 && rgb[0] == 42);
  CHECK_STATUS(cbrdf_model_eval_pdf(NULL, wi, wo, rgb, &q), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_pdf(m, wi, wo, NULL, &q), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_pdf(m, wi, wo, rgb, NULL), CBRDF_ERROR_INVALID_ARGUMENT);
}

/* Single precision: the batch equals the call bit for bit, both are close to the double
 * evaluation, and bad float directions are refused. */
#define N_F32 200
static void test_eval_f32(const cbrdf_model* m) {
  static float wi[N_F32 * 3], wo[N_F32 * 3], rgb[N_F32 * 3], batch[N_F32 * 3];
  double di[3], dout[3], ref[3], peak = 0;
  float one[3], big[3] = {1e30f, 0, 1e30f}, nan3[3] = {NAN, 0, 1};
  int k, c, same = 1, close = 1;
  for (k = 0; k < N_F32; ++k) {
    direction(85.0 * uniform01(), 360.0 * uniform01(), di);
    direction(85.0 * uniform01(), 360.0 * uniform01(), dout);
    for (c = 0; c < 3; ++c) {
      wi[3 * k + c] = (float)di[c];
      wo[3 * k + c] = (float)dout[c];
    }
    CHECK_STATUS(cbrdf_model_eval_f32(m, wi + 3 * k, wo + 3 * k, rgb + 3 * k), CBRDF_OK);
  }
  CHECK_STATUS(cbrdf_model_eval_batch_f32(m, N_F32, wi, wo, batch, 0), CBRDF_OK);
  for (k = 0; k < 3 * N_F32; ++k) same &= memcmp(&batch[k], &rgb[k], sizeof(float)) == 0;
  CHECK(same);
  for (k = 0; k < 3 * N_F32; ++k) peak = fmax(peak, (double)rgb[k]);
  for (k = 0; k < N_F32; ++k) {
    for (c = 0; c < 3; ++c) {
      di[c] = wi[3 * k + c];
      dout[c] = wo[3 * k + c];
    }
    CHECK_STATUS(cbrdf_model_eval(m, di, dout, ref), CBRDF_OK);
    for (c = 0; c < 3; ++c) {
      close &= fabs((double)rgb[3 * k + c] - ref[c]) <= 1e-4 * ref[c] + 1e-6 * peak;
    }
  }
  CHECK(peak > 0 && close);
  one[0] = 42;
  CHECK_STATUS(cbrdf_model_eval_f32(m, big, wo, one), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_f32(m, wi, nan3, one), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK(one[0] == 42);
  memcpy(batch, rgb, sizeof rgb);
  wo[3 * 8 + 2] = 2.0f;
  CHECK_STATUS(cbrdf_model_eval_batch_f32(m, N_F32, wi, wo, rgb, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("wo[8]");
  CHECK(memcmp(batch, rgb, sizeof rgb) == 0);
  CHECK_STATUS(cbrdf_model_eval_batch_f32(m, 0, NULL, NULL, NULL, 0), CBRDF_OK);
  CHECK_STATUS(cbrdf_model_eval_batch_f32(NULL, 1, wi, wo, rgb, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_batch_f32(m, 1, NULL, wo, rgb, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_batch_f32(m, SIZE_MAX, wi, wo, rgb, 0),
               CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_eval_f32(m, NULL, wo, one), CBRDF_ERROR_INVALID_ARGUMENT);
}

/* The directional albedo (experimental): the quadrature agrees with the mean weight of
 * stratified draws from the sampler (an independent estimate of the same integral), the table
 * holds the same values, and the horizon gives 0. */
#define N_STRATA 256
static void test_albedo(const cbrdf_model* m) {
  static double wo[N_STRATA * N_STRATA * 3], u[N_STRATA * N_STRATA * 2],
      wi[N_STRATA * N_STRATA * 3], pdf[N_STRATA * N_STRATA], weight[N_STRATA * N_STRATA * 3];
  const size_t n = (size_t)N_STRATA * N_STRATA;
  const double thetas[3] = {10.0, 45.0, 75.0};
  double table[8 * 3], a[3], mean[3], below[3], t;
  size_t k;
  int i, c;
  for (i = 0; i < 3; ++i) {
    direction(thetas[i], 0, wo);
    CHECK_STATUS(cbrdf_model_albedo(m, wo, a, 0), CBRDF_OK);
    for (k = 0; k < n; ++k) {
      memcpy(wo + 3 * k, wo, 3 * sizeof(double));
      u[2 * k] = ((double)(k / N_STRATA) + uniform01()) / N_STRATA;
      u[2 * k + 1] = ((double)(k % N_STRATA) + uniform01()) / N_STRATA;
    }
    CHECK_STATUS(cbrdf_model_sample_batch(m, n, wo, u, wi, pdf, weight, 0), CBRDF_OK);
    mean[0] = mean[1] = mean[2] = 0;
    for (k = 0; k < n; ++k) {
      for (c = 0; c < 3; ++c) mean[c] += weight[3 * k + c] / (double)n;
    }
    printf("albedo at %g deg: %.5f %.5f %.5f, sampled %.5f %.5f %.5f\n", thetas[i], a[0], a[1],
           a[2], mean[0], mean[1], mean[2]);
    /* 1%, and a floor for a channel near 0 (G of the Frank file, about 1e-6). */
    for (c = 0; c < 3; ++c) {
      CHECK(a[c] >= 0 && a[c] < 1.5 &&
            fabs(a[c] - mean[c]) <= 0.01 * fmax(a[c], mean[c]) + 1e-3 * (a[0] + a[1] + a[2]));
    }
    CHECK(a[0] + a[1] + a[2] > 0);
  }
  /* The table: entry k at theta = (k + 0.5) / 8 * 90 degrees, bit for bit. */
  CHECK_STATUS(cbrdf_model_albedo_table(m, 8, table, 1), CBRDF_OK);
  for (i = 0; i < 8; ++i) {
    t = (i + 0.5) / 8 * (PI / 2);
    wo[0] = sin(t);
    wo[1] = 0;
    wo[2] = cos(t);
    CHECK_STATUS(cbrdf_model_albedo(m, wo, a, 1), CBRDF_OK);
    CHECK(memcmp(a, table + 3 * i, sizeof a) == 0);
  }
  direction(100, 0, wo);
  CHECK_STATUS(cbrdf_model_albedo(m, wo, below, 0), CBRDF_OK);
  CHECK(below[0] == 0 && below[1] == 0 && below[2] == 0);
  table[0] = 42;
  CHECK_STATUS(cbrdf_model_albedo_table(m, 0, table, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_albedo_table(m, 257, table, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("1 to 256");
  CHECK(table[0] == 42);
  wo[2] = NAN;
  CHECK_STATUS(cbrdf_model_albedo(m, wo, a, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_albedo(NULL, wo, a, 0), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(cbrdf_model_albedo_table(m, 8, NULL, 0), CBRDF_ERROR_INVALID_ARGUMENT);
}

/* The residual modes are an enum type (they were #defines beside the enums). */
static void test_residual_mode_enum(void) {
  cbrdf_residual_mode mode = CBRDF_RESIDUAL_INTERPOLATED;
  CHECK(mode == 3 && CBRDF_RESIDUAL_NONE == -1 && sizeof(cbrdf_residual_mode) == sizeof(int));
}

static void test_renderer_calls(const cbrdf_model* m) {
  test_renormalized(m);
  test_single_sample(m);
  test_eval_pdf(m);
  test_eval_f32(m);
  test_albedo(m);
}

/* ---- Main -------------------------------------------------------------------------------------
 */

static void test_golden(const struct expected_model* e, double** table_out) {
  char path[512];
  size_t size = 0;
  unsigned char* bytes;
  cbrdf_model *from_file, *from_memory;
  double wi[3], wo[3], a[3], b[3];
  snprintf(path, sizeof path, "%s%s", GOLDEN_DIR, e->file);
  printf("%s\n", e->file);
  from_file = cbrdf_model_open_file(path);
  CHECK(from_file != NULL);
  CHECK(cbrdf_last_error_code() == CBRDF_OK);
  bytes = read_whole_file(path, &size);
  CHECK(bytes != NULL && size == e->file_bytes);
  from_memory = bytes != NULL ? cbrdf_model_open_memory(bytes, size) : NULL;
  CHECK(from_memory != NULL);
  /* The handle does not keep the bytes. */
  if (bytes != NULL) memset(bytes, 0, size);
  free(bytes);
  if (from_file == NULL || from_memory == NULL) {
    cbrdf_model_free(from_file);
    cbrdf_model_free(from_memory);
    return;
  }
  direction(30, 10, wi);
  direction(40, 200, wo);
  CHECK_STATUS(cbrdf_model_eval(from_file, wi, wo, a), CBRDF_OK);
  CHECK_STATUS(cbrdf_model_eval(from_memory, wi, wo, b), CBRDF_OK);
  CHECK(memcmp(a, b, sizeof a) == 0);
  cbrdf_model_free(from_memory);

  test_info(from_file, e);
  test_slices_and_components(from_file, e);
  test_metadata(from_file, e);
  test_eval(from_file);
  test_sampling(from_file);
  test_renderer_calls(from_file);
  if (table_out != NULL) {
    *table_out = test_table(from_file, e);
  } else {
    free(test_table(from_file, e));
  }
  cbrdf_model_free(from_file);
}

/* ---- The residual layer (container 1.2) -------------------------------------------------------
 */

#ifndef CBRDF_C_TEST_DECODER_ONLY
/* Largest |log1p(decoded / k) - log1p(source / k)| over measured bins (k = 1e-4 stored units, the
 * bound's unit); -1 when a not-measured bin did not come back bit for bit. */
static double residual_error(const double* source, const double* decoded, size_t count) {
  double worst = 0;
  size_t i;
  for (i = 0; i < count; ++i) {
    if (source[i] < 0) {
      if (memcmp(&source[i], &decoded[i], sizeof(double)) != 0) return -1;
      continue;
    }
    worst = fmax(worst, fabs(log1p(decoded[i] / 1e-4) - log1p(source[i] / 1e-4)));
  }
  return worst;
}

/* Encodes `table` with `s` and opens the file, with *info filled; NULL (a failed CHECK) when
 * either step fails. */
static cbrdf_model* encode_and_open(const double* table, const cbrdf_encode_settings* s,
                                    cbrdf_model_info* info, size_t* size) {
  void* bytes = NULL;
  cbrdf_model* m;
  CHECK_STATUS(cbrdf_encode_table(table, cbrdf_merl_table_size(), s, &bytes, size), CBRDF_OK);
  m = bytes != NULL ? cbrdf_model_open_memory(bytes, *size) : NULL;
  cbrdf_free(bytes);
  CHECK(m != NULL);
  if (m != NULL) {
    info->struct_size = sizeof *info;
    CHECK_STATUS(cbrdf_model_get_info(m, info), CBRDF_OK);
  }
  return m;
}
#endif /* CBRDF_C_TEST_DECODER_ONLY */

/* A golden file's description: its minor version, size, the residual's mode, bounds and chunk
 * bytes (knee 1e-4). */
static void check_residual_golden(const char* file, int minor, uint64_t file_bytes, int mode,
                                  double max_error, double min_error, uint64_t residual_bytes) {
  char path[512];
  cbrdf_model_info info;
  cbrdf_model* m;
  snprintf(path, sizeof path, "%s%s", GOLDEN_DIR, file);
  m = cbrdf_model_open_file(path);
  CHECK(m != NULL);
  if (m == NULL) return;
  info.struct_size = sizeof info;
  CHECK_STATUS(cbrdf_model_get_info(m, &info), CBRDF_OK);
  CHECK(info.version_minor == minor && info.file_bytes == file_bytes);
  CHECK(info.residual_mode == mode);
  CHECK(info.residual_max_error == max_error && info.residual_min_error == min_error);
  CHECK(info.residual_knee == 1e-4 && info.residual_bytes == residual_bytes);
  cbrdf_model_free(m);
}

/* The golden 1.2 files, as `cbrdf info --json` describes them: one bound, and a bound per row
 * (the coarsest row's and the finest row's). */
static void test_residual_goldens(void) {
  check_residual_golden("v1.2-residual-frank6-b10.cbrdf", 2, 6478, CBRDF_RESIDUAL_BOUNDED, 0.004,
                        0.004, 3073);
  check_residual_golden("v1.2-residual-rows-frank6-b10.cbrdf", 2, 6583, CBRDF_RESIDUAL_ROW_BOUNDED,
                        0.128, 0.004, 3173);
  /* Interpolated levels: the coarsest row's bound 0.128 times the finest multiplier 4. */
  check_residual_golden("v1.2-residual-interp-frank6-b10.cbrdf", 2, 7860,
                        CBRDF_RESIDUAL_INTERPOLATED, 0.512, 0.004, 4449);
  /* A step per level (1.3): the coarsest row's bound 0.02 times the largest multiplier 8. */
  check_residual_golden("v1.3-level-steps-residual-frank6-b10.cbrdf", 3, 13815,
                        CBRDF_RESIDUAL_LEVEL_STEPS, 0.16, 0.01, 12194);
}

#ifndef CBRDF_C_TEST_DECODER_ONLY
static void test_residual(const double* table) {
  const size_t count = cbrdf_merl_table_size();
  double* decoded = (double*)malloc(count * sizeof(double));
  cbrdf_encode_settings s;
  cbrdf_model_info info;
  cbrdf_model* m;
  void* bytes = NULL;
  size_t size = 0, bounded_size = 0;
  double worst;
  CHECK(decoded != NULL);
  if (decoded == NULL) return;

  /* Out of range, or both: refused before any work, naming the field. */
  cbrdf_encode_settings_init(&s);
  CHECK(s.max_error == 0 && s.lossless == 0);
  s.max_error = 1e-7;
  CHECK_STATUS(cbrdf_encode_table(table, count, &s, &bytes, &size), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("cbrdf_encode_settings.max_error must be from 1e-06 to 16, not 1e-07");
  s.max_error = NAN;
  CHECK_STATUS(cbrdf_encode_table(table, count, &s, &bytes, &size), CBRDF_ERROR_INVALID_ARGUMENT);
  s.max_error = 17;
  CHECK_STATUS(cbrdf_encode_table(table, count, &s, &bytes, &size), CBRDF_ERROR_INVALID_ARGUMENT);
  s.max_error = 0.01;
  s.lossless = 1;
  CHECK_STATUS(cbrdf_encode_table(table, count, &s, &bytes, &size), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("exclude each other");
  s.max_error = 0;
  s.lossless = 2;
  CHECK_STATUS(cbrdf_encode_table(table, count, &s, &bytes, &size), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("lossless");
  s.lossless = 0;
  CHECK(s.residual_steps == CBRDF_RESIDUAL_STEPS_ONE);
  s.residual_steps = 2;
  s.max_error = 0.01;
  CHECK_STATUS(cbrdf_encode_table(table, count, &s, &bytes, &size), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("residual_steps must be CBRDF_RESIDUAL_STEPS_ONE (0) or");
  s.residual_steps = CBRDF_RESIDUAL_STEPS_VISIBILITY;
  s.max_error = 0;
  CHECK_STATUS(cbrdf_encode_table(table, count, &s, &bytes, &size), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("visibility needs cbrdf_encode_settings.max_error above 0");
  CHECK(bytes == NULL && size == 0);

  /* A bound: every measured bin within it, the not-measured ones exact. */
  cbrdf_encode_settings_init(&s);
  s.bits = 10;
  s.zstd_level = 3;
  s.threads = 2;
  s.max_error = 0.01;
  m = encode_and_open(table, &s, &info, &size);
  if (m != NULL) { /* 1.3 where smaller, as the command writes it (1.2 with CBRDF_FORMAT_1_2) */
    CHECK(info.version_minor == 3 && info.residual_mode == CBRDF_RESIDUAL_BOUNDED);
    CHECK(info.residual_max_error == 0.01 && info.residual_min_error == 0.01);
    CHECK(info.residual_bytes > 0);
    CHECK(info.residual_bytes < info.file_bytes);
    CHECK_STATUS(cbrdf_model_table(m, decoded, count), CBRDF_OK);
    worst = residual_error(table, decoded, count);
    printf("max_error 0.01: %lu bytes, largest error %.6f\n", (unsigned long)size, worst);
    CHECK(worst >= 0 && worst <= 0.01 * (1 + 1e-9));
    cbrdf_model_free(m);
  }
  bounded_size = size;

  /* Visibility steps: the most visible rows within the bound, the others within a coarser one
   * (the file records both), for fewer bytes. */
  s.residual_steps = CBRDF_RESIDUAL_STEPS_VISIBILITY;
  m = encode_and_open(table, &s, &info, &size);
  if (m != NULL) {
    /* A 1.3 file: row bounds, interpolated levels with a step per level (RESD mode 4). */
    CHECK(info.version_minor == 3 && info.residual_mode == CBRDF_RESIDUAL_LEVEL_STEPS);
    CHECK(info.residual_min_error == 0.01);
    CHECK(info.residual_max_error > 0.01 && info.residual_max_error <= 16);
    CHECK_STATUS(cbrdf_model_table(m, decoded, count), CBRDF_OK);
    worst = residual_error(table, decoded, count);
    printf(
        "max_error 0.01, visibility steps: %lu bytes (one step: %lu), largest error %.6f of "
        "at most %.4f\n",
        (unsigned long)size, (unsigned long)bounded_size, worst, info.residual_max_error);
    CHECK(worst >= 0 && worst <= info.residual_max_error * (1 + 1e-9));
    CHECK(size < bounded_size);
    cbrdf_model_free(m);
  }
  /* A caller built against the struct before residual_steps: the field past its struct_size is
   * not read (here it would be refused without a max_error). */
  s.struct_size = (uint32_t)offsetof(cbrdf_encode_settings, residual_steps);
  s.max_error = 0;
  CHECK_STATUS(cbrdf_encode_table(table, count, &s, &bytes, &size), CBRDF_OK);
  cbrdf_free(bytes);
  bytes = NULL;
  s.struct_size = (uint32_t)sizeof s;
  s.residual_steps = CBRDF_RESIDUAL_STEPS_ONE;

  /* Lossless: the table bit for bit. */
  s.max_error = 0;
  s.lossless = 1;
  m = encode_and_open(table, &s, &info, &size);
  if (m != NULL) {
    CHECK(info.residual_mode == CBRDF_RESIDUAL_LOSSLESS && info.residual_max_error == 0);
    CHECK_STATUS(cbrdf_model_table(m, decoded, count), CBRDF_OK);
    CHECK(memcmp(table, decoded, count * sizeof(double)) == 0);
    printf("lossless: %lu bytes\n", (unsigned long)size);
    cbrdf_model_free(m);
  }
  cbrdf_free(bytes);
  free(decoded);
}

/* The noise estimate: near 0 on a decoded model's table (smooth), the injected size on the same
 * table with 3% multiplicative noise; bad arguments refused naming what is wrong. */
static void test_noise(const double* table) {
  const size_t count = cbrdf_merl_table_size();
  double* noisy = (double*)malloc(count * sizeof(double));
  cbrdf_noise_estimate e;
  size_t i;
  int c, b;
  CHECK(noisy != NULL);
  if (noisy == NULL) return;
  memset(&e, 0, sizeof e);
  e.struct_size = sizeof e;
  CHECK_STATUS(cbrdf_estimate_noise(table, count, &e), CBRDF_OK);
  CHECK(e.noisy == 0);
  for (c = 0; c < 3; ++c) CHECK(e.sigma[c] < 0.002);
  CHECK(e.psnr_ceiling_tonemapped == 100.0);

  for (i = 0; i < count; ++i) {
    /* Box-Muller: a normal deviate from two uniforms. */
    const double u1 = uniform01() * (1 - 1e-12) + 1e-12, u2 = uniform01();
    const double z = sqrt(-2 * log(u1)) * cos(2 * PI * u2);
    noisy[i] = table[i] >= 0 ? table[i] * exp(0.03 * z) : table[i];
  }
  CHECK_STATUS(cbrdf_estimate_noise(noisy, count, &e), CBRDF_OK);
  CHECK(e.struct_size == sizeof e);
  CHECK(e.noisy == 1);
  for (c = 0; c < 3; ++c) CHECK(close_rel(e.sigma[c], 0.03, 0.1));
  for (b = 0; b < CBRDF_NOISE_BANDS; ++b) CHECK(close_rel(e.band_sigma[b][1], 0.03, 0.2));
  CHECK(close_rel(e.grazing_growth, 1.0, 0.2));
  CHECK(e.psnr_ceiling_tonemapped > 20 && e.psnr_ceiling_tonemapped < 100);

  CHECK_STATUS(cbrdf_estimate_noise(NULL, count, &e), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("stored_values");
  CHECK_STATUS(cbrdf_estimate_noise(noisy, count - 1, &e), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("count");
  e.struct_size = 8;
  CHECK_STATUS(cbrdf_estimate_noise(noisy, count, &e), CBRDF_ERROR_INVALID_ARGUMENT);
  CHECK_MESSAGE_HAS("struct_size");
  free(noisy);
}

#endif /* CBRDF_C_TEST_DECODER_ONLY */

int main(void) {
  double* frank6_table = NULL;
  test_version_and_names();
  test_last_error_lifecycle();
  test_open_errors();
  test_residual_mode_enum();
  test_golden(&kFrank6, &frank6_table);
  test_golden(&kMixture3, NULL);
  test_threads();
  test_residual_goldens();
  CHECK(frank6_table != NULL);
#ifndef CBRDF_C_TEST_DECODER_ONLY
  /* The encoder half (libcbrdf_encoder): not in a decoder-only build. */
  if (frank6_table != NULL) {
    test_encode_settings(frank6_table);
    test_encode(frank6_table);
    test_residual(frank6_table);
    test_noise(frank6_table);
  }
#endif
  free(frank6_table);
  printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
