#[pfaff::mechanism]
mod link {
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static phi: Coordinate = Coordinate {};
    static bar: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: 1.0,
        inertia: 0.1,
    };
    static pin: Joint = Revolute {
        a: bar,
        at_a: [0.5, 0.0],
        b: bar,
        at_b: [-0.5, 0.0],
    };
}
fn main() {}
