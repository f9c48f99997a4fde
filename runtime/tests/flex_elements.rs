//! Beam elements and their assembly (docs/theory.md §finite-elements, case V9): element matrices,
//! element shape integrals, frames, rigid-body motions and the kinetic energy of rigid
//! motions of meshes in arbitrary orientation.

use pfaff::flex::{Dim, Element, FlexError, Invariants, Mesh, Section};

/// `|a - b| <= tol * max(1, |b|)` entry by entry, with the first failure reported.
fn assert_close(what: &str, got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what}: lengths");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (g - w).abs() <= tol * w.abs().max(1.0),
            "{what}[{i}]: got {g}, want {w}"
        );
    }
}

fn one_element(dim: Dim, l: f64, section: Section) -> Invariants {
    Mesh::line(dim, l, 1, section).invariants().unwrap()
}

/// E19: the planar consistent mass matrix (from the quadrature of E18) and stiffness.
#[test]
fn planar_element_matrices_e19() {
    let (l, rho_a, ea, ei) = (1.7, 2.3, 5.0e3, 31.0);
    let inv = one_element(Dim::Planar, l, Section::planar(rho_a, ea, ei));
    let f = rho_a * l / 420.0;
    #[rustfmt::skip]
    let m: Vec<f64> = [
        140.0, 0.0, 0.0, 70.0, 0.0, 0.0,
        0.0, 156.0, 22.0 * l, 0.0, 54.0, -13.0 * l,
        0.0, 22.0 * l, 4.0 * l * l, 0.0, 13.0 * l, -3.0 * l * l,
        70.0, 0.0, 0.0, 140.0, 0.0, 0.0,
        0.0, 54.0, 13.0 * l, 0.0, 156.0, -22.0 * l,
        0.0, -13.0 * l, -3.0 * l * l, 0.0, -22.0 * l, 4.0 * l * l,
    ].iter().map(|x| f * x).collect();
    assert_close("M_e", &inv.m_ff, &m, 1e-14);
    let (a, b12, b6, b4, b2) = (
        ea / l,
        12.0 * ei / l.powi(3),
        6.0 * ei / l.powi(2),
        4.0 * ei / l,
        2.0 * ei / l,
    );
    #[rustfmt::skip]
    let k = [
        a, 0.0, 0.0, -a, 0.0, 0.0,
        0.0, b12, b6, 0.0, -b12, b6,
        0.0, b6, b4, 0.0, -b6, b2,
        -a, 0.0, 0.0, a, 0.0, 0.0,
        0.0, -b12, -b6, 0.0, b12, -b6,
        0.0, b6, b2, 0.0, -b6, b4,
    ];
    assert_close("K_e", &inv.k_ff, &k, 1e-14);
    assert!((inv.mass - rho_a * l).abs() < 1e-14);
}

/// docs/theory.md §beam-elements: the element shape integrals ∫ρA S dx and ∫ρA SᵀĨS dx = S̄₂₁ − S̄₁₂ (V6, V9).
#[test]
fn planar_element_shape_integrals() {
    let (l, rho_a) = (0.8, 3.1);
    let inv = one_element(Dim::Planar, l, Section::planar(rho_a, 1.0, 1.0));
    let f = rho_a * l;
    #[rustfmt::skip]
    let s = [
        0.5, 0.0, 0.0, 0.5, 0.0, 0.0,
        0.0, 0.5, l / 12.0, 0.0, 0.5, -l / 12.0,
    ].map(|x| f * x);
    assert_close("S̄", &inv.s, &s, 1e-14);
    let g = rho_a * l / 420.0;
    #[rustfmt::skip]
    let sis = [
        0.0, -147.0, -21.0 * l, 0.0, -63.0, 14.0 * l,
        147.0, 0.0, 0.0, 63.0, 0.0, 0.0,
        21.0 * l, 0.0, 0.0, 14.0 * l, 0.0, 0.0,
        0.0, -63.0, -14.0 * l, 0.0, -147.0, 21.0 * l,
        63.0, 0.0, 0.0, 147.0, 0.0, 0.0,
        -14.0 * l, 0.0, 0.0, -21.0 * l, 0.0, 0.0,
    ].map(|x| g * x);
    let got: Vec<f64> = inv
        .sbar(1, 0)
        .iter()
        .zip(inv.sbar(0, 1))
        .map(|(a, b)| a - b)
        .collect();
    assert_close("S̄21 − S̄12", &got, &sis, 1e-14);
    // Ī1 = ∫ρA (x, 0) dx, I_11 = ∫ρA x² dx.
    assert_close("Ī1", &inv.i1, &[rho_a * l * l / 2.0, 0.0], 1e-14);
    assert_close(
        "I_kl",
        &inv.i_kl,
        &[rho_a * l.powi(3) / 3.0, 0.0, 0.0, 0.0],
        1e-14,
    );
}

/// docs/theory.md §beam-elements: the spatial stiffness table and the consistent-mass check values (with rotary
/// inertia), from the quadrature of E20.
#[test]
fn spatial_element_matrices() {
    let (l, rho_a, rho_iy, rho_iz) = (1.3, 2.0, 0.011, 0.027);
    let (ea, eiy, eiz, gj) = (7.0e3, 13.0, 29.0, 5.0);
    let section = Section::spatial(rho_a, ea, eiy, eiz, gj, rho_iy, rho_iz);
    let inv = one_element(Dim::Spatial, l, section);
    let n = 12;
    let at = |m: &[f64], i: usize, j: usize| m[(i - 1) * n + (j - 1)];
    // Every upper-triangle entry of K: the table's, all others zero.
    let mut k = vec![0.0; n * n];
    let (l2, l3) = (l * l, l * l * l);
    let mut put = |i: usize, j: usize, v: f64| {
        k[(i - 1) * n + j - 1] = v;
        k[(j - 1) * n + i - 1] = v;
    };
    for (i, j, s) in [(1, 1, 1.0), (7, 7, 1.0), (1, 7, -1.0)] {
        put(i, j, s * ea / l);
    }
    for (i, j, s) in [(2, 2, 1.0), (8, 8, 1.0), (2, 8, -1.0)] {
        put(i, j, s * 12.0 * eiz / l3);
    }
    for (i, j, s) in [(2, 6, 1.0), (2, 12, 1.0), (6, 8, -1.0), (8, 12, -1.0)] {
        put(i, j, s * 6.0 * eiz / l2);
    }
    for (i, j, s) in [(3, 3, 1.0), (9, 9, 1.0), (3, 9, -1.0)] {
        put(i, j, s * 12.0 * eiy / l3);
    }
    for (i, j, s) in [(3, 5, 1.0), (3, 11, 1.0), (5, 9, -1.0), (9, 11, -1.0)] {
        put(i, j, -s * 6.0 * eiy / l2);
    }
    for (i, j, s) in [(4, 4, 1.0), (10, 10, 1.0), (4, 10, -1.0)] {
        put(i, j, s * gj / l);
    }
    put(5, 5, 4.0 * eiy / l);
    put(11, 11, 4.0 * eiy / l);
    put(5, 11, 2.0 * eiy / l);
    put(6, 6, 4.0 * eiz / l);
    put(12, 12, 4.0 * eiz / l);
    put(6, 12, 2.0 * eiz / l);
    assert_close("K (§beam-elements)", &inv.k_ff, &k, 1e-14);

    // ρA = rho_a, ρI_y = rho_iy, ρI_z = rho_iz in the check values.
    let m = &inv.m_ff;
    let checks = [
        ("M11", at(m, 1, 1), rho_a * l / 3.0),
        ("M17", at(m, 1, 7), rho_a * l / 6.0),
        (
            "M22",
            at(m, 2, 2),
            (13.0 * rho_a * l2 + 42.0 * rho_iz) / (35.0 * l),
        ),
        (
            "M26",
            at(m, 2, 6),
            (11.0 * rho_a * l2 + 21.0 * rho_iz) / 210.0,
        ),
        (
            "M28",
            at(m, 2, 8),
            3.0 * (3.0 * rho_a * l2 - 28.0 * rho_iz) / (70.0 * l),
        ),
        (
            "M2,12",
            at(m, 2, 12),
            -(13.0 * rho_a * l2 - 42.0 * rho_iz) / 420.0,
        ),
        ("M44", at(m, 4, 4), l * (rho_iy + rho_iz) / 3.0),
        ("M55", at(m, 5, 5), l * (rho_a * l2 + 14.0 * rho_iy) / 105.0),
        (
            "M35",
            at(m, 3, 5),
            -(11.0 * rho_a * l2 + 21.0 * rho_iy) / 210.0,
        ),
    ];
    for (name, got, want) in checks {
        assert!(
            (got - want).abs() <= 1e-14 * want.abs().max(1.0),
            "{name}: got {got}, want {want}"
        );
    }
    // The z counterparts by the symmetry y ↔ z of the section (θ_y = −w′).
    assert!((at(m, 3, 3) - (13.0 * rho_a * l2 + 42.0 * rho_iy) / (35.0 * l)).abs() < 1e-14);
    assert!((at(m, 6, 6) - l * (rho_a * l2 + 14.0 * rho_iz) / 105.0).abs() < 1e-14);
    // Symmetric, M positive definite (every principal minor via Cholesky in the
    // reduction tests), and the section's offsets integrate to nothing.
    assert!(inv.consistency() < 1e-15, "{}", inv.consistency());
    assert_close("Ī1", &inv.i1, &[rho_a * l2 / 2.0, 0.0, 0.0], 1e-14);
    // I_kl = ∫ρ x_k x_l dV includes the section: I_22 = ρI_z l, I_33 = ρI_y l.
    assert_close(
        "I_kl",
        &inv.i_kl,
        &[
            rho_a * l3 / 3.0,
            0.0,
            0.0,
            0.0,
            rho_iz * l,
            0.0,
            0.0,
            0.0,
            rho_iy * l,
        ],
        1e-14,
    );
}

/// A deterministic generator for test geometry (xorshift).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// A bent, branched mesh in general position: a zig-zag chain with a side branch.
fn bent_mesh(dim: Dim, rng: &mut Rng) -> Mesh {
    let mut mesh = Mesh::new(dim);
    let z = |r: &mut Rng| if dim == Dim::Spatial { r.next() } else { 0.0 };
    let mut p = [0.1, -0.2, 0.05 * z(rng)];
    mesh.add_node(p);
    for i in 0..5 {
        p = [
            p[0] + 0.6 + 0.3 * rng.next(),
            p[1] + 0.5 * rng.next(),
            p[2] + 0.5 * z(rng),
        ];
        mesh.add_node(p);
        let section = match dim {
            Dim::Planar => Section::planar(1.0 + 0.5 * rng.next(), 100.0, 3.0 + rng.next()),
            Dim::Spatial => Section::spatial(
                1.0 + 0.5 * rng.next(),
                100.0,
                2.0 + rng.next(),
                3.0 + rng.next(),
                1.5,
                0.01 + 0.005 * rng.next(),
                0.02 + 0.005 * rng.next(),
            ),
        };
        mesh.add_element(Element {
            nodes: [i, i + 1],
            section,
            y_axis: if dim == Dim::Spatial && i % 2 == 1 {
                Some([rng.next(), rng.next(), rng.next()])
            } else {
                None
            },
        });
    }
    let q = mesh.add_node([1.0, 1.5, 0.7 * z(rng)]);
    let first = mesh.elements()[0];
    mesh.add_element(Element {
        nodes: [2, q],
        ..first
    });
    mesh
}

/// E16/E17 assembly: K_ff annihilates the rigid-body motions of a bent mesh with
/// elements in every orientation, and has exactly that null space (the reference check
/// relies on it).
#[test]
fn stiffness_null_space_is_the_rigid_motions() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for dim in [Dim::Planar, Dim::Spatial] {
        let mesh = bent_mesh(dim, &mut rng);
        let inv = mesh.invariants().unwrap();
        let (n, r) = (mesh.ndof(), dim.rigid_motions());
        let rigid = mesh.rigid_motions();
        let kmax = inv.k_ff.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for c in 0..r {
            for i in 0..n {
                let f: f64 = (0..n).map(|j| inv.k_ff[i * n + j] * rigid[j * r + c]).sum();
                assert!(
                    f.abs() < 1e-12 * kmax * 4.0,
                    "{dim:?}: (K R)[{i},{c}] = {f}"
                );
            }
        }
        // Exactly r zero eigenvalues: the eigenvalues of K relative to the largest.
        let k = faer::Mat::<f64>::from_fn(n, n, |i, j| inv.k_ff[i * n + j]);
        let ev = k.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        let zeros = ev.iter().filter(|&&v| v.abs() < 1e-10 * ev[n - 1]).count();
        assert_eq!(zeros, r, "{dim:?}: eigenvalues {ev:?}");
        assert!(ev[0] > -1e-10 * ev[n - 1]);
        assert!(inv.consistency() < 1e-14, "{}", inv.consistency());
    }
}

/// The kinetic energy of a rigid motion of a bent mesh, ½ q̇ᵀ M_ff q̇, equals the rigid
/// body's ½ m v² + ½ ωᵀ J ω with J from m, Ī1 and I_kl (E10): the shape functions
/// (E18, E20, section offsets included) reproduce rigid motions exactly, the frames are
/// consistent and the integrals agree with one another.
#[test]
fn rigid_motion_kinetic_energy() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for dim in [Dim::Planar, Dim::Spatial] {
        let mesh = bent_mesh(dim, &mut rng);
        let inv = mesh.invariants().unwrap();
        let (n, r, d) = (mesh.ndof(), dim.rigid_motions(), dim.d());
        let rigid = mesh.rigid_motions();
        // Centroid of the nodes (the rotations' axis point) and the inertia about it.
        let c: Vec<f64> = (0..d)
            .map(|k| mesh.nodes().iter().map(|p| p[k]).sum::<f64>() / mesh.nodes().len() as f64)
            .collect();
        let u = |k: usize, l: usize| {
            inv.i_kl[k * d + l] - c[k] * inv.i1[l] - inv.i1[k] * c[l] + inv.mass * c[k] * c[l]
        };
        for _ in 0..5 {
            let a: Vec<f64> = (0..r).map(|_| rng.next()).collect();
            let qd: Vec<f64> = (0..n)
                .map(|i| (0..r).map(|c| rigid[i * r + c] * a[c]).sum())
                .collect();
            let t2: f64 = (0..n)
                .map(|i| qd[i] * (0..n).map(|j| inv.m_ff[i * n + j] * qd[j]).sum::<f64>())
                .sum();
            // Velocity of a point: v + ω × (x − c).
            let want = match dim {
                Dim::Planar => {
                    let (v, w) = ([a[0], a[1]], a[2]);
                    let jc = u(0, 0) + u(1, 1);
                    // ∫ρ (v + ω ẑ × (x − c))² = m v² + 2 v·(ω ẑ × (Ī1 − m c)) + ω² J
                    let s = [inv.i1[0] - inv.mass * c[0], inv.i1[1] - inv.mass * c[1]];
                    inv.mass * (v[0] * v[0] + v[1] * v[1])
                        + 2.0 * w * (v[1] * s[0] - v[0] * s[1])
                        + w * w * jc
                }
                Dim::Spatial => {
                    let (v, w) = ([a[0], a[1], a[2]], [a[3], a[4], a[5]]);
                    let tr = u(0, 0) + u(1, 1) + u(2, 2);
                    let mut ww = 0.0;
                    for k in 0..3 {
                        for l in 0..3 {
                            let j = if k == l { tr } else { 0.0 } - u(k, l);
                            ww += w[k] * j * w[l];
                        }
                    }
                    let s = [
                        inv.i1[0] - inv.mass * c[0],
                        inv.i1[1] - inv.mass * c[1],
                        inv.i1[2] - inv.mass * c[2],
                    ];
                    let wxs = [
                        w[1] * s[2] - w[2] * s[1],
                        w[2] * s[0] - w[0] * s[2],
                        w[0] * s[1] - w[1] * s[0],
                    ];
                    inv.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
                        + 2.0 * (v[0] * wxs[0] + v[1] * wxs[1] + v[2] * wxs[2])
                        + ww
                }
            };
            assert!(
                (t2 - want).abs() < 1e-12 * want.abs(),
                "{dim:?}: {t2} vs {want}"
            );
        }
    }
}

/// A planar centre-line body has ū_o = N q_o (docs/theory.md §finite-elements), q_o the nodal positions with zero
/// rotations: then Ī1 = S̄ q_o, Ī_kl = q_oᵀ S̄_kl and I_kl = q_oᵀ S̄_kl q_o (E10, E11).
#[test]
fn planar_centre_line_integrals_from_nodal_positions() {
    let mut rng = Rng(77);
    let mesh = bent_mesh(Dim::Planar, &mut rng);
    let inv = mesh.invariants().unwrap();
    let n = mesh.ndof();
    let mut q0 = vec![0.0; n];
    for (i, p) in mesh.nodes().iter().enumerate() {
        q0[3 * i] = p[0];
        q0[3 * i + 1] = p[1];
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    for k in 0..2 {
        let s_k = &inv.s[k * n..][..n];
        assert!((dot(s_k, &q0) - inv.i1[k]).abs() < 1e-13 * inv.mass);
        for l in 0..2 {
            let b = inv.sbar(k, l);
            let qb: Vec<f64> = (0..n)
                .map(|j| (0..n).map(|i| q0[i] * b[i * n + j]).sum())
                .collect();
            assert_close("Ī_kl", inv.ibar(k, l), &qb, 1e-13);
            assert!((dot(&qb, &q0) - inv.i_kl[k * 2 + l]).abs() < 1e-12 * inv.i_kl[0].abs());
        }
    }
}

/// The flat layout of a data slot round-trips; a wrong length is a typed error.
#[test]
fn flat_layout_round_trip() {
    let inv = one_element(
        Dim::Spatial,
        1.0,
        Section::spatial(1.0, 1.0, 1.0, 1.0, 1.0, 0.1, 0.1),
    );
    let len = Invariants::flat_len(3, 12);
    assert_eq!(len, 1 + 3 + 36 + 9 + 108 + 1296 + 288);
    let mut flat = vec![0.0; len];
    inv.write_flat(&mut flat).unwrap();
    assert_eq!(flat[0], inv.mass);
    assert_eq!(Invariants::from_flat(3, 12, &flat).unwrap(), inv);
    assert_eq!(
        inv.write_flat(&mut flat[1..]),
        Err(FlexError::Layout {
            d: 3,
            n: 12,
            expected: len,
            got: len - 1
        })
    );
}

/// Defects of a mesh are typed errors.
#[test]
fn mesh_defects() {
    let s = Section::planar(1.0, 1.0, 1.0);
    assert_eq!(
        Mesh::new(Dim::Planar).invariants(),
        Err(FlexError::NoElements)
    );
    let mut m = Mesh::line(Dim::Planar, 1.0, 2, s);
    m.add_node([5.0, 0.0, 0.0]);
    assert_eq!(m.invariants(), Err(FlexError::Disconnected { node: 3 }));
    let mut m = Mesh::line(Dim::Planar, 1.0, 1, s);
    m.add_element(Element {
        nodes: [1, 7],
        section: s,
        y_axis: None,
    });
    assert!(matches!(
        m.invariants(),
        Err(FlexError::NodeIndex { node: 7, .. })
    ));
    let bad = Mesh::line(Dim::Planar, 1.0, 1, Section::planar(1.0, -1.0, 1.0));
    assert!(matches!(
        bad.invariants(),
        Err(FlexError::Section { field: "ea", .. })
    ));
    // A spatial section without rotary inertia has no inertia of torsion.
    let no_rot = Mesh::line(
        Dim::Spatial,
        1.0,
        1,
        Section::spatial(1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0),
    );
    assert!(matches!(
        no_rot.invariants(),
        Err(FlexError::Section {
            field: "rho_iy + rho_iz",
            ..
        })
    ));
    let mut hint = Mesh::line(
        Dim::Spatial,
        1.0,
        1,
        Section::spatial(1.0, 1.0, 1.0, 1.0, 1.0, 0.1, 0.1),
    );
    let e = hint.elements()[0];
    hint = {
        let mut m = Mesh::new(Dim::Spatial);
        m.add_node(hint.nodes()[0]);
        m.add_node(hint.nodes()[1]);
        m.add_element(Element {
            y_axis: Some([2.0, 0.0, 0.0]),
            ..e
        });
        m
    };
    assert!(matches!(
        hint.invariants(),
        Err(FlexError::AxisHint { element: 0, .. })
    ));
}
