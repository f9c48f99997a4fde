#[pfaff::mechanism]
mod pendulum {
    static x: Coordinate = Coordinate {};
    fn speed() -> f64 {
        x.dot() + 0.1 * speed()
    }
    fn kinetic_energy() -> f64 {
        0.5 * speed().powi(2)
    }
}
fn main() {}
