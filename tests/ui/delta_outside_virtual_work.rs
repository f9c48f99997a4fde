#[pfaff::mechanism]
mod spring {
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * x.dot().powi(2)
    }
    #[force(x)]
    fn push() -> f64 {
        delta(x)
    }
}
fn main() {}
