/* The compiled peer: SUNDIALS' CVODES and IDAS called directly from C on CasADi's
 * generated C for the same equations, with no interpreter between the integrator and
 * the right-hand side. Built by peers.py together with the generated source
 * (build/peers_driver_NAME.c), which defines
 *
 *   peer_ode(t, y) -> y'                   y = [q; v], the index-1 ODE
 *   peer_ode_jac(t, y) -> dy'/dy           dense, column-major (CasADi's exact Jacobian)
 *   peer_res(t, Y, Y') -> F                Y = [q; v; a; lambda], the semi-explicit DAE
 *   peer_res_jac(t, Y, Y', cj) -> dF/dY + cj dF/dY'   dense, column-major
 *
 * Usage:
 *   sundials METHOD RTOL ATOL T_END REPEAT NX NZ x_1 .. x_NX [z_1 .. z_NZ]
 * METHOD is one of
 *   cvodes-adams  CVODES, variable-order Adams-Moulton with fixed-point iteration (the
 *                 non-stiff setting: no Jacobian, no linear solver)
 *   cvodes-bdf    CVODES, BDF with Newton, dense direct solver and the exact Jacobian
 *   idas          IDAS on the DAE, dense direct solver and the exact Jacobian, the
 *                 consistent initial values given (z_0 = [a_0; lambda_0], Y'_0 = [v_0; a_0; 0])
 *                 and the algebraic variables out of the local error test
 * The integration from t = 0 to T_END is repeated REPEAT times (re-initialised each
 * time); the report is one line of JSON with the final x, the counters of the last run
 * and the best wall time of one integration (re-initialisation included, set-up not). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cvodes/cvodes.h>
#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

typedef long long int casadi_int;
typedef int (*casadi_fn)(const double **arg, double **res, casadi_int *iw, double *w, int mem);
typedef int (*casadi_work_fn)(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw,
                              casadi_int *sz_w);

#define DECLARE(name)                                                               \
  int name(const double **arg, double **res, casadi_int *iw, double *w, int mem);  \
  int name##_work(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w);
DECLARE(peer_ode)
DECLARE(peer_ode_jac)
DECLARE(peer_res)
DECLARE(peer_res_jac)

/* One generated function with its work arrays, allocated once. */
typedef struct {
  casadi_fn fn;
  const double **arg;
  double **res;
  casadi_int *iw;
  double *w;
} Call;

static Call call_new(casadi_fn fn, casadi_work_fn work) {
  casadi_int sz_arg, sz_res, sz_iw, sz_w;
  work(&sz_arg, &sz_res, &sz_iw, &sz_w);
  Call c = {fn, calloc((size_t)sz_arg + 1, sizeof(double *)),
            calloc((size_t)sz_res + 1, sizeof(double *)),
            calloc((size_t)sz_iw + 1, sizeof(casadi_int)), calloc((size_t)sz_w + 1, sizeof(double))};
  return c;
}

typedef struct {
  Call ode, ode_jac, res, res_jac;
  double t;
  double cj;
  long nx, nz;
} Problem;

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void *data) {
  Problem *p = data;
  p->t = t;
  p->ode.arg[0] = &p->t;
  p->ode.arg[1] = N_VGetArrayPointer(y);
  p->ode.res[0] = N_VGetArrayPointer(ydot);
  return p->ode.fn(p->ode.arg, p->ode.res, p->ode.iw, p->ode.w, 0) ? -1 : 0;
}

static int rhs_jac(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix jac, void *data,
                   N_Vector tmp1, N_Vector tmp2, N_Vector tmp3) {
  (void)fy, (void)tmp1, (void)tmp2, (void)tmp3;
  Problem *p = data;
  p->t = t;
  p->ode_jac.arg[0] = &p->t;
  p->ode_jac.arg[1] = N_VGetArrayPointer(y);
  p->ode_jac.res[0] = SM_DATA_D(jac); /* dense, column-major like CasADi's output */
  return p->ode_jac.fn(p->ode_jac.arg, p->ode_jac.res, p->ode_jac.iw, p->ode_jac.w, 0) ? -1 : 0;
}

static int residual(sunrealtype t, N_Vector yy, N_Vector yp, N_Vector rr, void *data) {
  Problem *p = data;
  p->t = t;
  p->res.arg[0] = &p->t;
  p->res.arg[1] = N_VGetArrayPointer(yy);
  p->res.arg[2] = N_VGetArrayPointer(yp);
  p->res.res[0] = N_VGetArrayPointer(rr);
  return p->res.fn(p->res.arg, p->res.res, p->res.iw, p->res.w, 0) ? -1 : 0;
}

static int residual_jac(sunrealtype t, sunrealtype cj, N_Vector yy, N_Vector yp, N_Vector rr,
                        SUNMatrix jac, void *data, N_Vector tmp1, N_Vector tmp2, N_Vector tmp3) {
  (void)rr, (void)tmp1, (void)tmp2, (void)tmp3;
  Problem *p = data;
  p->t = t;
  p->cj = cj;
  p->res_jac.arg[0] = &p->t;
  p->res_jac.arg[1] = N_VGetArrayPointer(yy);
  p->res_jac.arg[2] = N_VGetArrayPointer(yp);
  p->res_jac.arg[3] = &p->cj;
  p->res_jac.res[0] = SM_DATA_D(jac);
  return p->res_jac.fn(p->res_jac.arg, p->res_jac.res, p->res_jac.iw, p->res_jac.w, 0) ? -1 : 0;
}

static void fail(const char *what, int flag) {
  printf("{\"flag\": %d, \"failure\": \"%s\"}\n", flag, what);
  exit(0);
}

#define CHECK(call)                           \
  do {                                        \
    int flag_ = (call);                       \
    if (flag_ < 0) fail(#call, flag_);        \
  } while (0)

static void report(N_Vector y, long nx, double wall, long steps, long fevals, long jacs,
                   long nliters, long errfails) {
  double *v = N_VGetArrayPointer(y);
  printf("{\"flag\": 0, \"x\": [");
  for (long i = 0; i < nx; i++) printf("%s%.17g", i ? ", " : "", v[i]);
  printf("], \"wall\": %.9g, \"steps\": %ld, \"rhs_evals\": %ld, \"jacobians\": %ld, "
         "\"nonlinear_iterations\": %ld, \"error_test_failures\": %ld}\n",
         wall, steps, fevals, jacs, nliters, errfails);
}

static void run_cvodes(Problem *p, int bdf, double rtol, double atol, double t_end, long repeat,
                       const double *x0, SUNContext ctx) {
  long n = p->nx;
  N_Vector y = N_VNew_Serial(n, ctx);
  memcpy(N_VGetArrayPointer(y), x0, sizeof(double) * (size_t)n);
  void *mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, ctx);
  CHECK(CVodeInit(mem, rhs, 0.0, y));
  CHECK(CVodeSStolerances(mem, rtol, atol));
  CHECK(CVodeSetUserData(mem, p));
  CHECK(CVodeSetMaxNumSteps(mem, 10000000));
  SUNMatrix a = NULL;
  SUNLinearSolver ls = NULL;
  SUNNonlinearSolver nls = NULL;
  if (bdf) {
    a = SUNDenseMatrix(n, n, ctx);
    ls = SUNLinSol_Dense(y, a, ctx);
    CHECK(CVodeSetLinearSolver(mem, ls, a));
    CHECK(CVodeSetJacFn(mem, rhs_jac));
  } else {
    nls = SUNNonlinSol_FixedPoint(y, 0, ctx);
    CHECK(CVodeSetNonlinearSolver(mem, nls));
  }
  double best = INFINITY;
  for (long r = 0; r < repeat; r++) {
    double start = now();
    memcpy(N_VGetArrayPointer(y), x0, sizeof(double) * (size_t)n);
    CHECK(CVodeReInit(mem, 0.0, y));
    double t = 0.0;
    CHECK(CVode(mem, t_end, y, &t, CV_NORMAL));
    double wall = now() - start;
    if (wall < best) best = wall;
  }
  long steps = 0, fevals = 0, jacs = 0, nliters = 0, errfails = 0;
  CVodeGetNumSteps(mem, &steps);
  CVodeGetNumRhsEvals(mem, &fevals);
  CVodeGetNumNonlinSolvIters(mem, &nliters);
  CVodeGetNumErrTestFails(mem, &errfails);
  if (bdf) CVodeGetNumJacEvals(mem, &jacs);
  report(y, n, best, steps, fevals, jacs, nliters, errfails);
  CVodeFree(&mem);
  if (ls) SUNLinSolFree(ls);
  if (a) SUNMatDestroy(a);
  if (nls) SUNNonlinSolFree(nls);
  N_VDestroy(y);
}

static void run_idas(Problem *p, double rtol, double atol, double t_end, long repeat,
                     const double *x0, const double *z0, SUNContext ctx) {
  long nx = p->nx, nz = p->nz, n = nx + nz;
  N_Vector yy = N_VNew_Serial(n, ctx), yp = N_VNew_Serial(n, ctx), id = N_VNew_Serial(n, ctx);
  /* Y_0 = [x_0; z_0]; Y'_0 = [x'_0; 0] with x'_0 from the generated ODE, which solves
   * the same augmented system as z_0 (consistent to rounding); the residual does not
   * read z'. */
  double *yy0 = malloc(sizeof(double) * (size_t)n), *yp0 = calloc((size_t)n, sizeof(double));
  memcpy(yy0, x0, sizeof(double) * (size_t)nx);
  memcpy(yy0 + nx, z0, sizeof(double) * (size_t)nz);
  {
    double t0 = 0.0;
    p->ode.arg[0] = &t0;
    p->ode.arg[1] = x0;
    p->ode.res[0] = yp0;
    if (p->ode.fn(p->ode.arg, p->ode.res, p->ode.iw, p->ode.w, 0)) fail("peer_ode at t = 0", -1);
  }
  double *ids = N_VGetArrayPointer(id);
  for (long i = 0; i < n; i++) ids[i] = i < nx ? 1.0 : 0.0;
  memcpy(N_VGetArrayPointer(yy), yy0, sizeof(double) * (size_t)n);
  memcpy(N_VGetArrayPointer(yp), yp0, sizeof(double) * (size_t)n);
  void *mem = IDACreate(ctx);
  CHECK(IDAInit(mem, residual, 0.0, yy, yp));
  CHECK(IDASStolerances(mem, rtol, atol));
  CHECK(IDASetUserData(mem, p));
  CHECK(IDASetMaxNumSteps(mem, 10000000));
  CHECK(IDASetId(mem, id));
  CHECK(IDASetSuppressAlg(mem, SUNTRUE));
  SUNMatrix a = SUNDenseMatrix(n, n, ctx);
  SUNLinearSolver ls = SUNLinSol_Dense(yy, a, ctx);
  CHECK(IDASetLinearSolver(mem, ls, a));
  CHECK(IDASetJacFn(mem, residual_jac));
  double best = INFINITY;
  for (long r = 0; r < repeat; r++) {
    double start = now();
    memcpy(N_VGetArrayPointer(yy), yy0, sizeof(double) * (size_t)n);
    memcpy(N_VGetArrayPointer(yp), yp0, sizeof(double) * (size_t)n);
    CHECK(IDAReInit(mem, 0.0, yy, yp));
    double t = 0.0;
    CHECK(IDASolve(mem, t_end, &t, yy, yp, IDA_NORMAL));
    double wall = now() - start;
    if (wall < best) best = wall;
  }
  long steps = 0, fevals = 0, jacs = 0, nliters = 0, errfails = 0;
  IDAGetNumSteps(mem, &steps);
  IDAGetNumResEvals(mem, &fevals);
  IDAGetNumJacEvals(mem, &jacs);
  IDAGetNumNonlinSolvIters(mem, &nliters);
  IDAGetNumErrTestFails(mem, &errfails);
  report(yy, nx, best, steps, fevals, jacs, nliters, errfails);
  IDAFree(&mem);
  SUNLinSolFree(ls);
  SUNMatDestroy(a);
  N_VDestroy(yy);
  N_VDestroy(yp);
  N_VDestroy(id);
  free(yy0);
  free(yp0);
}

int main(int argc, char **argv) {
  if (argc < 8) {
    fprintf(stderr, "usage: %s METHOD RTOL ATOL T_END REPEAT NX NZ x.. [z..]\n", argv[0]);
    return 2;
  }
  const char *method = argv[1];
  double rtol = strtod(argv[2], NULL), atol = strtod(argv[3], NULL),
         t_end = strtod(argv[4], NULL);
  long repeat = strtol(argv[5], NULL, 10), nx = strtol(argv[6], NULL, 10),
       nz = strtol(argv[7], NULL, 10);
  int idas = strcmp(method, "idas") == 0;
  if (argc != 8 + nx + (idas ? nz : 0)) {
    fprintf(stderr, "%s: expected %ld initial values\n", argv[0], nx + (idas ? nz : 0));
    return 2;
  }
  double *x0 = malloc(sizeof(double) * (size_t)nx), *z0 = malloc(sizeof(double) * (size_t)(nz + 1));
  for (long i = 0; i < nx; i++) x0[i] = strtod(argv[8 + i], NULL);
  if (idas)
    for (long i = 0; i < nz; i++) z0[i] = strtod(argv[8 + nx + i], NULL);
  Problem p = {call_new(peer_ode, peer_ode_work), call_new(peer_ode_jac, peer_ode_jac_work),
               call_new(peer_res, peer_res_work), call_new(peer_res_jac, peer_res_jac_work),
               0.0, 0.0, nx, nz};
  SUNContext ctx;
  if (SUNContext_Create(NULL, &ctx)) fail("SUNContext_Create", -1);
  if (strcmp(method, "cvodes-adams") == 0) {
    run_cvodes(&p, 0, rtol, atol, t_end, repeat, x0, ctx);
  } else if (strcmp(method, "cvodes-bdf") == 0) {
    run_cvodes(&p, 1, rtol, atol, t_end, repeat, x0, ctx);
  } else if (idas) {
    run_idas(&p, rtol, atol, t_end, repeat, x0, z0, ctx);
  } else {
    fprintf(stderr, "%s: unknown method %s\n", argv[0], method);
    return 2;
  }
  SUNContext_Free(&ctx);
  return 0;
}
