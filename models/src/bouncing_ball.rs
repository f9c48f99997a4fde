//! A ball bouncing on the ground: the impacts accumulate in finite time
//! (docs/models.md, docs/theory.md V17.4).

/// Point mass dropped onto the ground, restitution `e` (docs/models.md).
///
/// The ball (mass `m`) starts at rest at height `h` and falls under gravity `g`; the
/// contact `floor` is its height `y`. Each bounce returns it to `e²` times the height
/// before, so the bounces accumulate at
/// $t_\infty = \sqrt{2h/g}\,(1+e)/(1-e)$ (1.35460 s for the defaults), after which it
/// rests on the ground. From `pull_start` on, an upward force `pull_rate·(t − pull_start)`
/// pulls on it (none by default): it leaves the ground when the force exceeds its
/// weight, at $t = $ `pull_start` $+ m g/$`pull_rate`.
#[pfaff::mechanism]
pub mod bouncing_ball {
    /// Mass [kg].
    const m: f64 = 1.0;
    /// Initial height [m].
    const h: f64 = 1.0;
    /// Coefficient of restitution.
    const e: f64 = 0.5;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;
    /// Growth rate of the upward pull [N/s] (0: no pull).
    const pull_rate: f64 = 0.0;
    /// Time the pull starts to grow [s].
    const pull_start: f64 = 2.0;

    /// Height of the ball above the ground [m].
    static y: Coordinate = Coordinate { q0: h, qd0: 0.0 };

    fn kinetic_energy() -> f64 {
        0.5 * m * y.dot().powi(2)
    }

    fn potential_energy() -> f64 {
        m * g * y
    }

    /// The upward pull, `pull_rate·(t − pull_start)` once `t > pull_start`.
    #[force(y)]
    fn pull() -> f64 {
        0.5 * pull_rate * ((t - pull_start) + (t - pull_start).abs())
    }

    /// The ball as drawn: a disc resting on its lowest point, which is at height `y`.
    static ball: Drawing = Disc {
        center: [0.0, y + 0.05 * h],
        radius: 0.05 * h,
        color: "#c0392b",
    };
    /// The ground as drawn.
    static ground_line: Drawing = Ground {
        at: [0.0, 0.0],
        normal: [0.0, 1.0],
    };

    /// The ground below the ball: its height.
    #[contact(e)]
    fn floor() -> f64 {
        y
    }
}
