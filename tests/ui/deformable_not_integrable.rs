#[pfaff::mechanism]
mod not_integrable {
    static phi: Coordinate = Coordinate {};
    static q1: Coordinate = Coordinate {};
    static rod: Body = Deformable {
        origin: [0.0, 0.0],
        angle: phi,
        elastic: [q1],
        span: 0.0..1.0,
        position: |xi| [xi, 0.0],
        density: 1.0,
        displacement: |xi| [0.0, q1 * xi.sqrt()],
    };
}
fn main() {}
