#[pfaff::mechanism]
mod particle {
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * x.dot().powi(2) + x.dot().powi(4)
    }
}
fn main() {}
