#[pfaff::mechanism]
mod beam_modes {
    /// A mode kept twice.
    static twice: Data = Beam {
        elements: 4,
        length: 1.0,
        rho_a: 1.0,
        ea: 1.0,
        ei: 1.0,
        modes: [0, 1, 1],
    };
    /// A mode past the clamped beam's 12 interior coordinates.
    static past: Data = Beam {
        elements: 4,
        length: 1.0,
        rho_a: 1.0,
        ea: 1.0,
        ei: 1.0,
        modes: [0, 12],
    };
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * x.dot().powi(2)
    }
}
fn main() {}
