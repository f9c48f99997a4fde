#[pfaff::mechanism]
mod pendulum {
    const m: f64 = 1.0;
    static x: Coordinate = Coordinate {};
    static m: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * m * x.dot().powi(2)
    }
}
fn main() {}
