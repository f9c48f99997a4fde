#[pfaff::mechanism]
mod misuse {
    const e: f64 = 0.5;
    const bounce: f64 = 1.5;
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    /// No coordinate in the gap.
    #[contact(e)]
    fn nowhere() -> f64 {
        t - 1.0
    }
    /// Restitution outside [0, 1].
    #[contact(bounce)]
    fn springy() -> f64 {
        x
    }
}
fn main() {}
