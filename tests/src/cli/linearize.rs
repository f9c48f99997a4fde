//! `pfaff::linearize` against closed forms.
//!
//! Tolerance: the state matrix is a central difference with the step
//! $h_j = \varepsilon^{1/3}(1 + |y_j|) \approx 6\cdot10^{-6}(1 + |y_j|)$, whose error is
//! $O(h^2|f'''|) + O(\varepsilon|f|/h) \approx 10^{-10}$ relative to the size of the
//! entries (about 10 here). Both matrices below are diagonalizable with well-conditioned
//! eigenvectors, so the eigenvalues carry the same error (Bauer–Fike); `1e-7` relative
//! leaves three orders of margin, and the tests also check the method's own error
//! estimate $\max|A_h - A_{2h}|$ against that bound.

use pfaff::{linearize, LinearizeError, LinearizeParams, Mechanism};
use pfaff_models::{pendulum, sleigh};

const TOL: f64 = 1e-7;

fn close(found: f64, expected: f64, scale: f64) -> bool {
    (found - expected).abs() <= TOL * scale
}

/// The pendulum hanging at rest (x = 0, y = −l): the reduced state is (x, ẋ) with
/// δẍ = −(g/l) δx, so the eigenvalues are ±i√(g/l).
#[test]
fn pendulum_at_the_bottom() {
    for (l, g) in [(1.0, 9.81), (2.5, 1.62)] {
        let mut model = pendulum::Model::default();
        let info = model.info();
        model.set_parameter(info.parameter_index("l").unwrap(), l);
        model.set_parameter(info.parameter_index("g").unwrap(), g);
        let lin = linearize(
            &model,
            0.0,
            &[0.0, -l],
            &[0.0, 0.0],
            &[],
            &LinearizeParams::default(),
        )
        .unwrap();
        let names: Vec<String> = lin.states.iter().map(ToString::to_string).collect();
        assert_eq!(names, ["x", "x'"]);
        assert_eq!(lin.partition[0], ["y"]);
        let w = (g / l).sqrt();
        assert_eq!(lin.eigenvalues.len(), 2);
        assert!(
            close(lin.eigenvalues[0].re, 0.0, w),
            "{:?}",
            lin.eigenvalues
        );
        assert!(
            close(lin.eigenvalues[1].re, 0.0, w),
            "{:?}",
            lin.eigenvalues
        );
        assert!(close(lin.eigenvalues[0].im, -w, w), "{:?}", lin.eigenvalues);
        assert!(close(lin.eigenvalues[1].im, w, w), "{:?}", lin.eigenvalues);
        // A = [[0, 1], [−g/l, 0]].
        assert!(close(lin.entry(0, 1), 1.0, 1.0));
        assert!(close(lin.entry(1, 0), -g / l, g / l));
        assert!(
            lin.error_estimate < 1e-8 * (g / l),
            "{}",
            lin.error_estimate
        );
    }
}

/// The pendulum upright (x = 0, y = +l) is unstable: eigenvalues ±√(g/l).
#[test]
fn pendulum_upright() {
    let model = pendulum::Model::default();
    let lin = linearize(
        &model,
        0.0,
        &[0.0, 1.0],
        &[0.0, 0.0],
        &[],
        &LinearizeParams::default(),
    )
    .unwrap();
    let w = 9.81f64.sqrt();
    assert!(close(lin.eigenvalues[0].re, -w, w) && close(lin.eigenvalues[1].re, w, w));
    assert!(lin.eigenvalues.iter().all(|e| e.im.abs() <= TOL * w));
}

/// The Chaplygin sleigh running straight along x at speed v (φ = 0, φ̇ = 0).
///
/// With the forward speed u and the turning rate ω of the body,
/// $\dot u = a\omega^2$ and $(i_c + m a^2)\dot\omega = -m a u\omega$ (docs/theory.md V11).
/// At φ = 0, Algorithm P makes ẏ dependent, so the reduced state is (y, x, φ, ẋ, φ̇)
/// and ẋ = u, φ̇ = ω there. The velocity rows do not depend on x, y (cyclic) nor, at
/// ω = 0, on φ, so dropping x, y, φ removes three zero eigenvalues and leaves
/// $\partial(\dot u, \dot\omega)/\partial(u, \omega) = \mathrm{diag}(0, -mav/(i_c+ma^2))$:
/// the eigenvalues 0 (a change of speed persists) and $-m a v/(i_c + m a^2)$
/// (the heading rate decays: straight motion with the blade behind is stable).
#[test]
fn sleigh_straight_motion() {
    let model = sleigh::Model::default();
    let (m, ic, a) = (2.0, 0.05, 0.3);
    for v in [0.5, 1.0, 5.0, -1.0] {
        let lin = linearize(
            &model,
            0.0,
            &[0.0, 0.0, 0.0],
            &[v, 0.0, 0.0],
            &["x", "y", "phi"],
            &LinearizeParams::default(),
        )
        .unwrap();
        let names: Vec<String> = lin.states.iter().map(ToString::to_string).collect();
        assert_eq!(names, ["x'", "phi'"], "v = {v}");
        let decay = -m * a * v / (ic + m * a * a);
        let mut re: Vec<f64> = lin.eigenvalues.iter().map(|e| e.re).collect();
        re.sort_by(f64::total_cmp);
        let expected = if decay < 0.0 {
            [decay, 0.0]
        } else {
            [0.0, decay]
        };
        for (found, want) in re.iter().zip(expected) {
            assert!(
                close(*found, want, decay.abs()),
                "v = {v}: {re:?} vs {expected:?}"
            );
        }
        assert!(lin.eigenvalues.iter().all(|e| e.im == 0.0));
        // The dropped coordinates really are decoupled here.
        assert!(lin.dropped_coupling < 1e-8, "{}", lin.dropped_coupling);
    }
}

/// Without dropping anything the sleigh has five reduced states and three more zero
/// eigenvalues.
#[test]
fn sleigh_full_reduced_state() {
    let model = sleigh::Model::default();
    let lin = linearize(
        &model,
        0.0,
        &[0.0; 3],
        &[1.0, 0.0, 0.0],
        &[],
        &LinearizeParams::default(),
    )
    .unwrap();
    assert_eq!(lin.states.len(), 5);
    assert_eq!(lin.partition, [vec![], vec!["y"], vec!["x", "phi"]]);
    let zeros = lin.eigenvalues.iter().filter(|e| e.re.abs() < 1e-7).count();
    assert_eq!(zeros, 4, "{:?}", lin.eigenvalues);
}

#[test]
fn unknown_ignorable_coordinate() {
    let model = sleigh::Model::default();
    let err = linearize(
        &model,
        0.0,
        &[0.0; 3],
        &[1.0, 0.0, 0.0],
        &["psi"],
        &LinearizeParams::default(),
    )
    .unwrap_err();
    assert!(matches!(err, LinearizeError::UnknownCoordinate { ref name, .. } if name == "psi"));
    assert_eq!(
        err.to_string(),
        "unknown coordinate `psi` among the ignorable ones, expected one of [\"x\", \"y\", \"phi\"]"
    );
}

/// A negative mass: the hanging pendulum with m = −1 has the kinetic energy
/// −(ẋ² + ẏ²)/2, negative along the rod's tangent (x at the bottom); the
/// linearization refuses it instead of describing a motion no mechanism has.
#[test]
fn a_negative_mass_is_refused() {
    let mut model = pendulum::Model::default();
    let m = model.info().parameter_index("m").unwrap();
    model.set_parameter(m, -1.0);
    let err = linearize(
        &model,
        0.0,
        &[0.0, -1.0],
        &[0.0, 0.0],
        &[],
        &LinearizeParams::default(),
    )
    .unwrap_err();
    match err {
        LinearizeError::NegativeMass { coordinate, ratio } => {
            assert_eq!(coordinate, "x");
            assert!(ratio < -0.5, "{ratio}");
        }
        other => panic!("{other}"),
    }
}
