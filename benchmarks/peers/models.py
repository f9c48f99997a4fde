"""The index-1 equations of the peer benchmark, written twice: NumPy for SciPy and
CasADi (symbolic, then generated C) for SUNDIALS, and the reference solutions.

Both models are the ones of pfaff's `models/src/` with the same parameters, coordinates
and initial state (docs/models.md). The index-1 form integrates y = [q; v] with

    [M(q)  J(q)^T] [a     ]   [Q(q, v)    ]
    [J(q)  0     ] [lambda] = [gamma(q, v)],     y' = [v; a],

J = C_q and gamma = -(C_q v)_q v (no explicit time), with neither projection nor
Baumgarte terms: the equations that pfaff's projection formulation evaluates at every
stage. The DAE handed to IDAS has x = [q; v] differential and z = [a; lambda]
algebraic with the same two block rows as residuals.
"""

import math

import numpy as np

# --------------------------------------------------------------------------------------
# Pendulum (IFToMM A01), models/src/pendulum.rs
# --------------------------------------------------------------------------------------

PENDULUM = {"m": 1.0, "l": 1.0, "g": 9.81}
PENDULUM_PERIOD = 2.36784194757624  # 4 K(1/2) sqrt(l/g), docs/models.md
PENDULUM_T_END = 3.0 * PENDULUM_PERIOD  # the span of `pfaff simulate pendulum`
PENDULUM_Q0 = np.array([1.0, 0.0])
PENDULUM_NAMES = ["x", "y"]


def pendulum_exact(t):
    """Closed form of docs/models.md: theta from the downward vertical,
    sin(theta/2) = k sn(K - w0 t | m = 1/2), k = 1/sqrt(2), w0 = sqrt(g/l); the bob is
    at (l sin theta, -l cos theta). Returns the positions (x, y)."""
    from scipy.special import ellipj

    K_HALF = 1.85407467730137191843  # K(1/2), docs/models.md
    w0 = math.sqrt(PENDULUM["g"] / PENDULUM["l"])
    sn, _, _, _ = ellipj(K_HALF - w0 * t, 0.5)
    theta = 2.0 * math.asin(math.sqrt(0.5) * sn)
    return np.array([math.sin(theta), -math.cos(theta)]) * PENDULUM["l"]


def pendulum_numpy(t, y):
    """Index-1 right-hand side of the pendulum (NumPy)."""
    a, b = pendulum_augmented(y, t)
    sol = np.linalg.solve(a, b)
    return np.concatenate([y[2:], sol[:2]])


def pendulum_augmented(y, t=0.0):
    """The augmented matrix [[M, J^T], [J, 0]] and right-hand side [Q; gamma] of the
    pendulum at y = [x, y, x', y']: C = x^2 + y^2 - l^2, J = [2x, 2y],
    gamma = -2 (x'^2 + y'^2)."""
    m, g = PENDULUM["m"], PENDULUM["g"]
    x, yy, vx, vy = y
    a = np.array([[m, 0.0, 2.0 * x], [0.0, m, 2.0 * yy], [2.0 * x, 2.0 * yy, 0.0]])
    return a, np.array([0.0, -m * g, -2.0 * (vx * vx + vy * vy)])


def pendulum_casadi(ca, t):
    """(q, v, T, Q_e, C) of the pendulum as CasADi SX (`t` unused: autonomous)."""
    m, l, g = PENDULUM["m"], PENDULUM["l"], PENDULUM["g"]
    q = ca.SX.sym("q", 2)
    v = ca.SX.sym("v", 2)
    kinetic = 0.5 * m * ca.dot(v, v)
    potential = m * g * q[1]
    c = ca.vertcat(q[0] ** 2 + q[1] ** 2 - l**2)
    return q, v, kinetic, -ca.gradient(potential, q), c


# --------------------------------------------------------------------------------------
# Andrews' squeezing mechanism, models/src/andrews.rs (Hairer & Wanner II, VII.7)
# --------------------------------------------------------------------------------------

ANDREWS = dict(
    m1=0.04325, m2=0.00365, m3=0.02373, m4=0.00706, m5=0.07050, m6=0.00706, m7=0.05498,
    i1=2.194e-6, i2=4.410e-7, i3=5.255e-6, i4=5.667e-7, i5=1.169e-5, i6=5.667e-7,
    i7=1.912e-5, xa=-0.06934, ya=-0.00227, xb=-0.03635, yb=0.03273, xc=0.014, yc=0.072,
    c0=4530.0, d=28e-3, da=115e-4, e=2e-2, ea=1421e-5, rr=7e-3, ra=92e-5, l0=7785e-5,
    ss=35e-3, sa=1874e-5, sb=1043e-5, sc=18e-3, sd=2e-2, ta=2308e-5, tb=916e-5, u=4e-2,
    ua=1228e-5, ub=449e-5, zf=2e-2, zt=4e-2, fa=1421e-5, mom=33e-3,
)  # fmt: skip
ANDREWS_T_END = 0.03
ANDREWS_NAMES = ["beta", "theta", "gamma", "phi", "delta", "omega", "epsilon"]
# The consistent initial configuration of docs/models.md, at rest.
ANDREWS_Q0 = np.array([
    -0.0617138900142764496358948458001,
    0.0,
    0.455279819163070380255912382449,
    0.222668390165885884674473185609,
    0.487364979543842550225598953530,
    -0.222668390165885884674473185609,
    1.23054744454982119249735015568,
])  # fmt: skip
# The reference positions at t = 0.03 of the "andrews" problem of the Bari test set for
# IVP solvers (Mazzia & Magherini), computed with PSIDE at rtol = atol = 1e-14 on a Cray
# C90 in Cray double precision; the same problem as Hairer & Wanner II, VII.7.
ANDREWS_REFERENCE = np.array([
    0.1581077119629904e2,
    -0.1575637105984298e2,
    0.4082224013073101e-1,
    -0.5347301163226948e0,
    0.5244099658805304e0,
    0.5347301163226948e0,
    0.1048080741042263e1,
])  # fmt: skip


def andrews_mass(q, cos, sin, p=ANDREWS):
    """The mass matrix entries (M11, M12, M22, M33, M44, M45, M55, M66, M67, M77) of
    docs/models.md, with `cos`/`sin` of NumPy or CasADi."""
    m1, m2, m3, m4, m5, m6, m7 = (p[k] for k in ("m1", "m2", "m3", "m4", "m5", "m6", "m7"))
    i1, i2, i3, i4, i5, i6, i7 = (p[k] for k in ("i1", "i2", "i3", "i4", "i5", "i6", "i7"))
    rr, ra, da, e, ea, zt = p["rr"], p["ra"], p["da"], p["e"], p["ea"], p["zt"]
    sa, sb, ta, tb, u, ua, ub = p["sa"], p["sb"], p["ta"], p["tb"], p["u"], p["ua"], p["ub"]
    zf, fa = p["zf"], p["fa"]
    cth, sph, som = cos(q[1]), sin(q[3]), sin(q[5])
    return (
        m1 * ra**2 + m2 * (rr**2 - 2 * da * rr * cth + da**2) + i1 + i2,
        m2 * (da**2 - da * rr * cth) + i2,
        m2 * da**2 + i2,
        m3 * (sa**2 + sb**2) + i3,
        m4 * (e - ea) ** 2 + i4,
        m4 * ((e - ea) ** 2 + zt * (e - ea) * sph) + i4,
        m4 * (zt**2 + 2 * zt * (e - ea) * sph + (e - ea) ** 2) + m5 * (ta**2 + tb**2) + i4 + i5,
        m6 * (zf - fa) ** 2 + i6,
        m6 * ((zf - fa) ** 2 - u * (zf - fa) * som) + i6,
        m6 * ((zf - fa) ** 2 - 2 * u * (zf - fa) * som + u**2) + m7 * (ua**2 + ub**2) + i6 + i7,
    )


def andrews_constraints(q, cos, sin, p=ANDREWS):
    """The six holonomic constraints of models/src/andrews.rs, in row order."""
    rr, d, ss, e, zt, zf, u = p["rr"], p["d"], p["ss"], p["e"], p["zt"], p["zf"], p["u"]
    xa, ya, xb, yb = p["xa"], p["ya"], p["xb"], p["yb"]
    be, th, ga, ph, de, om, ep = (q[i] for i in range(7))
    cx = rr * cos(be) - d * cos(be + th)
    cy = rr * sin(be) - d * sin(be + th)
    return [
        cx - ss * sin(ga) - xb,
        cy + ss * cos(ga) - yb,
        cx - e * sin(ph + de) - zt * cos(de) - xa,
        cy + e * cos(ph + de) - zt * sin(de) - ya,
        cx - zf * cos(om + ep) - u * sin(ep) - xa,
        cy - zf * sin(om + ep) + u * cos(ep) - ya,
    ]


def andrews_spring_length(q, cos, sin, p=ANDREWS):
    """Length L = |D - C| of the spring of models/src/andrews.rs."""
    ga = q[2]
    xd = p["sd"] * cos(ga) + p["sc"] * sin(ga) + p["xb"]
    yd = p["sd"] * sin(ga) - p["sc"] * cos(ga) + p["yb"]
    return ((xd - p["xc"]) ** 2 + (yd - p["yc"]) ** 2) ** 0.5


def andrews_numpy(t, y, p=ANDREWS):
    """Index-1 right-hand side of andrews as a SciPy user writes it: M and the forces f
    of Hairer & Wanner II, VII.7 (their f1, f2, f4..f7 are the Coriolis terms of
    T = q'^T M q' / 2, checked in tests/src/accuracy/andrews.rs), J = C_q and gamma by
    hand, and one dense solve of the augmented system."""
    a, b = andrews_augmented(y, t, p)
    sol = np.linalg.solve(a, b)
    return np.concatenate([y[7:], sol[:7]])


def andrews_augmented(y, t=0.0, p=ANDREWS):
    """The augmented matrix [[M, J^T], [J, 0]] and right-hand side [f; gamma] of
    `andrews_numpy` at y = [q; v]."""
    q, v = y[:7], y[7:]
    be, th, ga, ph, de, om, ep = q
    bed, thd, gad, phd, ded, omd, epd = v
    c, s = np.cos, np.sin
    m11, m12, m22, m33, m44, m45, m55, m66, m67, m77 = andrews_mass(q, c, s, p)
    m2, m4, m6 = p["m2"], p["m4"], p["m6"]
    rr, d, ss, e, ea, da = p["rr"], p["d"], p["ss"], p["e"], p["ea"], p["da"]
    zt, zf, fa, u = p["zt"], p["zf"], p["fa"], p["u"]
    sd, sc = p["sd"], p["sc"]
    # forces (Hairer & Wanner's f)
    xd = sd * c(ga) + sc * s(ga) + p["xb"]
    yd = sd * s(ga) - sc * c(ga) + p["yb"]
    length = math.hypot(xd - p["xc"], yd - p["yc"])
    k = -p["c0"] * (length - p["l0"]) / length
    fx, fy = k * (xd - p["xc"]), k * (yd - p["yc"])
    f = np.array([
        p["mom"] - m2 * da * rr * thd * (thd + 2 * bed) * s(th),
        m2 * da * rr * bed**2 * s(th),
        fx * (sc * c(ga) - sd * s(ga)) + fy * (sd * c(ga) + sc * s(ga)),
        m4 * zt * (e - ea) * ded**2 * c(ph),
        -m4 * zt * (e - ea) * phd * (phd + 2 * ded) * c(ph),
        -m6 * u * (zf - fa) * epd**2 * c(om),
        m6 * u * (zf - fa) * omd * (omd + 2 * epd) * c(om),
    ])  # fmt: skip
    # J = C_q and gamma = -(C_q v)_q v: every term of a constraint is a constant times
    # the cosine or sine of a sum of angles, so its second time derivative at a = 0 is
    # minus the term times the squared rate of that sum.
    sb, cb = rr * s(be), rr * c(be)
    sbt, cbt = d * s(be + th), d * c(be + th)
    spd, cpd = e * s(ph + de), e * c(ph + de)
    soe, coe = zf * s(om + ep), zf * c(om + ep)
    bt = bed + thd
    a = np.zeros((13, 13))
    a[0, 0], a[0, 1], a[1, 0], a[1, 1] = m11, m12, m12, m22
    a[2, 2] = m33
    a[3, 3], a[3, 4], a[4, 3], a[4, 4] = m44, m45, m45, m55
    a[5, 5], a[5, 6], a[6, 5], a[6, 6] = m66, m67, m67, m77
    jac = np.zeros((6, 7))
    jac[0::2, 0] = -sb + sbt
    jac[1::2, 0] = cb - cbt
    jac[0::2, 1] = sbt
    jac[1::2, 1] = -cbt
    jac[0, 2], jac[1, 2] = -ss * c(ga), -ss * s(ga)
    jac[2, 3], jac[2, 4] = -cpd, -cpd + zt * s(de)
    jac[3, 3], jac[3, 4] = -spd, -spd - zt * c(de)
    jac[4, 5], jac[4, 6] = soe, soe - u * c(ep)
    jac[5, 5], jac[5, 6] = -coe, -coe - u * s(ep)
    a[7:, :7] = jac
    a[:7, 7:] = jac.T
    gx = cb * bed**2 - cbt * bt**2  # the crank and body 2, x rows
    gy = sb * bed**2 - sbt * bt**2
    pd, oe = phd + ded, omd + epd
    gamma = np.array([
        gx - ss * s(ga) * gad**2,
        gy + ss * c(ga) * gad**2,
        gx - spd * pd**2 - zt * c(de) * ded**2,
        gy + cpd * pd**2 - zt * s(de) * ded**2,
        gx - coe * oe**2 - u * s(ep) * epd**2,
        gy - soe * oe**2 + u * c(ep) * epd**2,
    ])  # fmt: skip
    return a, np.concatenate([f, gamma])


def andrews_casadi(ca, t):
    """(q, v, T, Q_e, C) of andrews as CasADi SX: the kinetic energy, the applied forces
    (the motor on beta, the spring by its virtual work) and the constraints, from which
    `index1` derives Q and gamma as pfaff's generator does (`t` unused: autonomous)."""
    p = ANDREWS
    q = ca.SX.sym("q", 7)
    v = ca.SX.sym("v", 7)
    m11, m12, m22, m33, m44, m45, m55, m66, m67, m77 = andrews_mass(q, ca.cos, ca.sin)
    mass = ca.SX.zeros(7, 7)
    mass[0, 0], mass[0, 1], mass[1, 0], mass[1, 1] = m11, m12, m12, m22
    mass[2, 2] = m33
    mass[3, 3], mass[3, 4], mass[4, 3], mass[4, 4] = m44, m45, m45, m55
    mass[5, 5], mass[5, 6], mass[6, 5], mass[6, 6] = m66, m67, m67, m77
    kinetic = 0.5 * ca.dot(v, ca.mtimes(mass, v))
    length = andrews_spring_length(q, ca.cos, ca.sin)
    applied = -p["c0"] * (length - p["l0"]) * ca.gradient(length, q)
    applied[0] += p["mom"]
    c = ca.vertcat(*andrews_constraints(q, ca.cos, ca.sin))
    return q, v, kinetic, applied, c


# --------------------------------------------------------------------------------------
# Car axis (Rentrop, Roche & Steinebach 1989), models/src/car_axis.rs
# --------------------------------------------------------------------------------------

CAR_AXIS = {"eps": 1e-2, "mass": 10.0, "l": 1.0, "l0": 0.5, "r": 0.1, "w": 10.0, "g": 1.0}
CAR_AXIS_T_END = 3.0
CAR_AXIS_NAMES = ["xl", "yl", "xr", "yr"]
CAR_AXIS_Q0 = np.array([0.0, 0.5, 1.0, 0.5])  # (0, l0, l, l0)
CAR_AXIS_V0 = np.array([-0.5, 0.0, -0.5, 0.0])  # (-l0/l, 0, -l0/l, 0)
# The reference positions at t = 3 of the "car axis" problem of the Bari test set for IVP
# solvers (Mazzia & Magherini; computed with GAMD in quadruple precision).
CAR_AXIS_REFERENCE = np.array([
    0.493455784275402809122e-1,
    0.496989460230171153861e0,
    0.104174252488542151681e1,
    0.373911027265361256927e0,
])  # fmt: skip


def car_axis_road(t, sin, cos, p=CAR_AXIS):
    """The road point (x_b, y_b) = (sqrt(l^2 - y_b^2), r sin(w t))."""
    yb = p["r"] * sin(p["w"] * t)
    return (p["l"] ** 2 - yb**2) ** 0.5, yb


def car_axis_numpy(t, y):
    """Index-1 right-hand side of the car axis (NumPy)."""
    a, b = car_axis_augmented(y, t)
    sol = np.linalg.solve(a, b)
    return np.concatenate([y[4:], sol[:4]])


def car_axis_augmented(y, t, p=CAR_AXIS):
    """The augmented system of the car axis at time t, y = [q; v]: M = K I with
    K = mass eps^2 / 2, two springs of unit stiffness and rest length l0, gravity K g;
    C = (x_b xl + y_b yl, (xl - xr)^2 + (yl - yr)^2 - l^2), rheonomic through the road."""
    xl, yl, xr, yr, vxl, vyl, vxr, vyr = y
    k = p["mass"] * p["eps"] ** 2 / 2.0
    l0, r, w = p["l0"], p["r"], p["w"]
    xb, yb = car_axis_road(t, math.sin, math.cos)
    ybd, ybdd = r * w * math.cos(w * t), -r * w * w * math.sin(w * t)
    xbd = -yb * ybd / xb
    xbdd = -(ybd**2 + yb * ybdd + xbd**2) / xb
    left, right = math.hypot(xl, yl), math.hypot(xr - xb, yr - yb)
    fl, fr = -(left - l0) / left, -(right - l0) / right
    forces = [fl * xl, fl * yl - k * p["g"], fr * (xr - xb), fr * (yr - yb) - k * p["g"]]
    dx, dy = xl - xr, yl - yr
    jac = np.array([[xb, yb, 0.0, 0.0], [2 * dx, 2 * dy, -2 * dx, -2 * dy]])
    gamma = [
        -(xbdd * xl + 2 * xbd * vxl + ybdd * yl + 2 * ybd * vyl),
        -2.0 * ((vxl - vxr) ** 2 + (vyl - vyr) ** 2),
    ]
    a = np.zeros((6, 6))
    a[:4, :4] = k * np.eye(4)
    a[4:, :4] = jac
    a[:4, 4:] = jac.T
    return a, np.concatenate([forces, gamma])


def car_axis_casadi(ca, t):
    """(q, v, T, Q_e, C) of the car axis as CasADi SX: the potential of the springs and
    of gravity enters as Q_e = -V_q."""
    p = CAR_AXIS
    q = ca.SX.sym("q", 4)
    v = ca.SX.sym("v", 4)
    xl, yl, xr, yr = (q[i] for i in range(4))
    k = p["mass"] * p["eps"] ** 2 / 2.0
    xb, yb = car_axis_road(t, ca.sin, ca.cos)
    kinetic = 0.5 * k * ca.dot(v, v)
    left = ca.sqrt(xl**2 + yl**2)
    right = ca.sqrt((xr - xb) ** 2 + (yr - yb) ** 2)
    potential = 0.5 * (left - p["l0"]) ** 2 + 0.5 * (right - p["l0"]) ** 2 + k * p["g"] * (yl + yr)
    c = ca.vertcat(xb * xl + yb * yl, (xl - xr) ** 2 + (yl - yr) ** 2 - p["l"] ** 2)
    return q, v, kinetic, -ca.gradient(potential, q), c


def index1(ca, t, q, v, kinetic, applied, c):
    """The index-1 quantities from T, the applied forces and C(q, t), as pfaff's
    generator derives them (docs/theory.md §scope): M = T_vv, Q = Q_e + T_q - T_vq v - T_vt,
    J = C_q, gamma = -(J v)_q v - 2 J_t v - C_tt. Returns (M, Q, J, gamma)."""
    grad_v = ca.gradient(kinetic, v)
    mass = ca.jacobian(grad_v, v)
    forces = applied + ca.gradient(kinetic, q) - ca.mtimes(ca.jacobian(grad_v, q), v) - ca.jacobian(grad_v, t)
    jac = ca.jacobian(c, q)
    jv = ca.mtimes(jac, v)
    c_t = ca.jacobian(c, t)
    gamma = -ca.mtimes(ca.jacobian(jv, q), v) - 2 * ca.jacobian(jv, t) - ca.jacobian(c_t, t)
    return mass, forces, jac, gamma
