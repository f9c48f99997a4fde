//! Recoverable failures of the right-hand side ([`RhsError::recoverable`]) reject the
//! step attempt: every integrator retries with a shorter step, counts the rejection
//! and completes the run; a failure that persists down to the step-size underflow is
//! returned as the system's own error.

use pfaff::ode::{
    Adams, Dop853, Dopri5, Integrator, OdeError, OdeOptions, OdeStats, OdeSystem, RhsError, Rk4,
};

/// The system's error: an evaluation too far from the previous one.
#[derive(Debug, PartialEq)]
struct TooFar {
    t: f64,
}

impl std::fmt::Display for TooFar {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "evaluation at t = {} too far from the previous one",
            self.t
        )
    }
}

impl std::error::Error for TooFar {}

/// $y' = -y$, but an evaluation more than `reach` away in time from the previous one
/// fails recoverably (like K1 from a guess extrapolated too far).
struct ShortSighted {
    reach: f64,
    t_ok: f64,
    failures: u64,
}

impl ShortSighted {
    fn new(reach: f64) -> Self {
        Self {
            reach,
            t_ok: 0.0,
            failures: 0,
        }
    }
}

impl OdeSystem for ShortSighted {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let far = (t - self.t_ok).abs() > self.reach;
        self.t_ok = t;
        if far {
            self.failures += 1;
            return Err(RhsError::recoverable(TooFar { t }));
        }
        dy[0] = -y[0];
        Ok(())
    }
}

fn integrate<I: Integrator>(
    ode: &mut I,
    sys: &mut ShortSighted,
    t_end: f64,
) -> Result<f64, OdeError> {
    ode.reset(sys, 0.0, &[1.0], None)?;
    ode.integrate_to(sys, t_end)?;
    Ok(ode.y()[0])
}

fn check(name: &str, result: Result<f64, OdeError>, stats: &OdeStats, sys: &ShortSighted) {
    let y = result.unwrap_or_else(|e| panic!("{name}: {e}"));
    let exact = (-5.0_f64).exp();
    assert!((y - exact).abs() < 1e-6, "{name}: {y} vs {exact}");
    assert!(sys.failures > 0, "{name}: the step never went too far");
    // Every failure rejected one attempt (and nothing else was counted for it).
    assert!(stats.rejected >= sys.failures, "{name}: {stats:?}");
    eprintln!("{name}: {stats:?}, {} failures", sys.failures);
}

#[test]
fn every_integrator_completes_and_counts_the_rejections() {
    let opts = OdeOptions::with_tol(1e-9);
    let t_end = 5.0;
    let reach = 0.05;

    // DOPRI5 takes shorter steps (133 over the span here, 0.038 on average) and its
    // largest gap between stages (from 3h/10 to 4h/5) is half a step: a shorter reach.
    let mut sys = ShortSighted::new(0.6 * reach);
    let mut ode = Dopri5::new(1, opts.clone()).unwrap();
    let r = integrate(&mut ode, &mut sys, t_end);
    check("dopri5", r, ode.stats(), &sys);

    let mut sys = ShortSighted::new(reach);
    let mut ode = Dop853::new(1, opts.clone()).unwrap();
    let r = integrate(&mut ode, &mut sys, t_end);
    check("dop853", r, ode.stats(), &sys);

    let mut sys = ShortSighted::new(reach);
    let mut ode = Adams::new(1, opts.clone()).unwrap();
    let r = integrate(&mut ode, &mut sys, t_end);
    check("adams", r, ode.stats(), &sys);

    // RK4 with h = 0.1: the stages half a step apart sit at the edge of the reach, so
    // round-off makes some fail; those steps are halved.
    let mut sys = ShortSighted::new(reach);
    let mut ode = Rk4::new(1, 0.1).unwrap();
    let r = integrate(&mut ode, &mut sys, t_end);
    check("rk4", r, ode.stats(), &sys);
    assert_eq!(ode.stats().rejected, sys.failures);
}

/// A system that always fails recoverably after the start: the step size shrinks to
/// the underflow and the system's own error comes back, not `StepSizeTooSmall`.
#[test]
fn a_persistent_failure_returns_the_systems_error_at_underflow() {
    struct Never;
    impl OdeSystem for Never {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
            if t > 1.0 {
                return Err(RhsError::recoverable(TooFar { t }));
            }
            dy[0] = -y[0];
            Ok(())
        }
    }
    fn run<I: Integrator>(name: &str, ode: &mut I) {
        ode.reset(&mut Never, 0.0, &[1.0], Some(0.1)).unwrap();
        let e = ode.integrate_to(&mut Never, 2.0).unwrap_err();
        assert!(ode.t() <= 1.0 && ode.t() > 0.99, "{name}: {}", ode.t());
        assert!(ode.stats().rejected > 10, "{name}: {:?}", ode.stats());
        let OdeError::Rhs { source, .. } = e else {
            panic!("{name}: {e}")
        };
        assert!(source.is_recoverable());
        assert!(source.downcast_ref::<TooFar>().is_some(), "{name}");
    }
    let opts = OdeOptions::with_tol(1e-8);
    run("dopri5", &mut Dopri5::new(1, opts.clone()).unwrap());
    run("dop853", &mut Dop853::new(1, opts.clone()).unwrap());
    run("adams", &mut Adams::new(1, opts.clone()).unwrap());
    run("rk4", &mut Rk4::new(1, 0.1).unwrap());
}
