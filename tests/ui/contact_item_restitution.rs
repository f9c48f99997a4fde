// A `Contact` item whose coefficient of restitution defaults outside [0, 1].
#[pfaff::mechanism]
mod contacts {
    const bouncy: f64 = 1.5;
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static phi: Coordinate = Coordinate {};
    static rod: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: 1.0,
        inertia: 0.1,
    };
    static tip: Contact = PointPlane {
        point: rod.point([0.5, 0.0]),
        normal: [0.0, 1.0],
        restitution: bouncy,
    };
}
fn main() {}
