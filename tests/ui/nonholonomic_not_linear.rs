#[pfaff::mechanism]
mod sleigh {
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static phi: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2) + phi.dot().powi(2))
    }
    #[nonholonomic]
    fn blade() -> f64 {
        -phi.sin() * x.dot() + phi.cos() * y.dot() * phi.dot()
    }
}
fn main() {}
