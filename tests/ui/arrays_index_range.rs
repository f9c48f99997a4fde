#[pfaff::mechanism]
mod row {
    const N: usize = 3;
    const m: f64 = 1.0;
    static x: [Coordinate; N] = [Coordinate {}; N];
    fn kinetic_energy() -> f64 {
        (0..N).map(|i| 0.5 * m * x[i].dot().powi(2)).sum()
    }
    const _: () = for i in 0..N {
        #[holonomic]
        fn spacing() -> f64 {
            x[i + 1] - x[i] - 1.0
        }
    };
    #[output]
    fn before_first() -> f64 {
        x[0 - 1]
    }
}
fn main() {}
