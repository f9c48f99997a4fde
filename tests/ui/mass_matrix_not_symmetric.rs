#[pfaff::mechanism]
mod particle {
    const m: f64 = 1.0;
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    fn mass_matrix() -> [[f64; 2]; 2] {
        [[m, x.cos()], [x.sin(), m]]
    }
}
fn main() {}
