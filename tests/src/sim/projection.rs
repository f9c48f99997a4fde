//! The projection after an accepted step (`Formulation::Projection`, `StateSpace::keep`)
//! on states off the constraint manifold by an integrator's drift: the corrected state
//! meets $C = 0$ to the Newton tolerance and $J\dot q + [C_t; g] = 0$ to round-off, and
//! the correction has the metric it is documented with. With the model's generated solve
//! (`LinearSolver::Auto`) the velocity change is the one of least kinetic energy,
//! $M\Delta\dot q \in \operatorname{range} J^\mathsf{T}$ (the first block row of (E31)
//! with the right-hand side $[0; -(J\dot q + [C_t; g])]$, docs/theory.md §augmented); with the general
//! path (`LinearSolver::Dense`) it is the orthogonal one,
//! $\Delta\dot q \in \operatorname{range} J^\mathsf{T}$. The position correction has the
//! same metric to first order in its size (its Newton updates take $J$ at successive
//! points).

use pfaff::sim::{Formulation, StateSpace};
use pfaff::{LinearSolver, Mechanism};

use crate::accuracy::util::Rng;
use crate::states::moving_state;
fn norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0_f64, |s, x| s.max(x.abs()))
}

/// The dense $M$ (row-major) at `q`.
fn mass(model: &dyn Mechanism, t: f64, q: &[f64]) -> Vec<f64> {
    let info = model.info();
    let n = info.nq();
    let mut values = vec![0.0; info.mass_pattern.len()];
    model.mass_matrix(t, q, &mut values);
    let mut m = vec![0.0; n * n];
    for (&(r, c), v) in info.mass_pattern.iter().zip(&values) {
        m[r as usize * n + c as usize] = *v;
    }
    m
}

/// $C$, the dense $J = [C_q; G]$ (row-major) and the velocity residuals
/// $J\dot q + [C_t; g]$ at `(q, qd)`.
fn constraints(
    model: &dyn Mechanism,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let info = model.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let mut c = vec![0.0; mh];
    model.holonomic(t, q, &mut c);
    let mut cq = vec![0.0; info.holonomic_pattern.len()];
    model.holonomic_jacobian(t, q, &mut cq);
    let mut g = vec![0.0; info.nonholonomic_pattern.len()];
    model.nonholonomic_matrix(t, q, &mut g);
    let mut bias = vec![0.0; mnh];
    model.nonholonomic_bias(t, q, &mut bias);
    let mut ct = vec![0.0; mh];
    model.holonomic_rate(t, q, &mut ct);
    let mut jac = vec![0.0; (mh + mnh) * n];
    for (&(r, col), v) in info.holonomic_pattern.iter().zip(&cq) {
        jac[r as usize * n + col as usize] = *v;
    }
    for (&(r, col), v) in info.nonholonomic_pattern.iter().zip(&g) {
        jac[(mh + r as usize) * n + col as usize] = *v;
    }
    let mut vel: Vec<f64> = ct.into_iter().chain(bias).collect();
    for (i, v) in vel.iter_mut().enumerate() {
        *v += jac[i * n..(i + 1) * n]
            .iter()
            .zip(qd)
            .map(|(a, b)| a * b)
            .sum::<f64>();
    }
    (c, jac, vel)
}

/// How far `w` is from the range of $A^\mathsf{T}$ ($A$ is `m × n`, row-major):
/// $\lVert w - A^\mathsf{T}\mu\rVert_\infty / \lVert w\rVert_\infty$ with $\mu$ the
/// least-squares fit, from the normal equations $A A^\mathsf{T}\mu = A w$ (Gaussian
/// elimination with partial pivoting).
fn off_range(a: &[f64], m: usize, n: usize, w: &[f64]) -> f64 {
    let mut g = vec![0.0; m * (m + 1)];
    for i in 0..m {
        for j in 0..m {
            g[i * (m + 1) + j] = (0..n).map(|k| a[i * n + k] * a[j * n + k]).sum();
        }
        g[i * (m + 1) + m] = (0..n).map(|k| a[i * n + k] * w[k]).sum();
    }
    for col in 0..m {
        let pivot = (col..m)
            .max_by(|&x, &y| {
                g[x * (m + 1) + col]
                    .abs()
                    .total_cmp(&g[y * (m + 1) + col].abs())
            })
            .expect("a row");
        for k in 0..=m {
            g.swap(col * (m + 1) + k, pivot * (m + 1) + k);
        }
        for r in 0..m {
            if r != col {
                let f = g[r * (m + 1) + col] / g[col * (m + 1) + col];
                for k in col..=m {
                    g[r * (m + 1) + k] -= f * g[col * (m + 1) + k];
                }
            }
        }
    }
    let mu: Vec<f64> = (0..m)
        .map(|i| g[i * (m + 1) + m] / g[i * (m + 1) + i])
        .collect();
    let residual: Vec<f64> = (0..n)
        .map(|k| w[k] - (0..m).map(|i| a[i * n + k] * mu[i]).sum::<f64>())
        .collect();
    norm(&residual) / norm(w).max(1e-300)
}

/// What one projection did: the corrected state, and how far each correction is from
/// the range of $J^\mathsf{T}$ in the metric of $M$ and in the Euclidean one.
struct Projected {
    q: Vec<f64>,
    qd: Vec<f64>,
    position_off: (f64, f64),
    velocity_off: (f64, f64),
}

fn project(
    model: &dyn Mechanism,
    solver: LinearSolver,
    t: f64,
    (q0, qd0): (&[f64], &[f64]),
    y: &[f64],
) -> Projected {
    let info = model.info();
    let (n, m) = (info.nq(), info.nh() + info.nnh());
    let mut sys = StateSpace::new(model, Formulation::Projection, 1e-8, 1e-8)
        .and_then(|s| s.linear_solver(solver))
        .expect("a system");
    sys.start(t, q0, qd0).expect("a consistent start");
    sys.keep(t, y).expect("a projection");
    let (q, qd) = (sys.q().to_vec(), sys.qd().to_vec());
    let (qi, qdi) = y.split_at(n);
    let mass_in = mass(model, t, qi);
    let times_mass = |d: &[f64]| -> Vec<f64> {
        (0..n)
            .map(|i| (0..n).map(|j| mass_in[i * n + j] * d[j]).sum())
            .collect()
    };
    let dq: Vec<f64> = q.iter().zip(qi).map(|(a, b)| a - b).collect();
    let dqd: Vec<f64> = qd.iter().zip(qdi).map(|(a, b)| a - b).collect();
    let (_, jac_in, _) = constraints(model, t, qi, qdi);
    let (_, jac, _) = constraints(model, t, &q, &qd);
    let mh = info.nh();
    Projected {
        position_off: (
            off_range(&jac_in, m, n, &times_mass(&dq)),
            off_range(&jac_in[..mh * n], mh, n, &dq),
        ),
        velocity_off: (
            off_range(&jac, m, n, &times_mass(&dqd)),
            off_range(&jac, m, n, &dqd),
        ),
        q,
        qd,
    }
}

#[test]
fn projection_meets_the_constraints_in_the_metric_it_documents() {
    // Planar and spatial, relative and absolute coordinates, non-holonomic rows
    // (bicycle, rolling_disk), Euler parameters (chain10), a deformable body
    // (flexible_crank); every one has a generated solve.
    for (name, t, seed) in [
        ("andrews", 0.01, 1),
        ("car_axis", 0.5, 2),
        ("slider_crank", 0.3, 3),
        ("bicycle", 0.5, 4),
        ("rolling_disk", 0.5, 5),
        ("chain10", 0.05, 6),
        ("flexible_crank", 0.05, 7),
    ] {
        let entry = pfaff_models::find(name).expect("a built-in model");
        let model = (entry.make)();
        let model = model.as_ref();
        let info = model.info();
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        let (q0, qd0) = moving_state(model, t);
        // Off the manifold as an accepted step of an integrator at rtol 1e-8 leaves
        // it: positions and velocities moved by about 1e-8 of their size.
        let mut rng = Rng::new(seed);
        let (sq, sv) = (norm(&q0).max(1.0), norm(&qd0).max(1.0));
        let mut y: Vec<f64> = q0.iter().chain(&qd0).copied().collect();
        for (i, v) in y.iter_mut().enumerate() {
            *v += 1e-8 * if i < n { sq } else { sv } * rng.range(-1.0, 1.0);
        }
        let m0 = mass(model, t, &q0);
        let uniform = (0..n * n).all(|k| {
            let (i, j) = (k / n, k % n);
            m0[k] == if i == j { m0[0] } else { 0.0 }
        });
        // Auto: the generated solve, in the metric of M; Sparse: the runtime's sparse
        // LDLᵀ (what large models without a generated solve take), the same metric;
        // Dense: no solve without pivoting, the orthogonal projection.
        for solver in [
            LinearSolver::Auto,
            LinearSolver::Sparse,
            LinearSolver::Dense,
        ] {
            let p = project(model, solver, t, (&q0, &qd0), &y);
            let (c, jac, vel) = constraints(model, t, &p.q, &p.qd);
            for (i, ci) in c.iter().enumerate() {
                let row = norm(&jac[i * n..(i + 1) * n]);
                assert!(
                    ci.abs() <= 1e-13 * row * sq,
                    "{name} {solver:?}: constraint {i} {ci:.1e} after the projection"
                );
            }
            for (i, v) in vel.iter().enumerate() {
                let row = norm(&jac[i * n..(i + 1) * n]);
                assert!(
                    v.abs() <= 1e-12 * row * sv,
                    "{name} {solver:?}: velocity constraint {i} {v:.1e} after the projection"
                );
            }
            // The metric: exact for the velocities, to first order in the correction
            // (about 1e-8 relative) for the positions.
            let (position, velocity) = match solver {
                LinearSolver::Auto | LinearSolver::Sparse => (p.position_off.0, p.velocity_off.0),
                _ => (p.position_off.1, p.velocity_off.1),
            };
            assert!(
                velocity <= 1e-6 && position <= 1e-5,
                "{name} {solver:?}: corrections off the range of Jᵀ in their metric by \
                 {velocity:.1e} (velocities), {position:.1e} (positions)"
            );
            // and not in the other one, where the two differ: not where M is a multiple
            // of the identity (car_axis' equal point masses) or the constraints leave
            // no freedom (slider_crank is driven: every vector is in the range).
            if solver != LinearSolver::Dense && !uniform && m < n {
                assert!(
                    p.velocity_off.1 > 1e-3,
                    "{name}: the velocity correction is also orthogonal ({:.1e})",
                    p.velocity_off.1
                );
            }
        }
    }
}
