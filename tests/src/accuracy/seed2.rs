//! The two examples of Chen, Wu & Mei (2016) (docs/theory.md §free-motion-examples, V1–V4): the models
//! against their source expressions, and the multipliers of V1–V4 computed from the
//! generated functions.
//!
//! With the sign of docs/theory.md (E0), $M\ddot q + C_q^\mathsf{T}\lambda = Q$ and
//! $C_q\ddot q = \gamma_h$ give, for one constraint with row $c = C_q$,
//! $\lambda = (c M^{-1} Q - \gamma_h)/(c M^{-1} c^\mathsf{T})$, and $\lambda^{[S2]} = -\lambda$.

use pfaff::{Mechanism, TimeDependence};
use pfaff_models::{seed2_example1 as ex1, seed2_example2 as ex2};

use super::check::{check_info, Expected, State};
use super::reference::Reference;
use super::util::{dense, solve, Rng};
use super::{sweep, STATES};

/// The expressions of `models/src/seed2_example1.rs`, re-typed (S2-23 and the force of V2).
fn reference1() -> Reference {
    Reference::new(3, |_, _, v| {
        0.5 * (v[0].powi(2) + v[1].powi(2) + v[2].powi(2))
    })
    .holonomic(|t, q| t * q[0] + 2.0 * q[1] - 3.0 * q[2])
    .force(1, |_, _, v| -v[0])
}

/// The force of V4 that makes example 2 free.
fn free_force2(t: f64, q: &[f64], v: &[f64]) -> f64 {
    2.0 * q[0] + 4.0 * t * v[0] - t.powi(2) * t.cos() * v[0] / (2.0 + t.sin())
}

/// The expressions of `models/src/seed2_example2.rs`, re-typed (S2-25 and the force of V4).
fn reference2() -> Reference {
    Reference::new(3, |t, _, v| {
        0.5 * ((2.0 + t.sin()) * v[0].powi(2) + v[1].powi(2) + v[2].powi(2))
    })
    .holonomic(|t, q| t.powi(2) * q[0] - q[1] - q[2])
    .force(1, free_force2)
}

fn sample(rng: &mut Rng) -> State {
    State {
        t: rng.range(0.0, 3.0),
        q: rng.vec(3, -2.0, 2.0),
        qd: rng.vec(3, -2.0, 2.0),
    }
}

/// The `Info` of both examples: no parameters, one rheonomic constraint `f`.
fn expected(
    name: &'static str,
    time: TimeDependence,
    q0: &'static [f64],
    qd0: &'static [f64],
) -> Expected<'static> {
    Expected {
        name,
        coordinates: &["q1", "q2", "q3"],
        holonomic: &["f"],
        nonholonomic: &[],
        time,
        homogeneous: true,
        // Applied forces: T + V is not a first integral.
        conservative: false,
        q0,
        qd0,
    }
}

#[test]
fn info() {
    assert!(ex1::INFO.parameters.is_empty() && ex2::INFO.parameters.is_empty());
    let time1 = TimeDependence {
        holonomic: true,
        ..TimeDependence::default()
    };
    // V2 initial state.
    let e1 = expected("seed2_example1", time1, &[1.0, 0.0, 0.0], &[1.0, 1.0, 1.0]);
    check_info(&ex1::Model::default(), &e1);
    let time2 = TimeDependence {
        mass: true,
        forces: true,
        holonomic: true,
        nonholonomic: false,
    };
    // V4 initial state.
    let e2 = expected(
        "seed2_example2",
        time2,
        &[1.0, 0.5, -0.5],
        &[1.0, 0.2, -0.2],
    );
    check_info(&ex2::Model::default(), &e2);
}

#[test]
fn derivatives_example1() {
    sweep(
        "seed2_example1",
        0x5eed_0005,
        ex1::Model::default,
        |_| reference1(),
        sample,
    );
}

#[test]
fn derivatives_example2() {
    sweep(
        "seed2_example2",
        0x5eed_0006,
        ex2::Model::default,
        |_| reference2(),
        sample,
    );
}

/// The multiplier λ of docs/theory.md (E0) from the generated M, Q, C_q, γ_h, with the
/// applied force `applied` on q2 taken out of Q; returns (λ, the size of the terms).
fn multiplier(model: &dyn Mechanism, s: &State, applied: f64) -> (f64, f64) {
    let info = model.info();
    let mut m = vec![f64::NAN; info.mass_pattern.len()];
    model.mass_matrix(s.t, &s.q, &mut m);
    let m = dense(info.mass_pattern, &m, 3, 3);
    let mut f = [f64::NAN; 3];
    model.forces(s.t, &s.q, &s.qd, &mut f);
    f[1] -= applied;
    let mut c = vec![f64::NAN; info.holonomic_pattern.len()];
    model.holonomic_jacobian(s.t, &s.q, &mut c);
    let c = dense(info.holonomic_pattern, &c, 1, 3);
    let mut gamma = [f64::NAN];
    model.holonomic_gamma(s.t, &s.q, &s.qd, &mut gamma);
    let (mf, mc) = (solve(&m, &f), solve(&m, &c));
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let terms = c.iter().zip(&mf).map(|(a, b)| (a * b).abs()).sum::<f64>() + gamma[0].abs();
    let w = dot(&c, &mc);
    ((dot(&c, &mf) - gamma[0]) / w, terms / w)
}

/// V1 and V3: with Q = 0 the [S2] multipliers are −1/14 (example 1 at t = 1, q̇1 = 0.5,
/// any q, q̇2, q̇3) and −1.66030661896282 (example 2 at t = 1, q1 = 1, q̇1 = 0.5).
/// docs/theory.md §verification, tolerance for algebraic results: 1e-9 relative.
#[test]
fn v1_v3_multipliers() {
    let mut rng = Rng::new(0x5eed_0007);
    for _ in 0..STATES {
        let mut s = sample(&mut rng);
        s.t = 1.0;
        s.qd[0] = 0.5;
        let (lambda, _) = multiplier(&ex1::Model::default(), &s, -s.qd[0]);
        assert!(
            (-lambda - (-1.0 / 14.0)).abs() < 1e-9 / 14.0,
            "V1: λ = {}",
            -lambda
        );
        s.q[0] = 1.0;
        let (lambda, _) = multiplier(&ex2::Model::default(), &s, free_force2(s.t, &s.q, &s.qd));
        let expected = -1.660_306_618_962_82;
        assert!(
            (-lambda - expected).abs() < 1e-9 * expected.abs(),
            "V3: λ = {}",
            -lambda
        );
    }
}

/// V2 and V4: the models' forces satisfy the free-motion conditions (S2-24), (S2-26)
/// identically, so the multiplier vanishes at every state, not only along the motion.
/// The bound is 1e-13 of the terms λ is computed from (a few hundred ulps).
#[test]
fn v2_v4_motion_is_free() {
    let mut rng = Rng::new(0x5eed_0008);
    let mut worst: f64 = 0.0;
    for _ in 0..STATES {
        let s = sample(&mut rng);
        for model in [
            &ex1::Model::default() as &dyn Mechanism,
            &ex2::Model::default(),
        ] {
            let (lambda, scale) = multiplier(model, &s, 0.0);
            worst = worst.max(lambda.abs() / scale);
            assert!(
                lambda.abs() <= 1e-13 * scale,
                "{}: λ = {lambda:e} at {s:?}",
                model.info().name
            );
        }
    }
    println!("seed2 V2/V4: max |λ| / scale = {worst:.1e}");
}
