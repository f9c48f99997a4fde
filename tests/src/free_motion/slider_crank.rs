//! The reactions of `slider_crank` (absolute coordinates, so the multipliers are pin
//! forces) against an independent Newton–Euler computation per body.
//!
//! Reading of the multipliers (sign of docs/theory.md §sign, constraint force $-J_k^\mathsf{T}
//! \lambda_k$): at O the ground pushes the crank with $-(\lambda_{ox}, \lambda_{oy})$; at
//! A the coupler pushes the crank with $-(\lambda_{ax}, \lambda_{ay})$ and the crank the
//! coupler with the opposite; at B likewise between coupler and slider; the guide
//! pushes the slider with $(0, -\lambda_{gy})$ and the torque $-\lambda_{g\varphi}$; the
//! driver torque on the crank is $-\lambda_d$.
//!
//! Two checks at every recorded state of a driven run:
//! 1. the balance of every body, $m\ddot r = \sum F + m g$ and
//!    $J\ddot\varphi = \sum r \times F + \tau$, with these forces applied at the pin
//!    points (the moment arms come from the geometry, not from the Jacobian);
//! 2. the nine pin forces and torques solved from Newton–Euler alone (a 9 × 9 linear
//!    system in the forces, given the accelerations) equal those read from λ.

use pfaff::{ReactionAnalysis, Workspace};
use pfaff_models::slider_crank;

use super::sim::{samples, simulate, solve};

fn cross(r: [f64; 2], f: [f64; 2]) -> f64 {
    r[0] * f[1] - r[1] * f[0]
}

#[test]
fn reactions_match_newton_euler() {
    let model = slider_crank::Model::default();
    let p = model.params;
    let info = &slider_crank::INFO;
    let (mut q0, mut qd0) = ([0.0; 9], [0.0; 9]);
    pfaff::Mechanism::initial_state(&model, &mut q0, &mut qd0);
    let run = simulate(&model, true, 0.0, &q0, &qd0, 0.7, 1e-11);
    let mut ws = Workspace::new(info).unwrap();
    let mut ra = ReactionAnalysis::new(info, Default::default()).unwrap();
    let history = ra.along(&model, &mut ws, samples(&run)).unwrap();
    assert!(history.redundant.is_empty());

    let (mut worst_balance, mut worst_solve, mut scale) = (0.0_f64, 0.0_f64, 0.0_f64);
    for r in &history.samples {
        let s = run.iter().find(|s| s.t == r.t).unwrap();
        let q = &s.q;
        let a = &r.qdd;
        let l = |name: &str| r.get(name).unwrap().lambda;
        let u = |phi: f64| [phi.cos(), phi.sin()];
        let (u1, u2) = (u(q[2]), u(q[5]));
        let at = |k: f64, v: [f64; 2]| [k * v[0], k * v[1]];
        // Pin points relative to the body centres.
        let (r_o, r_a1) = (at(-0.5 * p.a, u1), at(0.5 * p.a, u1));
        let (r_a2, r_b2) = (at(-0.5 * p.b, u2), at(0.5 * p.b, u2));
        // Forces from the multipliers.
        let f_o = [-l("pin_o_x"), -l("pin_o_y")];
        let f_a = [-l("pin_a_x"), -l("pin_a_y")]; // on the crank; −f_a on the coupler
        let f_b = [-l("pin_b_x"), -l("pin_b_y")]; // on the coupler; −f_b on the slider
        let normal = -l("guide_y");
        let (tau_g, tau_d) = (-l("guide_phi"), -l("driver"));

        // 1. Balance per body.
        let residuals = [
            p.m1 * a[0] - (f_o[0] + f_a[0]),
            p.m1 * a[1] - (f_o[1] + f_a[1] - p.m1 * p.g),
            p.j1 * a[2] - (cross(r_o, f_o) + cross(r_a1, f_a) + tau_d),
            p.m2 * a[3] - (-f_a[0] + f_b[0]),
            p.m2 * a[4] - (-f_a[1] + f_b[1] - p.m2 * p.g),
            p.j2 * a[5] - (cross(r_a2, [-f_a[0], -f_a[1]]) + cross(r_b2, f_b)),
            p.m3 * a[6] - (-f_b[0]),
            p.m3 * a[7] - (-f_b[1] + normal - p.m3 * p.g),
            p.j3 * a[8] - tau_g,
        ];
        let size = f_o
            .iter()
            .chain(&f_a)
            .chain(&f_b)
            .chain(&[normal, tau_d])
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        scale = scale.max(size);
        for (k, res) in residuals.iter().enumerate() {
            worst_balance = worst_balance.max(res.abs() / size);
            assert!(
                res.abs() <= 1e-12 * size,
                "t = {}: equation {k}: {res:e}",
                r.t
            );
        }

        // 2. Newton–Euler alone: unknowns [F_O, F_A, F_B, N, τ_g, τ_d].
        let mut m = vec![0.0; 81];
        let mut b = vec![0.0; 9];
        let mut set = |row: usize, col: usize, v: f64| m[row * 9 + col] = v;
        // Crank.
        set(0, 0, 1.0);
        set(0, 2, 1.0);
        set(1, 1, 1.0);
        set(1, 3, 1.0);
        set(2, 0, -r_o[1]);
        set(2, 1, r_o[0]);
        set(2, 2, -r_a1[1]);
        set(2, 3, r_a1[0]);
        set(2, 8, 1.0);
        // Coupler.
        set(3, 2, -1.0);
        set(3, 4, 1.0);
        set(4, 3, -1.0);
        set(4, 5, 1.0);
        set(5, 2, r_a2[1]);
        set(5, 3, -r_a2[0]);
        set(5, 4, -r_b2[1]);
        set(5, 5, r_b2[0]);
        // Slider.
        set(6, 4, -1.0);
        set(7, 5, -1.0);
        set(7, 6, 1.0);
        set(8, 7, 1.0);
        b.copy_from_slice(&[
            p.m1 * a[0],
            p.m1 * (a[1] + p.g),
            p.j1 * a[2],
            p.m2 * a[3],
            p.m2 * (a[4] + p.g),
            p.j2 * a[5],
            p.m3 * a[6],
            p.m3 * (a[7] + p.g),
            p.j3 * a[8],
        ]);
        solve(&mut m, &mut b);
        let from_lambda = [
            f_o[0], f_o[1], f_a[0], f_a[1], f_b[0], f_b[1], normal, tau_g, tau_d,
        ];
        for (k, (x, y)) in b.iter().zip(&from_lambda).enumerate() {
            worst_solve = worst_solve.max((x - y).abs() / size);
            assert!(
                (x - y).abs() <= 1e-10 * size,
                "t = {}: unknown {k}: {x} vs {y}",
                r.t
            );
        }

        // The per-constraint generalized forces are these pin forces at the pin points:
        // e.g. `pin_a_x` acts on (x1, φ1) with (f, r_A × f) and on (x2, φ2) with the
        // opposite force at the coupler's end.
        let g = r.get("pin_a_x").unwrap().force;
        let fx = [f_a[0], 0.0];
        let expected = [
            fx[0],
            0.0,
            cross(r_a1, fx),
            -fx[0],
            0.0,
            cross(r_a2, [-fx[0], 0.0]),
            0.0,
            0.0,
            0.0,
        ];
        for (x, y) in g.iter().zip(&expected) {
            assert!((x - y).abs() <= 1e-14 * size);
        }
    }
    println!(
        "slider-crank: {} states, pin forces up to {scale:.3} N; balance residual {worst_balance:.1e}, Newton–Euler solve vs λ {worst_solve:.1e} (relative)",
        history.samples.len()
    );
}
