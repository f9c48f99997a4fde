#[pfaff::mechanism]
mod misuse {
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static phi: Coordinate = Coordinate {};
    static bar: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: 1.0,
        inertia: 0.1,
    };
    static pin: Joint = Revolut {
        a: bar,
    };
    static slide: Joint = Prismatic {
        a: bar,
        axis: [1.0, 0.0],
    };
    static ball: Joint = Spherical {
        a: bar,
    };
    static weight: Force = Gravity {
        acceleration: [0.0, 0.0, -9.81],
    };
}
fn main() {}
