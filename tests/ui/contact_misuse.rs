#[pfaff::mechanism]
mod misuse {
    const e: f64 = 0.5;
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    /// The restitution names no parameter.
    #[contact(restitutio)]
    fn floor() -> f64 {
        y
    }
    /// No restitution.
    #[contact]
    fn bare() -> f64 {
        x + y
    }
    /// Two roles.
    #[contact(e)]
    #[holonomic]
    fn both() -> f64 {
        x
    }
}
fn main() {}
