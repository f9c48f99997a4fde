//! Poses as nalgebra types (`pfaff::PoseExt`): against the raw `frame_poses` slices,
//! orthonormal rotations, unit quaternions equal to the Euler parameters.

use pfaff::nalgebra::{Matrix3, Point3, Vector3};
use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::{Mechanism, PoseExt};
use pfaff_models::{free_body, slider_crank_bodies};

/// The free body (docs/theory.md V12) along 10 s: every pose's rotation is orthonormal with
/// determinant 1 and equals the raw matrix of `frame_poses` to round-off; the pose's
/// translation is the raw origin; the quaternion is a unit quaternion equal (up to sign)
/// to the Euler parameters `(e0, e1, e2, e3)`, which are the quaternion of the rotation
/// `A(θ)` by definition (docs/theory.md E1); planar poses are refused for a spatial frame.
#[test]
fn spatial_poses_agree_with_the_raw_slices_and_the_euler_parameters() {
    let model = free_body::Model::default();
    let run = Simulation::new(&model)
        .formulation(Formulation::Projection)
        .integrator(Method::Dop853)
        .tolerances(1e-11, 1e-13)
        .output_every(0.25)
        .run(10.0)
        .expect("the free body runs");
    let tr = &run.trajectory;
    assert!(tr.len() > 40);
    let mut moved = 0.0_f64;
    for i in 0..tr.len() {
        let (t, q) = (tr.t[i], tr.q(i));
        let iso = model.frame_pose(t, q, 0);
        let mut raw = [0.0; 12];
        model.frame_poses(t, q, &mut raw);
        let r = iso.rotation.to_rotation_matrix().into_inner();
        let a = Matrix3::from_row_slice(&raw[3..]);
        assert!((r - a).amax() < 1e-12, "t = {t}: {r} against {a}");
        assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-12);
        assert!((r.determinant() - 1.0).abs() < 1e-12);
        assert_eq!(iso.translation.vector, Vector3::new(raw[0], raw[1], raw[2]));
        let u = iso.rotation.quaternion();
        assert!((u.norm() - 1.0).abs() < 1e-14);
        let e = [q[3], q[4], q[5], q[6]];
        let s = if u.w * e[0] + u.i * e[1] + u.j * e[2] + u.k * e[3] < 0.0 {
            -1.0
        } else {
            1.0
        };
        let d = [
            u.w - s * e[0],
            u.i - s * e[1],
            u.j - s * e[2],
            u.k - s * e[3],
        ];
        assert!(
            d.iter().all(|x| x.abs() < 1e-9),
            "t = {t}: quaternion {u:?} against Euler parameters {e:?}"
        );
        moved = moved.max((u.w - 1.0).abs());
        assert_eq!(model.frame_isometries(t, q), vec![iso]);
        assert!(model.frame_pose_2d(t, q, 0).is_none());
    }
    assert!(moved > 0.5, "the body turns: largest |w − 1| {moved}");
}

/// The slider-crank's planar frames: `frame_pose_2d` is the body's reference point and
/// angle (the coordinates `x1, y1, phi1` by the model's definition), the 3-D pose embeds
/// it, and the named point `tip` is the crank pose applied to its body coordinates
/// `(a/2, 0)` and equals `point_positions`.
#[test]
fn planar_poses_and_points() {
    let model = slider_crank_bodies::Model::default();
    let info = model.info();
    let crank = info.frame_index("crank").expect("a crank frame");
    let a = model.parameter(info.parameter_index("a").expect("a"));
    let run = Simulation::new(&model)
        .output_every(0.01)
        .run(0.6)
        .expect("the slider-crank runs");
    let tr = &run.trajectory;
    for i in 0..tr.len() {
        let (t, q) = (tr.t[i], tr.q(i));
        let p2 = model.frame_pose_2d(t, q, crank).expect("a planar frame");
        assert!((p2.translation.x - q[0]).abs() < 1e-15);
        assert!((p2.translation.y - q[1]).abs() < 1e-15);
        let turn = (p2.rotation.angle() - q[2]).rem_euclid(std::f64::consts::TAU);
        assert!(turn.min(std::f64::consts::TAU - turn) < 1e-12);
        let p3 = model.frame_pose(t, q, crank);
        assert!((p3.translation.vector - Vector3::new(q[0], q[1], 0.0)).norm() < 1e-15);
        let tip = model.point_position(t, q, 0);
        let from_pose = p3 * Point3::new(0.5 * a, 0.0, 0.0);
        assert!(
            (tip - from_pose).norm() < 1e-15,
            "{tip} against {from_pose}"
        );
        let mut raw = [0.0; 3];
        model.point_positions(t, q, &mut raw);
        assert_eq!(tip, Point3::from(raw));
        assert_eq!(model.point_positions_3d(t, q), vec![tip]);
    }
}
