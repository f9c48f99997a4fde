#[pfaff::mechanism]
mod pendulum {
    const l: f64 = 1.0;
    static x: Coordinate = Coordinate { q0: l };
    static y: Coordinate = Coordinate { q0: y0 };
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    fn potential_energy() -> f64 {
        9.81 * y.dot()
    }
    #[holonomic]
    fn rod() -> f64 {
        x.powi(2) + y.powi(2) - l.pow(2)
    }
}
fn main() {}
