#[pfaff::mechanism]
mod beam_nodes {
    static beam: Data = Beam {
        elements: 4,
        length: 1.0,
        rho_a: 1.0,
        ea: 1.0,
        ei: 1.0,
        modes: 2,
    };
    static set: Data = Data { len: 43 };
    static phi: Coordinate = Coordinate {};
    static q1: Coordinate = Coordinate {};
    static q2: Coordinate = Coordinate {};
    static q3: Coordinate = Coordinate {};
    static q4: Coordinate = Coordinate {};
    static rod: Body = Deformable {
        origin: [0.0, 0.0],
        angle: phi,
        elastic: [q1, q2],
        data: beam,
    };
    /// A node past the beam's last (4 elements: nodes 0..=4).
    static past: Point = Point {
        frame: rod,
        at: rod.node(5),
    };
    /// A node of a rigid body.
    static hub: Body = Body {
        origin: [0.0, 0.0],
        angle: phi,
        mass: 1.0,
    };
    static on_hub: Point = Point {
        frame: hub,
        at: hub.node(1),
    };
    /// Geometric stiffening of a body whose invariants the program sets.
    static other: Body = Deformable {
        origin: [0.0, 0.0],
        angle: phi,
        elastic: [q3, q4],
        data: set,
        stiffening: 1.0,
    };
}
fn main() {}
