//! A uniform rod falling without rotation onto a smooth floor (docs/models.md).

/// Uniform rod falling flat-on-an-angle onto a smooth floor (docs/models.md).
///
/// Rod of length `l` and mass `m`, centre of mass `(x, y)`, angle `phi` to the
/// horizontal. It starts at `phi = angle` without rotation, its lower end `gap` above
/// the floor, moving down at `speed`. The lower end strikes first: with
/// $v = \sqrt{\mathit{speed}^2 + 2 g\,\mathit{gap}}$ the impact comes at
/// $t^* = (v - \mathit{speed})/g$ (at $\mathit{gap}/\mathit{speed}$ when $g = 0$), with the
/// normal impulse $\hat P = (1+e)\,m v/(1 + 3\cos^2\varphi)$, after which
/// $\dot y^+ = -v + \hat P/m$ and $\dot\varphi^+ = -6\hat P\cos\varphi/(m l)$. Both ends
/// are contacts with the floor `y = 0`, written as points of the rod on a plane
/// (`PointPlane`); their gaps are the ends' heights `y ∓ (l/2) sin φ`.
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

    /// The rod: a uniform bar, its centre of mass at `(x, y)`, turned by `phi`.
    static rod: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: m,
        inertia: m * l.powi(2) / 12.0,
    };
    static gravity: Force = Gravity {
        acceleration: [0.0, -g],
    };

    /// The end at `−l/2` along the rod (the lower one at the start) above the floor.
    static lower_end: Contact = PointPlane {
        point: rod.point([-0.5 * l, 0.0]),
        normal: [0.0, 1.0],
        restitution: e,
    };

    /// The end at `+l/2` along the rod above the floor.
    static upper_end: Contact = PointPlane {
        point: rod.point([0.5 * l, 0.0]),
        normal: [0.0, 1.0],
        restitution: e,
    };

    /// The rod as drawn: the bar between its ends.
    static bar: Drawing = Link {
        frame: rod,
        points: [[-0.5 * l, 0.0], [0.5 * l, 0.0]],
    };
}
