//! Work counters are exact, `t_stop` is honoured exactly, and `set_state` does not
//! restart. Counts follow from the methods: RK4 4 evaluations per step; DOPRI5 6 per
//! attempt (FSAL) + 1 at reset (+1 for the automatic initial step); DOP853 11 per
//! attempt + 1 per accepted step (FSAL) + 3 per step for dense output + 1 at reset;
//! Adams (PECE) 2 per accepted step + 1 per rejected attempt + 1 at reset.

use pfaff::ode::samples::{Kepler, Oscillator};
use pfaff::ode::{Adams, Dop853, Dopri5, Integrator, OdeOptions, OdeSystem, Rk4};
use std::f64::consts::PI;

#[test]
fn rk4_uses_four_evaluations_per_step_and_lands_on_t_stop() {
    let mut sys = Oscillator { omega: 1.0 };
    let y0 = sys.y0();
    let mut ode = Rk4::new(2, 0.01).unwrap();
    ode.reset(&mut sys, 0.0, &y0, None).unwrap();
    ode.integrate_to(&mut sys, 1.0).unwrap();
    let s = *ode.stats();
    println!("rk4: {s:?}");
    assert_eq!(ode.t(), 1.0);
    assert_eq!(
        (s.steps, s.rhs_evals, s.rejected, s.restarts),
        (100, 400, 0, 1)
    );
    // A stop that is not a multiple of h: the last step is shortened.
    ode.integrate_to(&mut sys, 1.015).unwrap();
    assert_eq!(ode.t(), 1.015);
    assert!((ode.t() - ode.t_prev() - 0.005).abs() < 1e-12);
    assert_eq!(ode.stats().rhs_evals, 408);
}

#[test]
fn dopri5_is_fsal() {
    let mut sys = Kepler { e: 0.5 };
    let y0 = sys.y0();
    let mut ode = Dopri5::new(4, OdeOptions::with_tol(1e-8)).unwrap();
    ode.reset(&mut sys, 0.0, &y0, Some(1.0)).unwrap();
    ode.integrate_to(&mut sys, 2.0 * PI).unwrap();
    let s = *ode.stats();
    println!("dopri5 (h0 given): {s:?}");
    assert!(s.rejected > 0, "the test should exercise rejections");
    assert_eq!(s.rhs_evals, 6 * (s.steps + s.rejected) + 1);
    ode.reset(&mut sys, 0.0, &y0, None).unwrap();
    ode.integrate_to(&mut sys, 2.0 * PI).unwrap();
    let d = *ode.stats();
    let (steps, rejected) = (d.steps - s.steps, d.rejected - s.rejected);
    println!(
        "dopri5 (automatic h0): {steps} steps, {rejected} rejected, {} evaluations",
        d.rhs_evals - s.rhs_evals
    );
    assert_eq!(d.rhs_evals - s.rhs_evals, 6 * (steps + rejected) + 2);
    assert_eq!(d.restarts, 2);
}

#[test]
fn dop853_counts_with_and_without_dense_output() {
    let mut sys = Kepler { e: 0.5 };
    let y0 = sys.y0();
    for dense in [true, false] {
        let o = OdeOptions {
            dense_output: dense,
            ..OdeOptions::with_tol(1e-9)
        };
        let mut ode = Dop853::new(4, o).unwrap();
        ode.reset(&mut sys, 0.0, &y0, Some(1e-2)).unwrap();
        ode.integrate_to(&mut sys, 2.0 * PI).unwrap();
        let s = *ode.stats();
        println!("dop853 (dense {dense}): {s:?}");
        let extra = if dense { 4 } else { 1 };
        assert_eq!(
            s.rhs_evals,
            1 + 11 * (s.steps + s.rejected) + extra * s.steps
        );
        let mut out = [0.0; 4];
        assert_eq!(ode.interpolate(ode.t(), &mut out).is_ok(), dense);
    }
}

/// DOPRI5's interpolant costs no evaluation, only a pass over the stages: without
/// `dense_output` (or on a step short of `dense_output_from`) the pass is skipped, the
/// steps are bitwise those with it, and `interpolate` says the interpolant is missing.
#[test]
fn dopri5_prepares_its_interpolant_only_when_asked() {
    let mut sys = Kepler { e: 0.5 };
    let y0 = sys.y0();
    let run = |dense: bool, from: Option<f64>, sys: &mut Kepler| {
        let o = OdeOptions {
            dense_output: dense,
            ..OdeOptions::with_tol(1e-9)
        };
        let mut ode = Dopri5::new(4, o).unwrap();
        ode.dense_output_from(from);
        ode.reset(sys, 0.0, &y0, None).unwrap();
        ode.integrate_to(sys, PI).unwrap();
        let mut out = [0.0; 4];
        let interpolates = ode.interpolate(ode.t(), &mut out).is_ok();
        (ode.y().to_vec(), *ode.stats(), interpolates, out)
    };
    let (y_dense, s_dense, yes, out) = run(true, None, &mut sys);
    let (y_bare, s_bare, no, _) = run(false, None, &mut sys);
    let (y_late, _, late, _) = run(true, Some(2.0 * PI), &mut sys);
    assert!(yes && !no && !late);
    // At the end of the step the interpolant is the state, r1 + r2 = y_{n+1} (up to
    // the rounding of y + (y_{n+1} - y)).
    for (o, y) in out.iter().zip(&y_dense) {
        assert!((o - y).abs() <= 1e-14 * (1.0 + y.abs()), "{o} against {y}");
    }
    assert_eq!(y_dense, y_bare);
    assert_eq!(y_dense, y_late);
    assert_eq!(
        (s_dense.steps, s_dense.rejected, s_dense.rhs_evals),
        (s_bare.steps, s_bare.rejected, s_bare.rhs_evals)
    );
}

#[test]
fn adams_is_pece() {
    let mut sys = Kepler { e: 0.5 };
    let y0 = sys.y0();
    let mut ode = Adams::new(4, OdeOptions::with_tol(1e-9)).unwrap();
    ode.reset(&mut sys, 0.0, &y0, None).unwrap();
    ode.integrate_to(&mut sys, 2.0 * PI).unwrap();
    let s = *ode.stats();
    println!("adams: {s:?}, final order {}", ode.order());
    assert_eq!(s.rhs_evals, 1 + 2 * s.steps + s.rejected);
}

#[test]
fn steps_never_pass_t_stop() {
    let mut sys = Oscillator { omega: 1.0 };
    let y0 = sys.y0();
    let stops: Vec<f64> = (1..=40).map(|i| 0.37 * f64::from(i)).collect();
    let o = OdeOptions::with_tol(1e-9);
    let mut a = Dopri5::new(2, o.clone()).unwrap();
    let mut b = Dop853::new(2, o.clone()).unwrap();
    let mut c = Adams::new(2, o).unwrap();
    a.reset(&mut sys, 0.0, &y0, None).unwrap();
    b.reset(&mut sys, 0.0, &y0, None).unwrap();
    c.reset(&mut sys, 0.0, &y0, None).unwrap();
    for &ts in &stops {
        while a.t() < ts {
            assert!(a.step(&mut sys, Some(ts)).unwrap() <= ts);
        }
        while b.t() < ts {
            assert!(b.step(&mut sys, Some(ts)).unwrap() <= ts);
        }
        while c.t() < ts {
            assert!(c.step(&mut sys, Some(ts)).unwrap() <= ts);
        }
        assert_eq!((a.t(), b.t(), c.t()), (ts, ts, ts));
        for y in [a.y(), b.y(), c.y()] {
            assert!((y[0] - ts.cos()).abs() < 1e-7, "at {ts}: {}", y[0]);
        }
    }
    // Already at the stop: nothing happens.
    let n = c.stats().rhs_evals;
    assert_eq!(c.step(&mut sys, Some(c.t())).unwrap(), c.t());
    assert_eq!(c.stats().rhs_evals, n);
}

#[test]
fn set_state_keeps_history() {
    let mut sys = Oscillator { omega: 1.0 };
    let y0 = sys.y0();
    let o = OdeOptions::with_tol(1e-10);
    // Adams: the order survives the update and the solution stays accurate.
    let mut c = Adams::new(2, o.clone()).unwrap();
    c.reset(&mut sys, 0.0, &y0, None).unwrap();
    c.integrate_to(&mut sys, 1.0).unwrap();
    let k = c.order();
    let exact = sys.exact(1.0);
    c.set_state(&exact).unwrap();
    assert_eq!(c.order(), k);
    assert!(k > 1);
    let mut out = [0.0; 2];
    c.interpolate(1.0, &mut out).unwrap();
    assert_eq!(out, exact, "INTRP passes through the new state");
    c.integrate_to(&mut sys, 2.0).unwrap();
    assert!((c.y()[0] - 2f64.cos()).abs() < 1e-8);
    assert_eq!((c.stats().restarts, c.stats().state_updates), (1, 1));
    // DOPRI5: one extra evaluation for the stale FSAL stage.
    let mut a = Dopri5::new(2, o).unwrap();
    a.reset(&mut sys, 0.0, &y0, Some(0.1)).unwrap();
    a.step(&mut sys, None).unwrap();
    let before = *a.stats();
    let y = a.y().to_vec();
    a.set_state(&y).unwrap();
    a.step(&mut sys, None).unwrap();
    let s = a.stats();
    let rejected = s.rejected - before.rejected;
    assert_eq!(s.rhs_evals - before.rhs_evals, 6 * (1 + rejected) + 1);
}

/// Records the time of each evaluation and of each evaluation announced by
/// `step_end_next`, around the Kepler problem.
struct Announced {
    inner: Kepler,
    pending: bool,
    announced: Vec<f64>,
}

impl OdeSystem for Announced {
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), pfaff::ode::RhsError> {
        if std::mem::take(&mut self.pending) {
            self.announced.push(t);
        }
        self.inner.rhs(t, y, dy)
    }
    fn step_end_next(&mut self) {
        self.pending = true;
    }
}

/// DOP853 announces its FSAL evaluation of every accepted step, and nothing else: the
/// announced times are the accepted steps' ends. DOPRI5 announces its seventh stage,
/// the end of every attempt (accepted or not).
#[test]
fn the_explicit_pairs_announce_the_evaluation_at_the_step_end() {
    let y0 = Kepler { e: 0.5 }.y0();
    let new = || Announced {
        inner: Kepler { e: 0.5 },
        pending: false,
        announced: Vec::new(),
    };
    let mut sys = new();
    let mut ode = Dop853::new(4, OdeOptions::with_tol(1e-8)).unwrap();
    ode.reset(&mut sys, 0.0, &y0, Some(1.0)).unwrap();
    let mut ends = Vec::new();
    while ode.t() < 2.0 * PI {
        ends.push(ode.step(&mut sys, Some(2.0 * PI)).unwrap());
    }
    assert!(
        ode.stats().rejected > 0,
        "the test should exercise rejections"
    );
    assert_eq!(sys.announced, ends);
    let mut sys = new();
    let mut ode = Dopri5::new(4, OdeOptions::with_tol(1e-8)).unwrap();
    ode.reset(&mut sys, 0.0, &y0, Some(1.0)).unwrap();
    ode.integrate_to(&mut sys, 2.0 * PI).unwrap();
    let s = *ode.stats();
    assert!(s.rejected > 0);
    assert_eq!(sys.announced.len() as u64, s.steps + s.rejected);
}
