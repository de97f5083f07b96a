// SPDX-License-Identifier: MIT
/* The first calls in a process, through the shared decoder as a renderer links it: each run is a
   child forked before anything in cbrdf has run, which times its first cbrdf_model_open_file (with
   the library's one-time set-up), a second open of the same file, the first draw (the sampler and
   its tables for one elevation) and a draw at the same elevation after it. Prints each one's
   median, smallest and largest wall time over the runs and its median CPU time (the child's
   threads together), which a loaded machine disturbs less; compare figures within one run.
   Usage: cbrdf_capi_first_open FILE.cbrdf [RUNS]   (RUNS: 1 to 1000, default 21) */
#define _POSIX_C_SOURCE 200809L
#include <cbrdf/cbrdf_c.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

enum { kFirstOpen, kSecondOpen, kFirstDraw, kNextDraw, kMeasures };
static const char* const kNames[kMeasures] = {"first open in a process", "second open",
                                              "first draw (sampler set-up)", "next draw"};

/* Wall and CPU clocks together, in ms. */
typedef struct {
  double wall, cpu;
} Clocks;

static Clocks now(void) {
  struct timespec w, c;
  Clocks t;
  clock_gettime(CLOCK_MONOTONIC, &w);
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c);
  t.wall = 1e3 * (double)w.tv_sec + 1e-6 * (double)w.tv_nsec;
  t.cpu = 1e3 * (double)c.tv_sec + 1e-6 * (double)c.tv_nsec;
  return t;
}

/* out[m] is measure m's wall time, out[kMeasures + m] its CPU time. */
static void record(double* out, int m, Clocks from, Clocks to) {
  out[m] = to.wall - from.wall;
  out[kMeasures + m] = to.cpu - from.cpu;
}

/* One run, in the child: the times in ms, or a message and a non-zero return. */
static int measure(const char* path, double out[2 * kMeasures]) {
  const double wo[3] = {0.0, 0.6, 0.8};
  double wi[3], pdf, weight[3];
  cbrdf_model *first, *second;
  Clocks t0 = now(), t1;
  first = cbrdf_model_open_file(path);
  t1 = now();
  if (first == NULL) {
    fprintf(stderr, "cbrdf_capi_first_open: %s\n", cbrdf_last_error_message());
    return 1;
  }
  record(out, kFirstOpen, t0, t1);
  second = cbrdf_model_open_file(path);
  t0 = now();
  record(out, kSecondOpen, t1, t0);
  cbrdf_model_free(second);
  t0 = now();
  if (cbrdf_model_sample(first, wo, 0.3, 0.7, wi, &pdf, weight) != CBRDF_OK) {
    fprintf(stderr, "cbrdf_capi_first_open: %s\n", cbrdf_last_error_message());
    return 1;
  }
  t1 = now();
  record(out, kFirstDraw, t0, t1);
  cbrdf_model_sample(first, wo, 0.6, 0.2, wi, &pdf, weight);
  record(out, kNextDraw, t1, now());
  cbrdf_model_free(first);
  return 0;
}

static int compare(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

int main(int argc, char** argv) {
  static double times[2 * kMeasures][1000];
  int runs = 21, r, m;
  if (argc < 2 || argc > 3 || (argc == 3 && ((runs = atoi(argv[2])) < 1 || runs > 1000))) {
    fprintf(stderr, "usage: cbrdf_capi_first_open FILE.cbrdf [RUNS]  (RUNS 1 to 1000)\n");
    return 2;
  }
  for (r = 0; r < runs; ++r) {
    int fd[2], status;
    double one[2 * kMeasures];
    pid_t child;
    if (pipe(fd) != 0 || (child = fork()) < 0) {
      perror("cbrdf_capi_first_open");
      return 1;
    }
    if (child == 0) {
      close(fd[0]);
      if (measure(argv[1], one) != 0) _exit(1);
      _exit(write(fd[1], one, sizeof one) == (ssize_t)sizeof one ? 0 : 1);
    }
    close(fd[1]);
    const ssize_t got = read(fd[0], one, sizeof one);
    close(fd[0]);
    if (waitpid(child, &status, 0) != child || !WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
        got != (ssize_t)sizeof one) {
      fprintf(stderr, "cbrdf_capi_first_open: run %d failed\n", r + 1);
      return 1;
    }
    for (m = 0; m < 2 * kMeasures; ++m) times[m][r] = one[m];
  }
  printf("%s, %d runs; ms      wall median      min      max   cpu median\n", argv[1], runs);
  for (m = 0; m < 2 * kMeasures; ++m) qsort(times[m], (size_t)runs, sizeof times[m][0], compare);
  for (m = 0; m < kMeasures; ++m) {
    printf("%-32s %11.3f %8.3f %8.3f %12.3f\n", kNames[m], times[m][runs / 2], times[m][0],
           times[m][runs - 1], times[kMeasures + m][runs / 2]);
  }
  return 0;
}
