#[pfaff::mechanism]
mod pendulum {
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        1e400 * x.dot().powi(2)
    }
    fn potential_energy() -> f64 {
        x / (x - x) + x * (-1.0).sqrt()
    }
}
fn main() {}
