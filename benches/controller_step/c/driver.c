/* Bench driver of benches/controller_step.sh for the CasADi-generated law.
 *
 *   driver eval INPUTS.csv           u of every casadi_law_* function per input row (CSV)
 *   driver KIND N REPS INPUTS.csv    N calls of KIND, REPS times; prints
 *                                    best_ns_per_call=<f> checksum=<f>
 *
 * INPUTS.csv is the dump of the Rust driver (t,z,v,phi,zr,vr,ar,jr,...): the same
 * 1024 samples, cycled the same way. KIND: sat raw sat_cse raw_cse (the CasADi
 * functions, called through CasADi's generated API: arg/res pointer arrays) and
 * base (the same loop, argument pointers set, no call: loop overhead).
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "casadi_law.h"

#define MAXS 4096
static double xs[MAXS][7];
static int ns;

typedef int (*law_fn)(const casadi_real **, casadi_real **, casadi_int *, casadi_real *, int);

static const struct {
  const char *name;
  law_fn f;
} FNS[] = {
    {"sat", casadi_law_sat},
    {"raw", casadi_law_raw},
    {"sat_cse", casadi_law_sat_cse},
    {"raw_cse", casadi_law_raw_cse},
};
#define NFNS (sizeof FNS / sizeof FNS[0])

static void read_inputs(const char *path) {
  FILE *fp = fopen(path, "r");
  char line[4096];
  if (!fp || !fgets(line, sizeof line, fp)) { /* header */
    fprintf(stderr, "cannot read %s\n", path);
    exit(2);
  }
  while (ns < MAXS && fgets(line, sizeof line, fp)) {
    char *p = line;
    strtod(p, &p); /* t */
    for (int j = 0; j < 7; j++) {
      p++; /* comma */
      xs[ns][j] = strtod(p, &p);
    }
    ns++;
  }
  fclose(fp);
}

/* Work arrays sized for every function (CasADi's *_work queries). */
static const casadi_real *argv_[64];
static casadi_real *resv_[64];
static casadi_int iw_[64];
static casadi_real w_[256];

#define MAX_INTO(m, x) \
  do {                   \
    if ((x) > (m)) (m) = (x); \
  } while (0)

static void check_work(void) {
  casadi_int a, r, i, w, ma = 0, mr = 0, mi = 0, mw = 0;
  int (*work[])(casadi_int *, casadi_int *, casadi_int *, casadi_int *) = {
      casadi_law_sat_work, casadi_law_raw_work, casadi_law_sat_cse_work, casadi_law_raw_cse_work};
  for (unsigned k = 0; k < sizeof work / sizeof work[0]; k++) {
    work[k](&a, &r, &i, &w);
    MAX_INTO(ma, a);
    MAX_INTO(mr, r);
    MAX_INTO(mi, i);
    MAX_INTO(mw, w);
  }
  if (ma > 64 || mr > 64 || mi > 64 || mw > 256) {
    fprintf(stderr, "work arrays too small\n");
    exit(2);
  }
}

static double run(law_fn f, long n) {
  double acc = 0.0, u;
  int i = 0;
  resv_[0] = &u;
  for (long k = 0; k < n; k++) {
    const double *s = xs[i];
    for (int j = 0; j < 7; j++) argv_[j] = s + j;
    f(argv_, resv_, iw_, w_, 0);
    acc += u;
    if (++i == ns) i = 0;
  }
  return acc;
}

/* The same loop without the call (the compiler must still set the pointers:
 * argv_ is a global read by the opaque asm below). */
static double run_base(long n) {
  double acc = 0.0;
  int i = 0;
  for (long k = 0; k < n; k++) {
    const double *s = xs[i];
    for (int j = 0; j < 7; j++) argv_[j] = s + j;
    __asm__ volatile("" : : "r"(argv_) : "memory");
    acc += *argv_[0];
    if (++i == ns) i = 0;
  }
  return acc;
}

int main(int argc, char **argv) {
  check_work();
  if (argc == 3 && strcmp(argv[1], "eval") == 0) {
    read_inputs(argv[2]);
    printf("sat,raw,sat_cse,raw_cse\n");
    for (int i = 0; i < ns; i++) {
      for (unsigned f = 0; f < NFNS; f++) {
        double u;
        for (int j = 0; j < 7; j++) argv_[j] = xs[i] + j;
        resv_[0] = &u;
        FNS[f].f(argv_, resv_, iw_, w_, 0);
        printf(f + 1 < NFNS ? "%.17g," : "%.17g\n", u);
      }
    }
    return 0;
  }
  if (argc != 5) {
    fprintf(stderr, "usage: %s eval INPUTS.csv | KIND N REPS INPUTS.csv\n", argv[0]);
    return 2;
  }
  long n = atol(argv[2]);
  int reps = atoi(argv[3]);
  read_inputs(argv[4]);
  law_fn f = NULL;
  for (unsigned k = 0; k < NFNS; k++)
    if (strcmp(argv[1], FNS[k].name) == 0) f = FNS[k].f;
  if (!f && strcmp(argv[1], "base") != 0) {
    fprintf(stderr, "unknown kind %s\n", argv[1]);
    return 2;
  }
  double best = 1e300, checksum = 0.0;
  for (int r = 0; r < reps; r++) {
    struct timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);
    checksum = f ? run(f, n) : run_base(n);
    clock_gettime(CLOCK_MONOTONIC, &b);
    double ns_ = ((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / (double)n;
    if (ns_ < best) best = ns_;
  }
  printf("best_ns_per_call=%.6g checksum=%.17g\n", best, checksum);
  return 0;
}
