//! Hand-written `impl Mechanism` test models (the macro is not used here), with
//! derivatives computed by hand; `kin_models.rs` checks them against finite differences.
#![allow(dead_code)]

use pfaff::{Info, Mechanism, Parameter, Pattern, Symbol, TimeDependence};

pub const G: f64 = 9.81;

const fn sym(name: &'static str) -> Symbol {
    Symbol { name, doc: "" }
}

const NO_PARAMS: &[Parameter] = &[];

fn diag(n: usize) -> Pattern {
    Box::leak(
        (0..n as u32)
            .map(|i| (i, i))
            .collect::<Vec<_>>()
            .into_boxed_slice(),
    )
}

// ---------------------------------------------------------------------------------
// V10: planar slider-crank in absolute coordinates.

const SC_COORDS: &[Symbol] = &[
    sym("x1"),
    sym("y1"),
    sym("phi1"),
    sym("x2"),
    sym("y2"),
    sym("phi2"),
    sym("x3"),
    sym("y3"),
    sym("phi3"),
];
const SC_CONSTRAINTS: &[Symbol] = &[
    sym("pin_o_x"),
    sym("pin_o_y"),
    sym("pin_a_x"),
    sym("pin_a_y"),
    sym("pin_b_x"),
    sym("pin_b_y"),
    sym("slider_y"),
    sym("slider_phi"),
    sym("driver"),
];
const SC_PATTERN: Pattern = &[
    (0, 0),
    (0, 2),
    (1, 1),
    (1, 2),
    (2, 0),
    (2, 2),
    (2, 3),
    (2, 5),
    (3, 1),
    (3, 2),
    (3, 4),
    (3, 5),
    (4, 3),
    (4, 5),
    (4, 6),
    (5, 4),
    (5, 5),
    (5, 7),
    (6, 7),
    (7, 8),
    (8, 2),
];
const SC_MASS: Pattern = &[
    (0, 0),
    (1, 1),
    (2, 2),
    (3, 3),
    (4, 4),
    (5, 5),
    (6, 6),
    (7, 7),
    (8, 8),
];

pub static SLIDER_CRANK_DRIVEN: Info = Info {
    name: "slider_crank",
    doc: "planar slider-crank driven by phi1 = pi/6 + 10 t",
    coordinates: SC_COORDS,
    parameters: NO_PARAMS,
    holonomic: SC_CONSTRAINTS,
    nonholonomic: &[],
    mass_pattern: SC_MASS,
    holonomic_pattern: SC_PATTERN,
    nonholonomic_pattern: &[],
    time: TimeDependence {
        mass: false,
        forces: false,
        holonomic: true,
        nonholonomic: false,
    },
    nonholonomic_homogeneous: true,
    conservative: false,
    ..Info::EMPTY
};

pub static SLIDER_CRANK_FREE: Info = Info {
    name: "slider_crank_free",
    doc: "planar slider-crank without driver (one degree of freedom)",
    coordinates: SC_COORDS,
    parameters: NO_PARAMS,
    holonomic: SC_CONSTRAINTS.split_at(8).0,
    nonholonomic: &[],
    mass_pattern: SC_MASS,
    holonomic_pattern: SC_PATTERN.split_at(20).0,
    nonholonomic_pattern: &[],
    time: TimeDependence {
        mass: false,
        forces: false,
        holonomic: false,
        nonholonomic: false,
    },
    nonholonomic_homogeneous: true,
    conservative: true,
    ..Info::EMPTY
};

/// Crank `a`, coupler `b`, masses and inertias of the three bodies.
#[derive(Debug, Clone)]
pub struct SliderCrank {
    pub driven: bool,
    pub a: f64,
    pub b: f64,
    pub mass: [f64; 9],
}

impl SliderCrank {
    pub fn new(driven: bool) -> Self {
        Self {
            driven,
            a: 0.1,
            b: 0.3,
            mass: [1.0, 1.0, 0.01, 2.0, 2.0, 0.02, 0.5, 0.5, 0.001],
        }
    }

    /// The consistent configuration at crank angle `phi` (coupler below the axis
    /// when `sin phi > 0`).
    pub fn configuration(&self, phi: f64) -> [f64; 9] {
        let (a, b) = (self.a, self.b);
        let phi2 = -(a * phi.sin() / b).asin();
        let (ax, ay) = (a * phi.cos(), a * phi.sin());
        [
            a / 2.0 * phi.cos(),
            a / 2.0 * phi.sin(),
            phi,
            ax + b / 2.0 * phi2.cos(),
            ay + b / 2.0 * phi2.sin(),
            phi2,
            ax + b * phi2.cos(),
            0.0,
            0.0,
        ]
    }
}

impl Mechanism for SliderCrank {
    fn info(&self) -> &'static Info {
        if self.driven {
            &SLIDER_CRANK_DRIVEN
        } else {
            &SLIDER_CRANK_FREE
        }
    }
    fn parameter(&self, _: usize) -> f64 {
        unreachable!("no parameters")
    }
    fn set_parameter(&mut self, _: usize, _: f64) {
        unreachable!("no parameters")
    }
    fn mass_matrix(&self, _t: f64, _q: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&self.mass);
    }
    fn forces(&self, _t: f64, _q: &[f64], _qd: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for body in 0..3 {
            out[3 * body + 1] = -self.mass[3 * body + 1] * G;
        }
    }
    fn holonomic(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let (a, b) = (self.a, self.b);
        let (x1, y1, p1, x2, y2, p2, x3, y3, p3) =
            (q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8]);
        out[0] = x1 - a / 2.0 * p1.cos();
        out[1] = y1 - a / 2.0 * p1.sin();
        out[2] = x1 + a / 2.0 * p1.cos() - x2 + b / 2.0 * p2.cos();
        out[3] = y1 + a / 2.0 * p1.sin() - y2 + b / 2.0 * p2.sin();
        out[4] = x2 + b / 2.0 * p2.cos() - x3;
        out[5] = y2 + b / 2.0 * p2.sin() - y3;
        out[6] = y3;
        out[7] = p3;
        if self.driven {
            out[8] = p1 - std::f64::consts::FRAC_PI_6 - 10.0 * t;
        }
    }
    fn holonomic_jacobian(&self, _t: f64, q: &[f64], out: &mut [f64]) {
        let (a, b) = (self.a, self.b);
        let (s1, c1, s2, c2) = (q[2].sin(), q[2].cos(), q[5].sin(), q[5].cos());
        let values = [
            1.0,
            a / 2.0 * s1,
            1.0,
            -a / 2.0 * c1,
            1.0,
            -a / 2.0 * s1,
            -1.0,
            -b / 2.0 * s2,
            1.0,
            a / 2.0 * c1,
            -1.0,
            b / 2.0 * c2,
            1.0,
            -b / 2.0 * s2,
            -1.0,
            1.0,
            b / 2.0 * c2,
            -1.0,
            1.0,
            1.0,
            1.0,
        ];
        out.copy_from_slice(&values[..out.len()]);
    }
    fn holonomic_rate(&self, _t: f64, _q: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        if self.driven {
            out[8] = -10.0;
        }
    }
    fn holonomic_gamma(&self, _t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let (a, b) = (self.a, self.b);
        let (s1, c1, s2, c2) = (q[2].sin(), q[2].cos(), q[5].sin(), q[5].cos());
        let (w1, w2) = (qd[2] * qd[2], qd[5] * qd[5]);
        out.fill(0.0);
        out[0] = -a / 2.0 * c1 * w1;
        out[1] = -a / 2.0 * s1 * w1;
        out[2] = a / 2.0 * c1 * w1 + b / 2.0 * c2 * w2;
        out[3] = a / 2.0 * s1 * w1 + b / 2.0 * s2 * w2;
        out[4] = b / 2.0 * c2 * w2;
        out[5] = b / 2.0 * s2 * w2;
    }
    fn kinetic_energy(&self, _t: f64, _q: &[f64], qd: &[f64]) -> f64 {
        0.5 * self
            .mass
            .iter()
            .zip(qd)
            .map(|(m, v)| m * v * v)
            .sum::<f64>()
    }
    fn potential_energy(&self, _t: f64, q: &[f64]) -> f64 {
        (0..3)
            .map(|b| self.mass[3 * b + 1] * G * q[3 * b + 1])
            .sum()
    }
}

// ---------------------------------------------------------------------------------
// V11: Chaplygin sleigh.

pub static SLEIGH: Info = Info {
    name: "sleigh",
    doc: "Chaplygin sleigh: knife edge at body point (-a, 0)",
    coordinates: &[sym("x"), sym("y"), sym("phi")],
    parameters: NO_PARAMS,
    holonomic: &[],
    nonholonomic: &[sym("knife_edge")],
    mass_pattern: &[(0, 0), (1, 1), (2, 2)],
    holonomic_pattern: &[],
    nonholonomic_pattern: &[(0, 0), (0, 1), (0, 2)],
    time: TimeDependence {
        mass: false,
        forces: false,
        holonomic: false,
        nonholonomic: false,
    },
    nonholonomic_homogeneous: true,
    conservative: true,
    ..Info::EMPTY
};

#[derive(Debug, Clone)]
pub struct Sleigh {
    pub m: f64,
    pub jc: f64,
    pub a: f64,
}

impl Default for Sleigh {
    fn default() -> Self {
        Self {
            m: 2.0,
            jc: 0.05,
            a: 0.3,
        }
    }
}

impl Mechanism for Sleigh {
    fn info(&self) -> &'static Info {
        &SLEIGH
    }
    fn parameter(&self, _: usize) -> f64 {
        unreachable!("no parameters")
    }
    fn set_parameter(&mut self, _: usize, _: f64) {
        unreachable!("no parameters")
    }
    fn mass_matrix(&self, _t: f64, _q: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&[self.m, self.m, self.jc]);
    }
    fn forces(&self, _t: f64, _q: &[f64], _qd: &[f64], out: &mut [f64]) {
        out.fill(0.0);
    }
    fn nonholonomic_matrix(&self, _t: f64, q: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&[-q[2].sin(), q[2].cos(), -self.a]);
    }
    fn nonholonomic_gamma(&self, _t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        out[0] = qd[2] * (q[2].cos() * qd[0] + q[2].sin() * qd[1]);
    }
    fn kinetic_energy(&self, _t: f64, _q: &[f64], qd: &[f64]) -> f64 {
        0.5 * self.m * (qd[0] * qd[0] + qd[1] * qd[1]) + 0.5 * self.jc * qd[2] * qd[2]
    }
}

// ---------------------------------------------------------------------------------
// Pendulum in Cartesian coordinates, optionally with its constraint duplicated.

const PENDULUM_COORDS: &[Symbol] = &[sym("x"), sym("y")];

pub static PENDULUM: Info = Info {
    name: "pendulum",
    doc: "point mass on a rod: x^2 + y^2 - l^2 = 0",
    coordinates: PENDULUM_COORDS,
    parameters: NO_PARAMS,
    holonomic: &[sym("rod")],
    nonholonomic: &[],
    mass_pattern: &[(0, 0), (1, 1)],
    holonomic_pattern: &[(0, 0), (0, 1)],
    nonholonomic_pattern: &[],
    time: TimeDependence {
        mass: false,
        forces: false,
        holonomic: false,
        nonholonomic: false,
    },
    nonholonomic_homogeneous: true,
    conservative: true,
    ..Info::EMPTY
};

pub static PENDULUM_DUPLICATED: Info = Info {
    name: "pendulum_duplicated",
    doc: "the pendulum with its rod constraint written twice",
    coordinates: PENDULUM_COORDS,
    parameters: NO_PARAMS,
    holonomic: &[sym("rod"), sym("rod_copy")],
    nonholonomic: &[],
    mass_pattern: &[(0, 0), (1, 1)],
    holonomic_pattern: &[(0, 0), (0, 1), (1, 0), (1, 1)],
    nonholonomic_pattern: &[],
    time: TimeDependence {
        mass: false,
        forces: false,
        holonomic: false,
        nonholonomic: false,
    },
    nonholonomic_homogeneous: true,
    conservative: true,
    ..Info::EMPTY
};

#[derive(Debug, Clone)]
pub struct Pendulum {
    pub duplicated: bool,
    pub m: f64,
    pub l: f64,
}

impl Pendulum {
    pub fn new(duplicated: bool) -> Self {
        Self {
            duplicated,
            m: 1.0,
            l: 1.0,
        }
    }
    fn rows(&self) -> usize {
        if self.duplicated {
            2
        } else {
            1
        }
    }
}

impl Mechanism for Pendulum {
    fn info(&self) -> &'static Info {
        if self.duplicated {
            &PENDULUM_DUPLICATED
        } else {
            &PENDULUM
        }
    }
    fn parameter(&self, _: usize) -> f64 {
        unreachable!("no parameters")
    }
    fn set_parameter(&mut self, _: usize, _: f64) {
        unreachable!("no parameters")
    }
    fn mass_matrix(&self, _t: f64, _q: &[f64], out: &mut [f64]) {
        out.fill(self.m);
    }
    fn forces(&self, _t: f64, _q: &[f64], _qd: &[f64], out: &mut [f64]) {
        out[0] = 0.0;
        out[1] = -self.m * G;
    }
    fn holonomic(&self, _t: f64, q: &[f64], out: &mut [f64]) {
        out.fill(q[0] * q[0] + q[1] * q[1] - self.l * self.l);
    }
    fn holonomic_jacobian(&self, _t: f64, q: &[f64], out: &mut [f64]) {
        for r in 0..self.rows() {
            out[2 * r] = 2.0 * q[0];
            out[2 * r + 1] = 2.0 * q[1];
        }
    }
    fn holonomic_gamma(&self, _t: f64, _q: &[f64], qd: &[f64], out: &mut [f64]) {
        out.fill(-2.0 * (qd[0] * qd[0] + qd[1] * qd[1]));
    }
    fn kinetic_energy(&self, _t: f64, _q: &[f64], qd: &[f64]) -> f64 {
        0.5 * self.m * (qd[0] * qd[0] + qd[1] * qd[1])
    }
    fn potential_energy(&self, _t: f64, q: &[f64]) -> f64 {
        self.m * G * q[1]
    }
}

// ---------------------------------------------------------------------------------
// Chain of N point-mass pendulums in Cartesian coordinates.

#[derive(Debug, Clone)]
pub struct Chain {
    pub n: usize,
    pub m: f64,
    pub l: f64,
    info: &'static Info,
}

impl Chain {
    pub fn new(n: usize) -> Self {
        let leak = |s: String| -> &'static str { Box::leak(s.into_boxed_str()) };
        let coordinates: Vec<Symbol> = (1..=n)
            .flat_map(|k| [sym(leak(format!("x{k}"))), sym(leak(format!("y{k}")))])
            .collect();
        let holonomic: Vec<Symbol> = (1..=n).map(|k| sym(leak(format!("rod{k}")))).collect();
        let mut pattern = vec![(0, 0), (0, 1)];
        for k in 1..n as u32 {
            let c = 2 * (k - 1);
            pattern.extend([(k, c), (k, c + 1), (k, c + 2), (k, c + 3)]);
        }
        let info = Box::leak(Box::new(Info {
            name: "chain",
            doc: "chain of point-mass pendulums",
            coordinates: Box::leak(coordinates.into_boxed_slice()),
            parameters: NO_PARAMS,
            holonomic: Box::leak(holonomic.into_boxed_slice()),
            nonholonomic: &[],
            mass_pattern: diag(2 * n),
            holonomic_pattern: Box::leak(pattern.into_boxed_slice()),
            nonholonomic_pattern: &[],
            time: TimeDependence::default(),
            nonholonomic_homogeneous: true,
            conservative: true,
            ..Info::EMPTY
        }));
        Self {
            n,
            m: 1.0,
            l: 1.0,
            info,
        }
    }

    /// A consistent state: link `k` at angle `0.3 sin(k)` from the vertical, angular
    /// rate `0.5 cos(k)`.
    pub fn state(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut q, mut qd) = (vec![0.0; 2 * self.n], vec![0.0; 2 * self.n]);
        let (mut x, mut y, mut vx, mut vy) = (0.0, 0.0, 0.0, 0.0);
        for k in 0..self.n {
            let th = 0.3 * (k as f64 + 1.0).sin();
            let w = 0.5 * (k as f64 + 1.0).cos();
            x += self.l * th.sin();
            y -= self.l * th.cos();
            vx += self.l * th.cos() * w;
            vy += self.l * th.sin() * w;
            q[2 * k] = x;
            q[2 * k + 1] = y;
            qd[2 * k] = vx;
            qd[2 * k + 1] = vy;
        }
        (q, qd)
    }

    fn rel(v: &[f64], k: usize) -> (f64, f64) {
        if k == 0 {
            (v[0], v[1])
        } else {
            (v[2 * k] - v[2 * k - 2], v[2 * k + 1] - v[2 * k - 1])
        }
    }
}

impl Mechanism for Chain {
    fn info(&self) -> &'static Info {
        self.info
    }
    fn parameter(&self, _: usize) -> f64 {
        unreachable!("no parameters")
    }
    fn set_parameter(&mut self, _: usize, _: f64) {
        unreachable!("no parameters")
    }
    fn mass_matrix(&self, _t: f64, _q: &[f64], out: &mut [f64]) {
        out.fill(self.m);
    }
    fn forces(&self, _t: f64, _q: &[f64], _qd: &[f64], out: &mut [f64]) {
        for k in 0..self.n {
            out[2 * k] = 0.0;
            out[2 * k + 1] = -self.m * G;
        }
    }
    fn holonomic(&self, _t: f64, q: &[f64], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate() {
            let (dx, dy) = Self::rel(q, k);
            *o = dx * dx + dy * dy - self.l * self.l;
        }
    }
    fn holonomic_jacobian(&self, _t: f64, q: &[f64], out: &mut [f64]) {
        out[0] = 2.0 * q[0];
        out[1] = 2.0 * q[1];
        for k in 1..self.n {
            let (dx, dy) = Self::rel(q, k);
            let o = 2 + 4 * (k - 1);
            out[o..o + 4].copy_from_slice(&[-2.0 * dx, -2.0 * dy, 2.0 * dx, 2.0 * dy]);
        }
    }
    fn holonomic_gamma(&self, _t: f64, _q: &[f64], qd: &[f64], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate() {
            let (du, dv) = Self::rel(qd, k);
            *o = -2.0 * (du * du + dv * dv);
        }
    }
    fn kinetic_energy(&self, _t: f64, _q: &[f64], qd: &[f64]) -> f64 {
        0.5 * self.m * qd.iter().map(|v| v * v).sum::<f64>()
    }
    fn potential_energy(&self, _t: f64, q: &[f64]) -> f64 {
        (0..self.n).map(|k| self.m * G * q[2 * k + 1]).sum()
    }
}
