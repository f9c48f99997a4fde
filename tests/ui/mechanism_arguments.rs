// The only argument of `#[mechanism]` is `linearize`; a misspelling points at it.
#[pfaff::mechanism(linearise)]
mod point {
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * x.dot().powi(2)
    }
}
fn main() {}
