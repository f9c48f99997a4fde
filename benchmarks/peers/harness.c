/* Times one call of a CasADi-generated right-hand side `RHS(t, y)` (compile with
 * -DRHS=name and the generated source): harness CALLS y_1 ... y_n prints the best over
 * 5 batches of CALLS calls at t = 0 of the seconds per call, then the outputs. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define CAT2(a, b) a##b
#define CAT(a, b) CAT2(a, b)

typedef long long int casadi_int;
int RHS(const double **arg, double **res, casadi_int *iw, double *w, int mem);
int CAT(RHS, _work)(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w);

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: %s CALLS y_1 ... y_n\n", argv[0]);
    return 2;
  }
  long calls = atol(argv[1]);
  int n = argc - 2;
  double *y = malloc(sizeof(double) * (size_t)n), *out = malloc(sizeof(double) * (size_t)n);
  for (int i = 0; i < n; i++) y[i] = atof(argv[2 + i]);
  casadi_int sz_arg, sz_res, sz_iw, sz_w;
  CAT(RHS, _work)(&sz_arg, &sz_res, &sz_iw, &sz_w);
  const double **arg = calloc((size_t)sz_arg + 1, sizeof(double *));
  double **res = calloc((size_t)sz_res + 1, sizeof(double *));
  casadi_int *iw = calloc((size_t)sz_iw + 1, sizeof(casadi_int));
  double *w = calloc((size_t)sz_w + 1, sizeof(double));
  const double t = 0.0;
  arg[0] = &t;
  arg[1] = y;
  res[0] = out;
  double best = 1e300, sink = 0.0;
  for (int batch = 0; batch < 5; batch++) {
    double start = now();
    for (long k = 0; k < calls; k++) {
      if (RHS(arg, res, iw, w, 0)) return 1;
      sink += out[n - 1]; /* keeps every call observable */
    }
    double t = (now() - start) / (double)calls;
    if (t < best) best = t;
  }
  printf("%.6e\n", best);
  for (int i = 0; i < n; i++) printf("%.17g ", out[i]);
  printf("\n# %g\n", sink);
  return 0;
}
