//! Two test-only mechanisms that reach what the built-in models do not: kinetic energy
//! with terms linear in and free of the velocities, explicit time everywhere, a
//! non-homogeneous rheonomic non-holonomic constraint, several forces on one coordinate,
//! virtual work with several variations, nested intermediate definitions, integer
//! literals, and every function of the description language.
//!
//! `v5` is case V5 of docs/theory.md §verification, so its generated functions must also reproduce the
//! published A, h, c, λ and q̈.

use std::f64::consts::PI;

use pfaff::{Mechanism as _, TimeDependence};

use super::check::{check_info, Expected, State};
use super::reference::Reference;
use super::sweep;
use super::util::{dense, max_abs, max_diff, solve};

/// docs/theory.md V5: all terms of the multiplier formula active; with the linearization
/// Jacobian, whose explicit time dependence and non-diagonal mass matrix it exercises.
#[pfaff::mechanism(linearize)]
pub mod v5 {
    /// First coordinate.
    static q1: Coordinate = Coordinate {};
    /// Second coordinate.
    static q2: Coordinate = Coordinate {};
    /// Third coordinate.
    static q3: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * ((1.0 + q2.powi(2)) * q1.dot().powi(2)
            + (2.0 + t.cos()) * q2.dot().powi(2)
            + q3.dot().powi(2)
            + q1 * q1.dot() * q3.dot())
            + t * q2 * q1.dot()
            + q1.sin() * q3.dot()
            + t * q3.powi(2) / 3.0
    }

    /// First constraint.
    #[holonomic]
    fn f1() -> f64 {
        q1.powi(2) + q2 * q3 - t
    }

    /// Second constraint.
    #[holonomic]
    fn f2() -> f64 {
        q1 + t.sin() * q3
    }

    #[force(q1)]
    fn push1() -> f64 {
        0.2
    }

    #[force(q2)]
    fn push2() -> f64 {
        -0.1
    }

    #[force(q3)]
    fn push3() -> f64 {
        0.05
    }
}

/// The expressions of `v5`, re-typed (docs/theory.md V5).
fn reference_v5() -> Reference {
    Reference::new(3, |t, q, v| {
        0.5 * ((1.0 + q[1].powi(2)) * v[0].powi(2)
            + (2.0 + t.cos()) * v[1].powi(2)
            + v[2].powi(2)
            + q[0] * v[0] * v[2])
            + t * q[1] * v[0]
            + q[0].sin() * v[2]
            + t * q[2].powi(2) / 3.0
    })
    .holonomic(|t, q| q[0].powi(2) + q[1] * q[2] - t)
    .holonomic(|t, q| q[0] + t.sin() * q[2])
    .force(0, |_, _, _| 0.2)
    .force(1, |_, _, _| -0.1)
    .force(2, |_, _, _| 0.05)
}

/// Every function of the description language, with explicit time in every part.
#[pfaff::mechanism]
pub mod constructs {
    /// A stiffness.
    const k: f64 = 2.0;
    /// A drag coefficient; its default uses `k` and an integer literal.
    const c: f64 = k * 0.5 + 1;

    /// First coordinate.
    static x: Coordinate = Coordinate { q0: 0.1, qd0: 0.2 };
    /// Second coordinate.
    static y: Coordinate = Coordinate {};
    /// Third coordinate.
    static z: Coordinate = Coordinate { q0: 1, qd0: -1 };

    fn w() -> f64 {
        (2.0 + x.sin()).ln() + y.tanh()
    }

    fn w2() -> f64 {
        w() * z.cosh()
    }

    fn kinetic_energy() -> f64 {
        let s = 1 + x.powi(2);
        0.5 * (s * x.dot().powi(2)
            + (2.0 + y.cos()).powf(1.5) * y.dot().powi(2)
            + (3 + z.sin()) * z.dot().powi(2))
            + 0.1 * w() * x.dot() * y.dot()
            + t.sin() * z * x.dot()
            + x.atan() * t
    }

    fn potential_energy() -> f64 {
        k * w2()
            + (0.5 * y.sin()).asin()
            + (0.3 * z.cos()).acos()
            + x.exp() * t.cos()
            + (y - 3).abs()
            + z.signum() * y
            + y.atan2(z)
            + 0.1 * (x + std::f64::consts::PI).tan()
    }

    #[force(x)]
    fn drag() -> f64 {
        -c * x.dot() * x.dot().abs()
    }

    #[force(x)]
    fn push() -> f64 {
        t.sinh() * y.signum()
    }

    #[force(z)]
    fn tilt() -> f64 {
        y.atan2(z) * x.dot()
    }

    #[virtual_work]
    fn springs() -> f64 {
        let d1 = x - y;
        let d2 = (y.powi(2) + z.powi(2)).sqrt();
        -k * d1 * delta(d1) - (d2 - 1) * delta(d2) + t * delta(x * z)
    }

    /// A rheonomic holonomic constraint.
    #[holonomic]
    fn h() -> f64 {
        x.tan() * z - PI * t + y.powi(3)
    }

    /// A rheonomic, non-homogeneous non-holonomic constraint.
    #[nonholonomic]
    fn nh() -> f64 {
        (x * t).cos() * x.dot() + z * y.dot() - t.exp() * z.dot() + x * t.powi(2) + y
    }
}

/// The expressions of `constructs`, re-typed: q = (x, y, z).
fn reference_constructs(p: &constructs::Params) -> Reference {
    let (k, c) = (p.k, p.c);
    let w = |q: &[f64]| (2.0 + q[0].sin()).ln() + q[1].tanh();
    Reference::new(3, move |t, q, v| {
        let s = 1.0 + q[0].powi(2);
        0.5 * (s * v[0].powi(2)
            + (2.0 + q[1].cos()).powf(1.5) * v[1].powi(2)
            + (3.0 + q[2].sin()) * v[2].powi(2))
            + 0.1 * w(q) * v[0] * v[1]
            + t.sin() * q[2] * v[0]
            + q[0].atan() * t
    })
    .potential(move |t, q| {
        k * w(q) * q[2].cosh()
            + (0.5 * q[1].sin()).asin()
            + (0.3 * q[2].cos()).acos()
            + q[0].exp() * t.cos()
            + (q[1] - 3.0).abs()
            + q[2].signum() * q[1]
            + q[1].atan2(q[2])
            + 0.1 * (q[0] + PI).tan()
    })
    .force(0, move |_, _, v| -c * v[0] * v[0].abs())
    .force(0, |t, q, _| t.sinh() * q[1].signum())
    .force(2, |_, q, v| q[1].atan2(q[2]) * v[0])
    .virtual_work(move |_, q, _| -k * (q[0] - q[1]), |_, q| q[0] - q[1])
    .virtual_work(
        |_, q, _| -((q[1].powi(2) + q[2].powi(2)).sqrt() - 1.0),
        |_, q| (q[1].powi(2) + q[2].powi(2)).sqrt(),
    )
    .virtual_work(|t, _, _| t, |_, q| q[0] * q[2])
    .holonomic(|t, q| q[0].tan() * q[2] - PI * t + q[1].powi(3))
    .nonholonomic(|t, q, v| {
        (q[0] * t).cos() * v[0] + q[2] * v[1] - t.exp() * v[2] + q[0] * t.powi(2) + q[1]
    })
}

#[test]
fn info() {
    check_info(
        &v5::Model::default(),
        &Expected {
            name: "v5",
            coordinates: &["q1", "q2", "q3"],
            holonomic: &["f1", "f2"],
            nonholonomic: &[],
            time: TimeDependence {
                mass: true,
                forces: true,
                holonomic: true,
                nonholonomic: false,
            },
            homogeneous: true,
            conservative: false,
            q0: &[0.0; 3],
            qd0: &[0.0; 3],
        },
    );
    check_info(
        &constructs::Model::default(),
        &Expected {
            name: "constructs",
            coordinates: &["x", "y", "z"],
            holonomic: &["h"],
            nonholonomic: &["nh"],
            time: TimeDependence {
                mass: false,
                forces: true,
                holonomic: true,
                nonholonomic: true,
            },
            homogeneous: false,
            conservative: false,
            q0: &[0.1, 0.0, 1.0],
            qd0: &[0.2, 0.0, -1.0],
        },
    );
    let p = constructs::Params::default();
    assert_eq!((p.k, p.c), (2.0, 2.0));
}

#[test]
fn derivatives_v5() {
    sweep(
        "v5",
        0x5eed_000c,
        v5::Model::default,
        |_| reference_v5(),
        |rng| State {
            t: rng.range(0.0, 3.0),
            q: rng.vec(3, -1.0, 1.0),
            qd: rng.vec(3, -2.0, 2.0),
        },
    );
}

#[test]
fn derivatives_constructs() {
    // z stays away from 0 (the kink of signum) and |y| ≤ 1 keeps y − 3 away from the
    // kink of abs; x + π stays away from the poles of tan.
    sweep(
        "constructs",
        0x5eed_000d,
        constructs::Model::default,
        |m| reference_constructs(&m.params),
        |rng| State {
            t: rng.range(0.0, 2.0),
            q: vec![
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(0.5, 1.5),
            ],
            qd: rng.vec(3, -2.0, 2.0),
        },
    );
}

/// docs/theory.md V5 at t = 0.7, q = (0.3, −0.2, 0.5), q̇ = (0.1, 0.4, −0.3): A = M, h = Q,
/// c = −γ_h, and the solution of M q̈ + C_qᵀλ = Q, C_q q̈ = γ_h gives q̈ and
/// λ = −λ^[S2]; 1e-9 relative (docs/theory.md §verification; the table has 12 digits).
#[test]
#[allow(non_snake_case)]
fn v5_multipliers() {
    let model = v5::Model::default();
    let (t, q, qd) = (0.7, [0.3, -0.2, 0.5], [0.1, 0.4, -0.3]);
    let mut m = vec![f64::NAN; v5::INFO.mass_pattern.len()];
    model.mass_matrix(t, &q, &mut m);
    let M = dense(v5::INFO.mass_pattern, &m, 3, 3);
    let mut Q = [f64::NAN; 3];
    model.forces(t, &q, &qd, &mut Q);
    let mut cq = vec![f64::NAN; v5::INFO.holonomic_pattern.len()];
    model.holonomic_jacobian(t, &q, &mut cq);
    let Cq = dense(v5::INFO.holonomic_pattern, &cq, 2, 3);
    let mut gamma = [f64::NAN; 2];
    model.holonomic_gamma(t, &q, &qd, &mut gamma);

    // [M Cqᵀ; Cq 0] [q̈; λ] = [Q; γ]
    let mut kkt = vec![0.0; 25];
    for i in 0..3 {
        for j in 0..3 {
            kkt[i * 5 + j] = M[i * 3 + j];
        }
        for r in 0..2 {
            kkt[i * 5 + 3 + r] = Cq[r * 3 + i];
            kkt[(3 + r) * 5 + i] = Cq[r * 3 + i];
        }
    }
    let x = solve(&kkt, &[Q[0], Q[1], Q[2], gamma[0], gamma[1]]);
    let lambda_s2 = [-x[3], -x[4]];

    let a = [1.04, 0.0, 0.15, 0.0, 2.764_842_187_284, 0.0, 0.15, 0.0, 1.0];
    let h = [-0.150_600_946_738, 0.225_687_074_895, 0.182_799_684_421];
    let c = [-0.22, -0.781_014_155_990];
    let l = [0.096_308_984_403_6, 0.640_763_782_118];
    let qdd = [0.453_561_512_162, 0.099_044_194_405_1, 0.508_295_022_498];
    let rel = |x: &[f64], y: &[f64]| max_diff(x, y) / max_abs(y);
    let errors = [
        rel(&M, &a),
        rel(&Q, &h),
        rel(&gamma.map(|g| -g), &c),
        rel(&lambda_s2, &l),
        rel(&x[..3], &qdd),
    ];
    let shown = errors.map(|e| format!("{e:.1e}"));
    println!("v5: A, h, c, λ, q̈ relative errors {shown:?}");
    assert!(
        errors.iter().all(|e| *e < 1e-9),
        "{errors:?}: M {M:?}, Q {Q:?}, γ {gamma:?}, x {x:?}"
    );
}

/// Names that generated code also uses (a coordinate `applied`, the argument of
/// `free_motion_residual`; a coordinate `t0` and a parameter `tmp_0`, both of the form of
/// a temporary; a parameter `x_dot` beside a coordinate `x`) and expressions whose
/// printed form depends on precedence (`-x.powi(2)`, `(-x).powi(3)`, `a / (b * c)`,
/// `a - (b - c)`).
#[pfaff::mechanism]
pub mod names {
    const x_dot: f64 = 0.7;
    const tmp_0: f64 = 1.5;
    static x: Coordinate = Coordinate {};
    static applied: Coordinate = Coordinate {};
    static t0: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * (2.0 * x.dot().powi(2) + applied.dot().powi(2) + 3.0 * t0.dot().powi(2))
    }

    fn potential_energy() -> f64 {
        -x.powi(2) * (applied - (t0 - x)) + (-x).powi(3) - x_dot / (tmp_0 * (2.0 + t0.sin()))
            + x * t0 / (applied.cos() + 2.0) / (tmp_0 - x)
            - (x - applied) * (t0 - x_dot) * (x + t0).sin()
    }

    #[holonomic]
    fn sphere() -> f64 {
        x.powi(2) * applied + (applied - t0).powi(2) * t0.cos() - tmp_0 * (x - (t0 - applied))
    }
}

fn reference_names(p: &names::Params) -> Reference {
    let (x_dot, tmp_0) = (p.x_dot, p.tmp_0);
    Reference::new(3, |_, _, v| {
        0.5 * (2.0 * v[0].powi(2) + v[1].powi(2) + 3.0 * v[2].powi(2))
    })
    .potential(move |_, q| {
        let (x, a, t0) = (q[0], q[1], q[2]);
        -(x * x) * (a - (t0 - x)) - x * x * x - x_dot / (tmp_0 * (2.0 + t0.sin()))
            + x * t0 / (a.cos() + 2.0) / (tmp_0 - x)
            - (x - a) * (t0 - x_dot) * (x + t0).sin()
    })
    .holonomic(move |_, q| {
        let (x, a, t0) = (q[0], q[1], q[2]);
        x * x * a + (a - t0) * (a - t0) * t0.cos() - tmp_0 * (x - (t0 - a))
    })
}

#[test]
fn derivatives_names() {
    sweep(
        "names",
        0x5eed_000e,
        names::Model::default,
        |m| reference_names(&m.params),
        |rng| State {
            t: rng.range(0.0, 1.0),
            q: rng.vec(3, -1.0, 1.0),
            qd: rng.vec(3, -2.0, 2.0),
        },
    );
}

/// The free-motion residual of `names` with no applied force is `−γ + C_q M⁻¹ Q`, from
/// the model's own (checked) functions, whatever the coordinates are called.
#[test]
fn free_motion_names() {
    let model = names::Model::default();
    let (t, q, qd) = (0.3, [0.4, -0.2, 0.7], [0.5, -1.0, 0.3]);
    let mut m = vec![f64::NAN; names::INFO.mass_pattern.len()];
    model.mass_matrix(t, &q, &mut m);
    let m = dense(names::INFO.mass_pattern, &m, 3, 3);
    let mut f = [f64::NAN; 3];
    model.forces(t, &q, &qd, &mut f);
    let mut cq = vec![f64::NAN; names::INFO.holonomic_pattern.len()];
    model.holonomic_jacobian(t, &q, &mut cq);
    let cq = dense(names::INFO.holonomic_pattern, &cq, 1, 3);
    let mut gamma = [f64::NAN; 1];
    model.holonomic_gamma(t, &q, &qd, &mut gamma);
    let expected = -gamma[0] + (0..3).map(|k| cq[k] * f[k] / m[k * 4]).sum::<f64>();
    let mut w = [f64::NAN; 1];
    assert!(model.free_motion_residual(t, &q, &qd, &[0.0; 3], &mut w));
    assert!(
        (w[0] - expected).abs() <= 1e-12 * (1.0 + expected.abs()),
        "{w:?} vs {expected}"
    );
}
