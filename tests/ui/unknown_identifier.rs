#[pfaff::mechanism]
mod pendulum {
    const mass: f64 = 1.0;
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * mas * x.dot().powi(2)
    }
}
fn main() {}
