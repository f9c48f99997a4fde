//! Spin-up of a cantilever beam (Kane, Ryan & Banerjee 1987): the beam clamped at a hub
//! whose angle is prescribed, in the horizontal plane, modelled with and without the
//! geometric stiffening of the axially loaded beam.

/// Spin-up of a cantilever beam on a hub of radius 0 (Kane, Ryan & Banerjee 1987).
///
/// The hub turns by the prescribed angle
/// $\theta(t) = \frac{\Omega_s}{T_s}\left[\frac{t^2}{2} + \left(\frac{T_s}{2\pi}\right)^2
/// \left(\cos\frac{2\pi t}{T_s} - 1\right)\right]$ up to $T_s$ and
/// $\Omega_s (t - T_s/2)$ after (written with $s = \min(t, T_s)$). The beam's frame
/// turns with the hub; its displacement is four bending modes of the clamped-free beam
/// (`w1 … w4`, $\cosh\beta\xi - \cos\beta\xi - \sigma(\sinh\beta\xi - \sin\beta\xi)$,
/// tip value ±2) and a cubic axial ansatz (`u1 u2 u3`, $u = u_1\xi + u_2\xi^2 +
/// u_3\xi^3$, which holds the exact static stretch under the centrifugal load), with
/// $\xi = x/l$. Mass, stiffness and shape integrals are integrated at compile time;
/// `stiffening = 1` adds the nonlinear axial strain $u' + \frac12 w'^2$ to the strain
/// energy (geometric stiffening), `stiffening = 0` is the linear ("vanilla")
/// floating-frame model, whose bending stiffness the centrifugal field overcomes once
/// $\Omega$ passes the first bending frequency (3.7977 rad/s): its tip deflection grows
/// without bound after the spin-up. Output `tip_deflection`: the tip's displacement
/// perpendicular to the rotating frame's x axis.
#[pfaff::mechanism]
pub mod spinup_beam {
    /// Length of the beam [m].
    const l: f64 = 10.0;
    /// Axial rigidity EA [N].
    const ea: f64 = 2.8e7;
    /// Bending rigidity EI [N m²].
    const ei: f64 = 1.4e4;
    /// Mass per unit length [kg/m].
    const rho_a: f64 = 1.2;
    /// Duration of the spin-up [s].
    const ts: f64 = 15.0;
    /// Final angular velocity of the hub [rad/s].
    const omega_s: f64 = 6.0;
    /// 1: the geometric stiffening of the axially loaded beam is modelled; 0: not.
    const stiffening: f64 = 1.0;

    /// First bending mode [m].
    static w1: Coordinate = Coordinate {};
    /// Second bending mode [m].
    static w2: Coordinate = Coordinate {};
    /// Third bending mode [m].
    static w3: Coordinate = Coordinate {};
    /// Fourth bending mode [m].
    static w4: Coordinate = Coordinate {};
    /// Axial displacement, linear term [m].
    static u1: Coordinate = Coordinate {};
    /// Axial displacement, quadratic term [m].
    static u2: Coordinate = Coordinate {};
    /// Axial displacement, cubic term [m].
    static u3: Coordinate = Coordinate {};

    /// The end of the spin-up reached so far, `min(t, ts)` [s].
    fn s() -> f64 {
        0.5 * (t + ts - (t - ts).abs())
    }
    /// The prescribed hub angle [rad].
    fn hub() -> f64 {
        omega_s / ts
            * (0.5 * s() * s() + (ts / (2.0 * PI)).powi(2) * ((2.0 * PI * s() / ts).cos() - 1.0))
            + omega_s * (t - s())
    }
    /// Roots of cos β cosh β = −1 (clamped-free beam).
    fn b1() -> f64 {
        1.875104068711961
    }
    fn b2() -> f64 {
        4.694091132974175
    }
    fn b3() -> f64 {
        7.854757438237613
    }
    fn b4() -> f64 {
        10.99554073487547
    }
    /// σ = (sinh β − sin β)/(cosh β + cos β) of each mode.
    fn s1() -> f64 {
        (b1().sinh() - b1().sin()) / (b1().cosh() + b1().cos())
    }
    fn s2() -> f64 {
        (b2().sinh() - b2().sin()) / (b2().cosh() + b2().cos())
    }
    fn s3() -> f64 {
        (b3().sinh() - b3().sin()) / (b3().cosh() + b3().cos())
    }
    fn s4() -> f64 {
        (b4().sinh() - b4().sin()) / (b4().cosh() + b4().cos())
    }

    /// The beam, clamped at the hub: its frame turns with the hub.
    static beam: Body = Deformable {
        origin: [0.0, 0.0],
        angle: hub(),
        elastic: [w1, w2, w3, w4, u1, u2, u3],
        span: 0.0..1.0,
        position: |xi| [l * xi, 0.0],
        density: rho_a * l,
        displacement: |xi| {
            [
                u1 * xi + u2 * xi * xi + u3 * xi.powi(3),
                w1 * ((b1() * xi).cosh()
                    - (b1() * xi).cos()
                    - s1() * ((b1() * xi).sinh() - (b1() * xi).sin()))
                    + w2 * ((b2() * xi).cosh()
                        - (b2() * xi).cos()
                        - s2() * ((b2() * xi).sinh() - (b2() * xi).sin()))
                    + w3 * ((b3() * xi).cosh()
                        - (b3() * xi).cos()
                        - s3() * ((b3() * xi).sinh() - (b3() * xi).sin()))
                    + w4 * ((b4() * xi).cosh()
                        - (b4() * xi).cos()
                        - s4() * ((b4() * xi).sinh() - (b4() * xi).sin())),
            ]
        },
        axial_rigidity: ea,
        bending_rigidity: ei,
        stiffening,
    };

    /// The tip.
    static tip: Point = Point {
        frame: beam,
        at: beam.material(1.0),
    };

    /// Displacement of the tip perpendicular to the rotating frame's x axis [m].
    #[output]
    fn tip_deflection() -> f64 {
        beam.material(1.0).y()
    }
}
