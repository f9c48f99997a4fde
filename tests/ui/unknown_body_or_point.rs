#[pfaff::mechanism]
mod linkage {
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static phi: Coordinate = Coordinate {};
    static crank: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: 1.0,
        inertia: 0.1,
    };
    static tip: Point = Point {
        frame: crank,
        at: [0.5, 0.0],
    };
    static pin: Joint = Revolute {
        a: crank,
        b: cranck,
    };
    #[output]
    fn height() -> f64 {
        tipp.y()
    }
}
fn main() {}
