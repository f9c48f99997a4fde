#[pfaff::mechanism]
mod row {
    const m: f64 = 1.0;
    static x: [Coordinate; m] = [Coordinate {}; 2];
    static y: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * m * y.dot().powi(2)
    }
}
fn main() {}
