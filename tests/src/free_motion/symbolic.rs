//! The free-motion conditions the generator emits (docs/theory.md §free-motion-analysis step 1) for models
//! with a diagonal or constant mass matrix: the printed formulas of [S2]'s examples, and
//! the emitted residual against the numeric one of the runtime at random states.

use pfaff::{AppliedForces, FreeMotion, FreeMotionParams, FreeMotionPoint, Mechanism, Workspace};
use pfaff_models::{parallelogram, pendulum, seed2_example1, seed2_example2, slider_crank};

use super::Rng;

/// (S2-24) and (S2-26), as printed.
#[test]
fn printed_conditions_of_the_examples() {
    assert_eq!(
        seed2_example1::FREE_MOTION,
        ["2*q1' + t*Q_q1 + 2*Q_q2 - 3*Q_q3"]
    );
    assert_eq!(
        seed2_example2::FREE_MOTION,
        ["2*q1 + 4*t*q1' - q1'*t^2*cos(t)/(2 + sin(t)) + t^2*Q_q1/(2 + sin(t)) - Q_q2 - Q_q3"]
    );
    assert_eq!(
        seed2_example1::Model::default().free_motion_conditions(),
        seed2_example1::FREE_MOTION
    );
    assert_eq!(
        pendulum::FREE_MOTION,
        ["2*x'^2 + 2*y'^2 + 2*x*Q_x/m - 2*g*y + 2*y*Q_y/m"]
    );
    for c in slider_crank::FREE_MOTION {
        println!("slider_crank: {c} = 0");
    }
}

fn compare<M: Mechanism>(model: &M, rng: &mut Rng) -> f64 {
    let info = model.info();
    let (n, m) = (info.nq(), info.nh() + info.nnh());
    let mut ws = Workspace::new(info).unwrap();
    let mut fm = FreeMotion::new(info, FreeMotionParams::default());
    let mut p = FreeMotionPoint::new(info);
    let mut worst = 0.0_f64;
    for _ in 0..24 {
        let t = rng.range(0.0, 3.0);
        let q = rng.vec(n, -1.5, 1.5);
        let qd = rng.vec(n, -2.0, 2.0);
        let applied = rng.vec(n, -3.0, 3.0);
        let mut sym = vec![f64::NAN; m];
        assert!(model.free_motion_residual(t, &q, &qd, &applied, &mut sym));
        fm.evaluate(
            model,
            &mut ws,
            t,
            &q,
            &qd,
            AppliedForces::Replaced(&applied),
            &mut p,
        )
        .unwrap();
        let scale =
            p.c.iter()
                .chain(&p.h)
                .chain(&p.base_residual)
                .chain(&p.residual)
                .fold(1.0_f64, |a, v| a.max(v.abs()));
        for (a, b) in sym.iter().zip(&p.residual) {
            let e = (a - b).abs() / scale;
            worst = worst.max(e);
            assert!(e < 1e-13, "{}: symbolic {a} vs numeric {b}", info.name);
        }
    }
    worst
}

/// The emitted `free_motion_residual` equals `c + F A⁻¹ (h⁰ + Q)` computed numerically.
#[test]
fn emitted_residual_matches_numeric() {
    let mut rng = Rng::new(0xf4ee_0001);
    let worst = [
        compare(&seed2_example1::Model::default(), &mut rng),
        compare(&seed2_example2::Model::default(), &mut rng),
        compare(&pendulum::Model::default(), &mut rng),
        compare(&slider_crank::Model::default(), &mut rng),
        compare(&parallelogram::Model::default(), &mut rng),
    ];
    println!("emitted vs numeric free-motion residual (relative): {worst:?}");
}
