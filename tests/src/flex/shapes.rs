//! docs/theory.md V6 and V7: the mass matrix and the quadratic-velocity vector that the
//! generator derives for a deformable body integrated from its shape functions, against
//! the kinetic energy `T = ½ ∫ρ ṙ·ṙ` integrated here by quadrature (E9), against the
//! closed forms E13/E14 with the invariants E10 integrated here, and against
//! `∂T/∂q − Ṁ q̇` by finite differences.

use pfaff::{Mechanism, MechanismExt};

use super::models::{planar_element, spatial_flexible};
use super::{max_abs, max_diff, quad, Rng};

/// A body described the way the model source describes it: material position, shape
/// functions (row-major `dim × nf`) and mass per unit of the material coordinate ξ ∈ [0, 1].
struct Material {
    dim: usize,
    nf: usize,
    pos: fn(f64) -> Vec<f64>,
    n: fn(f64) -> Vec<f64>,
    rho: fn(f64) -> f64,
}

/// The planar beam element (docs/theory.md §beam-elements) as in `planar_element` (l = 0.7, ρA = 2.5, centre line offset 0.05).
fn element() -> Material {
    const L: f64 = 0.7;
    Material {
        dim: 2,
        nf: 6,
        pos: |x| vec![L * x, 0.05],
        n: |x| {
            let (x2, x3) = (x * x, x * x * x);
            vec![
                1.0 - x,
                0.0,
                0.0,
                x,
                0.0,
                0.0,
                0.0,
                1.0 - 3.0 * x2 + 2.0 * x3,
                L * (x - 2.0 * x2 + x3),
                0.0,
                3.0 * x2 - 2.0 * x3,
                L * (x3 - x2),
            ]
        },
        rho: |_| 2.5 * L,
    }
}

/// The body of `spatial_flexible`.
fn spatial() -> Material {
    Material {
        dim: 3,
        nf: 3,
        pos: |s| vec![0.8 * s, 0.1, -0.05 + 0.2 * s],
        n: |s| {
            vec![
                s * s,
                0.0,
                0.3 * s,
                0.0,
                (2.0 * s).sin(),
                s,
                (0.5 * s).sinh(),
                -0.2 * s.exp(),
                1.0 - s.cos(),
            ]
        },
        rho: |s| 1.5 + s,
    }
}

fn mat_vec(a: &[f64], cols: usize, v: &[f64]) -> Vec<f64> {
    a.chunks(cols)
        .map(|r| r.iter().zip(v).map(|(x, y)| x * y).sum())
        .collect()
}

/// The rotation and, applied to a body-frame vector `u`, the velocity term: planar
/// `Ȧu = θ̇ A Ĩ u`; spatial `A (ω̄ × u)` with `ω̄ = Ḡ θ̇ = 2 Ē θ̇` (E3–E6, the form of
/// docs/theory.md §floating-frame whose mass matrix and `Q_v` E12/E15 are).
fn rotation(dim: usize, q: &[f64], qd: &[f64]) -> (Vec<f64>, Vec<f64>) {
    if dim == 2 {
        let (s, c) = q[2].sin_cos();
        let w = qd[2];
        (vec![c, -s, s, c], vec![-s * w, -c * w, c * w, -s * w])
    } else {
        let (t, td) = (&q[3..7], &qd[3..7]);
        let (t0, v) = (t[0], [t[1], t[2], t[3]]);
        let sk = [0.0, -v[2], v[1], v[2], 0.0, -v[0], -v[1], v[0], 0.0];
        let a: Vec<f64> = (0..9)
            .map(|k| {
                let (i, j) = (k / 3, k % 3);
                let id = if i == j { 2.0 * t0 * t0 - 1.0 } else { 0.0 };
                id + 2.0 * (v[i] * v[j] + t0 * sk[k])
            })
            .collect();
        // Ē of E3, ω̄ = 2 Ē θ̇, and A ω̃̄ (so that A ω̃̄ u = A (ω̄ × u)).
        let eb = [
            -t[1], t[0], t[3], -t[2], //
            -t[2], -t[3], t[0], t[1], //
            -t[3], t[2], -t[1], t[0],
        ];
        let w: Vec<f64> = (0..3)
            .map(|i| 2.0 * (0..4).map(|k| eb[4 * i + k] * td[k]).sum::<f64>())
            .collect();
        let wt = [0.0, -w[2], w[1], w[2], 0.0, -w[0], -w[1], w[0], 0.0];
        let aw: Vec<f64> = (0..9)
            .map(|k| (0..3).map(|m| a[3 * (k / 3) + m] * wt[3 * m + k % 3]).sum())
            .collect();
        (a, aw)
    }
}

/// `T = ½ ∫ ρ |Ṙ + Ȧ(ū_o + N q_f) + A N q̇_f|² dξ` (E9 with E6), by quadrature.
fn kinetic(b: &Material, q: &[f64], qd: &[f64]) -> f64 {
    let d = b.dim;
    let nr = if d == 2 { 3 } else { 7 };
    let (a, ad) = rotation(d, q, qd);
    let (qf, qfd) = (&q[nr..], &qd[nr..]);
    quad(&mut |x| {
        let n = (b.n)(x);
        let nq = mat_vec(&n, b.nf, qf);
        let nqd = mat_vec(&n, b.nf, qfd);
        let u: Vec<f64> = (b.pos)(x).iter().zip(&nq).map(|(p, w)| p + w).collect();
        let adu = mat_vec(&ad, d, &u);
        let anqd = mat_vec(&a, d, &nqd);
        let v: Vec<f64> = (0..d).map(|k| qd[k] + adu[k] + anqd[k]).collect();
        0.5 * (b.rho)(x) * v.iter().map(|c| c * c).sum::<f64>()
    })
}

/// `∂T/∂q̇` (exact for a quadratic form: central difference with unit step).
fn momentum(b: &Material, q: &[f64], qd: &[f64]) -> Vec<f64> {
    (0..q.len())
        .map(|i| {
            let (mut p, mut m) = (qd.to_vec(), qd.to_vec());
            p[i] += 1.0;
            m[i] -= 1.0;
            0.5 * (kinetic(b, q, &p) - kinetic(b, q, &m))
        })
        .collect()
}

/// `∂T/∂q − Ṁ q̇` of the quadrature's `T`, by central differences (step `h`).
fn qv_reference(b: &Material, q: &[f64], qd: &[f64], h: f64) -> Vec<f64> {
    let n = q.len();
    let shift = |s: f64| -> Vec<f64> { q.iter().zip(qd).map(|(x, v)| x + s * v).collect() };
    let (pp, pm) = (momentum(b, &shift(h), qd), momentum(b, &shift(-h), qd));
    (0..n)
        .map(|i| {
            let (mut a, mut c) = (q.to_vec(), q.to_vec());
            a[i] += h;
            c[i] -= h;
            let dt = (kinetic(b, &a, qd) - kinetic(b, &c, qd)) / (2.0 * h);
            dt - (pp[i] - pm[i]) / (2.0 * h)
        })
        .collect()
}

/// The invariants of E10 by quadrature: `m, Ī₁, I_kl, S̄, Ī_kl, S̄_kl`.
struct Invariants {
    i1: Vec<f64>,
    sbar: Vec<f64>,
    ibar: Vec<f64>,
    skl: Vec<f64>,
    ikl: Vec<f64>,
}

fn invariants(b: &Material) -> Invariants {
    let (d, nf) = (b.dim, b.nf);
    let i1 = (0..d)
        .map(|k| quad(&mut |x| (b.rho)(x) * (b.pos)(x)[k]))
        .collect();
    let ikl = (0..d * d)
        .map(|e| quad(&mut |x| (b.rho)(x) * (b.pos)(x)[e / d] * (b.pos)(x)[e % d]))
        .collect();
    let sbar = (0..d * nf)
        .map(|e| quad(&mut |x| (b.rho)(x) * (b.n)(x)[e]))
        .collect();
    let ibar = (0..d * d * nf)
        .map(|e| {
            let (k, l, j) = (e / (d * nf), (e / nf) % d, e % nf);
            quad(&mut |x| (b.rho)(x) * (b.pos)(x)[k] * (b.n)(x)[l * nf + j])
        })
        .collect();
    let skl = (0..d * d * nf * nf)
        .map(|e| {
            let (kl, i, j) = (e / (nf * nf), (e / nf) % nf, e % nf);
            let (k, l) = (kl / d, kl % d);
            quad(&mut |x| {
                let n = (b.n)(x);
                (b.rho)(x) * n[k * nf + i] * n[l * nf + j]
            })
        })
        .collect();
    Invariants {
        i1,
        sbar,
        ibar,
        skl,
        ikl,
    }
}

/// docs/theory.md V6 with the planar beam element: the generated `M` equals the Hessian of the
/// quadrature's `T` and E13, the generated `Q_v` equals `∂T/∂q − Ṁq̇` and E14 in every
/// row, including the sign of the Coriolis term `−2θ̇(S̄₂₁ − S̄₁₂)q̇_f`.
#[test]
fn planar_mass_matrix_and_quadratic_velocity_vector_v6() {
    let model = planar_element::Model::default();
    let b = element();
    let inv = invariants(&b);
    let n = 9;
    let nf = 6;
    let mut rng = Rng(11);
    for _ in 0..10 {
        let mut q = rng.vec(n);
        for x in &mut q[3..] {
            *x *= 0.1;
        }
        let qd = rng.vec(n);
        let mut m = vec![0.0; n * n];
        model.mass_matrix_dense_inplace(0.0, &q, &mut m);
        // Hessian of the quadrature's T by polarization (exact for a quadratic form).
        let e = |i: usize| -> Vec<f64> { (0..n).map(|k| f64::from(u8::from(k == i))).collect() };
        for i in 0..n {
            for j in 0..n {
                let s: Vec<f64> = e(i).iter().zip(e(j)).map(|(a, c)| a + c).collect();
                let h = kinetic(&b, &q, &s) - kinetic(&b, &q, &e(i)) - kinetic(&b, &q, &e(j));
                let want = if i == j {
                    2.0 * kinetic(&b, &q, &e(i))
                } else {
                    h
                };
                assert!(
                    (m[i * n + j] - want).abs() < 1e-13,
                    "M[{i},{j}] {} vs {want}",
                    m[i * n + j]
                );
            }
        }
        // E13 with the quadrature's invariants.
        let qf = &q[3..];
        let (s, c) = q[2].sin_cos();
        let a = [c, -s, s, c];
        let at = [-s, -c, c, -s];
        let sq = mat_vec(&inv.sbar, nf, qf);
        let uc: Vec<f64> = (0..2).map(|k| inv.i1[k] + sq[k]).collect();
        let skl = |k: usize, l: usize| &inv.skl[(k * 2 + l) * nf * nf..(k * 2 + l + 1) * nf * nf];
        let ibar = |k: usize, l: usize| &inv.ibar[(k * 2 + l) * nf..(k * 2 + l + 1) * nf];
        let quadf = |s: &[f64], x: &[f64], y: &[f64]| -> f64 {
            (0..nf)
                .map(|i| (0..nf).map(|j| x[i] * s[i * nf + j] * y[j]).sum::<f64>())
                .sum()
        };
        let dotv = |x: &[f64], y: &[f64]| -> f64 { x.iter().zip(y).map(|(a, b)| a * b).sum() };
        let ukk = |k: usize| inv.ikl[k * 3] + 2.0 * dotv(ibar(k, k), qf) + quadf(skl(k, k), qf, qf);
        let mut e13 = vec![0.0; n * n];
        e13[0] = inv_mass(&b);
        e13[n + 1] = e13[0];
        let atuc = mat_vec(&at, 2, &uc);
        let asb: Vec<f64> = (0..2 * nf)
            .map(|e| {
                (0..2)
                    .map(|k| a[(e / nf) * 2 + k] * inv.sbar[k * nf + e % nf])
                    .sum()
            })
            .collect();
        for r in 0..2 {
            e13[r * n + 2] = atuc[r];
            for j in 0..nf {
                e13[r * n + 3 + j] = asb[r * nf + j];
            }
        }
        e13[2 * n + 2] = ukk(0) + ukk(1);
        let (s12, s21) = (skl(0, 1), skl(1, 0));
        for j in 0..nf {
            let qs: f64 = (0..nf)
                .map(|i| qf[i] * (s12[i * nf + j] - s21[i * nf + j]))
                .sum();
            e13[2 * n + 3 + j] = ibar(0, 1)[j] - ibar(1, 0)[j] + qs;
            for i in 0..nf {
                e13[(3 + i) * n + 3 + j] = skl(0, 0)[i * nf + j] + skl(1, 1)[i * nf + j];
            }
        }
        for i in 0..n {
            for j in 0..i {
                e13[i * n + j] = e13[j * n + i];
            }
        }
        assert!(max_diff(&m, &e13) < 1e-13, "E13: {:e}", max_diff(&m, &e13));
        // Q_v: the generated forces (no potential, no applied forces).
        let mut qv = vec![0.0; n];
        model.forces(0.0, &q, &qd, &mut qv);
        let reference = qv_reference(&b, &q, &qd, 1e-5);
        let scale = max_abs(&reference).max(1.0);
        assert!(
            max_diff(&qv, &reference) < 1e-8 * scale,
            "∂T/∂q − Ṁq̇: {:e}",
            max_diff(&qv, &reference)
        );
        // E14.
        let (w, qfd) = (qd[2], &qd[3..]);
        let mff: Vec<f64> = (0..nf * nf).map(|e| skl(0, 0)[e] + skl(1, 1)[e]).collect();
        let sqd = mat_vec(&inv.sbar, nf, qfd);
        let auc = mat_vec(&a, 2, &uc);
        let atsqd = mat_vec(&at, 2, &sqd);
        let mut e14 = vec![0.0; n];
        for r in 0..2 {
            e14[r] = w * w * auc[r] - 2.0 * w * atsqd[r];
        }
        let row: Vec<f64> = (0..nf)
            .map(|j| {
                ibar(0, 0)[j]
                    + ibar(1, 1)[j]
                    + (0..nf).map(|i| qf[i] * mff[i * nf + j]).sum::<f64>()
            })
            .collect();
        e14[2] = -2.0 * w * dotv(&row, qfd);
        let coriolis: Vec<f64> = (0..nf)
            .map(|i| {
                -2.0 * w
                    * (0..nf)
                        .map(|j| (s21[i * nf + j] - s12[i * nf + j]) * qfd[j])
                        .sum::<f64>()
            })
            .collect();
        for i in 0..nf {
            let centrifugal: f64 = (0..2)
                .map(|k| {
                    ibar(k, k)[i] + (0..nf).map(|j| skl(k, k)[i * nf + j] * qf[j]).sum::<f64>()
                })
                .sum();
            e14[3 + i] = w * w * centrifugal + coriolis[i];
        }
        assert!(
            max_diff(&qv, &e14) < 1e-12 * scale,
            "E14: {:e}",
            max_diff(&qv, &e14)
        );
        // The Coriolis term is there, and with the sign of E14: the opposite sign fails.
        let flipped: Vec<f64> = (0..n)
            .map(|i| {
                if i >= 3 {
                    e14[i] - 2.0 * coriolis[i - 3]
                } else {
                    e14[i]
                }
            })
            .collect();
        assert!(max_diff(&qv, &flipped) > 1e-3 * max_abs(&coriolis));
        assert!(max_abs(&coriolis) > 1e-3);
    }
}

fn inv_mass(b: &Material) -> f64 {
    quad(&mut |x| (b.rho)(x))
}

/// docs/theory.md V6, third item: the generated body reproduces the element integrals of
/// docs/theory.md §beam-elements, `∫ρA S dx` (through `M_Rf = A S̄` at θ = 0) and `∫ρA SᵀĨS dx = S̄₂₁ − S̄₁₂`
/// (through the Coriolis part of `Q_v^f = −2θ̇(S̄₂₁ − S̄₁₂)q̇_f`).
#[test]
fn element_shape_integrals_of_section_3_7() {
    let model = planar_element::Model::default();
    let (l, ra) = (0.7, 2.5);
    let n = 9;
    let q = vec![0.0; n];
    let mut m = vec![0.0; n * n];
    model.mass_matrix_dense_inplace(0.0, &q, &mut m);
    let s = [
        [0.5, 0.0, 0.0, 0.5, 0.0, 0.0],
        [0.0, 0.5, l / 12.0, 0.0, 0.5, -l / 12.0],
    ];
    for r in 0..2 {
        for j in 0..6 {
            let want = ra * l * s[r][j];
            assert!((m[r * n + 3 + j] - want).abs() < 1e-14, "S̄[{r},{j}]");
        }
    }
    // ρAl/420 · (the planar element's matrix)
    let sis = [
        [0.0, -147.0, -21.0 * l, 0.0, -63.0, 14.0 * l],
        [147.0, 0.0, 0.0, 63.0, 0.0, 0.0],
        [21.0 * l, 0.0, 0.0, 14.0 * l, 0.0, 0.0],
        [0.0, -63.0, -14.0 * l, 0.0, -147.0, 21.0 * l],
        [63.0, 0.0, 0.0, 147.0, 0.0, 0.0],
        [-14.0 * l, 0.0, 0.0, -21.0 * l, 0.0, 0.0],
    ];
    let mut f0 = vec![0.0; n];
    let mut qd = vec![0.0; n];
    qd[2] = 1.0;
    model.forces(0.0, &q, &qd, &mut f0);
    for j in 0..6 {
        let mut v = qd.clone();
        v[3 + j] = 1.0;
        let mut f = vec![0.0; n];
        model.forces(0.0, &q, &v, &mut f);
        for i in 0..6 {
            let coriolis = f[3 + i] - f0[3 + i];
            let want = -2.0 * ra * l / 420.0 * sis[i][j];
            assert!(
                (coriolis - want).abs() < 1e-13,
                "SᵀĨS[{i},{j}]: {coriolis} vs {want}"
            );
        }
    }
}

/// docs/theory.md V7: unit θ, θ̇ ⊥ θ. The generated `M` equals the Hessian of the quadrature's
/// `T` on such velocities; `Q_v` equals the quadrature's `∂T/∂q − Ṁq̇` in the R and f
/// rows, and in the θ rows up to a multiple of θ (parallelism tested, not the multiple).
#[test]
fn spatial_mass_matrix_and_quadratic_velocity_vector_v7() {
    let model = spatial_flexible::Model::default();
    let b = spatial();
    let n = 10;
    let mut rng = Rng(5);
    let tangent = |rng: &mut Rng, q: &[f64]| -> Vec<f64> {
        let mut v = rng.vec(n);
        let th = &q[3..7];
        let p: f64 = (0..4).map(|k| v[3 + k] * th[k]).sum();
        for k in 0..4 {
            v[3 + k] -= p * th[k];
        }
        v
    };
    for _ in 0..10 {
        let mut q = rng.vec(n);
        let norm: f64 = q[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
        for x in &mut q[3..7] {
            *x /= norm;
        }
        for x in &mut q[7..] {
            *x *= 0.1;
        }
        let qd = tangent(&mut rng, &q);
        let mut m = vec![0.0; n * n];
        model.mass_matrix_dense_inplace(0.0, &q, &mut m);
        for _ in 0..5 {
            let (v, w) = (tangent(&mut rng, &q), tangent(&mut rng, &q));
            let vw: Vec<f64> = v.iter().zip(&w).map(|(a, c)| a + c).collect();
            let want = kinetic(&b, &q, &vw) - kinetic(&b, &q, &v) - kinetic(&b, &q, &w);
            let mw = mat_vec(&m, n, &w);
            let got: f64 = v.iter().zip(&mw).map(|(a, c)| a * c).sum();
            assert!(
                (got - want).abs() < 1e-13 * want.abs().max(1.0),
                "vᵀMw {got} vs {want}"
            );
        }
        let mut qv = vec![0.0; n];
        model.forces(0.0, &q, &qd, &mut qv);
        let reference = qv_reference(&b, &q, &qd, 1e-5);
        let scale = max_abs(&reference).max(1.0);
        let d: Vec<f64> = qv.iter().zip(&reference).map(|(a, c)| a - c).collect();
        let rf: Vec<f64> = d[..3].iter().chain(&d[7..]).copied().collect();
        assert!(max_abs(&rf) < 1e-8 * scale, "R, f rows: {:e}", max_abs(&rf));
        let th = &q[3..7];
        let mu: f64 = (0..4).map(|k| d[3 + k] * th[k]).sum();
        let perp: Vec<f64> = (0..4).map(|k| d[3 + k] - mu * th[k]).collect();
        assert!(
            max_abs(&perp) < 1e-8 * scale,
            "θ rows off θ: {:e}",
            max_abs(&perp)
        );
    }
}

/// The generated `Q_v` is `∂T/∂q − Ṁq̇` of the generated `T` and `M` (the self-check
/// of docs/theory.md §scope), by central differences of `kinetic_energy` and `mass_matrix`, for
/// both bodies at states off the constraint (any θ, θ̇).
#[test]
fn quadratic_velocity_vector_is_the_lagrange_derivative_of_the_generated_energy() {
    fn check(model: &dyn Mechanism, n: usize, seed: u64) {
        let mut rng = Rng(seed);
        for _ in 0..5 {
            let q = rng.vec(n);
            let qd = rng.vec(n);
            let h = 1e-5;
            let mut qv = vec![0.0; n];
            model.forces(0.0, &q, &qd, &mut qv);
            let mq = |x: &[f64]| -> Vec<f64> {
                let mut m = vec![0.0; n * n];
                model.mass_matrix_dense_inplace(0.0, x, &mut m);
                mat_vec(&m, n, &qd)
            };
            let plus: Vec<f64> = q.iter().zip(&qd).map(|(a, v)| a + h * v).collect();
            let minus: Vec<f64> = q.iter().zip(&qd).map(|(a, v)| a - h * v).collect();
            let (mp, mm) = (mq(&plus), mq(&minus));
            let want: Vec<f64> = (0..n)
                .map(|i| {
                    let (mut a, mut c) = (q.clone(), q.clone());
                    a[i] += h;
                    c[i] -= h;
                    let dt = (model.kinetic_energy(0.0, &a, &qd)
                        - model.kinetic_energy(0.0, &c, &qd))
                        / (2.0 * h);
                    dt - (mp[i] - mm[i]) / (2.0 * h)
                })
                .collect();
            let scale = max_abs(&want).max(1.0);
            assert!(
                max_diff(&qv, &want) < 1e-7 * scale,
                "{:e}",
                max_diff(&qv, &want)
            );
        }
    }
    check(&planar_element::Model::default(), 9, 3);
    check(&spatial_flexible::Model::default(), 10, 4);
}
