#[pfaff::mechanism]
mod sizes {
    static phi: Coordinate = Coordinate {};
    static q1: Coordinate = Coordinate {};
    static q2: Coordinate = Coordinate {};
    static rod: Body = Deformable {
        origin: [0.0, 0.0],
        angle: phi,
        elastic: [q1, q2],
        mass: 1.0,
        invariants: Invariants {
            s_bar: [[0.0, 0.5], [0.3, 0.0, 0.1]],
            i_bar: 0.0,
            s_bar_kl: 0.0,
        },
    };
}
fn main() {}
