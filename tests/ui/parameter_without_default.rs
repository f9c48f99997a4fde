#[pfaff::mechanism]
mod particle {
    const m: f64;
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * m * x.dot().powi(2)
    }
}
fn main() {}
