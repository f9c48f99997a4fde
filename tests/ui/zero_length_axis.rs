#[pfaff::mechanism]
mod hinge {
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static z: Coordinate = Coordinate {};
    static psi: Coordinate = Coordinate {};
    static door: Body = Body {
        origin: [x, y, z],
        rotation: rot_z(psi),
        mass: 1.0,
        inertia: diag(1.0, 1.0, 1.0),
    };
    static pivot: Joint = Revolute {
        a: door,
        axis_a: [0.0, 0.0, 0.0],
        axis_b: [0.0, 0.0, 1.0],
    };
}
fn main() {}
