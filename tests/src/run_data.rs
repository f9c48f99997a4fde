//! Run-time data slots (`static name: Data = ..;`): a beam-element body's invariants
//! computed by `pfaff::flex` from the parameters when the model is built and when a
//! parameter changes, read by the generated code like parameters; slots set by the
//! program with typed errors.

use pfaff::flex::{Beam, Dim, Invariants, Reduction, Reference, Section};
use pfaff::{DataError, Mechanism, MechanismExt};

/// The spin-up beam of docs/models.md clamped in a fixed frame, reduced to its two
/// lowest modes `p1, p2`, written with the slot's modal mass and stiffness (flat layout
/// of `Invariants::write_flat` for d = 2, n = 2: `M_ff` at 35..39, `K_ff` at 39..43).
#[pfaff::mechanism]
mod clamped_beam {
    /// Length [m].
    const l: f64 = 10.0;
    /// Axial stiffness [N].
    const ea: f64 = 2.8e7;
    /// Bending stiffness [N m²].
    const ei: f64 = 1.4e4;
    /// Mass per length [kg/m].
    const rho_a: f64 = 1.2;
    /// The beam's invariants: 8 elements, clamped at node 0, 2 modes.
    static rod: Data = Beam {
        elements: 8,
        length: l,
        rho_a,
        ea,
        ei,
        modes: 2,
        reference: Clamped,
    };
    /// Exported invariants of another body, set by the program.
    static fe: Data = Data { len: 3 };
    static p1: Coordinate = Coordinate { q0: 0.1 };
    static p2: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * (rod[35] * p1.dot() * p1.dot()
            + 2.0 * rod[36] * p1.dot() * p2.dot()
            + rod[38] * p2.dot() * p2.dot())
    }
    fn potential_energy() -> f64 {
        0.5 * (rod[39] * p1 * p1 + 2.0 * rod[40] * p1 * p2 + rod[42] * p2 * p2) + fe[0] * p1
    }
}

fn reference_beam(ei: f64) -> Beam {
    Beam {
        dim: Dim::Planar,
        elements: 8,
        length: 10.0,
        section: Section::planar(1.2, 2.8e7, ei),
        reference: Reference::Clamped { node: 0 },
        reduction: Reduction::Modes(2),
    }
}

/// The slot of a beam: `Beam::write_slot`'s layout, the invariants first.
fn slot(beam: &Beam) -> Vec<f64> {
    let mut out = vec![0.0; beam.slot_len()];
    beam.write_slot(&mut out).unwrap();
    let mut flat = vec![0.0; Invariants::flat_len(beam.dim.d(), beam.coordinates())];
    beam.invariants().unwrap().write_flat(&mut flat).unwrap();
    assert_eq!(&out[..flat.len()], &flat[..]);
    out
}

#[test]
fn beam_slot_is_filled_from_the_parameters() {
    let mut model = clamped_beam::Model::default();
    let info = model.info();
    assert_eq!(info.data.len(), 2);
    // 43 invariants, length and EA, T (27 nodal coordinates × 2), K_Ω (2 × 2).
    assert_eq!(
        (info.data[0].name, info.data[0].len),
        ("rod", 43 + 2 + 54 + 4)
    );
    assert_eq!(Invariants::flat_len(2, 2), 43);
    assert_eq!(reference_beam(1.4e4).slot_len(), 103);
    assert_eq!((info.data[1].name, info.data[1].len), ("fe", 3));
    assert_eq!(model.data(0), &slot(&reference_beam(1.4e4))[..]);
    assert_eq!(model.data(1), &[0.0; 3]);
    // The generated mass matrix is the modal one (identity), the forces −K p with
    // K = diag(ω1², ω2²), ω1 = 3.7977 rad/s (docs/models.md).
    let mut m = [0.0; 4];
    model.mass_matrix_dense_inplace(0.0, &[0.3, -0.2], &mut m);
    for (k, x) in m.iter().enumerate() {
        let want = if k % 3 == 0 { 1.0 } else { 0.0 };
        assert!((x - want).abs() < 1e-12, "M[{k}] = {x}");
    }
    let mut f = [0.0; 2];
    model.forces(0.0, &[1.0, 0.0], &[0.0, 0.0], &mut f);
    assert!((-f[0] - 3.7977f64.powi(2)).abs() < 1e-3 * 14.42, "{f:?}");
    assert!(f[1].abs() < 1e-9 * -f[0]);
    // A parameter change recomputes the slot: ω² scales with EI.
    model.set_parameter(2, 2.8e4);
    assert_eq!(model.data(0), &slot(&reference_beam(2.8e4))[..]);
    let mut f2 = [0.0; 2];
    model.forces(0.0, &[1.0, 0.0], &[0.0, 0.0], &mut f2);
    assert!((f2[0] / f[0] - 2.0).abs() < 1e-12);
    // A parameter that makes no beam fills the slot with NaN and says why.
    let mut bad = model;
    bad.set_parameter(2, -1.0);
    assert!(bad.data(0).iter().all(|x| x.is_nan()));
    assert!(matches!(
        bad.refresh_data(),
        Err(pfaff::flex::FlexError::Section { field: "ei_z", .. })
    ));
}

#[test]
fn program_slot_is_set_with_typed_errors() {
    let mut model = clamped_beam::Model::default();
    model.set_data(1, &[2.0, 0.0, 0.0]).unwrap();
    assert_eq!(model.data(1), &[2.0, 0.0, 0.0]);
    // `fe[0] p1` in V: a constant force −fe[0] on p1.
    let mut f = [0.0; 2];
    model.forces(0.0, &[0.0, 0.0], &[0.0, 0.0], &mut f);
    assert!((f[0] + 2.0).abs() < 1e-12);
    assert_eq!(
        model.set_data(1, &[1.0]),
        Err(DataError::Length {
            slot: "fe",
            expected: 3,
            got: 1
        })
    );
    assert_eq!(
        model.set_data(1, &[1.0, f64::INFINITY, 0.0]),
        Err(DataError::NotFinite {
            slot: "fe",
            index: 1,
            value: f64::INFINITY
        })
    );
    assert_eq!(
        model.set_data(2, &[1.0]),
        Err(DataError::NoSlot {
            model: "clamped_beam",
            index: 2
        })
    );
    assert_eq!(model.data(1), &[2.0, 0.0, 0.0]);
}

/// A spatial beam reduced by Craig–Bampton and a simply supported planar one: the
/// emitted calls build the same bodies as `pfaff::flex` called directly.
#[pfaff::mechanism]
mod beam_kinds {
    const l: f64 = 2.0;
    const rho_a: f64 = 3.0;
    const ea: f64 = 5.0e4;
    const gj: f64 = 20.0;
    /// Spatial, clamped at node 0, the tip (node 4) as boundary and 2 fixed-interface
    /// modes: 6 + 2 coordinates.
    static arm: Data = SpatialBeam {
        elements: 4,
        length: l,
        rho_a,
        ea,
        ei_y: 40.0,
        ei_z: 90.0,
        gj,
        rho_iy: 1e-3,
        rho_iz: 2e-3,
        modes: 2,
        boundary: [4],
    };
    /// Planar, simply supported between nodes 0 and 6, 3 modes.
    static span: Data = Beam {
        elements: 6,
        length: 2.0 * l,
        rho_a,
        ea,
        ei: 7.0,
        modes: 3,
        reference: SimplySupported,
    };
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * (arm[0] + span[0]) * x.dot().powi(2)
    }
}

#[test]
fn spatial_craig_bampton_and_simply_supported_slots() {
    let model = beam_kinds::Model::default();
    let arm = Beam {
        dim: Dim::Spatial,
        elements: 4,
        length: 2.0,
        section: Section::spatial(3.0, 5.0e4, 40.0, 90.0, 20.0, 1e-3, 2e-3),
        reference: Reference::Clamped { node: 0 },
        reduction: Reduction::CraigBampton {
            boundary: vec![4],
            modes: 2,
        },
    };
    let span = Beam {
        dim: Dim::Planar,
        elements: 6,
        length: 4.0,
        section: Section::planar(3.0, 5.0e4, 7.0),
        reference: Reference::SimplySupported { first: 0, last: 6 },
        reduction: Reduction::Modes(3),
    };
    for (k, beam, n) in [(0, arm, 8), (1, span, 3)] {
        assert_eq!(beam.coordinates(), n);
        let want = slot(&beam);
        assert_eq!(model.info().data[k].len as usize, want.len());
        assert_eq!(model.data(k), &want[..]);
    }
    // The kinetic energy reads the two masses: ρA (l + 2l).
    let mut m = [0.0];
    model.mass_matrix(0.0, &[0.0], &mut m);
    assert!((m[0] - 3.0 * 6.0).abs() < 1e-12);
}

/// A planar beam-element body on a free hub: the `Deformable` body reads its invariants
/// and stiffness from the beam slot (8 elements, clamped at the hub, 4 modes).
#[pfaff::mechanism]
mod hub_beam {
    const l: f64 = 10.0;
    const ea: f64 = 2.8e7;
    const ei: f64 = 1.4e4;
    const rho_a: f64 = 1.2;
    static rod_fe: Data = Beam {
        elements: 8,
        length: l,
        rho_a,
        ea,
        ei,
        modes: 4,
        reference: Clamped,
    };
    static theta: Coordinate = Coordinate {};
    static p1: Coordinate = Coordinate {};
    static p2: Coordinate = Coordinate {};
    static p3: Coordinate = Coordinate {};
    static p4: Coordinate = Coordinate {};
    static rod: Body = Deformable {
        origin: [0.0, 0.0],
        angle: theta,
        elastic: [p1, p2, p3, p4],
        data: rod_fe,
    };
}

/// The beam of `hub_beam` with 16 elements and 12 modes: from 8 modes on, the generated
/// code contracts the slot's blocks with `q_f`, `q̇_f` in loops (`dot_strided`).
#[pfaff::mechanism]
mod hub_beam12 {
    static rod_fe: Data = Beam {
        elements: 16,
        length: 10.0,
        rho_a: 1.2,
        ea: 2.8e7,
        ei: 1.4e4,
        modes: 12,
        reference: Clamped,
    };
    static theta: Coordinate = Coordinate {};
    static p1: Coordinate = Coordinate {};
    static p2: Coordinate = Coordinate {};
    static p3: Coordinate = Coordinate {};
    static p4: Coordinate = Coordinate {};
    static p5: Coordinate = Coordinate {};
    static p6: Coordinate = Coordinate {};
    static p7: Coordinate = Coordinate {};
    static p8: Coordinate = Coordinate {};
    static p9: Coordinate = Coordinate {};
    static p10: Coordinate = Coordinate {};
    static p11: Coordinate = Coordinate {};
    static p12: Coordinate = Coordinate {};
    static rod: Body = Deformable {
        origin: [0.0, 0.0],
        angle: theta,
        elastic: [p1, p2, p3, p4, p5, p6, p7, p8, p9, p10, p11, p12],
        data: rod_fe,
    };
}

/// docs/theory.md V6 on a body from beam elements: the generated mass matrix and forces of
/// `hub_beam` equal E13 and E14 (with `−K_ff q_f`) evaluated from the `pfaff::flex`
/// invariants, at random states, to 1e-12 relative.
#[test]
fn deformable_body_from_a_beam_slot_matches_e13_e14() {
    check_e13_e14(&hub_beam::Model::default(), 8, 4);
}

/// As [`deformable_body_from_a_beam_slot_matches_e13_e14`] with 12 modes, whose
/// generated code evaluates the contractions in loops.
#[test]
fn deformable_body_of_many_modes_matches_e13_e14() {
    check_e13_e14(&hub_beam12::Model::default(), 16, 12);
}

fn check_e13_e14(model: &dyn Mechanism, elements: usize, n: usize) {
    let inv = Beam {
        dim: Dim::Planar,
        elements,
        length: 10.0,
        section: Section::planar(1.2, 2.8e7, 1.4e4),
        reference: Reference::Clamped { node: 0 },
        reduction: Reduction::Modes(n),
    }
    .invariants()
    .unwrap();
    let nq = n + 1;
    let mut seed = 11_u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mat_vec = |m: &[f64], v: &[f64]| -> Vec<f64> {
        (0..n).map(|i| dot(&m[i * n..(i + 1) * n], v)).collect()
    };
    for _ in 0..10 {
        let q: Vec<f64> = (0..nq).map(|_| rnd()).collect();
        let qd: Vec<f64> = (0..nq).map(|_| 3.0 * rnd()).collect();
        let (p, pd, w) = (&q[1..], &qd[1..], qd[0]);
        // E11: U_kl, and E13's blocks.
        let u = |k: usize, l: usize| {
            inv.i_kl[k * 2 + l]
                + dot(inv.ibar(k, l), p)
                + dot(inv.ibar(l, k), p)
                + dot(p, &mat_vec(inv.sbar(k, l), p))
        };
        let mut m = vec![0.0; nq * nq];
        m[0] = u(0, 0) + u(1, 1);
        let s12: Vec<f64> = (0..n * n)
            .map(|i| inv.sbar(0, 1)[i] - inv.sbar(1, 0)[i])
            .collect();
        // pᵀ(S̄12 − S̄21): row vector.
        let ps: Vec<f64> = (0..n)
            .map(|j| (0..n).map(|i| p[i] * s12[i * n + j]).sum())
            .collect();
        for j in 0..n {
            let c = inv.ibar(0, 1)[j] - inv.ibar(1, 0)[j] + ps[j];
            m[j + 1] = c;
            m[(j + 1) * nq] = c;
            for k in 0..n {
                m[(j + 1) * nq + k + 1] = inv.m_ff[j * n + k];
            }
        }
        // E14 and −K q_f.
        let mut f = vec![0.0; nq];
        let i11_22: Vec<f64> = (0..n)
            .map(|j| inv.ibar(0, 0)[j] + inv.ibar(1, 1)[j])
            .collect();
        let pm = (0..n)
            .map(|j| (0..n).map(|i| p[i] * inv.m_ff[i * n + j]).sum::<f64>())
            .collect::<Vec<_>>();
        f[0] = -2.0 * w * (0..n).map(|j| (i11_22[j] + pm[j]) * pd[j]).sum::<f64>();
        let s21m12: Vec<f64> = s12.iter().map(|x| -x).collect();
        let cor = mat_vec(&s21m12, pd);
        let kp = mat_vec(&inv.k_ff, p);
        for j in 0..n {
            let cent = inv.ibar(0, 0)[j]
                + inv.ibar(1, 1)[j]
                + mat_vec(inv.sbar(0, 0), p)[j]
                + mat_vec(inv.sbar(1, 1), p)[j];
            f[j + 1] = w * w * cent - 2.0 * w * cor[j] - kp[j];
        }
        let mut mg = vec![0.0; nq * nq];
        model.mass_matrix_dense_inplace(0.0, &q, &mut mg);
        let mut fg = vec![0.0; nq];
        model.forces(0.0, &q, &qd, &mut fg);
        let scale_m = m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for i in 0..nq * nq {
            assert!(
                (mg[i] - m[i]).abs() < 1e-12 * scale_m,
                "M[{i}]: {} vs {}",
                mg[i],
                m[i]
            );
        }
        let scale_f = f.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for i in 0..nq {
            assert!(
                (fg[i] - f[i]).abs() < 1e-11 * scale_f,
                "Q[{i}]: {} vs {}",
                fg[i],
                f[i]
            );
        }
    }
}
