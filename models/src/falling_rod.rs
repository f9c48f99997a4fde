//! A uniform rod falling without rotation onto a smooth floor (benchmark-models.md).

/// Uniform rod falling flat-on-an-angle onto a smooth floor (benchmark-models.md).
///
/// Rod of length `l` and mass `m`, centre of mass `(x, y)`, angle `phi` to the
/// horizontal. It starts at `phi = angle` without rotation, its lower end `gap` above
/// the floor, moving down at `speed`. The lower end strikes first: with
/// $v = \sqrt{\mathit{speed}^2 + 2 g\,\mathit{gap}}$ the impact comes at
/// $t^* = (v - \mathit{speed})/g$ (at $\mathit{gap}/\mathit{speed}$ when $g = 0$), with the
/// normal impulse $\hat P = (1+e)\,m v/(1 + 3\cos^2\varphi)$, after which
/// $\dot y^+ = -v + \hat P/m$ and $\dot\varphi^+ = -6\hat P\cos\varphi/(m l)$. Both ends
/// are contacts.
#[pfaff::mechanism]
pub mod falling_rod {
    /// Length [m].
    const l: f64 = 1.0;
    /// Mass [kg].
    const m: f64 = 1.0;
    /// Initial angle of the rod to the horizontal [rad].
    const angle: f64 = FRAC_PI_4;
    /// Initial downward speed [m/s].
    const speed: f64 = 1.0;
    /// Initial height of the lower end above the floor [m].
    const gap: f64 = 0.01;
    /// Coefficient of restitution.
    const e: f64 = 0.5;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;

    /// Centre of mass, x [m].
    static x: Coordinate = Coordinate {};
    /// Centre of mass, y [m].
    static y: Coordinate = Coordinate {
        q0: gap + 0.5 * l * angle.sin(),
        qd0: -speed,
    };
    /// Angle of the rod to the horizontal [rad].
    static phi: Coordinate = Coordinate { q0: angle };

    fn kinetic_energy() -> f64 {
        0.5 * m * (x.dot().powi(2) + y.dot().powi(2)) + m * l.powi(2) / 24.0 * phi.dot().powi(2)
    }

    fn potential_energy() -> f64 {
        m * g * y
    }

    /// The end at `−l/2` along the rod (the lower one at the start) above the floor.
    #[contact(e)]
    fn lower_end() -> f64 {
        y - 0.5 * l * phi.sin()
    }

    /// The end at `+l/2` along the rod above the floor.
    #[contact(e)]
    fn upper_end() -> f64 {
        y + 0.5 * l * phi.sin()
    }
}
