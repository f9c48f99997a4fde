#[pfaff::mechanism]
mod spring {
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * x.dot().powi(2)
    }
    #[virtual_work]
    fn spring() -> f64 {
        -x * delta(x) * delta(x)
    }
}
fn main() {}
