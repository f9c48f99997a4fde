//! Poses and points as nalgebra types.
//!
//! Generated code writes poses into plain slices ([`Mechanism::frame_poses`]: 12 values
//! per frame, the origin and the row-major rotation matrix; [`Mechanism::point_positions`]:
//! 3 per point). [`PoseExt`] turns them into the types the Rust geometry and rendering
//! ecosystem uses: [`Isometry3`], [`Isometry2`] for planar frames, [`UnitQuaternion`]
//! and [`Point3`]. nalgebra is re-exported as [`pfaff::nalgebra`](crate::nalgebra).
//!
//! These functions allocate a buffer for the slices of all frames (or points) of the
//! model on each call: they serve output, not the integration's hot path. To convert
//! many poses without allocating, evaluate [`Mechanism::frame_poses`] into a buffer of
//! your own and use [`isometry_from_raw`].

use nalgebra::{
    Isometry2, Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector2,
};

use crate::Mechanism;

/// The rotation of a raw pose (values 3..12, row-major) as a unit quaternion.
///
/// A rotation matrix that is orthonormal to round-off (the generated rotations are;
/// those from Euler parameters are when the parameters meet their normalization) gives
/// its quaternion to round-off; the result is normalized in any case.
#[must_use]
pub fn quaternion_from_raw(raw: &[f64]) -> UnitQuaternion<f64> {
    let m = Matrix3::from_row_slice(&raw[3..12]);
    let u = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
    // nalgebra leaves the quaternion of a matrix that is orthonormal only to the
    // constraint tolerance (Euler parameters off their normalization) off unit length.
    UnitQuaternion::new_normalize(u.into_inner())
}

/// The isometry of one raw pose: `raw[0..3]` the origin, `raw[3..12]` the rotation
/// matrix, row-major (the layout of [`Mechanism::frame_poses`]).
///
/// # Panics
/// When `raw` holds fewer than 12 values.
#[must_use]
pub fn isometry_from_raw(raw: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(raw[0], raw[1], raw[2]),
        quaternion_from_raw(raw),
    )
}

/// The planar isometry of one raw pose of a planar frame: the origin's `x`, `y` and the
/// angle of the rotation about z.
///
/// # Panics
/// When `raw` holds fewer than 12 values.
#[must_use]
pub fn isometry2_from_raw(raw: &[f64]) -> Isometry2<f64> {
    // Row-major: R[1][0] = raw[3 + 3], R[0][0] = raw[3].
    let angle = raw[6].atan2(raw[3]);
    Isometry2::new(Vector2::new(raw[0], raw[1]), angle)
}

/// Poses of frames and positions of points as nalgebra types, for every [`Mechanism`].
pub trait PoseExt: Mechanism {
    /// The poses of all frames of [`Info::frames`](crate::Info::frames) at `(t, q)`.
    fn frame_isometries(&self, t: f64, q: &[f64]) -> Vec<Isometry3<f64>> {
        let nf = self.info().frames.len();
        let mut raw = vec![0.0; 12 * nf];
        self.frame_poses(t, q, &mut raw);
        raw.chunks_exact(12).map(isometry_from_raw).collect()
    }

    /// The pose of frame `i` at `(t, q)`: the map from frame to global coordinates.
    ///
    /// # Panics
    /// When the model has no frame `i`.
    fn frame_pose(&self, t: f64, q: &[f64], i: usize) -> Isometry3<f64> {
        let nf = self.info().frames.len();
        assert!(i < nf, "frame {i} of a model with {nf} frames");
        let mut raw = vec![0.0; 12 * nf];
        self.frame_poses(t, q, &mut raw);
        isometry_from_raw(&raw[12 * i..12 * i + 12])
    }

    /// The pose of the planar frame `i` at `(t, q)`, or `None` when the frame is
    /// spatial.
    ///
    /// # Panics
    /// When the model has no frame `i`.
    fn frame_pose_2d(&self, t: f64, q: &[f64], i: usize) -> Option<Isometry2<f64>> {
        let frames = self.info().frames;
        assert!(
            i < frames.len(),
            "frame {i} of a model with {} frames",
            frames.len()
        );
        if !frames[i].planar {
            return None;
        }
        let mut raw = vec![0.0; 12 * frames.len()];
        self.frame_poses(t, q, &mut raw);
        Some(isometry2_from_raw(&raw[12 * i..12 * i + 12]))
    }

    /// The global positions of all points of [`Info::points`](crate::Info::points).
    fn point_positions_3d(&self, t: f64, q: &[f64]) -> Vec<Point3<f64>> {
        let np = self.info().points.len();
        let mut raw = vec![0.0; 3 * np];
        self.point_positions(t, q, &mut raw);
        raw.chunks_exact(3)
            .map(|p| Point3::new(p[0], p[1], p[2]))
            .collect()
    }

    /// The global position of point `i` at `(t, q)` (`z = 0` in planar models).
    ///
    /// # Panics
    /// When the model has no point `i`.
    fn point_position(&self, t: f64, q: &[f64], i: usize) -> Point3<f64> {
        let np = self.info().points.len();
        assert!(i < np, "point {i} of a model with {np} points");
        self.point_positions_3d(t, q)[i]
    }
}

impl<M: Mechanism + ?Sized> PoseExt for M {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raw_pose_of_a_rotation_about_z() {
        let (c, s) = (0.3_f64.cos(), 0.3_f64.sin());
        let raw = [1.0, 2.0, 0.0, c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0];
        let iso = isometry_from_raw(&raw);
        // Closed form: a rotation by θ about z is the quaternion (cos θ/2, 0, 0, sin θ/2).
        let q = iso.rotation.quaternion();
        assert!((q.w - 0.15_f64.cos()).abs() < 1e-15);
        assert!((q.k - 0.15_f64.sin()).abs() < 1e-15);
        let p = iso * Point3::new(1.0, 0.0, 0.0);
        assert!((p - Point3::new(1.0 + c, 2.0 + s, 0.0)).norm() < 1e-15);
        let iso2 = isometry2_from_raw(&raw);
        assert!((iso2.rotation.angle() - 0.3).abs() < 1e-15);
        assert_eq!(iso2.translation.vector, Vector2::new(1.0, 2.0));
    }
}
