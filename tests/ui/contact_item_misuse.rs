// `Contact` items (a point on a plane or outside a sphere): an unknown kind, a
// restitution that is a number or names no parameter, a zero normal, vectors of mixed
// dimension, a missing radius, a gap that depends on velocities.
#[pfaff::mechanism]
mod contacts {
    const e: f64 = 0.5;
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static phi: Coordinate = Coordinate {};
    static rod: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: 1.0,
        inertia: 0.1,
    };
    static a: Contact = PointPlan { point: rod.origin(), normal: [0.0, 1.0], restitution: e };
    static b: Contact = PointPlane { point: rod.origin(), normal: [0.0, 1.0], restitution: 0.5 };
    static c: Contact = PointPlane { point: rod.origin(), normal: [0.0, 1.0], restitution: f };
    static d: Contact = PointPlane { point: rod.origin(), normal: [0.0, 0.0], restitution: e };
    static h: Contact = PointPlane { point: rod.origin(), normal: [0.0, 1.0, 0.0], restitution: e };
    static k: Contact = PointSphere { point: rod.origin(), center: [0.0, 0.0], restitution: e };
    static v: Contact = PointPlane { point: [x.dot(), y], normal: [0.0, 1.0], restitution: e };
}
fn main() {}
