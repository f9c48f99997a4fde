//! The Chaplygin sleigh of `sleigh` written with a body and a knife edge.

/// Chaplygin sleigh from the body level: a planar body on a `KnifeEdge` (docs/theory.md V11).
///
/// Same coordinates, parameters and initial state as `sleigh`; the kinetic energy and the
/// non-holonomic row are generated: the blade point, `a` behind the centre of mass on the
/// body axis, has no velocity along the body's lateral axis.
#[pfaff::mechanism]
pub mod sleigh_bodies {
    /// Mass [kg].
    const m: f64 = 2.0;
    /// Moment of inertia about the centre of mass [kg m²].
    const ic: f64 = 0.05;
    /// Distance from the centre of mass back to the blade [m].
    const a: f64 = 0.3;

    /// Position of the centre of mass along x [m].
    static x: Coordinate = Coordinate { q0: 0.0, qd0: 1.0 };
    /// Position of the centre of mass along y [m].
    static y: Coordinate = Coordinate {
        q0: 0.0,
        qd0: 0.5 * a,
    };
    /// Heading: angle from the x axis to the body axis [rad].
    static phi: Coordinate = Coordinate { q0: 0.0, qd0: 0.5 };

    /// The sleigh, its frame at the centre of mass.
    static sled: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: m,
        inertia: ic,
    };

    /// The blade point has no velocity across the blade.
    static blade: Joint = KnifeEdge {
        a: sled,
        at_a: [-a, 0.0],
        lateral: [0.0, 1.0],
    };
}
