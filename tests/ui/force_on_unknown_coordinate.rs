#[pfaff::mechanism]
mod crank {
    static phi: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * phi.dot().powi(2)
    }
    #[force(ph)]
    fn motor() -> f64 {
        1.0
    }
}
fn main() {}
