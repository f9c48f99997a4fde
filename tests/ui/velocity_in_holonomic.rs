#[pfaff::mechanism]
mod pendulum {
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    #[holonomic]
    fn rod() -> f64 {
        x * x.dot() + y * y.dot()
    }
}
fn main() {}
