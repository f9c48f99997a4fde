#[pfaff::mechanism]
mod misuse {
    const e: f64 = 0.5;
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    /// A velocity in a gap.
    #[contact(e)]
    fn moving() -> f64 {
        y - x.dot()
    }
}
fn main() {}
