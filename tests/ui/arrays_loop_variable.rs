#[pfaff::mechanism]
mod row {
    const N: usize = 3;
    const m: f64 = 1.0;
    static x: [Coordinate; N] = from_fn(|i| Coordinate { q0: i as f64 });
    fn kinetic_energy() -> f64 {
        (0..N).map(|j| 0.5 * m * x[j].dot().powi(2)).sum()
    }
    fn potential_energy() -> f64 {
        m * x[i]
    }
    #[output]
    fn all() -> f64 {
        x
    }
}
fn main() {}
