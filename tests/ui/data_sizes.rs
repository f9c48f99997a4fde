#[pfaff::mechanism]
mod data_sizes {
    /// More values than one slot holds.
    static big: Data = Data { len: 4294967296 };
    /// A mesh finer than a beam body assembles.
    static fine: Data = Beam {
        elements: 2147483647,
        length: 1.0,
        rho_a: 1.0,
        ea: 1.0,
        ei: 1.0,
        modes: 4,
    };
    /// More elastic coordinates than a body has.
    static many: Data = Beam {
        elements: 2000,
        length: 1.0,
        rho_a: 1.0,
        ea: 1.0,
        ei: 1.0,
        modes: 1500,
    };
    static d: Data = Data { len: 2 };
    static x: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * d[0] * x.dot().powi(2)
    }
}
fn main() {}
