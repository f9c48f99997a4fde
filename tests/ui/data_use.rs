#[pfaff::mechanism]
mod data_use {
    const l: f64 = 1.0;
    const ei: f64 = -1.0;
    /// A negative bending stiffness at the parameters' defaults.
    static c: Data = Beam {
        elements: 2,
        length: l,
        rho_a: 1.0,
        ea: 1.0,
        ei: ei,
        modes: 1,
    };
    static d: Data = Data { len: 2 };
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        // An index past the slot, and the slot as a scalar.
        0.5 * d[0] * x.dot().powi(2) + d[2] * x + d * x
    }
}
fn main() {}
