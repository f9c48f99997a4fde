//! Verification case V17 of docs/theory.md §verification (integrator), items 1, 2, 3 and 5, for
//! DOPRI5, DOP853 and the Shampine–Gordon Adams port. Item 4 (bouncing ball with event
//! location and restarts) is in `ode_events.rs`.
//!
//! Reference values: closed forms. $e^{-10} = 4.539992976248485\times10^{-5}$ (docs/theory.md
//! V17 item 1; `f64::exp(-10.0)` agrees to an ulp); the oscillator and the Kepler orbit (semi-major
//! axis 1, so period $2\pi$ by Kepler's third law) return to their initial states.

use pfaff::ode::samples::{Decay, Kepler, Oscillator};
use pfaff::ode::{Adams, Dop853, Dopri5, Integrator, OdeOptions, OdeSystem};
use std::f64::consts::PI;

/// Integrates `sys` from 0 to `t_end` with each adaptive method at tolerance `tol` and
/// hands the final state and the method's name to `check`.
fn each_method<S: OdeSystem>(
    sys: &mut S,
    y0: &[f64],
    t_end: f64,
    tol: f64,
    mut check: impl FnMut(&str, &[f64], u64),
) {
    let n = y0.len();
    let o = OdeOptions::with_tol(tol);
    let mut a = Dopri5::new(n, o.clone()).unwrap();
    a.reset(sys, 0.0, y0, None).unwrap();
    a.integrate_to(sys, t_end).unwrap();
    check("dopri5", a.y(), a.stats().rhs_evals);
    let mut b = Dop853::new(n, o.clone()).unwrap();
    b.reset(sys, 0.0, y0, None).unwrap();
    b.integrate_to(sys, t_end).unwrap();
    check("dop853", b.y(), b.stats().rhs_evals);
    let mut c = Adams::new(n, o).unwrap();
    c.reset(sys, 0.0, y0, None).unwrap();
    c.integrate_to(sys, t_end).unwrap();
    check("adams", c.y(), c.stats().rhs_evals);
}

#[test]
fn v17_1_exponential_decay() {
    let mut sys = Decay { lambda: 1.0 };
    let exact = 4.539992976248485e-5;
    assert!((exact - (-10.0f64).exp()).abs() <= 4.0 * f64::EPSILON * exact);
    each_method(&mut sys, &[1.0], 10.0, 1e-10, |name, y, evals| {
        let err = (y[0] - exact).abs();
        println!("V17.1 {name}: |y(10) - e^-10| = {err:.3e} ({evals} evaluations)");
        assert!(err <= 1e-9, "{name}: error {err:e}");
    });
}

#[test]
fn v17_2_oscillator_ten_periods() {
    let mut sys = Oscillator { omega: 1.0 };
    each_method(&mut sys, &[1.0, 0.0], 20.0 * PI, 1e-11, |name, y, evals| {
        let (e0, e1) = ((y[0] - 1.0).abs(), y[1].abs());
        println!("V17.2 {name}: |y - 1| = {e0:.3e}, |y'| = {e1:.3e} ({evals} evaluations)");
        assert!(e0 <= 1e-7 && e1 <= 1e-7, "{name}: errors {e0:e}, {e1:e}");
    });
}

#[test]
fn v17_3_kepler_one_period() {
    let mut sys = Kepler { e: 0.5 };
    let y0 = sys.y0();
    assert_eq!(y0, [0.5, 0.0, 0.0, 3f64.sqrt()]);
    each_method(&mut sys, &y0, 2.0 * PI, 1e-10, |name, y, evals| {
        let err = y
            .iter()
            .zip(&y0)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let de = (Kepler::energy(y) + 0.5).abs();
        println!("V17.3 {name}: max |y(2pi) - y0| = {err:.3e}, energy drift {de:.1e} ({evals} evaluations)");
        assert!(err <= 1e-6, "{name}: error {err:e}");
    });
}

#[test]
fn v17_5_adams_restarts_at_order_one() {
    let mut sys = Kepler { e: 0.5 };
    let mut ode = Adams::new(4, OdeOptions::with_tol(1e-10)).unwrap();
    let y0 = sys.y0();
    ode.reset(&mut sys, 0.0, &y0, None).unwrap();
    assert_eq!(ode.order(), 1);
    let mut max_order = 0;
    for _ in 0..40 {
        ode.step(&mut sys, None).unwrap();
        max_order = max_order.max(ode.order());
    }
    println!(
        "V17.5: order before restart {} (max {max_order})",
        ode.order()
    );
    assert!(
        max_order >= 8,
        "the start phase should raise the order, got {max_order}"
    );
    let (t, y) = (ode.t(), ode.y().to_vec());
    ode.reset(&mut sys, t, &y, None).unwrap();
    assert_eq!(ode.order(), 1);
    assert_eq!(ode.last_order(), 0);
    ode.step(&mut sys, None).unwrap();
    assert_eq!(
        ode.last_order(),
        1,
        "the first step after a restart is taken at order 1"
    );
    assert_eq!(
        ode.order(),
        2,
        "the start phase raises the order by one per step"
    );
    assert_eq!(ode.stats().restarts, 2);
}
