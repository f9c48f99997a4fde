"""pfaff beside its peers: the same models at the same tolerances, one table.

Run through `run.sh` (which makes the virtual environment and builds pfaff); see the
README beside this file for what each column means. Usage:

    python peers.py --pfaff PATH [--models pendulum,andrews] [--tols 1e-4,...,1e-12]
                    [--pfaff-tols 1e-2,3e-3,...,1e-13] [--repeat 5] [--budget 2]
                    [--output results.md]
"""

import argparse
import ctypes
import datetime
import json
import math
import os
import platform
import re
import subprocess
import sys
import time

import numpy as np

import models as mo

HERE = os.path.dirname(os.path.abspath(__file__))
BUILD = os.path.join(HERE, "build")
CFLAGS = ["-O3"]

# pfaff's methods (formulation, integrator); the first is the default of the command
# and the one the ratios refer to.
PFAFF_METHODS = [
    ("partitioning", "adams"),
    ("projection", "adams"),
    ("partitioning", "dop853"),
    ("projection", "dop853"),
    # The lower order pays at the loosest tolerances (andrews at rtol 1e-3: 254
    # evaluations where DOP853 takes 383 for an error within the same decade).
    ("projection", "dopri5"),
]
PFAFF_DEFAULT = "pfaff partitioning+adams"


class Model:
    """What the runners need of one model."""

    def __init__(self, name, q0, v0, t_end, exact, numpy_rhs, augmented, casadi_parts):
        self.name = name
        self.n = len(q0)
        self.y0 = np.concatenate([q0, v0])
        self.t_end = t_end
        self.exact = exact  # the reference positions at t_end
        self.numpy_rhs = numpy_rhs
        self.augmented = augmented  # (y, t) -> (augmented matrix, right-hand side), NumPy
        self.casadi_parts = casadi_parts

    def error(self, q):
        """Largest absolute error of the final positions."""
        return float(np.max(np.abs(np.asarray(q, dtype=float) - self.exact)))


def converged_andrews(pfaff):
    """Two independent converged runs of andrews at t = 0.03: pfaff (partitioning and
    DOP853 at rtol 1e-13, atol 1e-15, the reference of `pfaff work-precision`) and SciPy's
    DOP853 on the NumPy right-hand side at rtol = atol = 1e-13."""
    from scipy.integrate import solve_ivp

    out = subprocess.run(
        [pfaff, "simulate", "andrews", "--json", "--integrator", "dop853", "--rtol=1e-13", "--atol=1e-15"],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    final = json.loads(out.stdout)["final"]["q"]
    q_pfaff = np.array([final[c] for c in mo.ANDREWS_NAMES])
    y0 = np.concatenate([mo.ANDREWS_Q0, np.zeros(7)])
    sol = solve_ivp(mo.andrews_numpy, (0.0, mo.ANDREWS_T_END), y0, method="DOP853", rtol=1e-13, atol=1e-13)
    return q_pfaff, sol.y[:7, -1]


MODELS = {
    "pendulum": Model(
        "pendulum",
        mo.PENDULUM_Q0,
        np.zeros(2),
        mo.PENDULUM_T_END,
        mo.pendulum_exact(mo.PENDULUM_T_END),
        mo.pendulum_numpy,
        mo.pendulum_augmented,
        mo.pendulum_casadi,
    ),
    "andrews": Model(
        "andrews",
        mo.ANDREWS_Q0,
        np.zeros(7),
        mo.ANDREWS_T_END,
        mo.ANDREWS_REFERENCE,
        mo.andrews_numpy,
        mo.andrews_augmented,
        mo.andrews_casadi,
    ),
    "car_axis": Model(
        "car_axis",
        mo.CAR_AXIS_Q0,
        mo.CAR_AXIS_V0,
        mo.CAR_AXIS_T_END,
        mo.CAR_AXIS_REFERENCE,
        mo.car_axis_numpy,
        mo.car_axis_augmented,
        mo.car_axis_casadi,
    ),
}
NAMES = {"pendulum": mo.PENDULUM_NAMES, "andrews": mo.ANDREWS_NAMES, "car_axis": mo.CAR_AXIS_NAMES}


MIN_TIME = 0.2
"""Seconds of repetitions a short run is timed over at least (`--min-time`)."""
MAX_REPEAT = 1000


def repetitions(first, repeat, budget):
    """How many times to time a run whose first call took `first` seconds: once when
    it took more than `budget`; else `repeat` times, and more for a short run, until
    the repetitions add up to `MIN_TIME` (at most `MAX_REPEAT`). On a shared machine a
    sub-millisecond run is disturbed by a slice of another process often enough that
    five repetitions do not find its undisturbed time; the same rule holds for every
    tool."""
    if first > budget:
        return 1
    return max(repeat, min(MAX_REPEAT, math.ceil(MIN_TIME / max(first, 1e-9))))


def best_of(run, repeat, budget):
    """Calls `run()` (which returns (result, seconds)) as often as `repetitions` says;
    returns the last result and the best time."""
    result, best = run()
    for _ in range(repetitions(best, repeat, budget) - 1):
        result, seconds = run()
        best = min(best, seconds)
    return result, best


# --------------------------------------------------------------------------------------
# pfaff
# --------------------------------------------------------------------------------------


def pfaff_run(pfaff, model, formulation, integrator, tol, repeat):
    """One `pfaff simulate --json --repeat N`: its wall time is the run's own (the
    command times the integration, not its start-up), best of N in one process."""
    cmd = [
        pfaff, "simulate", model.name, "--json",
        "--formulation", formulation, "--integrator", integrator,
        f"--rtol={tol:g}", f"--atol={tol:g}", f"--t-end={model.t_end!r}",
        "--repeat", str(repeat),
    ]  # fmt: skip
    out = subprocess.run(cmd, capture_output=True, text=True, check=False)
    report = json.loads(out.stdout)
    if "error" in report:
        return None, report["stats"]["rhs_evals"], report["wall_seconds"], report["error"]["kind"]
    q = [report["final"]["q"][c] for c in NAMES[model.name]]
    return model.error(q), report["stats"]["rhs_evals"], report["wall_seconds"], None


def pfaff_rows(pfaff, model, tol, repeat, budget):
    rows = []
    for formulation, integrator in PFAFF_METHODS:
        first = pfaff_run(pfaff, model, formulation, integrator, tol, 1)
        err, evals, wall, fail = first
        if first[2] <= budget and fail is None:
            count = repetitions(first[2], repeat, budget)
            err, evals, wall, fail = pfaff_run(pfaff, model, formulation, integrator, tol, count)
        rows.append(row(model, f"pfaff {formulation}+{integrator}", tol, err, evals, min(wall, first[2]), fail))
    return rows


# --------------------------------------------------------------------------------------
# CasADi: the index-1 equations as generated C, compiled, loaded with `external`
# --------------------------------------------------------------------------------------


class Compiled:
    """The generated C of one model: `NAME_ode(t, y) -> y'` and
    `NAME_dae(t, x, z) -> (ode, alg)`, each with its Jacobian, in one shared library."""

    def __init__(self, ca, model):
        t = ca.SX.sym("t")
        q, v, kinetic, applied, c = model.casadi_parts(ca, t)
        mass, forces, jac, gamma = mo.index1(ca, t, q, v, kinetic, applied, c)
        n, m = model.n, jac.shape[0]
        augmented = ca.blockcat([[mass, jac.T], [jac, ca.SX.zeros(m, m)]])
        parts = ca.Function("parts", [t, ca.vertcat(q, v)], [augmented, ca.vertcat(forces, gamma)])
        # The solve of the augmented system: CasADi's sparse LDL^T (generated with the
        # rest). Its symbolic `solve` of SX matrices is no option: it loses about 8
        # digits on andrews.
        time_mx = ca.MX.sym("t")
        y = ca.MX.sym("y", 2 * n)
        a_mx, b_mx = parts(time_mx, y)
        ode = ca.Function(
            f"{model.name}_ode", [time_mx, y], [ca.vertcat(y[n:], ca.solve(a_mx, b_mx, "ldl")[:n])]
        )  # fmt: skip
        x = ca.MX.sym("x", 2 * n)
        z = ca.MX.sym("z", n + m)
        a_x, b_x = parts(time_mx, x)
        dae = ca.Function(
            f"{model.name}_dae", [time_mx, x, z], [ca.vertcat(x[n:], z[:n]), ca.mtimes(a_x, z) - b_x],
            ["t", "x", "z"], ["ode", "alg"],
        )  # fmt: skip
        os.makedirs(BUILD, exist_ok=True)
        source = f"peers_{model.name}.c"
        gen = ca.CodeGenerator(source)
        for f in (ode, ode.jacobian(), dae, dae.jacobian()):
            gen.add(f)
        gen.generate(BUILD + os.sep)
        self.source = os.path.join(BUILD, source)
        self.library = os.path.join(BUILD, f"libpeers_{model.name}.so")
        subprocess.run(["gcc", *CFLAGS, "-fPIC", "-shared", self.source, "-o", self.library, "-lm"], check=True)
        self.symbol = ode.name()
        self.parts, self.m, self.ode_fn = parts, m, ode
        self.ode = ca.external(ode.name(), self.library)
        self.dae = ca.external(dae.name(), self.library)
        self.operations = parts.n_instructions()
        # consistent algebraic state at the start: [a; lambda] from the NumPy model
        a, b = model.augmented(model.y0, 0.0)
        self.z0 = np.linalg.solve(a, b)
        self.n = n


class Driver:
    """The compiled peer (sundials.c): CVODES and IDAS called from C on CasADi's generated
    C, linked statically against SUNDIALS (Debian's libsundials-dev, unpacked by run.sh).
    The generated source defines `peer_ode` and `peer_ode_jac` (the index-1 ODE and its
    exact Jacobian, dense), `peer_res` and `peer_res_jac` (the semi-explicit DAE
    F(t, Y, Y') = [x' - [v; a]; A(x) z - b(x)], Y = [x; z], z = [a; lambda], and
    dF/dY + cj dF/dY', dense)."""

    def __init__(self, ca, model, compiled, sundials):
        n, m = compiled.n, compiled.m
        t = ca.MX.sym("t")
        y = ca.MX.sym("y", 2 * n)
        ode = compiled.ode_fn(t, y)
        peer_ode = ca.Function("peer_ode", [t, y], [ode])
        peer_ode_jac = ca.Function("peer_ode_jac", [t, y], [ca.densify(ca.jacobian(ode, y))])
        ts = ca.SX.sym("t")
        big = ca.SX.sym("Y", 3 * n + m)
        big_p = ca.SX.sym("Yp", 3 * n + m)
        cj = ca.SX.sym("cj")
        x, z, xp = big[: 2 * n], big[2 * n :], big_p[: 2 * n]
        a, b = compiled.parts(ts, x)
        res = ca.vertcat(xp - ca.vertcat(x[n:], z[:n]), ca.mtimes(a, z) - b)
        peer_res = ca.Function("peer_res", [ts, big, big_p], [res])
        jac = ca.densify(ca.jacobian(res, big) + cj * ca.jacobian(res, big_p))
        peer_res_jac = ca.Function("peer_res_jac", [ts, big, big_p, cj], [jac])
        source = f"peers_driver_{model.name}.c"
        gen = ca.CodeGenerator(source)
        for f in (peer_ode, peer_ode_jac, peer_res, peer_res_jac):
            gen.add(f)
        gen.generate(BUILD + os.sep)
        self.exe = os.path.join(BUILD, f"sundials_{model.name}")
        lib = os.path.join(sundials, "lib", "x86_64-linux-gnu")
        if not os.path.isdir(lib):
            lib = os.path.join(sundials, "lib")
        static = [os.path.join(lib, f"libsundials_{name}.a") for name in (
            "cvodes", "idas", "sunnonlinsolfixedpoint", "sunnonlinsolnewton", "sunlinsoldense",
            "sunmatrixdense", "nvecserial", "generic")]  # fmt: skip
        static = [f for f in static if os.path.exists(f)]
        subprocess.run(
            ["gcc", *CFLAGS, "-I", os.path.join(sundials, "include"), os.path.join(HERE, "sundials.c"),
             os.path.join(BUILD, source), *static, "-lm", "-o", self.exe],
            check=True,
        )  # fmt: skip
        self.nx, self.nz = 2 * n, n + m
        self.z0 = compiled.z0
        self.library = os.path.join(BUILD, f"libpeers_driver_{model.name}.so")
        subprocess.run(["gcc", *CFLAGS, "-fPIC", "-shared", os.path.join(BUILD, source), "-o", self.library, "-lm"],
                       check=True)  # fmt: skip
        self.jacobian = CtypesRhs(compiled, self.library, "peer_ode_jac", (2 * n, 2 * n))

    def run(self, method, model, tol, repeat):
        """One process: the integration repeated `repeat` times; the report of the last."""
        args = [self.exe, method, repr(tol), repr(tol), repr(model.t_end), str(repeat), str(self.nx), str(self.nz)]
        args += [repr(float(v)) for v in model.y0]
        if method == "idas":
            args += [repr(float(v)) for v in self.z0]
        out = subprocess.run(args, capture_output=True, text=True, check=True)
        return json.loads(out.stdout)


DRIVER_METHODS = [
    ("C + CVODES adams (compiled)", "cvodes-adams"),
    ("C + CVODES bdf (compiled)", "cvodes-bdf"),
    ("C + IDAS (compiled)", "idas"),
]


def driver_rows(model, driver, tol, repeat, budget):
    """The compiled peer at one tolerance: a first run finds the time of one integration,
    then as many repetitions as `repetitions` says, in one process (as pfaff's --repeat)."""
    rows = []
    for label, method in DRIVER_METHODS:
        first = driver.run(method, model, tol, 1)
        if first["flag"] != 0:
            rows.append(row(model, label, tol, None, 0, 0.0, first["failure"][:40]))
            continue
        report = first
        count = repetitions(first["wall"], repeat, budget)
        if count > 1:
            report = driver.run(method, model, tol, count)
        err = model.error(report["x"][: model.n])
        rows.append(row(model, label, tol, err, report["rhs_evals"], min(first["wall"], report["wall"]), None))
    return rows


class CtypesRhs:
    """A compiled function of (t, y) called through ctypes, as a Python callable for
    SciPy (`y, t` as odeint passes them): `NAME_ode`, or with `library`/`symbol`/`shape`
    another one with a dense output of that shape (the Jacobian `peer_ode_jac`)."""

    def __init__(self, compiled, library=None, symbol=None, shape=None):
        lib = ctypes.CDLL(library or compiled.library)
        symbol = symbol or compiled.symbol
        self.fn = getattr(lib, symbol)
        size = ctypes.c_longlong
        sizes = [size() for _ in range(4)]
        getattr(lib, symbol + "_work")(*[ctypes.byref(s) for s in sizes])
        n_arg, n_res, n_iw, n_w = (max(1, s.value) for s in sizes)
        self.shape = shape
        self.t = np.zeros(1)
        self.y = np.zeros(2 * compiled.n)
        self.out = np.zeros(shape[0] * shape[1] if shape else 2 * compiled.n)
        dp = ctypes.POINTER(ctypes.c_double)
        self.arg = (dp * n_arg)(self.t.ctypes.data_as(dp), self.y.ctypes.data_as(dp))
        self.res = (dp * n_res)(self.out.ctypes.data_as(dp))
        self.iw = (ctypes.c_longlong * n_iw)()
        self.w = (ctypes.c_double * n_w)()
        self.fn.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int]
        self.fn.restype = ctypes.c_int
        self.args = (self.arg, self.res, self.iw, self.w, 0)

    def __call__(self, y, t):
        self.t[0] = t
        self.y[:] = y
        self.fn(*self.args)
        if self.shape:
            return self.out.reshape(self.shape, order="F")  # CasADi's dense output is column-major
        return self.out.copy()


def sundials_rows(ca, model, compiled, tol, repeat, budget):
    rows = []
    common = {"reltol": tol, "abstol": tol, "max_num_steps": 10**7}
    t = ca.MX.sym("t")
    x = ca.MX.sym("x", 2 * model.n)
    z = ca.MX.sym("z", compiled.z0.size)
    ode_problem = {"t": t, "x": x, "ode": compiled.ode(t, x)}
    dae_ode, dae_alg = compiled.dae(t, x, z)
    dae_problem = {"t": t, "x": x, "z": z, "ode": dae_ode, "alg": dae_alg}
    cases = [
        ("CasADi C + CVODES bdf", "cvodes", ode_problem, {}),
        ("CasADi C + CVODES adams", "cvodes", ode_problem,
         {"linear_multistep_method": "adams", "nonlinear_solver_iteration": "functional"}),
        ("CasADi C + IDAS (DAE)", "idas", dae_problem, {}),
    ]  # fmt: skip
    for label, plugin, problem, options in cases:
        integrator = ca.integrator("I", plugin, problem, 0.0, model.t_end, {**common, **options})
        inputs = {"x0": model.y0}
        if "z" in problem:
            inputs["z0"] = compiled.z0

        def run(integrator=integrator, inputs=inputs):
            start = time.perf_counter()
            out = integrator(**inputs)
            return out, time.perf_counter() - start

        try:
            out, wall = best_of(run, repeat, budget)
            stats = integrator.stats()
            err = model.error(np.array(out["xf"]).ravel()[: model.n])
            rows.append(row(model, label, tol, err, stats["nfevals"], wall, None))
        except RuntimeError as e:
            flag = re.findall(r'"((?:IDA|CV)_[A-Z_]+)"', str(e))
            rows.append(row(model, label, tol, None, 0, 0.0, flag[-1] if flag else str(e).splitlines()[-1][-60:]))
    return rows


# --------------------------------------------------------------------------------------
# SciPy
# --------------------------------------------------------------------------------------


def scipy_rows(model, compiled_rhs, jacobian, tol, repeat, budget, numpy=True):
    """SciPy's runs; `numpy=False`: only odeint on the compiled right-hand side."""
    from scipy.integrate import odeint, solve_ivp

    rows = []
    for method in ("DOP853", "LSODA", "Radau") if numpy else ():

        def run(method=method):
            start = time.perf_counter()
            sol = solve_ivp(model.numpy_rhs, (0.0, model.t_end), model.y0, method=method, rtol=tol, atol=tol)
            return sol, time.perf_counter() - start

        sol, wall = best_of(run, repeat, budget)
        fail = None if sol.success else sol.message[:40]
        rows.append(row(model, f"SciPy {method} + NumPy", tol, model.error(sol.y[: model.n, -1]), sol.nfev, wall, fail))

    # LSODA given CasADi's exact Jacobian (`Dfun`), as a careful user sets it up: its
    # switch to BDF then needs no finite differences.
    def run_c():
        start = time.perf_counter()
        y, info = odeint(compiled_rhs, model.y0, [0.0, model.t_end], Dfun=jacobian, rtol=tol, atol=tol,
                         mxstep=10**7, full_output=True)  # fmt: skip
        return (y, info), time.perf_counter() - start

    (y, info), wall = best_of(run_c, repeat, budget)
    fail = None if info["message"].startswith("Integration successful") else info["message"][:40]
    rows.append(row(model, "SciPy LSODA (odeint) + CasADi C + Jacobian", tol, model.error(y[-1, : model.n]), int(info["nfe"][-1]), wall, fail))
    return rows


# --------------------------------------------------------------------------------------
# The right-hand side alone
# --------------------------------------------------------------------------------------


def c_rhs_seconds(compiled, y, calls):
    """Seconds per call of the generated `NAME_ode`, timed in C (harness.c)."""
    exe = os.path.join(BUILD, f"harness_{compiled.symbol}")
    subprocess.run(
        ["gcc", *CFLAGS, f"-DRHS={compiled.symbol}", os.path.join(HERE, "harness.c"), compiled.source, "-o", exe, "-lm"],
        check=True,
    )  # fmt: skip
    out = subprocess.run([exe, str(calls), *map(repr, map(float, y))], capture_output=True, text=True, check=True)
    return float(out.stdout.split()[0])


def python_seconds(f, calls):
    best = math.inf
    for _ in range(5):
        start = time.perf_counter()
        for _ in range(calls):
            f()
        best = min(best, (time.perf_counter() - start) / calls)
    return best


def rhs_table(pfaff, model, compiled, ctypes_rhs, rows, tol):
    """Seconds per right-hand side, alone and inside a run at `tol`."""
    out = subprocess.run([pfaff, "rhs-time", model.name, "--json"], capture_output=True, text=True, check=True)
    alone_pfaff = json.loads(out.stdout)["seconds_per_call"]
    y0 = model.y0
    alone = {
        "pfaff index-1 (rhs-time)": alone_pfaff,
        "CasADi generated C, gcc -O3 (in C)": c_rhs_seconds(compiled, y0, 200_000),
        "CasADi generated C through ctypes (from Python)": python_seconds(lambda: ctypes_rhs(y0, 0.0), 20_000),
        "NumPy (from Python)": python_seconds(lambda: model.numpy_rhs(0.0, y0), 2_000),
    }
    in_run = {r["tool"]: r["wall"] / r["evals"] for r in rows if r["tol"] == tol and r["evals"] and r["error"] is not None}
    return alone, in_run, tol


# --------------------------------------------------------------------------------------
# The table
# --------------------------------------------------------------------------------------


def best_rows(kept, new):
    """The rows of one more round merged into those kept: each (tool, tolerance) keeps
    its best wall time over the rounds (its error and evaluations are the same in every
    round). The rounds spread each entry's repetitions over the whole run, so a slow
    spell of the machine (seconds of a shared core running slower) reaches one round of
    an entry, not all of its repetitions."""
    if not kept:
        return new
    by_key = {(r["tool"], r["tol"], r.get("extra", False)): r for r in new}
    merged = []
    for r in kept:
        other = by_key.get((r["tool"], r["tol"], r.get("extra", False)))
        if other is not None and r["failure"] is None and other["failure"] is None:
            r = {**r, "wall": min(r["wall"], other["wall"])}
        merged.append(r)
    return merged


def row(model, tool, tol, error, evals, wall, failure, extra=False):
    """One run; `extra`: a pfaff run at a tolerance the peers were not run at (a
    candidate of the equal-accuracy comparison, listed in its own table)."""
    return {"model": model.name, "tool": tool, "tol": tol, "error": error, "evals": evals, "wall": wall,
            "failure": failure, "extra": extra}  # fmt: skip


def fmt_e(x):
    return "—" if x is None else f"{x:.1e}"


def fmt_ratio(x):
    if x is None:
        return "—"
    return f"{x:.2g}" if x < 10 else f"{x:.0f}"


def envelope(rows):
    """For each run, the largest error of its method (model and tool) at its tolerance
    and every tighter one: the accuracy the run can be counted on for. A final error is
    one sample of the error's oscillation along the run, and a loose run can land near
    the reference by a lucky phase (andrews, projection + DOP853: 4.1e-6 at rtol 3e-3
    but 5.9e-4 at 1e-4); such a run must not stand in for an accurate one. The same
    rule holds for every tool."""
    for r in rows:
        if r["error"] is not None:
            tighter = [
                p["error"] for p in rows
                if (p["model"], p["tool"]) == (r["model"], r["tool"]) and p["tol"] <= r["tol"]
                and p["error"] is not None
            ]  # fmt: skip
            r["assured"] = max(tighter)


def annotate(rows):
    """Adds the ratios to pfaff's default at the same tolerance and to the fastest pfaff
    run (any method, any tolerance) that is at least as accurate (by the error it can be
    counted on for, see `envelope`)."""
    envelope(rows)
    for r in rows:
        ref = next((p for p in rows if p["model"] == r["model"] and p["tol"] == r["tol"] and p["tool"] == PFAFF_DEFAULT), None)
        ok = ref is not None and ref["error"] is not None and r["error"] is not None
        r["wall_ratio"] = r["wall"] / ref["wall"] if ok and r["failure"] is None else None
        r["error_ratio"] = r["error"] / ref["error"] if ok and ref["error"] > 0 else None
        r["equal"] = None
        if r["error"] is not None and not r["tool"].startswith("pfaff"):
            candidates = [
                p for p in rows
                if p["model"] == r["model"] and p["tool"].startswith("pfaff") and p["error"] is not None
                and p["assured"] <= r["error"]
            ]  # fmt: skip
            if candidates:
                best = min(candidates, key=lambda p: p["wall"])
                r["equal"] = (r["wall"] / best["wall"], best)


def render(rows):
    lines = [
        "| model | tool / method | rtol = atol | error | rhs evals | wall [ms] | wall / pfaff | error / pfaff | wall / pfaff at equal error (pfaff run) |",
        "|---|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    for r in rows:
        if r["extra"]:
            continue
        if r["equal"] is None:
            equal = "—" if not r["tool"].startswith("pfaff") else ""
        else:
            ratio, p = r["equal"]
            equal = f"{fmt_ratio(ratio)} ({p['tool'].removeprefix('pfaff ')}, {p['tol']:.0e})"
        wall = "—" if r["failure"] else f"{r['wall'] * 1e3:.3g}"
        error = f"failed: {r['failure']}" if r["failure"] else fmt_e(r["error"])
        lines.append(
            f"| {r['model']} | {r['tool']} | {r['tol']:.0e} | {error} | {r['evals']} | {wall} | "
            f"{fmt_ratio(r['wall_ratio'])} | {fmt_ratio(r['error_ratio'])} | {equal} |"
        )
    return "\n".join(lines)


def render_extra(rows):
    lines = [
        "| model | tool / method | rtol = atol | error | rhs evals | wall [ms] |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for r in sorted((r for r in rows if r["extra"]), key=lambda r: (r["model"], r["tool"], -r["tol"])):
        wall = "—" if r["failure"] else f"{r['wall'] * 1e3:.3g}"
        error = f"failed: {r['failure']}" if r["failure"] else fmt_e(r["error"])
        lines.append(f"| {r['model']} | {r['tool']} | {r['tol']:.0e} | {error} | {r['evals']} | {wall} |")
    return "\n".join(lines)


def fastest(rows, model, tool, target):
    """The fastest run of `tool` on `model` (any tolerance) whose assured error (see
    `envelope`) is at most `target`, or None."""
    fit = [
        r for r in rows
        if r["model"] == model and r["tool"] == tool and r["failure"] is None
        and r.get("assured") is not None and r["assured"] <= target
    ]  # fmt: skip
    return min(fit, key=lambda r: r["wall"]) if fit else None


def render_targets(rows, targets):
    """Work at equal accuracy, every tool alike: for each error target, each tool's
    fastest run (any of its tolerances) whose assured error is within the target, as a
    ratio to pfaff's default method and to pfaff's fastest method at the same target."""
    out = []
    for model in dict.fromkeys(r["model"] for r in rows):
        tools = list(dict.fromkeys(r["tool"] for r in rows if r["model"] == model))
        pfaff = [t for t in tools if t.startswith("pfaff")]
        peers = [t for t in tools if not t.startswith("pfaff")]
        lines = [
            f"### {model}",
            "",
            "| error ≤ | pfaff default [ms] | pfaff fastest [ms] (method, rtol) | "
            + " | ".join(peers) + " |",
            "|---:|---:|---|" + "---:|" * len(peers),
        ]
        for target in targets:
            default = fastest(rows, model, PFAFF_DEFAULT, target)
            candidates = [f for f in (fastest(rows, model, t, target) for t in pfaff) if f is not None]
            best = min(candidates, key=lambda r: r["wall"]) if candidates else None
            cells = []
            for peer in peers:
                p = fastest(rows, model, peer, target)
                if p is None:
                    cells.append("—")
                    continue
                by_default = fmt_ratio(p["wall"] / default["wall"]) if default else "—"
                by_best = fmt_ratio(p["wall"] / best["wall"]) if best else "—"
                cells.append(f"{by_default} / {by_best}")
            d = f"{default['wall'] * 1e3:.3g}" if default else "—"
            b = (f"{best['wall'] * 1e3:.3g} ({best['tool'].removeprefix('pfaff ')}, {best['tol']:.0e})"
                 if best else "—")  # fmt: skip
            lines.append(f"| {target:.0e} | {d} | {b} | " + " | ".join(cells) + " |")
        out.append("\n".join(lines))
    return "\n\n".join(out)


def render_equal(rows, tols):
    lines = [
        "| model | peer | " + " | ".join(f"{t:.0e}" for t in tols) + " |",
        "|---|---|" + "---:|" * len(tols),
    ]
    seen = []
    for r in rows:
        key = (r["model"], r["tool"])
        if r["tool"].startswith("pfaff") or key in seen:
            continue
        seen.append(key)
        cells = []
        for t in tols:
            match = next((x for x in rows if (x["model"], x["tool"]) == key and x["tol"] == t), None)
            if match is None or match["failure"]:
                cells.append("failed" if match else "")
            else:
                cells.append(fmt_ratio(match["equal"][0]) if match["equal"] else "—")
        lines.append(f"| {key[0]} | {key[1]} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def render_rhs(tables):
    lines = [
        "| model | right-hand side | alone [µs/call] | in a run: wall / rhs evals [µs] |",
        "|---|---|---:|---:|",
    ]
    for name, (alone, in_run, tol) in tables.items():
        for label, seconds in alone.items():
            lines.append(f"| {name} | {label} | {seconds * 1e6:.3g} | |")
        for label, seconds in in_run.items():
            lines.append(f"| {name} | {label}, rtol {tol:.0e} | | {seconds * 1e6:.3g} |")
    return "\n".join(lines)


def cpu_times():
    """The machine's CPU times since boot (`/proc/stat`: user, nice, system, idle,
    iowait, irq, softirq, steal), or None where there is no such file."""
    try:
        with open("/proc/stat", encoding="utf-8") as f:
            return [int(x) for x in f.readline().split()[1:9]]
    except (OSError, ValueError):
        return None


def stolen(start):
    """The share of the CPU time since `start` (`cpu_times()`) that the hypervisor gave
    to other guests, or None."""
    end = cpu_times()
    if start is None or end is None or len(end) < 8:
        return None
    delta = [b - a for a, b in zip(start, end)]
    return delta[7] / max(1, sum(delta))


def machine(pfaff, load_start, cpu_start):
    cpu = platform.processor() or "?"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    import casadi
    import scipy

    def tool_version(cmd):
        try:
            return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.splitlines()[0]
        except (OSError, subprocess.CalledProcessError, IndexError):
            return "?"

    commit = tool_version(["git", "-C", HERE, "log", "-1", "--format=%h %s"])
    load = ", ".join(f"{x[0]:.1f}" for x in (load_start, os.getloadavg()))
    steal = stolen(cpu_start)
    steal = "" if steal is None else f"; CPU time stolen by the hypervisor during the run {100 * steal:.1f} %"
    return "\n".join([
        f"- date: {datetime.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')}",
        f"- CPU: {cpu}, {os.cpu_count()} logical cores; {platform.system()} {platform.release()}; "
        f"load average (1 min) at the start and at the end {load} (a load above the number of cores means other work shared the machine){steal}",
        f"- pfaff: {tool_version([pfaff, '--version'])}, commit {commit}; {tool_version(['rustc', '--version'])}",
        f"- Python {platform.python_version()}, NumPy {np.__version__}, SciPy {scipy.__version__}, "
        f"CasADi {casadi.__version__} (SUNDIALS plugins of its wheel); {tool_version(['gcc', '--version'])}, flags {' '.join(CFLAGS)}",
    ])  # fmt: skip


def main():
    global MIN_TIME
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pfaff", required=True, help="path of the release `pfaff` binary")
    parser.add_argument("--models", default="pendulum,andrews,car_axis")
    parser.add_argument("--tols", default=",".join(f"1e-{k}" for k in range(4, 13)))
    parser.add_argument("--pfaff-tols",
                        default=",".join(f"1e-{k},5e-{k + 1},3e-{k + 1},2e-{k + 1}" for k in range(2, 13)) + ",1e-13",
                        help="pfaff is also run at these tolerances (default: four per decade, 1, 5, 3 and "
                             "2 times 10^-k, from 1e-2 to 1e-13), as candidates of the equal-accuracy "
                             "comparison")  # fmt: skip
    parser.add_argument("--repeat", type=int, default=5, help="timed repetitions (best is kept)")
    parser.add_argument("--rounds", type=int, default=3,
                        help="the whole table is measured this many times; each entry keeps its best")  # fmt: skip
    parser.add_argument("--min-time", type=float, default=MIN_TIME,
                        help="a short run is repeated until its repetitions add up to this many seconds")  # fmt: skip
    parser.add_argument("--budget", type=float, default=2.0,
                        help="a run longer than this many seconds is timed once")  # fmt: skip
    parser.add_argument("--targets", default=",".join(f"1e-{k}" for k in range(3, 13)),
                        help="error targets of the table of work at equal accuracy")  # fmt: skip
    parser.add_argument("--rhs-tol", type=float, default=1e-8, help="tolerance of the in-run right-hand-side costs")
    parser.add_argument("--andrews-reference", choices=["testset", "converged"], default="testset",
                        help="andrews' reference: the test set's values, or a converged pfaff run")  # fmt: skip
    parser.add_argument("--sundials", help="prefix of SUNDIALS' headers and static libraries (include/, lib/): "
                        "builds the compiled peer (sundials.c); run.sh unpacks Debian's libsundials-dev there")
    parser.add_argument("--output", help="also write the report (Markdown) to this file")
    args = parser.parse_args()
    MIN_TIME = args.min_time
    load_start, cpu_start = os.getloadavg(), cpu_times()

    import casadi as ca

    tols = [float(t) for t in args.tols.split(",")]
    targets = [float(t) for t in args.targets.split(",")]
    notes = []
    if "andrews" in args.models.split(","):
        q_pfaff, q_scipy = converged_andrews(args.pfaff)
        andrews = MODELS["andrews"]
        notes.append(
            "andrews: converged runs of pfaff (partitioning+dop853, rtol 1e-13) and of SciPy (DOP853 + NumPy, "
            f"rtol 1e-13) agree to {np.max(np.abs(q_pfaff - q_scipy)):.1e} and differ from the test-set reference by "
            f"{andrews.error(q_pfaff):.1e} and {andrews.error(q_scipy):.1e} (in beta and theta, about 15.8 rad): "
            "errors near that are the reference's own. "
            + ("Here the errors are measured against the pfaff run instead (`--andrews-reference converged`)."
               if args.andrews_reference == "converged" else "")
        )  # fmt: skip
        if args.andrews_reference == "converged":
            andrews.exact = q_pfaff
    rows, rhs = [], {}
    for name in args.models.split(","):
        model = MODELS[name]
        compiled = Compiled(ca, model)
        ctypes_rhs = CtypesRhs(compiled)
        driver = Driver(ca, model, compiled, args.sundials) if args.sundials else None
        jacobian = driver.jacobian if driver else None
        # the two right-hand sides agree before anything is timed
        y = model.y0 + np.linspace(0.01, 0.05, 2 * model.n)
        gap = np.max(np.abs(ctypes_rhs(y, 0.0) - model.numpy_rhs(0.0, y))) / np.max(np.abs(model.numpy_rhs(0.0, y)))
        if gap > 1e-10:
            sys.exit(f"{name}: the NumPy and generated right-hand sides differ by {gap:.1e}")
        print(f"{name}: generated C of M, Q, J, gamma in {compiled.operations} operations, then LDL^T; "
              f"NumPy and C agree to {gap:.1e}", file=sys.stderr)  # fmt: skip
        model_rows = []
        extra = [float(t) for t in args.pfaff_tols.split(",") if float(t) not in tols]
        for round_ in range(1, args.rounds + 1):
            rows_now = []
            for tol in tols:
                print(f"{name}: round {round_}/{args.rounds}, rtol = atol = {tol:.0e}", file=sys.stderr)
                rows_now += pfaff_rows(args.pfaff, model, tol, args.repeat, args.budget)
                rows_now += scipy_rows(model, ctypes_rhs, jacobian, tol, args.repeat, args.budget)
                rows_now += sundials_rows(ca, model, compiled, tol, args.repeat, args.budget)
                if driver:
                    rows_now += driver_rows(model, driver, tol, args.repeat, args.budget)
            for tol in extra:
                # Between the decades: pfaff and the compiled peers (the C driver and
                # odeint on the C right-hand side) get the same grid of tolerances.
                print(f"{name}: round {round_}/{args.rounds}, rtol = atol = {tol:.0e} (between the decades)",
                      file=sys.stderr)  # fmt: skip
                between = pfaff_rows(args.pfaff, model, tol, args.repeat, args.budget)
                between += scipy_rows(model, ctypes_rhs, jacobian, tol, args.repeat, args.budget, numpy=False)
                if driver:
                    between += driver_rows(model, driver, tol, args.repeat, args.budget)
                rows_now += [{**r, "extra": True} for r in between]
            model_rows = best_rows(model_rows, rows_now)
        near = min(tols, key=lambda t: abs(math.log10(t / args.rhs_tol)))
        rhs[name] = rhs_table(args.pfaff, model, compiled, ctypes_rhs, model_rows, near)
        rows += model_rows
    annotate(rows)
    spans = ", ".join(
        f"{n} over [0, {MODELS[n].t_end:.6g}] s" for n in args.models.split(",")
    )
    report = "\n\n".join([
        "# pfaff and its peers",
        machine(args.pfaff, load_start, cpu_start),
        f"Final position error (largest absolute error of the coordinates at the end: {spans}; "
        "pendulum against its closed form, car_axis against the test-set reference, andrews against "
        + ("pfaff's converged run (partitioning + DOP853 at rtol 1e-13)"
           if args.andrews_reference == "converged" else "the test-set reference")
        + "), "
        "right-hand-side evaluations and wall time (the best of at least `--repeat` runs, and of as many as "
        f"take {MIN_TIME:g} s together for a short run, in each of {args.rounds} rounds over the whole table). "
        f"Ratios are to `{PFAFF_DEFAULT}` at the same tolerance; the last column compares "
        "with the fastest pfaff run, any method and tolerance (this table's and those of the table "
        "between the decades below), that is at least as accurate: whose error, and that of the same pfaff method at every "
        "tighter tolerance, is at most the peer's (a loose run that meets the reference by a lucky phase "
        "does not count).",
        *notes,
        render(rows),
        "## Work at equal accuracy",
        "Every tool alike: for each error target, each tool's fastest run, among all its tolerances "
        "(the decades, and the points between them for pfaff and the compiled peers), whose error, and "
        "that of the same tool at every tighter tolerance, is within the target. A cell is the peer's wall "
        f"time over that of `{PFAFF_DEFAULT}` / over that of pfaff's fastest method at the same target: "
        "above 1 pfaff is faster; `—`: no run of the tool (or of pfaff) reaches the target. The rows "
        "`C + CVODES …` and `C + IDAS` are the compiled peer (sundials.c): SUNDIALS called from C on "
        "CasADi's generated C, no interpreter in between.",
        render_targets(rows, targets),
        "## At equal accuracy, by the peer's tolerance",
        "The last column of the table by tolerance: a peer's wall time over that of the fastest pfaff run "
        "(any method, any tolerance) at least as accurate; above 1 pfaff is faster, `—`: no pfaff run as accurate.",
        render_equal(rows, tols),
        "## pfaff between the decades",
        "pfaff alone at the tolerances of `--pfaff-tols` the peers were not run at (four per decade): "
        "candidates of the comparison at equal accuracy, so that the pfaff run it picks is not much more "
        "accurate, and slower, than the peer's run only because the decades are far apart.",
        render_extra(rows),
        "## One right-hand side",
        "Alone: the index-1 right-hand side (M, Q, C_q, gamma and the augmented solve) at the "
        "initial state. In a run: the run's wall time divided by its right-hand-side evaluations "
        "(integrator overhead included).",
        render_rhs(rhs),
    ])  # fmt: skip
    print(report)
    if args.output:
        with open(args.output, "w", encoding="utf-8") as f:
            f.write(report + "\n")


if __name__ == "__main__":
    main()
