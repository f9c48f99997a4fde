//! A plain simulation for the tests (the simulation layer is not used here): the state
//! $y = (q, \dot q)$ integrated by DOP853, with $\ddot q$ either from the augmented
//! solve of `Dynamics` (with multipliers) or from $M\ddot q = Q$ alone (Lagrange's
//! equations of the second kind in all redundant coordinates, (S2-22)).

use pfaff::ode::{Dop853, Integrator, OdeOptions, OdeSystem, RhsError};
use pfaff::{Dynamics, DynamicsParams, Mechanism, MechanismExt, Workspace};

/// One recorded state.
#[derive(Clone, Debug)]
pub struct Step {
    pub t: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// Multipliers of the augmented solve at this state (empty for the unconstrained
    /// system).
    pub lambda: Vec<f64>,
}

struct System<'a, M: ?Sized> {
    mech: &'a M,
    ws: Workspace,
    dynamics: Option<Dynamics>,
    lambda: Vec<f64>,
}

impl<M: Mechanism + ?Sized> System<'_, M> {
    fn accelerations(&mut self, t: f64, y: &[f64], qdd: &mut [f64]) -> Result<(), RhsError> {
        let n = self.mech.info().nq();
        let (q, qd) = y.split_at(n);
        match self.dynamics.as_mut() {
            Some(d) => {
                d.accelerations(self.mech, &mut self.ws, t, q, qd, qdd, &mut self.lambda)
                    .map_err(RhsError::new)?;
            }
            None => {
                // M q̈ = Q by Gaussian elimination (tiny dense systems).
                let mut m = vec![0.0; n * n];
                self.mech.mass_matrix_dense_inplace(t, q, &mut m);
                self.mech.forces(t, q, qd, qdd);
                solve(&mut m, qdd);
            }
        }
        Ok(())
    }
}

impl<M: Mechanism + ?Sized> OdeSystem for System<'_, M> {
    fn dim(&self) -> usize {
        2 * self.mech.info().nq()
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.mech.info().nq();
        dy[..n].copy_from_slice(&y[n..]);
        self.accelerations(t, y, &mut dy[n..])
    }
}

/// Solves the dense row-major `A x = b` in place (partial pivoting).
pub fn solve(a: &mut [f64], b: &mut [f64]) {
    let n = b.len();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
            .unwrap();
        for j in 0..n {
            a.swap(k * n + j, p * n + j);
        }
        b.swap(k, p);
        for i in k + 1..n {
            let f = a[i * n + k] / a[k * n + k];
            for j in k..n {
                a[i * n + j] -= f * a[k * n + j];
            }
            b[i] -= f * b[k];
        }
    }
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|j| a[k * n + j] * b[j]).sum();
        b[k] = (b[k] - s) / a[k * n + k];
    }
}

/// Integrates from `(t0, q0, q̇0)` to `t_end` with DOP853 at tolerance `tol`, recording
/// every accepted step (at most 0.02 apart, and the start). With `constrained`, the multipliers are part of
/// the solve and recorded.
pub fn simulate<M: Mechanism + ?Sized>(
    mech: &M,
    constrained: bool,
    t0: f64,
    q0: &[f64],
    qd0: &[f64],
    t_end: f64,
    tol: f64,
) -> Vec<Step> {
    let info = mech.info();
    let n = info.nq();
    let m = info.nh() + info.nnh();
    let mut sys = System {
        mech,
        ws: Workspace::new(info).unwrap(),
        dynamics: constrained.then(|| Dynamics::new(info, DynamicsParams::default()).unwrap()),
        lambda: vec![0.0; m],
    };
    let mut y0 = q0.to_vec();
    y0.extend_from_slice(qd0);
    // A bounded step so that the record is dense enough to watch λ along the motion.
    let opts = OdeOptions {
        h_max: 0.02,
        ..OdeOptions::with_tol(tol)
    };
    let mut ode = Dop853::new(2 * n, opts).unwrap();
    ode.reset(&mut sys, t0, &y0, None).unwrap();
    let mut steps = Vec::new();
    let mut dy = vec![0.0; 2 * n];
    let mut record = |sys: &mut System<'_, M>, t: f64, y: &[f64]| {
        sys.rhs(t, y, &mut dy).unwrap();
        steps.push(Step {
            t,
            q: y[..n].to_vec(),
            qd: y[n..].to_vec(),
            lambda: if constrained {
                sys.lambda.clone()
            } else {
                Vec::new()
            },
        });
    };
    record(&mut sys, t0, &y0);
    while ode.t() < t_end {
        let t = ode.step(&mut sys, Some(t_end)).unwrap();
        let y = ode.y().to_vec();
        record(&mut sys, t, &y);
    }
    steps
}

/// The samples of a recorded run, as `(t, q, q̇)`.
pub fn samples(steps: &[Step]) -> impl Iterator<Item = (f64, &[f64], &[f64])> + '_ {
    steps.iter().map(|s| (s.t, &s.q[..], &s.qd[..]))
}
