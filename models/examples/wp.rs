use pfaff::sim::{Formulation, Method, Run, Simulation};
use pfaff::Mechanism;
use pfaff_models::{andrews, car_axis, pendulum, slider_crank};

fn jacobi(u: f64, m: f64) -> (f64, f64) {
    let mut a = [0.0_f64; 16];
    let mut c = [0.0_f64; 16];
    a[0] = 1.0;
    let mut b = (1.0 - m).sqrt();
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
fn pend_exact(t: f64) -> (Vec<f64>, Vec<f64>) {
    let w0 = 9.81_f64.sqrt();
    let k = std::f64::consts::FRAC_1_SQRT_2;
    let (sn, cn) = jacobi(1.854_074_677_301_371_9 - w0 * t, 0.5);
    let th = 2.0 * (k * sn).asin();
    let thd = -2.0 * k * w0 * cn;
    (
        vec![th.sin(), -th.cos()],
        vec![th.cos() * thd, th.sin() * thd],
    )
}

fn err(run: &Run, refs: &[(Vec<f64>, Vec<f64>)]) -> f64 {
    let tr = &run.trajectory;
    let mut worst = 0.0_f64;
    let rows: Vec<usize> = if std::env::var("FINAL").is_ok() {
        vec![tr.len() - 1]
    } else {
        (0..tr.len()).collect()
    };
    for i in rows {
        let r = &refs[if refs.len() == 1 { 0 } else { i }];
        let (q, qd) = (tr.q(i), tr.qd(i));
        let sq = r.0.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
        let sv = r.1.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
        let eq = q
            .iter()
            .zip(&r.0)
            .fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()))
            / sq;
        let ev = qd
            .iter()
            .zip(&r.1)
            .fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()))
            / sv;
        worst = worst.max(eq.max(ev));
    }
    worst
}

fn sweep(name: &str, model: &dyn Mechanism, t_end: f64, reference: Vec<(Vec<f64>, Vec<f64>)>) {
    for form in Formulation::ALL {
        for method in [
            Method::Rk4 { h: 0.0 },
            Method::Dopri5,
            Method::Dop853,
            Method::Adams,
        ] {
            let mut line = format!("{name:13} {:12} {:6}", form.name(), method.name());
            let mut prev = f64::NAN;
            let mut flags = String::new();
            for k in 3..=12 {
                let rtol = 10f64.powi(-k);
                let m = match method {
                    Method::Rk4 { .. } => Method::Rk4 {
                        h: t_end * rtol.powf(0.25) / 10.0,
                    },
                    m => m,
                };
                let r = Simulation::new(model)
                    .formulation(form)
                    .integrator(m)
                    .tolerances(rtol, rtol / 100.0)
                    .output_every(t_end / 100.0)
                    .run(t_end);
                let e = match r {
                    Ok(run) => err(&run, &reference),
                    Err(e) => {
                        flags.push_str(&format!(" FAIL@{k}:{}", e.kind));
                        f64::NAN
                    }
                };
                line.push_str(&format!(" {:8.1e}", e));
                if e > 20.0 * rtol && e > 1e-13 {
                    flags.push_str(&format!(" >20@{k}({:.0})", e / rtol));
                }
                if e > 2.0 * prev && e > 1e-13 {
                    flags.push_str(&format!(" nonmono@{k}"));
                }
                prev = e;
            }
            println!("{line}{flags}");
        }
    }
}

fn tight(model: &dyn Mechanism, t_end: f64) -> Vec<(Vec<f64>, Vec<f64>)> {
    let run = Simulation::new(model)
        .formulation(Formulation::Projection)
        .integrator(Method::Dop853)
        .tolerances(1e-14, 1e-16)
        .output_every(t_end / 100.0)
        .run(t_end)
        .unwrap();
    let tr = &run.trajectory;
    (0..tr.len())
        .map(|i| (tr.q(i).to_vec(), tr.qd(i).to_vec()))
        .collect()
}

fn main() {
    let which: Vec<String> = std::env::args().skip(1).collect();
    let want = |n: &str| which.is_empty() || which.iter().any(|w| w == n);
    if want("pendulum") {
        let t = 3.0 * 2.367_841_947_576_24;
        sweep(
            "pendulum",
            &pendulum::Model::default(),
            t,
            (0..=100)
                .map(|k| pend_exact((k as f64 * t / 100.0).min(t)))
                .collect(),
        );
    }
    if want("slider_crank") {
        let m = slider_crank::Model::default();
        let t = std::f64::consts::TAU / 10.0;
        sweep("slider_crank", &m, t, tight(&m, t));
    }
    if want("andrews") {
        let m = andrews::Model::default();
        sweep("andrews", &m, 0.03, tight(&m, 0.03));
    }
    if want("car_axis") {
        let m = car_axis::Model::default();
        sweep("car_axis", &m, 3.0, tight(&m, 3.0));
    }
}
