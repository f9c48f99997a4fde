//! What the program knows about a model beyond its `Info`: a sensible time span, the
//! steady motion to linearize about, and closed-form solutions used as the reference of
//! `pfaff work-precision`. Each [`crate::Entry`] carries its [`Scene`]; an entry that
//! sets none has [`Scene::fallback`] (span 1 s, no steady motion, no closed form).

use pfaff::Mechanism;

/// The reference solution of a model at time `t`: `(coordinates, velocities)` by name.
pub type ClosedForm = fn(&dyn Mechanism, f64) -> Vec<(&'static str, f64, f64)>;

/// The exact impact times of a model up to an end time: `(contact, t)`.
pub type ImpactTimes = fn(&dyn Mechanism, f64) -> Vec<(&'static str, f64)>;

/// A steady motion: coordinates set (the rest assembled), the coordinate whose velocity
/// is the forward speed, and the coordinates that are ignorable in that motion.
#[derive(Clone, Copy, Debug)]
pub struct Steady {
    /// `(name, value)` of coordinates held at the operating point.
    pub coordinates: &'static [(&'static str, f64)],
    /// `(name, value)` of velocities at the operating point, besides the speed.
    pub velocities: &'static [(&'static str, f64)],
    /// The coordinate whose velocity `--speed` sets, and the default speed.
    pub speed: Option<(&'static str, f64)>,
    /// That velocity per unit of speed (a wheel's spin rate is `−v / r`); `None` for 1.
    pub speed_ratio: Option<fn(&dyn Mechanism) -> f64>,
    /// Coordinates whose velocities are states of the linearized system (the lean and
    /// steer rates rather than the yaw rate); empty to leave the choice to the
    /// partition.
    pub independent_velocities: &'static [&'static str],
    /// Ignorable coordinates, dropped from the state matrix.
    pub ignorable: &'static [&'static str],
    /// What the steady motion is, for the report.
    pub summary: &'static str,
}

/// Program-level knowledge of one model.
#[derive(Clone, Copy, Debug)]
pub struct Scene {
    /// Default end time of `simulate`, in seconds.
    pub t_end: f64,
    /// Why that span.
    pub span: &'static str,
    /// The default operating point of `linearize`.
    pub steady: Option<Steady>,
    /// Exact solution from the default initial state, when there is one.
    pub closed_form: Option<ClosedForm>,
    /// The exact impact times up to an end time, `(contact, t)` in time order, for
    /// models with impacts and a closed form.
    pub impact_times: Option<ImpactTimes>,
}

impl Scene {
    /// The scene of an entry that says nothing more: a span of 1 s, no steady motion,
    /// no closed form.
    pub const fn fallback() -> Self {
        Self {
            t_end: 1.0,
            span: "1 s",
            steady: None,
            closed_form: None,
            impact_times: None,
        }
    }
}
