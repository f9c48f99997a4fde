#[pfaff::mechanism]
mod misuse {
    static x: Coordinate = Coordinate {};
    static phi: Coordinate = Coordinate {};
    static q1: Coordinate = Coordinate {};
    static bar: Body = Body {
        origin: [x, 0.0],
        angle: phi,
        mass: 1.0,
    };
    static tip: Point = Point {
        frame: bar,
        at: bar.material(1.0),
    };
    static rod: Body = Deformable {
        origin: [0.0, 0.0],
        angle: phi,
        elastic: [q1, x, q1],
        mass: 1.0,
    };
}
fn main() {}
