//! Reactions per joint (`pfaff::JointReactions`): against the multipliers of the
//! hand-written slider-crank, against the closed form of a hanging spatial body,
//! Newton's third law and the balance of each body, and the fit at random states of
//! every joint kind.

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::{
    DynamicsParams, JointReactions, Mechanism, MechanismExt, ReactionAnalysis, Reactions,
    Workspace, Wrench,
};
use pfaff_models::{slider_crank, slider_crank_bodies};

use super::models::{planar_zoo, spatial_zoo};

/// A rigid body hanging from a spherical joint at the ground's origin, oriented by
/// Euler parameters: the joint is at `[0, 0, d]` in body axes, above the centre.
#[pfaff::mechanism]
pub mod hanging_body {
    /// Mass [kg].
    const m: f64 = 2.0;
    /// Distance from the joint to the centre of mass [m].
    const d: f64 = 0.5;
    /// Gravity along −z [m/s²].
    const g: f64 = 9.81;

    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static z: Coordinate = Coordinate { q0: -d };
    static e0: Coordinate = Coordinate { q0: 1.0 };
    static e1: Coordinate = Coordinate {};
    static e2: Coordinate = Coordinate {};
    static e3: Coordinate = Coordinate {};

    static gravity: Force = Gravity {
        acceleration: [0.0, 0.0, -g],
    };
    static body: Body = Body {
        origin: [x, y, z],
        rotation: euler_parameters(e0, e1, e2, e3),
        mass: m,
        inertia: diag(0.3, 0.4, 0.2),
    };
    static pivot: Joint = Spherical {
        a: body,
        at_a: [0.0, 0.0, d],
    };
}

/// Two free bodies, one by Euler parameters, one by successive rotations, joined by a
/// universal joint (spatial_zoo's universal joint joins a relative frame that cannot
/// always meet it).
#[pfaff::mechanism]
pub mod universal_pair {
    static x1: Coordinate = Coordinate {};
    static y1: Coordinate = Coordinate {};
    static z1: Coordinate = Coordinate {};
    static e0: Coordinate = Coordinate { q0: 1.0 };
    static e1: Coordinate = Coordinate {};
    static e2: Coordinate = Coordinate {};
    static e3: Coordinate = Coordinate {};
    static x2: Coordinate = Coordinate {};
    static y2: Coordinate = Coordinate {};
    static z2: Coordinate = Coordinate {};
    static psi: Coordinate = Coordinate {};
    static th: Coordinate = Coordinate {};
    static ph: Coordinate = Coordinate {};

    static b1: Body = Body {
        origin: [x1, y1, z1],
        rotation: euler_parameters(e0, e1, e2, e3),
        mass: 1.0,
        inertia: diag(0.1, 0.2, 0.3),
    };
    static b2: Body = Body {
        origin: [x2, y2, z2],
        rotation: rot_z(psi) * rot_x(th) * rot_y(ph),
        mass: 2.0,
        inertia: diag(0.2, 0.3, 0.25),
    };
    static cross: Joint = Universal {
        a: b1,
        at_a: [0.1, 0.2, 0.0],
        axis_a: [1.0, 0.0, 0.0],
        b: b2,
        at_b: [0.0, 0.2, -0.1],
        axis_b: [0.0, 1.0, 0.0],
    };
}

fn reactions_at(m: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64]) -> Reactions {
    let info = m.info();
    let mut ws = Workspace::new(info).unwrap();
    let mut analysis = ReactionAnalysis::new(info, DynamicsParams::default()).unwrap();
    let mut r = Reactions::new(info);
    analysis.evaluate(m, &mut ws, t, q, qd, &mut r).unwrap();
    r
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Closed form of the body swinging about the global y axis (a principal axis of the
/// body, so the motion stays planar) at angle φ from the downward vertical with rate
/// ω: with the centre at c = −d (sin φ, 0, cos φ) from the joint, I_O = I_yy + m d²,
/// α = −m g d sin φ / I_O, the centre accelerates by a = α e_y × c − ω² c, and the
/// joint pushes on the body with F = m a − m g⃗ (Newton), whose torque about the
/// centre is T = (O − c) × F = −c × F.
#[test]
fn hanging_body_against_the_closed_form() {
    let model = hanging_body::Model::default();
    let (m, d, g, iyy) = (2.0, 0.5, 9.81, 0.4);
    for (phi, w) in [(0.0, 0.0), (0.0, 1.5), (0.7, 0.0), (-1.2, 2.0)] {
        let (s, c) = (f64::sin(phi), f64::cos(phi));
        let (sh, ch) = (f64::sin(phi / 2.0), f64::cos(phi / 2.0));
        let centre = [-d * s, 0.0, -d * c];
        let q = [centre[0], 0.0, centre[2], ch, 0.0, sh, 0.0];
        let qd = [
            -d * c * w,
            0.0,
            d * s * w,
            -0.5 * sh * w,
            0.0,
            0.5 * ch * w,
            0.0,
        ];
        let r = reactions_at(&model, 0.0, &q, &qd);
        let joints = r.joints(&model, &q);
        let j = joints.get("pivot").unwrap();
        assert_eq!((j.rank, j.components), (6, 6));
        assert!(j.residual < 1e-10, "residual {:e}", j.residual);
        let alpha = -m * g * d * s / (iyy + m * d * d);
        let acc = cross([0.0, alpha, 0.0], centre);
        let acc: Vec<f64> = (0..3).map(|k| acc[k] - w * w * centre[k]).collect();
        let force = [m * acc[0], m * acc[1], m * acc[2] + m * g];
        let torque = cross(centre.map(|v| -v), force);
        let first: Wrench = j.first.unwrap();
        let scale = m * g;
        assert!(
            close(&first.force, &force, 1e-9 * scale),
            "{first:?} vs {force:?}"
        );
        assert!(
            close(&first.torque, &torque, 1e-9 * scale * d),
            "{first:?} vs {torque:?}"
        );
        // In body axes: Aᵀ F with A the rotation about y by φ.
        let body_force = [
            c * force[0] - s * force[2],
            force[1],
            s * force[0] + c * force[2],
        ];
        assert!(close(&first.force_body, &body_force, 1e-9 * scale));
        // The ground feels the opposite force at its origin (the joint), no torque
        // about it.
        let second = j.second.unwrap();
        assert!(close(&second.force, &force.map(|v| -v), 1e-9 * scale));
        assert!(close(&second.torque, &[0.0; 3], 1e-9 * scale * d));
    }
    // Hanging at rest: the joint carries the weight m g, straight up.
    let q = [0.0, 0.0, -d, 1.0, 0.0, 0.0, 0.0];
    let r = reactions_at(&model, 0.0, &q, &[0.0; 7]);
    let first = r.joints(&model, &q).get("pivot").unwrap().first.unwrap();
    assert!(
        close(&first.force, &[0.0, 0.0, m * g], 1e-9 * m * g),
        "{first:?}"
    );
}

/// The bodies' slider-crank against the hand-written one along a run: the force each
/// pin puts on its first body is minus the pin's multipliers of `slider_crank` (whose
/// rows are `x_first − x_second`), and its torque about the body's centre is that of
/// the force at the pin.
#[test]
fn slider_crank_pins_against_the_hand_written_multipliers() {
    let (hand, bodies) = (
        slider_crank::Model::default(),
        slider_crank_bodies::Model::default(),
    );
    let (a, b) = (0.1, 0.3);
    let run = Simulation::new(&hand)
        .formulation(Formulation::Projection)
        .integrator(Method::Dop853)
        .tolerances(1e-12, 1e-14)
        .output_every(0.1)
        .run(1.0)
        .unwrap();
    let tr = &run.trajectory;
    let hinfo = hand.info();
    let lam = |r: &Reactions, name: &str| {
        r.lambda[hinfo.holonomic.iter().position(|s| s.name == name).unwrap()]
    };
    let mut worst = 0.0_f64;
    let mut worst_residual = 0.0_f64;
    for i in 0..tr.len() {
        let (t, q, qd) = (tr.t[i], tr.q(i), tr.qd(i));
        let rh = reactions_at(&hand, t, q, qd);
        let rb = reactions_at(&bodies, t, q, qd);
        let joints = rb.joints(&bodies, q);
        let (p1, p2) = (q[2], q[5]);
        let u1 = [p1.cos(), p1.sin()];
        let u2 = [p2.cos(), p2.sin()];
        // (joint, pin rows of the hand-written model, pin minus first body's centre).
        let cases = [
            (
                "pin_o",
                "pin_o_x",
                "pin_o_y",
                [-0.5 * a * u1[0], -0.5 * a * u1[1]],
            ),
            (
                "pin_a",
                "pin_a_x",
                "pin_a_y",
                [0.5 * a * u1[0], 0.5 * a * u1[1]],
            ),
            (
                "pin_b",
                "pin_b_x",
                "pin_b_y",
                [0.5 * b * u2[0], 0.5 * b * u2[1]],
            ),
        ];
        for (joint, rx, ry, arm) in cases {
            let j = joints.get(joint).unwrap();
            assert_eq!((j.rank, j.components), (3, 3));
            worst_residual = worst_residual.max(j.residual);
            let w = j.first.unwrap();
            let f = [-lam(&rh, rx), -lam(&rh, ry)];
            let tz = arm[0] * f[1] - arm[1] * f[0];
            let scale = f[0].abs().max(f[1].abs()).max(1.0);
            let err = [
                w.force[0] - f[0],
                w.force[1] - f[1],
                w.torque[2] - tz,
                w.force[2],
                w.torque[0],
                w.torque[1],
            ]
            .iter()
            .fold(0.0_f64, |m, e| m.max(e.abs()))
                / scale;
            worst = worst.max(err);
        }
        // The driver has no frames: no wrench, its generalized force only.
        let driver = joints.get("driver").unwrap();
        assert!(driver.first.is_none());
        let k = bodies.info().joint_index("driver").unwrap();
        let qdrv = joints.generalized_force(k);
        assert!((qdrv[2] + lam(&rh, "driver")).abs() < 1e-9 * lam(&rh, "driver").abs().max(1.0));
    }
    eprintln!(
        "slider-crank pins: largest relative difference {worst:e}, fit residual {worst_residual:e}"
    );
    assert!(worst < 1e-9, "largest relative difference {worst:e}");
    assert!(
        worst_residual < 1e-10,
        "largest fit residual {worst_residual:e}"
    );
}

/// Newton's third law between the two frames of a joint, and the balance of each
/// body: the coupler of the slider-crank (absolute coordinates) feels, from `pin_a`,
/// exactly the pin's generalized force on its own coordinates (x2, y2, φ2), which is
/// the pin's `second` wrench; and the wrenches on the coupler from both pins plus its
/// weight give m₂ ẍ₂, m₂ ÿ₂ and j₂ φ̈₂ of the acceleration solve.
#[test]
fn third_law_and_the_balance_of_each_body() {
    let model = slider_crank_bodies::Model::default();
    let info = model.info();
    let (m2, j2, g) = (0.3, 0.3 * 0.3 * 0.3 / 12.0, 9.81);
    let run = Simulation::new(&model)
        .integrator(Method::Dop853)
        .tolerances(1e-11, 1e-13)
        .output_every(0.125)
        .run(1.0)
        .unwrap();
    let tr = &run.trajectory;
    for i in 0..tr.len() {
        let (t, q, qd) = (tr.t[i], tr.q(i), tr.qd(i));
        let r = reactions_at(&model, t, q, qd);
        let joints = r.joints(&model, q);
        let pin_a = joints.get("pin_a").unwrap();
        let on_coupler = pin_a.second.unwrap();
        let on_crank = pin_a.first.unwrap();
        let qa = joints.generalized_force(info.joint_index("pin_a").unwrap());
        let scale = qa.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        // Third law: the coupler's share (x2, y2, φ2) is the second wrench; the force
        // on the crank is its opposite.
        assert!(close(
            &[
                on_coupler.force[0],
                on_coupler.force[1],
                on_coupler.torque[2]
            ],
            &qa[3..6],
            1e-9 * scale
        ));
        assert!(close(
            &[on_crank.force[0], on_crank.force[1]],
            &[-on_coupler.force[0], -on_coupler.force[1]],
            1e-12 * scale
        ));
        assert!(close(
            &[on_crank.force[0], on_crank.force[1], on_crank.torque[2]],
            &qa[0..3],
            1e-9 * scale
        ));
        // Balance of the coupler.
        let pin_b = joints.get("pin_b").unwrap().first.unwrap();
        let fx = on_coupler.force[0] + pin_b.force[0];
        let fy = on_coupler.force[1] + pin_b.force[1] - m2 * g;
        let tz = on_coupler.torque[2] + pin_b.torque[2];
        let expect = [m2 * r.qdd[3], m2 * r.qdd[4], j2 * r.qdd[5]];
        assert!(
            close(&[fx, fy, tz], &expect, 1e-9 * scale),
            "t = {t}: {:?} vs {expect:?}",
            [fx, fy, tz]
        );
    }
}

/// Solves the small square system `a x = b` (row-major, partial pivoting).
fn solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
    let r = b.len();
    for k in 0..r {
        let p = (k..r)
            .max_by(|&i, &j| a[i * r + k].abs().total_cmp(&a[j * r + k].abs()))
            .unwrap();
        for c in 0..r {
            a.swap(k * r + c, p * r + c);
        }
        b.swap(k, p);
        for i in k + 1..r {
            let f = a[i * r + k] / a[k * r + k];
            for c in k..r {
                a[i * r + c] -= f * a[k * r + c];
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = vec![0.0; r];
    for k in (0..r).rev() {
        let s: f64 = (k + 1..r).map(|c| a[k * r + c] * x[c]).sum();
        x[k] = (b[k] - s) / a[k * r + k];
    }
    x
}

/// Moves `q` onto the rows `rows` of the holonomic constraints by minimum-norm Newton
/// steps; returns the final violation.
fn satisfy(m: &dyn Mechanism, t: f64, q: &mut [f64], rows: &[usize]) -> f64 {
    let info = m.info();
    let n = info.nq();
    let mut c = vec![0.0; info.nh()];
    let mut jac = vec![0.0; info.nh() * n];
    for _ in 0..50 {
        m.holonomic(t, q, &mut c);
        m.holonomic_jacobian_dense_inplace(t, q, &mut jac);
        let r = rows.len();
        let mut jjt = vec![0.0; r * r];
        for (a, &ra) in rows.iter().enumerate() {
            for (b, &rb) in rows.iter().enumerate() {
                jjt[a * r + b] = (0..n).map(|i| jac[ra * n + i] * jac[rb * n + i]).sum();
            }
        }
        let y = solve(jjt, rows.iter().map(|&k| c[k]).collect());
        for i in 0..n {
            q[i] -= rows
                .iter()
                .zip(&y)
                .map(|(&k, y)| jac[k * n + i] * y)
                .sum::<f64>();
        }
    }
    m.holonomic(t, q, &mut c);
    rows.iter().fold(0.0_f64, |w, &k| w.max(c[k].abs()))
}

/// At random states that satisfy the joint's own rows (and the Euler-parameter
/// normalization), with arbitrary multipliers, every joint's generalized force is that
/// of one wrench on its first frame and the opposite on its second: the fit residual
/// is at the level of the pose differences for every joint kind, planar and spatial,
/// with absolute and relative frames. (At a state that violates a joint between two
/// bodies the points the joint pins together differ, and no wrench pair reproduces its
/// force: the residual shows it.)
#[test]
fn every_joint_kind_is_a_wrench_pair() {
    let spatial = spatial_zoo::Model::default();
    let planar = planar_zoo::Model::default();
    let pair = universal_pair::Model::default();
    let mut seed = 5_u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let t = 0.37;
    let mut worst = 0.0_f64;
    let (mut tested, mut unmet) = (Vec::new(), Vec::new());
    for model in [&spatial as &dyn Mechanism, &planar, &pair] {
        let info = model.info();
        let mut jr = JointReactions::new(info);
        for (index, joint) in info.joints.iter().enumerate() {
            let (h0, hl) = (joint.holonomic.0 as usize, joint.holonomic.1 as usize);
            let mut rows: Vec<usize> = (h0..h0 + hl).collect();
            rows.extend(
                info.frames
                    .iter()
                    .filter_map(|f| f.normalization.map(|r| r as usize)),
            );
            for _ in 0..3 {
                let mut q: Vec<f64> = (0..info.nq()).map(|_| rnd()).collect();
                let violation = satisfy(model, t, &mut q, &rows);
                if violation > 1e-12 {
                    // The zoo's frames cannot always meet this joint (a relative frame
                    // with fewer coordinates than the joint's rows).
                    unmet.push(joint.name);
                    continue;
                }
                let lambda: Vec<f64> = (0..info.nh() + info.nnh()).map(|_| 10.0 * rnd()).collect();
                jr.evaluate(model, t, &q, &lambda);
                let j = jr.iter().nth(index).unwrap();
                if joint.kind == pfaff::JointKind::Driver {
                    assert!(j.first.is_none());
                    continue;
                }
                assert_eq!(j.components, if info.name == "planar_zoo" { 3 } else { 6 });
                assert!(
                    j.residual < 1e-9,
                    "{}.{}: residual {:e}",
                    info.name,
                    j.name,
                    j.residual
                );
                worst = worst.max(j.residual);
                tested.push(joint.kind);
            }
        }
    }
    eprintln!("largest fit residual over every joint kind: {worst:e}; not met: {unmet:?}");
    use pfaff::JointKind as K;
    for k in [
        K::PlanarRevolute,
        K::PlanarPrismatic,
        K::PlanarFixed,
        K::Spherical,
        K::Revolute,
        K::Universal,
        K::Cylindrical,
        K::Prismatic,
        K::Fixed,
        K::Distance,
        K::ZeroVelocity,
        K::RollingWheel,
    ] {
        assert!(tested.contains(&k), "{k:?} not tested");
    }
}
