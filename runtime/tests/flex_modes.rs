//! Reference conditions, modal reduction and Craig–Bampton (docs/theory.md §reduction, case V9):
//! cantilever frequencies against the table of V9 and the closed-form Euler–Bernoulli
//! values, the spin-up beam's first frequency (docs/models.md), M → I and
//! K → diag(ω²), and Craig–Bampton against the full model.

use pfaff::flex::{Beam, Dim, FlexError, Mesh, Reduction, Reference, Section};

/// β_k L of the clamped-free Euler–Bernoulli beam (roots of cos βL cosh βL = −1).
const BETA_L: [f64; 4] = [
    1.875_104_068_7,
    4.694_091_133_0,
    7.854_757_438_2,
    10.995_540_734_9,
];

/// The bending frequencies of a planar cantilever of `n` elements (`EI = ρA = L = 1`),
/// axial modes (no lateral component) left out.
fn planar_cantilever_bending(n: usize) -> Vec<f64> {
    // EA large enough that no axial mode falls among the first bending ones; modes are
    // classified by their shape anyway.
    let mesh = Mesh::line(Dim::Planar, 1.0, n, Section::planar(1.0, 1.0e6, 1.0));
    let c = mesh.constrain(&Reference::Clamped { node: 0 }).unwrap();
    let all = c.modes(c.invariants.n).unwrap();
    let nm = all.frequencies.len();
    (0..nm)
        .filter(|&k| {
            // A bending mode has no axial (u) component.
            (0..=n).all(|node| all.basis[(3 * node) * nm + k].abs() < 1e-9)
        })
        .map(|k| all.frequencies[k])
        .collect()
}

/// V9: the table of ω₁, ω₂, ω₃ for N = 1, 2, 4, 8, 16 planar elements (given to 8
/// significant digits), converging to β_k² √(EI/ρA)/L².
#[test]
fn v9_cantilever_table() {
    let table: [(usize, &[f64]); 5] = [
        (1, &[3.532_731_5, 34.806_893]),
        (2, &[3.517_715, 22.221_474, 75.157_083]),
        (4, &[3.516_130_3, 22.060_166, 62.174_893]),
        (8, &[3.516_022_6, 22.036_253, 61.734_741]),
        (16, &[3.516_015_7, 22.034_604, 61.699_667]),
    ];
    let mut last_err = [f64::INFINITY; 3];
    for (n, want) in table {
        let got = planar_cantilever_bending(n);
        for (k, w) in want.iter().enumerate() {
            assert!(
                (got[k] - w).abs() < 6e-8 * w,
                "N = {n}, ω{}: got {}, V9 {w}",
                k + 1,
                got[k]
            );
            // Convergence from above to the exact value (Rayleigh–Ritz).
            let exact = BETA_L[k] * BETA_L[k];
            let err = got[k] - exact;
            assert!(err > 0.0 && err < last_err[k], "N = {n}, ω{}: {err}", k + 1);
            last_err[k] = err;
        }
    }
    // With 16 elements the first three are within 1e-6, 6e-6, 4e-5 of the closed form
    // (relative).
    let got = planar_cantilever_bending(16);
    for (k, tol) in [1e-6, 6e-6, 4e-5].iter().enumerate() {
        let exact = BETA_L[k] * BETA_L[k];
        assert!(
            (got[k] - exact).abs() < tol * exact,
            "ω{}: {}",
            k + 1,
            got[k]
        );
    }
}

/// docs/models.md, `spinup_beam`: the first non-rotating bending frequency of the
/// clamped beam (l = 10, EI = 1.4e4, ρA = 1.2) is 1.8751² √(EI/ρA)/l² = 3.7977 rad/s.
#[test]
fn spinup_beam_first_frequency() {
    let beam = Beam {
        dim: Dim::Planar,
        elements: 8,
        length: 10.0,
        section: Section::planar(1.2, 2.8e7, 1.4e4),
        reference: Reference::Clamped { node: 0 },
        reduction: Reduction::Modes(4),
    };
    let body = beam.reduce().unwrap();
    let exact = BETA_L[0].powi(2) * (1.4e4f64 / 1.2).sqrt() / 100.0;
    assert!((exact - 3.7977).abs() < 5e-5);
    assert!(
        (body.frequencies[0] - 3.7977).abs() < 1e-4,
        "{}",
        body.frequencies[0]
    );
    assert!((body.frequencies[0] - exact).abs() < 1e-5 * exact);
    assert_eq!(beam.coordinates(), 4);
}

/// E21: the reduced mass matrix is the identity, the stiffness diag(ω²), and every
/// invariant is the nodal one transformed by T = B_r Φ.
#[test]
fn modal_reduction_normalizes() {
    for dim in [Dim::Planar, Dim::Spatial] {
        let section = match dim {
            Dim::Planar => Section::planar(1.2, 2.8e7, 1.4e4),
            Dim::Spatial => Section::spatial(1.2, 2.8e7, 1.1e4, 1.4e4, 9.0e3, 2e-4, 3e-4),
        };
        let mesh = Mesh::line(dim, 10.0, 8, section);
        let nodal = mesh.invariants().unwrap();
        let c = mesh.constrain(&Reference::Clamped { node: 0 }).unwrap();
        let modes = 6;
        let r = c.modes(modes).unwrap();
        let inv = &r.invariants;
        assert_eq!(inv.n, modes);
        for i in 0..modes {
            for j in 0..modes {
                let delta = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (inv.m_ff[i * modes + j] - delta).abs() < 1e-12,
                    "{dim:?} M[{i},{j}]"
                );
                let w2 = if i == j {
                    r.frequencies[i].powi(2)
                } else {
                    0.0
                };
                assert!(
                    (inv.k_ff[i * modes + j] - w2).abs() < 1e-11 * r.frequencies[modes - 1].powi(2),
                    "{dim:?} K[{i},{j}] = {}",
                    inv.k_ff[i * modes + j]
                );
            }
        }
        assert!(r.frequencies.windows(2).all(|w| w[0] <= w[1]));
        // Against the nodal invariants through the basis T (ndof × modes).
        let t = &r.basis;
        let nf = mesh.ndof();
        let direct = nodal.transform(t, modes);
        let scale = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for (name, a, b) in [
            ("s", &inv.s, &direct.s),
            ("ibar", &inv.ibar, &direct.ibar),
            ("sbar", &inv.sbar, &direct.sbar),
            ("k_ff", &inv.k_ff, &direct.k_ff),
        ] {
            let s = scale(b);
            for (x, y) in a.iter().zip(b.iter()) {
                assert!((x - y).abs() < 1e-11 * s, "{dim:?} {name}: {x} vs {y}");
            }
        }
        assert_eq!(t.len(), nf * modes);
        assert_eq!(
            (inv.mass, &inv.i1, &inv.i_kl),
            (nodal.mass, &nodal.i1, &nodal.i_kl)
        );
        assert!(inv.consistency() < 1e-12, "{}", inv.consistency());
        // The clamped node does not move in any mode.
        assert!(t[..dim.dofs_per_node() * modes].iter().all(|&x| x == 0.0));
    }
}

/// Spatial cantilever along a general direction of the body frame: axial, torsional
/// and both bending families converge to their closed forms, independently of the
/// beam's orientation.
#[test]
fn spatial_cantilever_closed_forms() {
    let (l, rho_a, ea, eiy, eiz, gj) = (2.0, 3.0, 5.0e4, 40.0, 90.0, 20.0);
    // Rotary inertia small enough that the bending frequencies are Euler–Bernoulli's to
    // 1e-7 (the Rayleigh correction is of relative order ρI/(ρA l²) · (βl)²).
    let (rho_iy, rho_iz) = (3e-9, 4e-9);
    let ip = rho_iy + rho_iz;
    let section = Section::spatial(rho_a, ea, eiy, eiz, gj, rho_iy, rho_iz);
    let n = 24;
    // Along the unit vector a, with the section's y axis fixed by a hint.
    let a = [0.48, 0.6, 0.64];
    let mut mesh = Mesh::new(Dim::Spatial);
    for i in 0..=n {
        let s = l * i as f64 / n as f64;
        mesh.add_node([s * a[0], s * a[1], s * a[2]]);
    }
    for i in 0..n {
        mesh.add_element(pfaff::flex::Element {
            nodes: [i, i + 1],
            section,
            y_axis: Some([0.0, 0.0, 1.0]),
        });
    }
    let c = mesh.constrain(&Reference::Clamped { node: 0 }).unwrap();
    let got = c.frequencies().unwrap();
    let pi = std::f64::consts::PI;
    let mut want = Vec::new();
    for (k, beta) in BETA_L.iter().take(3).enumerate() {
        want.push((beta / l).powi(2) * (eiy / rho_a).sqrt());
        want.push((beta / l).powi(2) * (eiz / rho_a).sqrt());
        let half = (2.0 * k as f64 + 1.0) * pi / 2.0 / l;
        want.push(half * (ea / rho_a).sqrt());
        want.push(half * (gj / ip).sqrt());
    }
    want.sort_by(f64::total_cmp);
    // Each closed-form frequency is matched by a computed one within 2e-5 relative.
    for w in &want[..6] {
        let best = got
            .iter()
            .map(|g| (g - w).abs() / w)
            .fold(f64::INFINITY, f64::min);
        assert!(best < 2e-5, "closed form {w}: nearest relative {best}");
    }
}

/// docs/theory.md §reduction, simply supported: a simply supported planar beam (u₁ = v₁ = v_N = 0) has the pinned–pinned
/// bending frequencies (kπ)² √(EI/ρA)/L²; a spatial one along x (6 coordinates) too.
#[test]
fn simply_supported_frequencies() {
    let pi = std::f64::consts::PI;
    let n = 16;
    for dim in [Dim::Planar, Dim::Spatial] {
        let section = match dim {
            Dim::Planar => Section::planar(1.0, 1e6, 1.0),
            Dim::Spatial => Section::spatial(1.0, 1e6, 1.0, 1.0, 1e6, 1e-9, 1e-9),
        };
        let mesh = Mesh::line(dim, 1.0, n, section);
        let c = mesh
            .constrain(&Reference::SimplySupported { first: 0, last: n })
            .unwrap();
        let got = c.frequencies().unwrap();
        for k in 1..=3 {
            let w = (k as f64 * pi).powi(2);
            let best = got
                .iter()
                .map(|g| (g - w).abs() / w)
                .fold(f64::INFINITY, f64::min);
            // Hermite elements: relative error of order (k h)⁴.
            println!("{dim:?}, simply supported, k = {k}: relative error {best:.2e}");
            assert!(
                best < 1e-5 * (k as f64).powi(4),
                "{dim:?}: (kπ)² = {w}, nearest relative {best}"
            );
        }
        // Spatial: bending in both planes, so each appears twice.
        if dim == Dim::Spatial {
            let w1 = pi * pi;
            let near = got.iter().filter(|g| (*g - w1).abs() < 1e-4 * w1).count();
            assert_eq!(near, 2);
        }
    }
}

/// B_rᵀ K B_r singular is a typed error naming how many rigid motions remain.
#[test]
fn reference_conditions_that_leave_rigid_motion() {
    let s = Section::planar(1.0, 1.0, 1.0);
    let mesh = Mesh::line(Dim::Planar, 1.0, 4, s);
    // Only the axial displacement of node 0: the lateral translation and the rotation remain.
    assert_eq!(
        mesh.constrain(&Reference::Coordinates(vec![0]))
            .unwrap_err(),
        FlexError::RigidBodyMotion {
            remaining: 2,
            total: 3
        }
    );
    // u and v at both ends but no rotation: still a pinned–pinned beam, fine;
    // u at both ends and v at one: the rotation about node 0 remains.
    assert!(mesh
        .constrain(&Reference::Coordinates(vec![0, 1, 12, 13]))
        .is_ok());
    assert_eq!(
        mesh.constrain(&Reference::Coordinates(vec![0, 1, 12]))
            .unwrap_err(),
        FlexError::RigidBodyMotion {
            remaining: 1,
            total: 3
        }
    );
    // A spatial beam along y, simply supported as a beam along x: the rotation about
    // its own axis (y) and a rotation about z (with a translation along x) remain, since
    // u_y at the far end is axial.
    let mut m = Mesh::new(Dim::Spatial);
    m.add_node([0.0, 0.0, 0.0]);
    m.add_node([0.0, 1.0, 0.0]);
    m.add_element(pfaff::flex::Element {
        nodes: [0, 1],
        section: Section::spatial(1.0, 1.0, 1.0, 1.0, 1.0, 0.1, 0.1),
        y_axis: None,
    });
    assert_eq!(
        m.constrain(&Reference::SimplySupported { first: 0, last: 1 })
            .unwrap_err(),
        FlexError::RigidBodyMotion {
            remaining: 2,
            total: 6
        }
    );
    assert_eq!(
        mesh.constrain(&Reference::Clamped { node: 9 }).unwrap_err(),
        FlexError::ReferenceIndex {
            what: "node",
            index: 9,
            len: 5
        }
    );
    let c = mesh.constrain(&Reference::Clamped { node: 0 }).unwrap();
    assert_eq!(
        c.modes(13).unwrap_err(),
        FlexError::Modes {
            requested: 13,
            available: 12
        }
    );
    assert_eq!(
        c.craig_bampton(&[0], 2).unwrap_err(),
        FlexError::Boundary { node: 0 }
    );
}

/// The generalized eigenvalues of a reduced body's (K_ff, M_ff), ascending, by faer's
/// QZ (generalized non-symmetric) decomposition: a path independent of the reduction's
/// Cholesky-based symmetric one.
fn reduced_frequencies(inv: &pfaff::flex::Invariants) -> Vec<f64> {
    let n = inv.n;
    let m = faer::Mat::<f64>::from_fn(n, n, |i, j| inv.m_ff[i * n + j]);
    let k = faer::Mat::<f64>::from_fn(n, n, |i, j| inv.k_ff[i * n + j]);
    let g = k.generalized_eigen(&m).unwrap();
    let mut w: Vec<f64> = (0..n)
        .map(|i| {
            let (a, b) = (g.S_a()[i], g.S_b()[i]);
            assert!(a.im.abs() < 1e-9 * a.re.abs());
            (a.re / b.re).sqrt()
        })
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

/// E22: Craig–Bampton with the tip as boundary reproduces the full model's low
/// frequencies, better with more fixed-interface modes; with every node in the boundary
/// it is the full model.
#[test]
fn craig_bampton_reproduces_low_frequencies() {
    let n = 16;
    let mesh = Mesh::line(Dim::Planar, 10.0, n, Section::planar(1.2, 2.8e7, 1.4e4));
    let c = mesh.constrain(&Reference::Clamped { node: 0 }).unwrap();
    let full = c.frequencies().unwrap();
    let mut last = f64::INFINITY;
    for modes in [2, 4, 8] {
        let cb = c.craig_bampton(&[n], modes).unwrap();
        assert_eq!(cb.invariants.n, 3 + modes);
        let got = reduced_frequencies(&cb.invariants);
        // Rayleigh–Ritz: each from above.
        let errs: Vec<f64> = (0..4)
            .map(|k| {
                assert!(
                    got[k] >= full[k] * (1.0 - 1e-12),
                    "{modes}: ω{k} {} < {}",
                    got[k],
                    full[k]
                );
                (got[k] - full[k]) / full[k]
            })
            .collect();
        println!(
            "Craig–Bampton, tip boundary + {modes} modes: relative errors of ω1..ω4 {:?}",
            errs.iter().map(|e| format!("{e:.2e}")).collect::<Vec<_>>()
        );
        let err = errs.iter().copied().fold(0.0, f64::max);
        assert!(err < last, "{modes} modes: {err}");
        last = err;
        assert!(cb.invariants.consistency() < 1e-12);
    }
    // Measured (16 elements, tip boundary): 2 modes 1.1 (ω4 has no shape to go to),
    // 4 modes 1.6e-3, 8 modes 1.7e-4 on the worst of ω1..ω4; ω1 alone 5.8e-5, 5.4e-6,
    // 3.0e-7.
    assert!(last < 5e-4, "{last}");
    // Every node a boundary node: T is a permutation, the frequencies are the full ones.
    let all: Vec<usize> = (1..=n).collect();
    let cb = c.craig_bampton(&all, 0).unwrap();
    let got = reduced_frequencies(&cb.invariants);
    for k in 0..10 {
        assert!((got[k] - full[k]).abs() < 1e-9 * full[k]);
    }
}
