//! `flexible_crank` against the equations of the Test Set for IVP Solvers ("crank",
//! Simeon's slider crank with an elastic connecting rod) as docs/models.md
//! transcribes them; the run to t = 0.1 with RADAU5; the rigid limit.

use pfaff::sim::{Formulation, Method, Run, Simulation};
use pfaff::{Mechanism, MechanismExt};
use pfaff_models::{flexible_crank, flexible_crank_shapes};

use super::models::rigid_crank;
use super::{max_abs, max_diff, Rng};

/// The test set's data (docs/models.md, "flexible_crank"), π written 3.1415927.
struct TestSet {
    m1: f64,
    m2: f64,
    m3: f64,
    l1: f64,
    l2: f64,
    j1: f64,
    j2: f64,
    rho: f64,
    grav: f64,
    mq: [[f64; 4]; 4],
    kq: [[f64; 4]; 4],
    bq: [[f64; 4]; 4],
    c1: [f64; 4],
    c2: [f64; 4],
    c12: [f64; 4],
    c21: [f64; 4],
}

fn test_set(grav: f64) -> TestSet {
    // The test set's rounded π, on purpose (docs/models.md).
    #[allow(clippy::approx_constant)]
    let pi = 3.1415927;
    test_set_with(grav, pi, 15.0)
}

/// The closed-form integrals of the rod's shape functions (ξ = x/l2, lateral
/// `sin πξ, sin 2πξ`, axial `4ξ(1−ξ), 2ξ² − ξ`), by hand: `∫ sin² kπξ = ½`;
/// `∫ (4ξ(1−ξ))² = 8/15`, `∫ 4ξ(1−ξ)(2ξ²−ξ) = 1/15`, `∫ (2ξ²−ξ)² = 2/15` (the test
/// set's 8, 1, 2 are 15 times these: docs/models.md); `∫ 4ξ(1−ξ) = 2/3`,
/// `∫ (2ξ²−ξ) = 1/6`, `∫ sin πξ = 2/π`, `∫ ξ·4ξ(1−ξ) = 1/3`, `∫ ξ(2ξ²−ξ) = 1/6`,
/// `∫ ξ sin πξ = 1/π`, `∫ ξ sin 2πξ = −1/(2π)`, `∫ sin πξ · 4ξ(1−ξ) = 16/π³`,
/// `∫ sin πξ (2ξ²−ξ) = 1/π − 8/π³`, `∫ sin 2πξ (2ξ²−ξ) = 1/(2π)`, `∫ sin 2πξ · 4ξ(1−ξ) = 0`;
/// the strain energy `½∫(EA u'² + EI w''²) dx` gives the test set's `KQ` with π exact.
/// These are the test set's `c1, c2, c12, c21, BQ, KQ` with π exact and `MQ`'s axial
/// block divided by 15.
fn closed_form(grav: f64) -> TestSet {
    test_set_with(grav, std::f64::consts::PI, 1.0)
}

fn test_set_with(grav: f64, pi: f64, axial: f64) -> TestSet {
    let (ee, bb, hh, rho, l2) = (2.0e11, 0.008, 0.008, 7870.0, 0.30);
    let facm = rho * bb * hh * l2;
    let fack = ee * bb * hh / l2;
    let facb = bb * hh * l2;
    let mut mq = [[0.0; 4]; 4];
    mq[0][0] = 0.5 * facm;
    mq[1][1] = 0.5 * facm;
    mq[2][2] = 8.0 / 15.0 * axial * facm;
    mq[2][3] = axial / 15.0 * facm;
    mq[3][2] = axial / 15.0 * facm;
    mq[3][3] = 2.0 / 15.0 * axial * facm;
    let mut kq = [[0.0; 4]; 4];
    kq[0][0] = fack * pi.powi(4) / 24.0 * (hh / l2).powi(2);
    kq[1][1] = fack * pi.powi(4) * 2.0 / 3.0 * (hh / l2).powi(2);
    kq[2][2] = 16.0 / 3.0 * fack;
    kq[2][3] = -8.0 / 3.0 * fack;
    kq[3][2] = -8.0 / 3.0 * fack;
    kq[3][3] = 7.0 / 3.0 * fack;
    let mut bq = [[0.0; 4]; 4];
    bq[0][2] = -16.0 * facb / pi.powi(3);
    bq[0][3] = facb * (8.0 / pi.powi(3) - 1.0 / pi);
    bq[1][3] = 0.5 * facb / pi;
    bq[2][0] = 16.0 * facb / pi.powi(3);
    bq[3][0] = -facb * (8.0 / pi.powi(3) - 1.0 / pi);
    bq[3][1] = -0.5 * facb / pi;
    TestSet {
        m1: 0.36,
        m2: 0.151104,
        m3: 0.075552,
        l1: 0.15,
        l2,
        j1: 0.002727,
        j2: 0.0045339259,
        rho,
        grav,
        mq,
        kq,
        bq,
        c1: [0.0, 0.0, 2.0 / 3.0 * facb, 1.0 / 6.0 * facb],
        c2: [2.0 / pi * facb, 0.0, 0.0, 0.0],
        c12: [0.0, 0.0, 1.0 / 3.0 * l2 * facb, 1.0 / 6.0 * l2 * facb],
        c21: [1.0 / pi * l2 * facb, -0.5 / pi * l2 * facb, 0.0, 0.0],
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn mv(m: &[[f64; 4]; 4], v: &[f64]) -> [f64; 4] {
    let mut o = [0.0; 4];
    for i in 0..4 {
        o[i] = dot(&m[i], v);
    }
    o
}

fn mtv(m: &[[f64; 4]; 4], v: &[f64]) -> [f64; 4] {
    let mut o = [0.0; 4];
    for i in 0..4 {
        o[i] = (0..4).map(|j| m[j][i] * v[j]).sum();
    }
    o
}

impl TestSet {
    /// `AM` (7 × 7, row-major).
    fn am(&self, y: &[f64]) -> Vec<f64> {
        let (p1, p2, q) = (y[0], y[1], &y[3..7]);
        let (s12, c12) = (p1 - p2).sin_cos();
        let r = self.rho;
        let mut a = vec![0.0; 49];
        a[0] = self.j1 + self.m2 * self.l1 * self.l1;
        a[1] = 0.5 * self.l1 * self.l2 * self.m2 * c12
            + r * self.l1 * (s12 * dot(&self.c2, q) + c12 * dot(&self.c1, q));
        a[8] = self.j2 + dot(q, &mv(&self.mq, q)) + 2.0 * r * dot(&self.c12, q);
        a[16] = self.m3;
        let bt = mtv(&self.bq, q);
        for i in 0..4 {
            a[3 + i] = r * self.l1 * (-s12 * self.c1[i] + c12 * self.c2[i]);
            a[7 + 3 + i] = r * self.c21[i] + r * bt[i];
            for j in 0..4 {
                a[(3 + j) * 7 + 3 + i] = self.mq[j][i];
            }
        }
        for i in 0..7 {
            for j in 0..i {
                a[i * 7 + j] = a[j * 7 + i];
            }
        }
        a
    }

    /// `F` (7).
    fn f(&self, y: &[f64], v: &[f64]) -> Vec<f64> {
        let (p1, p2, q, qd) = (y[0], y[1], &y[3..7], &v[3..7]);
        let (v1, v2) = (v[0], v[1]);
        let (s12, c12) = (p1 - p2).sin_cos();
        let (r, g, l1, l2, m2) = (self.rho, self.grav, self.l1, self.l2, self.m2);
        let (c1q, c2q) = (dot(&self.c1, q), dot(&self.c2, q));
        let (c1qd, c2qd) = (dot(&self.c1, qd), dot(&self.c2, qd));
        let mqq = mv(&self.mq, q);
        let bqd = mv(&self.bq, qd);
        let kqq = mv(&self.kq, q);
        let mut f = vec![0.0; 7];
        f[0] = -0.5 * l1 * g * (self.m1 + 2.0 * m2) * p1.cos() - 0.5 * l1 * l2 * m2 * v2 * v2 * s12
            + r * l1 * v2 * v2 * (-s12 * c1q + c12 * c2q)
            - 2.0 * r * l1 * v2 * (c12 * c1qd + s12 * c2qd);
        f[1] = -0.5 * l2 * g * m2 * p2.cos()
            + 0.5 * l1 * l2 * m2 * v1 * v1 * s12
            + r * l1 * v1 * v1 * (s12 * c1q - c12 * c2q)
            - 2.0 * r * v2 * dot(&self.c12, qd)
            - 2.0 * v2 * dot(qd, &mqq)
            - r * dot(qd, &bqd)
            - r * g * (p2.cos() * c1q - p2.sin() * c2q);
        for i in 0..4 {
            f[3 + i] = v2 * v2 * mqq[i]
                + r * (v2 * v2 * self.c12[i]
                    + l1 * v1 * v1 * (c12 * self.c1[i] + s12 * self.c2[i])
                    + 2.0 * v2 * bqd[i])
                - r * g * (p2.sin() * self.c1[i] + p2.cos() * self.c2[i])
                - kqq[i];
        }
        f
    }

    /// The constraints, in the test set's order and signs.
    fn constraints(&self, t: f64, y: &[f64]) -> [f64; 3] {
        let (p1, p2, x3, q4) = (y[0], y[1], y[2], y[6]);
        [
            self.l1 * p1.sin() + (self.l2 + q4) * p2.sin(),
            x3 - self.l1 * p1.cos() - (self.l2 + q4) * p2.cos(),
            p1 - 150.0 * t,
        ]
    }
}

/// A random state of the crank near the test set's: elastic coordinates of a millimetre,
/// crank and rod rates of the run's size.
fn crank_state(rng: &mut Rng) -> (Vec<f64>, Vec<f64>) {
    let mut q = rng.vec(7);
    for x in &mut q[3..] {
        *x *= 1e-3;
    }
    let mut qd = rng.vec(7);
    qd[0] *= 150.0;
    qd[1] *= 75.0;
    (q, qd)
}

/// The generated mass matrix, forces and constraints equal the test set's `AM`, `F` and
/// constraints (docs/models.md) at random states to 1e-12 (relative to the largest
/// entry), with gravity off (the test set's value) and on.
#[test]
fn generated_equations_equal_the_test_set() {
    let mut model = flexible_crank::Model::default();
    let k = model.info().parameter_index("grav").unwrap();
    let mut rng = Rng(17);
    for grav in [0.0, 9.81] {
        model.set_parameter(k, grav);
        let ts = test_set(grav);
        for _ in 0..20 {
            let (q, qd) = crank_state(&mut rng);
            let t = 0.01 * rng.next().abs();
            let mut m = vec![0.0; 49];
            model.mass_matrix_dense_inplace(t, &q, &mut m);
            let am = ts.am(&q);
            assert!(
                max_diff(&m, &am) <= 1e-12 * max_abs(&am),
                "AM: {:e}",
                max_diff(&m, &am)
            );
            let mut f = vec![0.0; 7];
            model.forces(t, &q, &qd, &mut f);
            let want = ts.f(&q, &qd);
            assert!(
                max_diff(&f, &want) <= 1e-12 * max_abs(&want),
                "F: {:e}\n{f:?}\n{want:?}",
                max_diff(&f, &want)
            );
            // Rows `pin_b.x`, `pin_b.y`, `driver` against the test set's y, −x and driver.
            let mut c = vec![0.0; 3];
            model.holonomic(t, &q, &mut c);
            let want = ts.constraints(t, &q);
            let got = [c[1], -c[0], c[2]];
            assert!(max_diff(&got, &want) <= 1e-15, "C: {got:?} {want:?}");
        }
    }
}

/// `flexible_crank_shapes`, whose rod is integrated from its shape functions at compile
/// time: its mass matrix and forces equal the test set's formulas with the closed-form
/// integrals of [`closed_form`] at random states to 1e-12, and its modal mass's axial
/// block is exactly 1/15 of `flexible_crank`'s (docs/models.md), the rest of `M`
/// equal to the rounding of the test set's π.
#[test]
fn integrated_invariants_equal_the_closed_form_integrals() {
    let mut model = flexible_crank_shapes::Model::default();
    let given = flexible_crank::Model::default();
    let k = model.info().parameter_index("grav").unwrap();
    let mut rng = Rng(29);
    for grav in [0.0, 9.81] {
        model.set_parameter(k, grav);
        let cf = closed_form(grav);
        for _ in 0..20 {
            let (q, qd) = crank_state(&mut rng);
            let mut m = vec![0.0; 49];
            model.mass_matrix_dense_inplace(0.0, &q, &mut m);
            let am = cf.am(&q);
            assert!(
                max_diff(&m, &am) <= 1e-12 * max_abs(&am),
                "AM: {:e}",
                max_diff(&m, &am)
            );
            let mut f = vec![0.0; 7];
            model.forces(0.0, &q, &qd, &mut f);
            let want = cf.f(&q, &qd);
            assert!(
                max_diff(&f, &want) <= 1e-12 * max_abs(&want),
                "F: {:e}",
                max_diff(&f, &want)
            );
            let mut mg = vec![0.0; 49];
            given.mass_matrix_dense_inplace(0.0, &q, &mut mg);
            for i in 0..7 {
                for j in 0..7 {
                    let (a, b) = (mg[i * 7 + j], m[i * 7 + j]);
                    if (i, j) == (1, 1) {
                        // AM22 holds qᵀ MQ q: the axial block's factor shows there too.
                        let d = test_set(grav).am(&q)[8] - am[8];
                        assert!((a - b - d).abs() <= 1e-7 * a.abs(), "M[1,1]: {a} vs {b}");
                    } else if i >= 5 && j >= 5 {
                        assert!(
                            (a - 15.0 * b).abs() <= 1e-15 * a.abs(),
                            "M[{i},{j}]: {a} vs 15 × {b}"
                        );
                    } else {
                        assert!(
                            (a - b).abs() <= 1e-7 * max_abs(&mg),
                            "M[{i},{j}]: {a} vs {b}"
                        );
                    }
                }
            }
        }
    }
}

/// The generated constraint Jacobian and `γ` against finite differences.
#[test]
fn generated_derivatives_agree_with_finite_differences() {
    let model = flexible_crank::Model::default();
    let mut rng = Rng(23);
    for _ in 0..5 {
        let q: Vec<f64> = rng
            .vec(7)
            .iter()
            .enumerate()
            .map(|(i, x)| if i >= 3 { 1e-3 * x } else { *x })
            .collect();
        let qd = rng.vec(7);
        let c = model.check_derivatives(0.003, &q, &qd);
        let worst = [
            c.holonomic_jacobian,
            c.holonomic_rate,
            c.holonomic_gamma,
            c.mass_matrix,
        ]
        .into_iter()
        .fold(0.0_f64, f64::max);
        assert!(worst < 1e-6, "{c:?}");
    }
}

/// The absolute tolerance per unit of relative tolerance: the elastic coordinates are of
/// order 1e-5 m (axial) to 1e-3 m (lateral), so an absolute tolerance equal to the
/// relative one would leave them unresolved.
const ATOL_PER_RTOL: f64 = 1e-6;

fn run(model: &dyn Mechanism, form: Formulation, rtol: f64, t_end: f64) -> Run {
    Simulation::new(model)
        .formulation(form)
        .integrator(Method::Radau5)
        .tolerances(rtol, ATOL_PER_RTOL * rtol)
        .output_times(&[])
        .run(t_end)
        .expect("the flexible slider crank runs")
}

/// The run to t = 0.1 from the test set's consistent initial state completes with
/// RADAU5 at rtol 1e-8 (coordinate partitioning, the default, and projection agree),
/// and the elastic coordinates converge as the tolerance tightens: the error of the
/// final `q1 … q4` against a run at rtol 1e-12 falls with the tolerance (the observed
/// order is printed with `--nocapture`).
#[test]
fn runs_to_the_end_with_radau5_and_converges() {
    let model = flexible_crank::Model::default();
    let reference = run(&model, Formulation::Partitioning, 1e-12, 0.1);
    let (_, qr, _) = reference.final_state().unwrap();
    let projected = run(&model, Formulation::Projection, 1e-12, 0.1);
    let (_, qp, _) = projected.final_state().unwrap();
    let agree = max_diff(&qp[3..7], &qr[3..7]) / max_abs(&qr[3..7]);
    println!("partitioning and projection at rtol 1e-12: q_f within {agree:e} (relative)");
    assert!(agree < 1e-7);
    let (mut errors, mut steps): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    for rtol in [1e-5, 1e-6, 1e-7, 1e-8] {
        let r = run(&model, Formulation::Partitioning, rtol, 0.1);
        let (t, q, _) = r.final_state().unwrap();
        assert!((t - 0.1).abs() < 1e-12);
        let e = max_diff(&q[3..7], &qr[3..7]) / max_abs(&qr[3..7]);
        println!(
            "rtol {rtol:e}: relative error of q_f {e:e}, {} steps",
            r.stats.steps
        );
        errors.push(e);
        steps.push(r.stats.steps as f64);
    }
    for k in 1..errors.len() {
        println!(
            "error ∝ rtol^{:.2}, ∝ steps^-{:.2}",
            (errors[k - 1] / errors[k]).log10(),
            (errors[k - 1] / errors[k]).ln() / (steps[k] / steps[k - 1]).ln()
        );
    }
    // Tolerance proportionality: within 100 × rtol at every tolerance.
    for (e, rtol) in errors.iter().zip([1e-5, 1e-6, 1e-7, 1e-8]) {
        assert!(*e < 100.0 * rtol, "{errors:?}");
    }
    assert!(errors[3] < 0.01 * errors[0], "{errors:?}");
}

/// A stiffer rod approaches the rigid rod's motion: with Young's modulus ×10 and ×100
/// (from an undeformed, consistent state), the largest difference of `phi2` and `x3`
/// from `rigid_crank` over [0, 0.05] falls roughly as 1/stiffness (the deflection under
/// the inertial loads, and the vibration they excite, scale as 1/stiffness).
#[test]
fn stiff_rod_approaches_the_rigid_rod() {
    let rigid = rigid_crank::Model::default();
    let y0 = [0.0, 0.0, 0.45];
    let v0 = [150.0, -75.0, 0.0];
    let t_end = 0.05;
    let times: Vec<f64> = (1..=100).map(|i| f64::from(i) * 5e-4).collect();
    let r = Simulation::new(&rigid)
        .formulation(Formulation::Projection)
        .integrator(Method::Dop853)
        .tolerances(1e-12, 1e-12)
        .output_times(&times)
        .initial_state(&y0, &v0)
        .run(t_end)
        .unwrap();
    let mut diffs = Vec::new();
    for factor in [1.0, 10.0, 100.0] {
        let mut model = flexible_crank::Model::default();
        let k = model.info().parameter_index("ee").unwrap();
        model.set_parameter(k, 2.0e11 * factor);
        let q0 = [0.0, 0.0, 0.45, 0.0, 0.0, 0.0, 0.0];
        let v0 = [150.0, -75.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let f = Simulation::new(&model)
            .formulation(Formulation::Projection)
            .integrator(Method::Radau5)
            .tolerances(1e-10, 1e-10)
            .output_times(&times)
            .initial_state(&q0, &v0)
            .run(t_end)
            .unwrap();
        assert_eq!(f.trajectory.len(), r.trajectory.len());
        let d = (0..f.trajectory.len())
            .map(|i| max_diff(&f.trajectory.q(i)[..3], r.trajectory.q(i)))
            .fold(0.0_f64, f64::max);
        println!("E × {factor}: |(phi2, x3) − rigid| = {d:e}");
        diffs.push(d);
    }
    assert!(
        diffs[1] < 0.2 * diffs[0] && diffs[2] < 0.2 * diffs[1],
        "{diffs:?}"
    );
}
