#[pfaff::mechanism]
mod particle {
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * x.dot().powi(2)
    }
    fn potential_energy() -> f64 {
        x.cbrt() + x.log10()
    }
}
fn main() {}
