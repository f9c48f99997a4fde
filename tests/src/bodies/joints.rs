//! Every joint type and force element against finite differences at random states: the
//! constraint Jacobian, γ_h, γ_nh and the mass matrix (`MechanismExt::check_derivatives`),
//! the generalized forces against Lagrange's equations differenced from `T` and `V` plus
//! the applied forces by virtual power, and the generated poses against the point
//! positions.

use pfaff::{Mechanism, MechanismExt};

use super::models::{planar_zoo, spatial_zoo};

fn random_states(n: usize, count: usize, mut seed: u64) -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..count)
        .map(|_| {
            (
                (0..n).map(|_| rnd()).collect(),
                (0..n).map(|_| rnd()).collect(),
            )
        })
        .collect()
}

/// `Q − Q_e` against `∂T/∂q − (d/dt ∂T/∂q̇)|_{q̈=0} − ∂V/∂q`, all by central differences
/// of the generated `T` and `V`: per coordinate the residual and the expected value.
fn lagrange_residual(m: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = q.len();
    let h = 1e-5;
    let mut f = vec![0.0; n];
    let mut qe = vec![0.0; n];
    m.forces(t, q, qd, &mut f);
    m.applied_forces(t, q, qd, &mut qe);
    let tk = |q: &[f64], qd: &[f64], t: f64| m.kinetic_energy(t, q, qd);
    let (mut residual, mut expected) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..n {
        let shift = |v: &[f64], j: usize, d: f64| {
            let mut w = v.to_vec();
            w[j] += d;
            w
        };
        let dt_dq = (tk(&shift(q, i, h), qd, t) - tk(&shift(q, i, -h), qd, t)) / (2.0 * h);
        let dv_dq = (m.potential_energy(t, &shift(q, i, h))
            - m.potential_energy(t, &shift(q, i, -h)))
            / (2.0 * h);
        // p_i = ∂T/∂q̇_i; its rate along (q̇, t) at q̈ = 0.
        let p = |q: &[f64], t: f64| {
            (tk(q, &shift(qd, i, h), t) - tk(q, &shift(qd, i, -h), t)) / (2.0 * h)
        };
        let qp: Vec<f64> = q.iter().zip(qd).map(|(a, b)| a + h * b).collect();
        let qm: Vec<f64> = q.iter().zip(qd).map(|(a, b)| a - h * b).collect();
        let pdot = (p(&qp, t + h) - p(&qm, t - h)) / (2.0 * h);
        let expect = dt_dq - pdot - dv_dq;
        residual[i] = f[i] - qe[i] - expect;
        expected[i] = expect;
    }
    (residual, expected)
}

/// The coordinates of each Euler-parameter frame: the columns of its `normalization` row.
fn euler_groups(m: &dyn Mechanism) -> Vec<Vec<usize>> {
    let info = m.info();
    info.holonomic
        .iter()
        .enumerate()
        .filter(|(_, c)| c.name.ends_with(".normalization"))
        .map(|(r, _)| {
            info.holonomic_pattern
                .iter()
                .filter(|&&(row, _)| row as usize == r)
                .map(|&(_, col)| col as usize)
                .collect()
        })
        .collect()
}

/// Puts every Euler-parameter group on its manifold: `θᵀθ = 1`, `θᵀθ̇ = 0`. Off it, the
/// body-axis angular velocity `2Ēθ̇` is not the rate of a rotation, and the equations of
/// motion are only defined up to the constraint.
fn on_manifold(groups: &[Vec<usize>], q: &mut [f64], qd: &mut [f64]) {
    for g in groups {
        let norm = g.iter().map(|&i| q[i] * q[i]).sum::<f64>().sqrt();
        for &i in g {
            q[i] /= norm;
        }
        let along: f64 = g.iter().map(|&i| q[i] * qd[i]).sum();
        for &i in g {
            qd[i] -= along * q[i];
        }
    }
}

/// Removes from `r` its components along the gradients of the Euler-parameter
/// normalizations (`2θ` on each group), which the constraints' multipliers absorb: rigid
/// bodies' inertia forces come from Kane's method, whose θ-rows differ from Lagrange's
/// `∂T/∂θ − (d/dt ∂T/∂θ̇)` by such a multiple.
fn without_normalization_gradients(groups: &[Vec<usize>], q: &[f64], r: &mut [f64]) {
    for g in groups {
        let along: f64 = g.iter().map(|&i| q[i] * r[i]).sum();
        for &i in g {
            r[i] -= along * q[i];
        }
    }
}

fn check_model(m: &dyn Mechanism, seed: u64) {
    let n = m.info().nq();
    let groups = euler_groups(m);
    for (mut q, mut qd) in random_states(n, 8, seed) {
        on_manifold(&groups, &mut q, &mut qd);
        let t = 0.37;
        let d = m.check_derivatives(t, &q, &qd);
        let scale = 1e-5;
        assert!(d.holonomic_jacobian < scale, "{}: C_q {d:?}", m.info().name);
        assert!(d.holonomic_rate < scale, "{}: C_t {d:?}", m.info().name);
        assert!(d.holonomic_gamma < 1e-3, "{}: γ_h {d:?}", m.info().name);
        assert!(
            d.nonholonomic_gamma < scale,
            "{}: γ_nh {d:?}",
            m.info().name
        );
        assert!(d.mass_matrix < scale, "{}: M {d:?}", m.info().name);
        let (mut r, expected) = lagrange_residual(m, t, &q, &qd);
        without_normalization_gradients(&groups, &q, &mut r);
        let worst = r
            .iter()
            .zip(&expected)
            .fold(0.0_f64, |a, (x, e)| a.max(x.abs() / (1.0 + e.abs())));
        // The rate of `p_i` is a second central difference of `T` (step 1e-5): its
        // rounding error is about ε|T|/h² ≈ 2e-6 |T|, which a heavy model (the
        // bicycle's 85 kg rider, |T| ~ 10²) reaches.
        let kinetic = m.kinetic_energy(t, &q, &qd).abs();
        assert!(
            worst < 1e-5 * (1.0 + kinetic),
            "{}: Lagrange residual {worst:e}",
            m.info().name
        );
    }
}

#[test]
fn spatial_joints_and_forces_against_finite_differences() {
    let m = spatial_zoo::Model::default();
    let info = m.info();
    let kinds: Vec<_> = info.joints.iter().map(|j| j.kind).collect();
    use pfaff::JointKind as K;
    for k in [
        K::Spherical,
        K::Revolute,
        K::Universal,
        K::Cylindrical,
        K::Prismatic,
        K::Fixed,
        K::Distance,
        K::Driver,
        K::ZeroVelocity,
        K::RollingWheel,
    ] {
        assert!(kinds.contains(&k), "{k:?} is exercised");
    }
    // Row counts per joint as documented on `JointKind`.
    let rows: Vec<(u32, u32)> = info
        .joints
        .iter()
        .map(|j| (j.holonomic.1, j.nonholonomic.1))
        .collect();
    assert_eq!(
        rows,
        [
            (3, 0),
            (5, 0),
            (4, 0),
            (4, 0),
            (5, 0),
            (6, 0),
            (1, 0),
            (1, 0),
            (0, 1),
            (0, 1),
            (1, 2)
        ]
    );
    assert_eq!(info.holonomic[0].name, "b1.normalization");
    assert_eq!(info.holonomic[1].name, "ball.x");
    check_model(&m, 11);
}

/// The built-in spatial models, whose frames carry their angular velocities and origin
/// velocities down the frame tree and whose rolling wheels read `C_q` and `γ_h` from
/// the contact point's velocity
/// (docs/decisions/0007-kinematics-down-the-frame-tree.md): the same checks.
#[test]
fn built_in_spatial_models_against_finite_differences() {
    use pfaff_models::{bicycle, bricard, chain10, free_body, rolling_disk, spatial_four_bar};
    check_model(&bicycle::Model::default(), 3);
    check_model(&rolling_disk::Model::default(), 4);
    check_model(&bricard::Model::default(), 6);
    check_model(&spatial_four_bar::Model::default(), 7);
    check_model(&free_body::Model::default(), 8);
    check_model(&chain10::Model::default(), 9);
}

#[test]
fn planar_joints_and_forces_against_finite_differences() {
    let m = planar_zoo::Model::default();
    let rows: Vec<(u32, u32)> = m
        .info()
        .joints
        .iter()
        .map(|j| (j.holonomic.1, j.nonholonomic.1))
        .collect();
    assert_eq!(rows, [(2, 0), (2, 0), (3, 0), (1, 0), (1, 0), (0, 1)]);
    check_model(&m, 5);
}

/// The generated poses place the named point where its frame says: `origin + A ū`.
#[test]
fn poses_and_points_agree() {
    let m = spatial_zoo::Model::default();
    let info = m.info();
    for (q, _) in random_states(info.nq(), 5, 3) {
        let mut poses = vec![0.0; 12 * info.frames.len()];
        m.frame_poses(0.1, &q, &mut poses);
        let mut pts = vec![0.0; 3 * info.points.len()];
        m.point_positions(0.1, &q, &mut pts);
        let f = info.points[0].frame as usize;
        let (o, a) = (&poses[12 * f..12 * f + 3], &poses[12 * f + 3..12 * f + 12]);
        let u = [0.2, 0.0, 0.1];
        for r in 0..3 {
            let expect = o[r] + (0..3).map(|c| a[3 * r + c] * u[c]).sum::<f64>();
            assert!((pts[r] - expect).abs() < 1e-14);
        }
        // Frames given by rotations are orthonormal.
        let b2 = &poses[12 + 3..24];
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| b2[3 * k + i] * b2[3 * k + j]).sum();
                assert!((d - f64::from(u8::from(i == j))).abs() < 1e-14);
            }
        }
    }
}
