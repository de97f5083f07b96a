// SPDX-License-Identifier: MIT
/* The native library's answers for the WebAssembly tests (tests/wasm/wasm_test.mjs) and benchmark
 * (tests/wasm/bench.mjs), through the same C API that cbrdf.wasm exports. Binary inputs come on
 * stdin as doubles, outputs go to stdout as doubles or one line of JSON:
 *
 *   wasm_reference open            stdin: a file's bytes   -> {"code":..,"status":..,"message":..}
 *   wasm_reference info FILE       -> JSON as cbrdf.mjs's Model.info()
 *   wasm_reference table FILE      -> the 4,374,000 doubles of cbrdf_model_table
 *   wasm_reference eval FILE       stdin: wi (3n), wo (3n)  -> rgb (3n), cbrdf_model_eval_batch
 *   wasm_reference sample FILE     stdin: wo (3n), u (2n)   -> wi (3n), pdf (n), weight (3n)
 *   wasm_reference bench FILE MS   stdin: wi, wo            -> {"ns_per_pair":..,"pairs":..} (CPU)
 *
 * Exit status 0, or 1 with a message on stderr (2 for bad usage). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cbrdf/cbrdf_c.h"

static void fail_api(const char* what) {
  fprintf(stderr, "wasm_reference: %s: %s (%s)\n", what, cbrdf_last_error_message(),
          cbrdf_status_name(cbrdf_last_error_code()));
  exit(1);
}

static void* xmalloc(size_t n) {
  void* p = malloc(n ? n : 1);
  if (!p) {
    fprintf(stderr, "wasm_reference: out of memory (%zu bytes)\n", n);
    exit(1);
  }
  return p;
}

/* All of a stream, *size bytes. */
static unsigned char* read_all(FILE* f, size_t* size) {
  size_t cap = 1 << 16, n = 0;
  unsigned char* b = xmalloc(cap);
  for (;;) {
    if (n == cap) {
      cap *= 2;
      unsigned char* grown = realloc(b, cap);
      if (!grown) {
        fprintf(stderr, "wasm_reference: out of memory reading input\n");
        exit(1);
      }
      b = grown;
    }
    const size_t got = fread(b + n, 1, cap - n, f);
    n += got;
    if (got == 0) break;
  }
  if (ferror(f)) {
    fprintf(stderr, "wasm_reference: reading input failed\n");
    exit(1);
  }
  *size = n;
  return b;
}

static cbrdf_model* open_path(const char* path) {
  FILE* f = fopen(path, "rb");
  if (!f) {
    fprintf(stderr, "wasm_reference: cannot open %s\n", path);
    exit(1);
  }
  size_t size = 0;
  unsigned char* bytes = read_all(f, &size);
  fclose(f);
  cbrdf_model* m = cbrdf_model_open_memory(bytes, size);
  free(bytes);
  if (!m) fail_api(path);
  return m;
}

/* Doubles from stdin: *count of them. */
static double* read_doubles(size_t* count) {
  size_t size = 0;
  unsigned char* b = read_all(stdin, &size);
  if (size % sizeof(double) != 0) {
    fprintf(stderr, "wasm_reference: stdin holds %zu bytes, not whole doubles\n", size);
    exit(1);
  }
  *count = size / sizeof(double);
  return (double*)b;
}

static void write_doubles(const double* v, size_t n) {
  if (fwrite(v, sizeof(double), n, stdout) != n) {
    fprintf(stderr, "wasm_reference: writing output failed\n");
    exit(1);
  }
}

static void json_string(const char* s) {
  putchar('"');
  for (const unsigned char* p = (const unsigned char*)s; *p; ++p) {
    if (*p == '"' || *p == '\\') {
      printf("\\%c", *p);
    } else if (*p < 0x20) {
      printf("\\u%04x", *p);
    } else {
      putchar(*p);
    }
  }
  putchar('"');
}

static const char* const kFamilies[] = {"independence", "frank", "clayton", "gumbel", "joe"};

static void print_info(const cbrdf_model* m) {
  cbrdf_model_info info;
  info.struct_size = (uint32_t)sizeof info;
  if (cbrdf_model_get_info(m, &info) != CBRDF_OK) fail_api("info");
  printf(
      "{\"versionMajor\":%d,\"versionMinor\":%d,\"slices\":%d,\"maxComponents\":%d,\"bits\":%d,"
      "\"fileBytes\":%llu,\"notMeasuredBins\":%llu,\"residualMode\":%d,"
      "\"residualMaxError\":%.17g,\"residualMinError\":%.17g,\"residualKnee\":%.17g,"
      "\"residualBytes\":%llu,\"sliceList\":[",
      info.version_major, info.version_minor, info.slices, info.max_components, info.bits,
      (unsigned long long)info.file_bytes, (unsigned long long)info.not_measured_bins,
      info.residual_mode, info.residual_max_error, info.residual_min_error, info.residual_knee,
      (unsigned long long)info.residual_bytes);
  for (int s = 0; s < info.slices; ++s) {
    int begin = 0, end = 0;
    if (cbrdf_model_get_slice(m, s, &begin, &end) != CBRDF_OK) fail_api("slice");
    printf("%s{\"thetaDBegin\":%d,\"thetaDEnd\":%d,\"channels\":[", s ? "," : "", begin, end);
    for (int c = 0; c < 3; ++c) {
      int count = 0;
      if (cbrdf_model_get_component_count(m, s, c, &count) != CBRDF_OK) fail_api("components");
      printf("%s[", c ? "," : "");
      for (int k = 0; k < count; ++k) {
        int family = 0;
        double theta = 0, scale = 0;
        if (cbrdf_model_get_component(m, s, c, k, &family, &theta, &scale) != CBRDF_OK) {
          fail_api("component");
        }
        printf("%s{\"family\":", k ? "," : "");
        if (family >= 0 && family < 5) {
          json_string(kFamilies[family]);
        } else {
          printf("\"%d\"", family);
        }
        printf(",\"theta\":%.17g,\"scale\":%.17g}", theta, scale);
      }
      printf("]");
    }
    printf("]}");
  }
  printf("],\"metadata\":[");
  size_t n = 0;
  if (cbrdf_model_metadata_count(m, &n) != CBRDF_OK) fail_api("metadata count");
  for (size_t i = 0; i < n; ++i) {
    const char *key = NULL, *value = NULL;
    if (cbrdf_model_metadata_at(m, i, &key, &value) != CBRDF_OK) fail_api("metadata");
    printf("%s[", i ? "," : "");
    json_string(key);
    putchar(',');
    json_string(value);
    putchar(']');
  }
  printf("]}\n");
}

/* The process's CPU time: on a loaded machine it counts the time this process ran, not the time
 * it waited, as bench.mjs counts node's (one thread evaluates in both). */
static double now_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: wasm_reference open|info|table|eval|sample|bench [FILE] [MS]\n");
    return 2;
  }
  const char* mode = argv[1];
  if (strcmp(mode, "open") == 0) {
    size_t size = 0;
    unsigned char* bytes = read_all(stdin, &size);
    cbrdf_model* m = cbrdf_model_open_memory(bytes, size);
    const cbrdf_status code = m ? CBRDF_OK : cbrdf_last_error_code();
    printf("{\"code\":%d,\"status\":", (int)code);
    json_string(cbrdf_status_name(code));
    printf(",\"message\":");
    json_string(m ? "" : cbrdf_last_error_message());
    printf("}\n");
    cbrdf_model_free(m);
    free(bytes);
    return 0;
  }
  if (argc < 3) {
    fprintf(stderr, "wasm_reference %s: missing FILE\n", mode);
    return 2;
  }
  /* As cbrdf.wasm, which has no threads (the results do not depend on it). */
  cbrdf_set_thread_limit(1);
  cbrdf_model* m = open_path(argv[2]);
  if (strcmp(mode, "info") == 0) {
    print_info(m);
  } else if (strcmp(mode, "table") == 0) {
    const size_t count = cbrdf_merl_table_size();
    double* t = xmalloc(count * sizeof(double));
    if (cbrdf_model_table(m, t, count) != CBRDF_OK) fail_api("table");
    write_doubles(t, count);
    free(t);
  } else if (strcmp(mode, "eval") == 0 || strcmp(mode, "bench") == 0) {
    size_t count = 0;
    double* in = read_doubles(&count);
    const size_t n = count / 6;
    double* rgb = xmalloc(3 * n * sizeof(double));
    if (strcmp(mode, "eval") == 0) {
      if (cbrdf_model_eval_batch(m, n, in, in + 3 * n, rgb, 1) != CBRDF_OK) fail_api("eval");
      write_doubles(rgb, 3 * n);
    } else {
      const double budget = (argc > 3 ? atof(argv[3]) : 1000.0) * 1e6;
      long reps = 0;
      const double start = now_ns();
      double elapsed = 0;
      do {
        if (cbrdf_model_eval_batch(m, n, in, in + 3 * n, rgb, 1) != CBRDF_OK) fail_api("eval");
        ++reps;
        elapsed = now_ns() - start;
      } while (elapsed < budget);
      printf("{\"ns_per_pair\":%.4f,\"pairs\":%zu,\"reps\":%ld,\"check\":%.17g}\n",
             elapsed / ((double)reps * (double)n), n, reps, rgb[0]);
    }
    free(rgb);
    free(in);
  } else if (strcmp(mode, "sample") == 0) {
    size_t count = 0;
    double* in = read_doubles(&count);
    const size_t n = count / 5;
    double* out = xmalloc(7 * n * sizeof(double));
    if (cbrdf_model_sample_batch(m, n, in, in + 3 * n, out, out + 3 * n, out + 4 * n, 1) !=
        CBRDF_OK) {
      fail_api("sample");
    }
    write_doubles(out, 7 * n);
    free(out);
    free(in);
  } else {
    fprintf(stderr, "wasm_reference: unknown mode %s\n", mode);
    cbrdf_model_free(m);
    return 2;
  }
  cbrdf_model_free(m);
  return 0;
}
