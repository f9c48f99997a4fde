#[pfaff::mechanism]
mod data_misuse {
    const l: f64 = 1.0;
    /// Unknown kind.
    static a: Data = Bean { len: 3 };
    /// Too many modes for one clamped element (3 coordinates left).
    static b: Data = Beam {
        elements: 1,
        length: l,
        rho_a: 1.0,
        ea: 1.0,
        ei: 1.0,
        modes: 4,
    };
    /// A reference node that does not exist; a misspelt field.
    static c: Data = Beam {
        elements: 2,
        length: l,
        rho_a: 1.0,
        ea: 1.0,
        ei: 1.0,
        modes: 1,
        reference: Clamped(5),
        boundry: [2],
    };
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * x.dot().powi(2)
    }
}
fn main() {}
