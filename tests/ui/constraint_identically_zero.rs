#[pfaff::mechanism]
mod particle {
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    #[holonomic]
    fn useless() -> f64 {
        (x + y) - (y + x)
    }
}
fn main() {}
