//! `flexible_sleigh` (a knife edge at a material point of an elastic tail) against an
//! independent derivation: the kinetic and strain energy of the tail integrated here over
//! its beam elements from the nodal displacements `d = T p`, and the blade's constraint
//! written from the tip node's position and section rotation. Only the reduced basis `T`
//! comes from `pfaff::flex`; the shape integrals, `K_ff` and the generated expressions
//! do not enter. `M`, `Q`, `G`, `g` and `γ_nh` are the difference quotients of
//! `reference`.

use std::f64::consts::PI;

use pfaff::flex::{Beam, Dim, Reduction, Reference as Clamp, Section};
use pfaff::{Mechanism, MechanismExt, TimeDependence};
use pfaff_models::flexible_sleigh::{Model, Params, INFO};

use super::check::{check_info, check_parameters, perturb, Expected, TOL_D1, TOL_D11, TOL_EVAL};
use super::reference::Reference;
use super::util::{dense, max_abs, max_diff, Rng};

/// The tail's elements and modes (as in the model).
const ELEMENTS: usize = 6;
const MODES: usize = 3;

/// The tail of `p`, reduced.
pub fn tail_basis(p: &Params) -> Vec<f64> {
    Beam {
        dim: Dim::Planar,
        elements: ELEMENTS,
        length: p.l,
        section: Section::planar(p.rho_a, p.ea, p.ei),
        reference: Clamp::Clamped { node: 0 },
        reduction: Reduction::Modes(MODES),
    }
    .reduce()
    .expect("the tail reduces")
    .basis
}

/// Nodal coordinates `d = T p` (3 per node: u, v, θ).
fn nodal(basis: &[f64], p: &[f64]) -> Vec<f64> {
    (0..basis.len() / MODES)
        .map(|r| (0..MODES).map(|j| basis[r * MODES + j] * p[j]).sum())
        .collect()
}

/// 5-point Gauss–Legendre on [0, 1] (exact to degree 9; the integrands have degree ≤ 6).
#[allow(clippy::excessive_precision)] // the digits of the tabulated nodes and weights
const GAUSS: [(f64, f64); 5] = [
    (0.046_910_077_030_668_0, 0.118_463_442_528_094_5),
    (0.230_765_344_947_158_5, 0.239_314_335_249_683_2),
    (0.5, 0.284_444_444_444_444_4),
    (0.769_234_655_052_841_5, 0.239_314_335_249_683_2),
    (0.953_089_922_969_332_0, 0.118_463_442_528_094_5),
];

/// The element's displacement `(u, v)` at `s ∈ [0, 1]` from its end coordinates
/// `[u1, v1, θ1, u2, v2, θ2]`: linear axial, Hermite cubic lateral (length `h`).
fn element_displacement(e: &[f64], h: f64, s: f64) -> (f64, f64) {
    let (s2, s3) = (s * s, s * s * s);
    let u = (1.0 - s) * e[0] + s * e[3];
    let v = (1.0 - 3.0 * s2 + 2.0 * s3) * e[1]
        + h * (s - 2.0 * s2 + s3) * e[2]
        + (3.0 * s2 - 2.0 * s3) * e[4]
        + h * (s3 - s2) * e[5];
    (u, v)
}

/// `(u', v'')` of the element at `s` (derivatives in x = s h).
fn element_strains(e: &[f64], h: f64, s: f64) -> (f64, f64) {
    let du = (e[3] - e[0]) / h;
    let ddv = ((-6.0 + 12.0 * s) * e[1]
        + h * (-4.0 + 6.0 * s) * e[2]
        + (6.0 - 12.0 * s) * e[4]
        + h * (6.0 * s - 2.0) * e[5])
        / (h * h);
    (du, ddv)
}

/// The blade's constraint `n · v_tip` and the model's energies, from `p`.
pub fn reference(p: &Params) -> Reference {
    let basis = tail_basis(p);
    let (m, ic, c, l, rho_a, ea, ei) = (p.m, p.ic, p.c, p.l, p.rho_a, p.ea, p.ei);
    let h = l / ELEMENTS as f64;
    let b1 = basis.clone();
    let b2 = basis.clone();
    let b3 = basis;
    Reference::new(6, move |_, q, v| {
        let (phi, w) = (q[2], v[2]);
        let d = nodal(&b1, &q[3..]);
        let dd = nodal(&b1, &v[3..]);
        // The tail's frame: origin R, angle ψ = φ + π, rate φ'.
        let (sp, cp) = (phi.sin(), phi.cos());
        let rd = [v[0] + c * sp * w, v[1] - c * cp * w];
        let (sa, ca) = ((phi + PI).sin(), (phi + PI).cos());
        let mut tail = 0.0;
        for k in 0..ELEMENTS {
            let e = &d[3 * k..3 * k + 6];
            let ed = &dd[3 * k..3 * k + 6];
            for (s, wt) in GAUSS {
                let (u, vv) = element_displacement(e, h, s);
                let (ud, vd) = element_displacement(ed, h, s);
                // Local position and velocity in the tail's frame.
                let (px, py) = ((k as f64 + s) * h + u, vv);
                // ω × r in the frame is (−ω y, ω x); plus the elastic velocity; rotated.
                let (lx, ly) = (-w * py + ud, w * px + vd);
                let gx = rd[0] + ca * lx - sa * ly;
                let gy = rd[1] + sa * lx + ca * ly;
                tail += 0.5 * rho_a * h * wt * (gx * gx + gy * gy);
            }
        }
        0.5 * m * (v[0] * v[0] + v[1] * v[1]) + 0.5 * ic * w * w + tail
    })
    .potential(move |_, q| {
        let d = nodal(&b2, &q[3..]);
        let mut u = 0.0;
        for k in 0..ELEMENTS {
            let e = &d[3 * k..3 * k + 6];
            for (s, wt) in GAUSS {
                let (du, ddv) = element_strains(e, h, s);
                u += 0.5 * h * wt * (ea * du * du + ei * ddv * ddv);
            }
        }
        u
    })
    .nonholonomic(move |_, q, v| {
        let (phi, w) = (q[2], v[2]);
        let d = nodal(&b3, &q[3..]);
        let dd = nodal(&b3, &v[3..]);
        let tip = 3 * ELEMENTS;
        let (px, py, th) = (l + d[tip], d[tip + 1], d[tip + 2]);
        let (sp, cp) = (phi.sin(), phi.cos());
        let (sa, ca) = ((phi + PI).sin(), (phi + PI).cos());
        let (lx, ly) = (-w * py + dd[tip], w * px + dd[tip + 1]);
        let vx = v[0] + c * sp * w + ca * lx - sa * ly;
        let vy = v[1] - c * cp * w + sa * lx + ca * ly;
        // Across the blade: the tail's y axis turned by the tip's rotation θ.
        let (nlx, nly) = (-th.sin(), th.cos());
        let nx = ca * nlx - sa * nly;
        let ny = sa * nlx + ca * nly;
        nx * vx + ny * vy
    })
}

#[test]
fn info() {
    check_parameters!(
        m = 2.0,
        ic = 0.05,
        c = 0.1,
        l = 0.2,
        rho_a = 0.5,
        ea = 1.0e6,
        ei = 0.32,
        v0 = 1.0,
        spin = 2.0
    );
    check_info(
        &Model::default(),
        &Expected {
            name: "flexible_sleigh",
            coordinates: &["x", "y", "phi", "p1", "p2", "p3"],
            holonomic: &[],
            nonholonomic: &["blade"],
            time: TimeDependence::default(),
            homogeneous: true,
            conservative: true,
            q0: &[0.0; 6],
            qd0: &[1.0, 0.6, 2.0, 0.0, 0.0, 0.0],
        },
    );
}

/// The generated M, Q, G, g and γ_nh against the independent derivation at 24 random
/// states (every other one with all parameters perturbed by up to ±20 %; elastic
/// coordinates up to a tip deflection of about a third of the tail), with the tolerances
/// of `check`. Written out rather than through `sweep`: the modes are mass-normalized,
/// so the off-diagonal entries of `M_ff` that the mass pattern keeps (the slot's values
/// are known at run time only) are zero at every state.
#[test]
fn derivatives() {
    let mut rng = Rng::new(0x5eed_f1e5);
    let mut worst = [0.0_f64; 7];
    for k in 0..24 {
        let mut model = Model::default();
        if k % 2 == 1 {
            perturb(&mut model, &mut rng, 0.2);
        }
        let r = reference(&model.params);
        let t = rng.range(0.0, 10.0);
        let q = vec![
            rng.range(-2.0, 2.0),
            rng.range(-2.0, 2.0),
            rng.range(-PI, PI),
            rng.range(-0.01, 0.01),
            rng.range(-0.01, 0.01),
            rng.range(-0.01, 0.01),
        ];
        // Elastic rates of the tip's section up to a few rad/s: the fifth derivative
        // along the motion stays small enough for the difference quotients (`util`).
        let mut qd = rng.vec(3, -2.0, 2.0);
        qd.extend(rng.vec(3, -0.05, 0.05));
        let n = 6;
        let (tk, vk) = (r.kinetic_energy(t, &q, &qd), r.potential_energy(t, &q));
        let rel = |a: &[f64], b: &[f64], s: f64| max_diff(a, b) / (max_abs(b) + s);
        let mut m = vec![0.0; n * n];
        model.mass_matrix_dense_inplace(t, &q, &mut m);
        let mut f = vec![0.0; n];
        model.forces(t, &q, &qd, &mut f);
        let mut gs = vec![f64::NAN; INFO.nonholonomic_pattern.len()];
        model.nonholonomic_matrix(t, &q, &mut gs);
        let g = dense(INFO.nonholonomic_pattern, &gs, 1, n);
        let mut bias = [f64::NAN];
        model.nonholonomic_bias(t, &q, &mut bias);
        let mut gamma = [f64::NAN];
        model.nonholonomic_gamma(t, &q, &qd, &mut gamma);
        let ns = max_abs(&r.nonholonomic_values(t, &q, &qd));
        let errs = [
            (
                rel(&[model.kinetic_energy(t, &q, &qd)], &[tk], 0.0),
                TOL_EVAL,
            ),
            (rel(&[model.potential_energy(t, &q)], &[vk], 0.0), TOL_EVAL),
            (rel(&m, &r.mass_matrix(t, &q, &qd), tk), TOL_D11),
            (rel(&f, &r.forces(t, &q, &qd), tk + vk), TOL_D11),
            (rel(&g, &r.nonholonomic_matrix(t, &q), ns), TOL_D1),
            (rel(&bias, &r.nonholonomic_bias(t, &q), ns), TOL_EVAL),
            (rel(&gamma, &r.nonholonomic_gamma(t, &q, &qd), ns), TOL_D1),
        ];
        for (i, (e, tol)) in errs.iter().enumerate() {
            assert!(
                *e <= *tol,
                "quantity {i} (T V M Q G g gamma_nh): {e:e} > {tol:e} at t = {t}, q = {q:?}, q' = {qd:?}"
            );
            worst[i] = worst[i].max(*e);
        }
        // The elastic coordinates enter G and γ_nh: G's elastic entries are not the
        // undeformed ones.
        let g0 = r.nonholonomic_matrix(t, &[q[0], q[1], q[2], 0.0, 0.0, 0.0]);
        assert!(max_diff(&g[2..], &g0[2..]) > 1e-3 * max_abs(&g0));
    }
    println!(
        "accuracy flexible_sleigh (24 states): T {:.1e}, V {:.1e}, M {:.1e}, Q {:.1e}, G {:.1e}, g {:.1e}, gamma_nh {:.1e}",
        worst[0], worst[1], worst[2], worst[3], worst[4], worst[5], worst[6]
    );
}
