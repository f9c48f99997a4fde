//! Simulations for the tests, through `pfaff::sim` from a given state: index 1 without
//! stabilization ($\ddot q$ and $\lambda$ from the augmented solve), or Lagrange's
//! equations of the second kind in all redundant coordinates without multipliers,
//! $M\ddot q = Q$ ((S2-22), [`Formulation::Unconstrained`]), integrated by DOP853.

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::Mechanism;

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

/// Integrates from `(t0, q0, q̇0)` (taken as given: consistent, or unconstrained) to
/// `t_end` with DOP853 at tolerance `tol`, recording every accepted step (at most 0.02
/// apart, and the start). With `constrained`, the multipliers are part of the solve and
/// recorded.
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
    let form = if constrained {
        Formulation::Baumgarte {
            alpha: 0.0,
            beta: 0.0,
        }
    } else {
        Formulation::Unconstrained
    };
    // Every coordinate and velocity given: checked against the constraints and kept as
    // it is (or, unconstrained, just kept).
    let mut sim = Simulation::new(mech)
        .formulation(form)
        .integrator(Method::Dop853)
        .tolerances(tol, tol)
        .start_time(t0)
        .max_step(0.02)
        .output_steps();
    for (s, (&q, &qd)) in info.coordinates.iter().zip(q0.iter().zip(qd0)) {
        sim = sim
            .prescribe_coordinate(s.name, q)
            .prescribe_velocity(s.name, qd);
    }
    let run = sim.run(t_end).expect("the test simulation");
    let tr = &run.trajectory;
    (0..tr.len())
        .map(|i| Step {
            t: tr.t[i],
            q: tr.q(i).to_vec(),
            qd: tr.qd(i).to_vec(),
            lambda: if constrained {
                tr.lambda(i).to_vec()
            } else {
                Vec::new()
            },
        })
        .collect()
}

/// The samples of a recorded run, as `(t, q, q̇)`.
pub fn samples(steps: &[Step]) -> impl Iterator<Item = (f64, &[f64], &[f64])> + '_ {
    steps.iter().map(|s| (s.t, &s.q[..], &s.qd[..]))
}
