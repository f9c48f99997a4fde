//! Work-precision tables (`pfaff::sim::work_precision`): final error against right-hand
//! side evaluations and wall time, rtol = 1e-3 … 1e-12, every formulation × integrator.
//!
//! - `pendulum` over one period (2.36784194757624 s), against the exact solution
//!   (docs/models.md, Jacobi sn by the AGM, A&S §16.4);
//! - `sleigh` to t = 1, against docs/theory.md V11 (φ and φ̇ = ω);
//! - `andrews` over [0, 0.03], against the best converged run (DOP853, rtol 1e-13,
//!   partitioning; its distance to the same run with projection is printed).
//!
//! `cargo bench -p pfaff-tests --bench sim [-- pendulum|sleigh|andrews]`.

use pfaff::sim::{format_table, work_precision, Formulation, Method, Reference, Simulation, Sweep};
use pfaff_models::{andrews, pendulum, sleigh};

// K(1/2) as printed in docs/models.md.
#[allow(clippy::excessive_precision)]
const K_HALF: f64 = 1.854_074_677_301_371_918_43;

fn sn_cn(u: f64, m: f64) -> (f64, f64) {
    let (mut a, mut b, mut c) = ([0.0_f64; 16], (1.0 - m).sqrt(), [0.0_f64; 16]);
    a[0] = 1.0;
    c[0] = m.sqrt();
    let mut n = 0;
    while c[n].abs() > f64::EPSILON && n < 15 {
        let (an, bn) = (a[n], b);
        n += 1;
        a[n] = 0.5 * (an + bn);
        b = (an * bn).sqrt();
        c[n] = 0.5 * (an - bn);
    }
    let mut phi = f64::from(1u32 << n) * a[n] * u;
    for k in (1..=n).rev() {
        phi = 0.5 * (phi + (c[k] / a[k] * phi.sin()).asin());
    }
    (phi.sin(), phi.cos())
}

fn pendulum_reference(t: f64) -> Reference {
    let w0 = 9.81_f64.sqrt();
    let k = std::f64::consts::FRAC_1_SQRT_2;
    let (sn, cn) = sn_cn(K_HALF - w0 * t, 0.5);
    let th = 2.0 * (k * sn).asin();
    let thd = -2.0 * k * w0 * cn;
    Reference {
        coordinates: vec![("x".into(), th.sin()), ("y".into(), -th.cos())],
        velocities: vec![("x".into(), th.cos() * thd), ("y".into(), th.sin() * thd)],
        impacts: Vec::new(),
    }
}

fn main() {
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let want = |name: &str| filter.is_empty() || filter.iter().any(|f| name.contains(f.as_str()));

    if want("pendulum") {
        let t_end = 2.367_841_947_576_24;
        let rows = work_precision(
            &pendulum::Model::default(),
            &Sweep::standard(t_end),
            &pendulum_reference(t_end),
        );
        println!(
            "## pendulum, one period, exact solution\n\n{}",
            format_table(&rows)
        );
    }
    if want("sleigh") {
        let reference = Reference {
            coordinates: vec![("phi".into(), 0.176_360_706_663)],
            velocities: vec![("phi".into(), 0.035_719_741_683_2)],
            impacts: Vec::new(),
        };
        let rows = work_precision(&sleigh::Model::default(), &Sweep::standard(1.0), &reference);
        println!(
            "## sleigh, t = 1, docs/theory.md V11\n\n{}",
            format_table(&rows)
        );
    }
    if want("andrews") {
        let model = andrews::Model::default();
        let best = |form| {
            Simulation::new(&model)
                .formulation(form)
                .integrator(Method::Dop853)
                .tolerances(1e-13, 1e-15)
                .output_times(&[])
                .run(0.03)
                .expect("reference run")
        };
        let reference = Reference::from_run(&best(Formulation::Partitioning));
        let check = reference.error(&best(Formulation::Projection));
        let rows = work_precision(&model, &Sweep::standard(0.03), &reference);
        println!(
            "## andrews, t = 0.03, reference DOP853 rtol 1e-13 partitioning \
             (distance to the projection run {check:.1e})\n\n{}",
            format_table(&rows)
        );
    }
}
