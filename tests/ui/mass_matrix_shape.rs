#[pfaff::mechanism]
mod particle {
    const m: f64 = 1.0;
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    fn mass_matrix() -> [[f64; 3]; 3] {
        [[m, 0.0, 0.0], [0.0, m, 0.0], [0.0, 0.0, m]]
    }
}
fn main() {}
