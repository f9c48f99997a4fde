//! Verification case V17 item 4 of docs/theory.md §verification: a bouncing ball, integrated by each
//! adaptive method with event location on the dense output and a restart after every
//! impact; and item 5 through it: the Adams method begins again at order 1.
//!
//! Reference (closed form, docs/models.md `bouncing_ball`): dropped from height
//! $h$ at rest with restitution $e$, the first impact is at $t_1 = \sqrt{2h/g}$ with
//! speed $v_0 = \sqrt{2gh}$, and the flight after impact $k$ lasts $2 e^k v_0 / g$, so
//! $t_{k+1} = t_1 + \frac{2 v_0}{g}\, e\,\frac{1 - e^k}{1 - e}$ and the impacts
//! accumulate at $t_\infty = \sqrt{2h/g}\,(1+e)/(1-e)$.

use pfaff::ode::{
    Adams, Crossing, Dop853, Dopri5, EventLocator, Integrator, OdeOptions, OdeSystem, Radau5,
    RhsError,
};

const G: f64 = 9.81;
const H: f64 = 1.0;
const E: f64 = 0.5;

/// Free flight: y = (height, vertical velocity).
struct Ball;
impl OdeSystem for Ball {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = y[1];
        dy[1] = -G;
        Ok(())
    }
}

fn exact_impact(k: usize) -> f64 {
    let t1 = (2.0 * H / G).sqrt();
    let v0 = (2.0 * G * H).sqrt();
    #[allow(clippy::cast_possible_truncation, clippy::cast_possible_wrap)]
    let ek = E.powi(k as i32 - 1);
    t1 + 2.0 * v0 / G * E * (1.0 - ek) / (1.0 - E)
}

/// Bounces `n` times; returns the impact times and, per restart, the order the method
/// used for the first step after it (if it reports one).
fn bounce<I: Integrator>(
    integ: &mut I,
    n: usize,
    order: impl Fn(&I) -> Option<usize>,
) -> (Vec<f64>, Vec<usize>) {
    let mut sys = Ball;
    let height = |_t: f64, y: &[f64]| y[0];
    let mut events = EventLocator::new(2, Crossing::Falling, 1e-13);
    integ.reset(&mut sys, 0.0, &[H, 0.0], None).unwrap();
    events.start(integ, &height);
    let (mut times, mut orders) = (Vec::new(), Vec::new());
    let mut after_restart = false;
    while times.len() < n {
        assert!(
            integ.t() < 10.0,
            "an impact was missed: the ball fell through the ground"
        );
        integ.step(&mut sys, Some(10.0)).unwrap();
        if after_restart {
            if let Some(k) = order(integ) {
                orders.push(k);
            }
            after_restart = false;
        }
        if let Some(t) = events.check(integ, &height).unwrap() {
            times.push(t);
            // Newton's restitution at the ground; the position does not jump.
            let v = events.state()[1];
            integ.reset(&mut sys, t, &[0.0, -E * v], None).unwrap();
            events.start(integ, &height);
            after_restart = true;
        }
    }
    (times, orders)
}

fn check_times(name: &str, times: &[f64]) {
    for (k, &t) in times.iter().enumerate() {
        let exact = exact_impact(k + 1);
        assert!(
            (t - exact).abs() < 1e-9,
            "{name}: impact {} at {t}, exact {exact}",
            k + 1
        );
    }
    let t_inf = (2.0 * H / G).sqrt() * (1.0 + E) / (1.0 - E);
    let v0 = (2.0 * G * H).sqrt();
    #[allow(clippy::cast_possible_truncation, clippy::cast_possible_wrap)]
    let remaining = 2.0 * v0 / G * E.powi(times.len() as i32) / (1.0 - E);
    let last = *times.last().unwrap();
    assert!(last < t_inf, "{name}: the impacts stay before t∞ = {t_inf}");
    assert!(
        (t_inf - last - remaining).abs() < 1e-9,
        "{name}: t∞ − t_n = {} against the geometric remainder {remaining}",
        t_inf - last
    );
}

#[test]
fn v17_4_bouncing_ball_impact_times_and_accumulation() {
    let o = OdeOptions::with_tol(1e-10);
    let (t, _) = bounce(&mut Dopri5::new(2, o.clone()).unwrap(), 25, |_| None);
    check_times("dopri5", &t);
    let (t, _) = bounce(&mut Dop853::new(2, o.clone()).unwrap(), 25, |_| None);
    check_times("dop853", &t);
    let (t, _) = bounce(&mut Radau5::new(2, o.clone()).unwrap(), 25, |_| None);
    check_times("radau5", &t);
    let (t, orders) = bounce(&mut Adams::new(2, o).unwrap(), 25, |a: &Adams| {
        Some(a.last_order())
    });
    check_times("adams", &t);
    assert_eq!(
        orders.len(),
        24,
        "one first step after each restart but the last"
    );
    assert!(
        orders.iter().all(|&k| k == 1),
        "Adams restarts at order 1: {orders:?}"
    );
}
