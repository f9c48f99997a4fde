//! The generated linearization (`#[mechanism(linearize)]`): its Jacobian against finite
//! differences of the generated functions at random states, the state matrix against the
//! difference path, the Whipple bicycle against its published linear model, and the
//! rolling disk's critical speed against its closed form.

use pfaff::{
    linearize_with, scatter_row_major, Eigenvalue, Linearization, LinearizeMethod, LinearizeParams,
    Mechanism, States,
};
use pfaff_models::{bicycle, pendulum, rolling_disk, sleigh};

use crate::accuracy::coverage::v5;
use crate::accuracy::util::{d1, Rng};

/// The stacked residuals of `Mechanism::linearization_jacobian` at `(q, q̇)` with the
/// inputs `u = [a; λ_h; λ_nh]`, from the model's other generated functions.
fn residuals(m: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64], u: &[f64]) -> Vec<f64> {
    let info = m.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let dense = |pattern, values: &[f64], rows| {
        let mut out = vec![0.0; rows * n];
        scatter_row_major(pattern, values, n, &mut out);
        out
    };
    let mut mv = vec![0.0; info.mass_pattern.len()];
    m.mass_matrix(t, q, &mut mv);
    let mass = dense(info.mass_pattern, &mv, n);
    let mut cv = vec![0.0; info.holonomic_pattern.len()];
    m.holonomic_jacobian(t, q, &mut cv);
    let cq = dense(info.holonomic_pattern, &cv, mh);
    let mut gv = vec![0.0; info.nonholonomic_pattern.len()];
    m.nonholonomic_matrix(t, q, &mut gv);
    let gm = dense(info.nonholonomic_pattern, &gv, mnh);
    let mut forces = vec![0.0; n];
    m.forces(t, q, qd, &mut forces);
    let (mut gh, mut gnh, mut ct, mut gb) =
        (vec![0.0; mh], vec![0.0; mnh], vec![0.0; mh], vec![0.0; mnh]);
    m.holonomic_gamma(t, q, qd, &mut gh);
    m.nonholonomic_gamma(t, q, qd, &mut gnh);
    m.holonomic_rate(t, q, &mut ct);
    m.nonholonomic_bias(t, q, &mut gb);
    let (a, lh, lnh) = (&u[..n], &u[n..n + mh], &u[n + mh..]);
    let row = |mat: &[f64], r: usize, x: &[f64]| (0..n).map(|j| mat[r * n + j] * x[j]).sum::<f64>();
    let mut out = Vec::new();
    for i in 0..n {
        let constraint_forces: f64 = (0..mh).map(|k| cq[k * n + i] * lh[k]).sum::<f64>()
            + (0..mnh).map(|k| gm[k * n + i] * lnh[k]).sum::<f64>();
        out.push(row(&mass, i, a) + constraint_forces - forces[i]);
    }
    out.extend((0..mh).map(|k| row(&cq, k, a) - gh[k]));
    out.extend((0..mnh).map(|k| row(&gm, k, a) - gnh[k]));
    out.extend((0..mh).map(|k| row(&cq, k, qd) + ct[k]));
    out.extend((0..mnh).map(|k| row(&gm, k, qd) + gb[k]));
    out
}

/// Every entry of the generated Jacobian, and every structural zero, against five-point
/// differences of [`residuals`] at random states and inputs.
fn check_jacobian(m: &dyn Mechanism, seed: u64) -> f64 {
    let info = m.info();
    let pattern = info.linearization.expect("the model emits the Jacobian");
    let n = info.nq();
    let rows = n + 2 * (info.nh() + info.nnh());
    let mut rng = Rng::new(seed);
    let mut worst = 0.0_f64;
    for _ in 0..5 {
        let t = rng.range(0.0, 2.0);
        let q = rng.vec(n, -1.0, 1.0);
        let qd = rng.vec(n, -1.0, 1.0);
        let u = rng.vec(n + info.nh() + info.nnh(), -1.0, 1.0);
        let mut values = vec![0.0; pattern.len()];
        m.linearization_jacobian(t, &q, &qd, &u, &mut values);
        let mut jac = vec![0.0; rows * 2 * n];
        scatter_row_major(pattern, &values, 2 * n, &mut jac);
        for col in 0..2 * n {
            let column: Vec<Vec<f64>> = [-2.0, -1.0, 1.0, 2.0]
                .iter()
                .map(|&k| {
                    let (mut q, mut qd) = (q.clone(), qd.clone());
                    if col < n {
                        q[col] += k * crate::accuracy::util::H;
                    } else {
                        qd[col - n] += k * crate::accuracy::util::H;
                    }
                    residuals(m, t, &q, &qd, &u)
                })
                .collect();
            for r in 0..rows {
                // d1 evaluates f at ±h, ±2h: the four residuals above, in that order.
                let fd = d1(|s| {
                    let k = (s / crate::accuracy::util::H).round() as i64;
                    column[match k {
                        -2 => 0,
                        -1 => 1,
                        1 => 2,
                        _ => 3,
                    }][r]
                });
                let got = jac[r * 2 * n + col];
                let err = (got - fd).abs() / (1.0 + fd.abs());
                assert!(
                    err < 1e-8,
                    "{}: ∂r{r}/∂{}{} = {got}, differences give {fd}",
                    info.name,
                    info.coordinates[col % n].name,
                    if col < n { "" } else { "'" }
                );
                worst = worst.max(err);
            }
        }
    }
    worst
}

#[test]
fn generated_jacobian_matches_differences() {
    let models: Vec<Box<dyn Mechanism>> = vec![
        Box::new(v5::Model::default()),
        Box::new(pendulum::Model::default()),
        Box::new(sleigh::Model::default()),
        Box::new(rolling_disk::Model::default()),
        Box::new(bicycle::Model::default()),
    ];
    for (k, m) in models.iter().enumerate() {
        let worst = check_jacobian(m.as_ref(), 11 + k as u64);
        eprintln!("{}: worst relative error {worst:.1e}", m.info().name);
    }
}

/// The consistent operating point of upright straight running of the bicycle at
/// `speed`, linearized by `method`.
fn bicycle_at(speed: f64, method: LinearizeMethod) -> Linearization {
    let model = bicycle::Model::default();
    let info = model.info();
    let n = info.nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    let idx = |name| info.coordinate_index(name).expect("coordinate");
    let r_r = model.params.r_r;
    let r_f = model.params.r_f;
    q[idx("z")] = -r_r;
    qd[idx("x")] = speed;
    qd[idx("theta_r")] = -speed / r_r;
    qd[idx("theta_f")] = -speed / r_f;
    linearize_with(
        &model,
        0.0,
        &q,
        &qd,
        States {
            ignorable: &["x", "y", "psi", "theta_r", "theta_f"],
            velocities: &["phi", "delta", "theta_r"],
        },
        &LinearizeParams {
            method,
            ..LinearizeParams::default()
        },
    )
    .expect("the bicycle linearizes")
}

/// The lean/steer block `[φ, δ, φ', δ']` of a bicycle linearization.
fn lean_steer(lin: &Linearization) -> [[f64; 4]; 4] {
    let find = |name: &str, velocity: bool| {
        lin.states
            .iter()
            .position(|s| s.coordinate == name && s.velocity == velocity)
            .unwrap_or_else(|| panic!("state {name} in {:?}", lin.states))
    };
    let k = [
        find("phi", false),
        find("delta", false),
        find("phi", true),
        find("delta", true),
    ];
    let mut out = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            out[i][j] = lin.entry(k[i], k[j]);
        }
    }
    out
}

/// The published linear model of Meijaard, Papadopoulos, Ruina & Schwab (2007), Proc.
/// R. Soc. A 463, eq. (A 20)–(A 23) as quoted in docs/models.md:
/// `[0 I; −M⁻¹(g K0 + v² K2) −v M⁻¹ C1]`.
fn published(v: f64) -> [[f64; 4]; 4] {
    let m = [
        [80.81722, 2.319_413_322_087_09],
        [2.319_413_322_087_09, 0.297_841_881_996_86],
    ];
    let c1 = [
        [0.0, 33.866_413_914_924_94],
        [-0.850_356_414_569_78, 1.685_403_973_975_60],
    ];
    let k0 = [
        [-80.95, -2.599_516_852_498_72],
        [-2.599_516_852_498_72, -0.803_294_884_586_18],
    ];
    let k2 = [[0.0, 76.597_345_895_732_22], [0.0, 2.654_315_237_946_04]];
    let g = 9.81;
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = [
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ];
    let mul = |a: [[f64; 2]; 2]| {
        let mut out = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                out[i][j] = -(inv[i][0] * a[0][j] + inv[i][1] * a[1][j]);
            }
        }
        out
    };
    let stiff = mul([
        [
            g * k0[0][0] + v * v * k2[0][0],
            g * k0[0][1] + v * v * k2[0][1],
        ],
        [
            g * k0[1][0] + v * v * k2[1][0],
            g * k0[1][1] + v * v * k2[1][1],
        ],
    ]);
    let damp = mul([[v * c1[0][0], v * c1[0][1]], [v * c1[1][0], v * c1[1][1]]]);
    [
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
        [stiff[0][0], stiff[0][1], damp[0][0], damp[0][1]],
        [stiff[1][0], stiff[1][1], damp[1][0], damp[1][1]],
    ]
}

#[test]
fn bicycle_lean_steer_block_matches_the_published_matrices() {
    let mut worst = 0.0_f64;
    for v in 0..=10 {
        let v = f64::from(v);
        let lin = bicycle_at(v, LinearizeMethod::Generated);
        assert_eq!(lin.method, LinearizeMethod::Generated);
        let got = lean_steer(&lin);
        let want = published(v);
        for i in 0..4 {
            for j in 0..4 {
                let err = (got[i][j] - want[i][j]).abs();
                worst = worst.max(err);
                assert!(
                    err < 1e-10,
                    "v = {v}: A[{i}][{j}] = {}, published {}",
                    got[i][j],
                    want[i][j]
                );
            }
        }
    }
    eprintln!("bicycle lean/steer block, v = 0…10: worst difference {worst:.1e}");
}

/// Eigenvalues of a 4 × 4 matrix, sorted by real part, then imaginary part.
fn eigen4(a: &[[f64; 4]; 4]) -> Vec<Eigenvalue> {
    let m = faer::Mat::<f64>::from_fn(4, 4, |i, j| a[i][j]);
    let mut e: Vec<Eigenvalue> = m
        .eigenvalues()
        .expect("eigenvalues")
        .iter()
        .map(|z| Eigenvalue { re: z.re, im: z.im })
        .collect();
    e.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    e
}

#[test]
fn bicycle_eigenvalues_at_5_m_per_s() {
    // docs/models.md (Meijaard et al. 2007, Table 2): v = 5 m/s.
    let want = [
        (-14.078_389_692_798_22, 0.0),
        (-0.775_341_882_195_85, -4.464_867_713_788_23),
        (-0.775_341_882_195_85, 4.464_867_713_788_23),
        (-0.322_866_429_004_09, 0.0),
    ];
    let lin = bicycle_at(5.0, LinearizeMethod::Generated);
    let got = eigen4(&lean_steer(&lin));
    for (g, (re, im)) in got.iter().zip(want) {
        assert!(
            (g.re - re).abs() < 1e-10 && (g.im - im).abs() < 1e-10,
            "{g:?} vs {re} {im}i"
        );
    }
    // The full reduced system adds the forward speed, neutral: one more zero.
    assert_eq!(lin.eigenvalues.len(), 5);
    assert!(lin
        .eigenvalues
        .iter()
        .any(|e| e.re.abs() < 1e-12 && e.im == 0.0));
}

#[test]
fn generated_and_difference_state_matrices_agree() {
    for v in [0.5, 3.0, 6.0] {
        let g = bicycle_at(v, LinearizeMethod::Generated);
        let d = bicycle_at(v, LinearizeMethod::Differences);
        assert_eq!(g.states, d.states);
        let diff = g
            .state_matrix
            .iter()
            .zip(&d.state_matrix)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            diff <= 10.0 * d.error_estimate + 1e-8,
            "v = {v}: generated and differences differ by {diff:.1e} (estimate {:.1e})",
            d.error_estimate
        );
    }
}

/// The rolling disk's upright rolling at `speed`, linearized with the generated
/// derivatives.
fn disk_at(speed: f64) -> Linearization {
    let model = rolling_disk::Model::default();
    let info = model.info();
    let n = info.nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    let idx = |name| info.coordinate_index(name).expect("coordinate");
    let r = model.params.radius;
    q[idx("z")] = r;
    qd[idx("x")] = speed;
    qd[idx("theta")] = speed / r;
    let lin = linearize_with(
        &model,
        0.0,
        &q,
        &qd,
        States {
            ignorable: &["x", "y", "psi", "theta"],
            velocities: &["psi", "phi", "theta"],
        },
        &LinearizeParams::default(),
    )
    .expect("the disk linearizes");
    assert_eq!(lin.method, LinearizeMethod::Generated);
    lin
}

/// The sum of the principal 2 × 2 minors of the state matrix: with the two neutral
/// modes (the spin rate and the heading) the characteristic polynomial is
/// `s² (s² + a₂)`, so `a₂` is the product of the lean pair, `−σ²` while it is real and
/// unstable, `+ω²` while it oscillates. It crosses zero linearly at the critical speed,
/// where the eigenvalues themselves meet with a square-root sensitivity.
fn lean_pair_product(lin: &Linearization) -> f64 {
    let d = lin.states.len();
    let mut a2 = 0.0;
    for i in 0..d {
        for j in i + 1..d {
            a2 += lin.entry(i, i) * lin.entry(j, j) - lin.entry(i, j) * lin.entry(j, i);
        }
    }
    a2
}

#[test]
fn rolling_disk_critical_speed() {
    // Routh's condition for upright rolling of a disk with spin rate Ω = v / r: the
    // lean obeys (A + m r²) φ'' + (C (C + m r²) Ω² / A − m g r) φ = 0 (Neĭmark &
    // Fufaev, Dynamics of Nonholonomic Systems, ch. III), stable iff
    // Ω² > m g r A / (C (C + m r²)); for a thin uniform disk, A = m r²/4 and
    // C = m r²/2, that is v² > g r / 3.
    let model = rolling_disk::Model::default();
    let (g, r) = (model.params.g, model.params.radius);
    let critical = (g * r / 3.0).sqrt();
    let growth = |v: f64| {
        disk_at(v)
            .eigenvalues
            .iter()
            .map(|e| e.re)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    assert!(growth(0.5 * critical) > 1e-1, "slow rolling is unstable");
    let fast = disk_at(2.0 * critical);
    assert_eq!(fast.states.len(), 4);
    assert!(
        fast.eigenvalues.iter().all(|e| e.re.abs() < 1e-9),
        "fast rolling oscillates: {:?}",
        fast.eigenvalues
    );
    assert!(lean_pair_product(&disk_at(0.5 * critical)) < 0.0);
    assert!(lean_pair_product(&fast) > 0.0);
    let (mut lo, mut hi) = (0.5 * critical, 2.0 * critical);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if lean_pair_product(&disk_at(mid)) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let found = 0.5 * (lo + hi);
    eprintln!("rolling disk: critical speed {found:.12} vs √(g r/3) = {critical:.12}");
    assert!((found - critical).abs() < 1e-10, "{found} vs {critical}");
}
