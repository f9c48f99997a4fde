#[pfaff::mechanism]
mod particle {
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * z.dot().powi(2)
    }
}
fn main() {
    // The fallback module keeps this line from adding errors of its own.
    let _model = particle::Model::new(particle::Params::default());
}
