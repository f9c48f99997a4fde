//! The generated drawing (`Mechanism::drawing`, `drawing_values`) of the models with every
//! joint type and force element: points fixed in a frame keep their frame coordinates,
//! and the default shapes are where the declarations put them.

use std::collections::HashMap;

use pfaff::nalgebra::{Matrix3, Vector3};
use pfaff::{Mechanism, ShapeKind};

use super::models::{planar_zoo, spatial_zoo};

fn state(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}

/// `(origin, rotation)` of frame `f` from the raw poses.
fn pose(m: &dyn Mechanism, t: f64, q: &[f64], f: usize) -> (Vector3<f64>, Matrix3<f64>) {
    let mut raw = vec![0.0; 12 * m.info().frames.len()];
    m.frame_poses(t, q, &mut raw);
    let r = &raw[12 * f..12 * f + 12];
    (
        Vector3::new(r[0], r[1], r[2]),
        Matrix3::from_row_slice(&r[3..12]),
    )
}

fn values(m: &dyn Mechanism, t: f64, q: &[f64]) -> Vec<f64> {
    let mut v = vec![0.0; m.drawing().len()];
    m.drawing_values(t, q, &mut v);
    v
}

fn point(v: &[f64], i: u32) -> Vector3<f64> {
    let i = 3 * i as usize;
    Vector3::new(v[i], v[i + 1], v[i + 2])
}

/// At two unrelated states, every drawing point fixed in a frame has the same frame
/// coordinates (`R⁻¹(p − o)`; directions `R⁻¹ n`), which is what "fixed in the frame"
/// means; the rotations need not be orthonormal at these states.
#[test]
fn drawing_points_are_fixed_in_their_frames() {
    let models: [Box<dyn Mechanism>; 2] = [
        Box::new(spatial_zoo::Model::default()),
        Box::new(planar_zoo::Model::default()),
    ];
    for m in &models {
        let d = m.drawing();
        let name = m.info().name;
        assert!(!d.shapes.is_empty() && !d.points.is_empty(), "{name}");
        let normals: Vec<u32> = d.shapes.iter().filter_map(|s| s.normal).collect();
        let n = m.info().nq();
        let local = |q: &[f64], i: u32, f: u32| {
            let v = values(m.as_ref(), 0.3, q);
            let (o, r) = pose(m.as_ref(), 0.3, q, f as usize);
            let inv = r.try_inverse().expect("a regular rotation");
            if normals.contains(&i) {
                inv * point(&v, i)
            } else {
                inv * (point(&v, i) - o)
            }
        };
        let (q1, q2) = (state(n, 3), state(n, 11));
        let mut fixed = 0;
        for (i, p) in d.points.iter().enumerate() {
            let Some(f) = p.frame else { continue };
            let i = u32::try_from(i).expect("small");
            let (a, b) = (local(&q1, i, f), local(&q2, i, f));
            assert!(
                (a - b).norm() < 1e-12,
                "{name}: {} moves in its frame: {a} {b}",
                p.name
            );
            fixed += 1;
        }
        assert!(fixed >= 6, "{name}: {fixed} points fixed in frames");
    }
}

/// `spatial_zoo`'s default drawing: a disc of radius 0.3 about b1's origin normal to b1's
/// y axis (`RollingWheel { axis: [0, 1, 0], radius: 0.3 }`) on the plane z = 0, a spring
/// from b1's `[0, 0.1, 0]` to b3's origin, a rod for the distance joint, a support at the
/// hinge's ground point `[0.1, 0.2, 0.3]`, and a shape for every body.
#[test]
fn default_shapes_of_the_spatial_zoo() {
    let m = spatial_zoo::Model::default();
    let d = m.drawing();
    let q = state(m.info().nq(), 5);
    let v = values(&m, 0.3, &q);
    let by_name: HashMap<&str, _> = d.shapes.iter().map(|s| (s.name, s)).collect();
    for body in ["b1", "b2", "b3"] {
        assert!(by_name.contains_key(body), "a shape for {body}");
    }
    let (o1, r1) = pose(&m, 0.3, &q, 0);
    let (o3, _) = pose(&m, 0.3, &q, 2);

    let wheel = by_name["wheel"];
    assert_eq!(wheel.kind, ShapeKind::Disc);
    assert_eq!(
        v[3 * d.points.len() + wheel.radius.expect("a radius") as usize],
        0.3
    );
    assert!((point(&v, wheel.points[0]) - o1).norm() < 1e-14);
    let axis = r1 * Vector3::new(0.0, 1.0, 0.0);
    assert!((point(&v, wheel.normal.expect("an axis")) - axis).norm() < 1e-14);
    let ground = d
        .shapes
        .iter()
        .find(|s| s.kind == ShapeKind::Ground)
        .expect("the rolling plane");
    assert_eq!(point(&v, ground.normal.expect("a normal")), Vector3::z());

    let spring = by_name["spring"];
    assert_eq!(spring.kind, ShapeKind::Spring);
    let a = o1 + r1 * Vector3::new(0.0, 0.1, 0.0);
    assert!((point(&v, spring.points[0]) - a).norm() < 1e-14);
    assert!((point(&v, spring.points[1]) - o3).norm() < 1e-14);

    assert_eq!(by_name["rod"].kind, ShapeKind::Link);
    let hinge = by_name["hinge"];
    assert_eq!((hinge.kind, hinge.frame), (ShapeKind::Marker, None));
    assert_eq!(point(&v, hinge.points[0]), Vector3::new(0.1, 0.2, 0.3));
}

/// A body drawn as a block (no joint or named point to draw it by) is sized by its own
/// mass and inertia, not by the extent of a run: the half-side of the uniform box with
/// them, $\sqrt{\operatorname{tr}\bar I/2m}$ (a cube of half-side $h$ has
/// $\bar I = \tfrac23 m h^2$ about each axis). `free_body`: $\bar I = \operatorname{diag}(1,
/// 1, 2)$, $m = 1$, so $h = \sqrt 2$; the block follows a parameter change.
#[test]
fn a_block_is_sized_by_its_body() {
    let mut m = pfaff_models::free_body::Model::default();
    let d = m.drawing();
    let block = d
        .shapes
        .iter()
        .find(|s| s.name == "body")
        .expect("the body's shape");
    assert_eq!(block.kind, ShapeKind::Marker);
    let r = 3 * d.points.len() + block.radius.expect("a size") as usize;
    let q = state(m.info().nq(), 7);
    assert!((values(&m, 0.0, &q)[r] - 2f64.sqrt()).abs() < 1e-15);
    let i = m.info().parameter_index("m").expect("a mass parameter");
    m.set_parameter(i, 4.0);
    assert!((values(&m, 0.0, &q)[r] - 0.5 * 2f64.sqrt()).abs() < 1e-15);
    assert_eq!(d.up, None, "free_body declares no up direction");
}

/// `Scene { up }` is three scalars of the drawing: the bicycle's `[0, 0, −1]`.
#[test]
fn the_bicycle_is_drawn_z_down() {
    let m = pfaff_models::bicycle::Model::default();
    let d = m.drawing();
    let k = 3 * d.points.len() + d.up.expect("the bicycle declares up") as usize;
    let q = state(m.info().nq(), 1);
    assert_eq!(&values(&m, 0.0, &q)[k..k + 3], &[0.0, 0.0, -1.0]);
}
