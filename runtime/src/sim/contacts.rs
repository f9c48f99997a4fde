//! Contacts inside a simulation (docs/theory.md §impacts-in-a-run, Algorithm I): event location of gap
//! closings on the integrator's dense output, the impulse solve at each event with the
//! sequential law for simultaneous contacts, resting contact when impacts accumulate,
//! and its release when its normal force changes sign.
//!
//! **Location.** After every accepted step the gaps of the open contacts are sampled on
//! the step's dense output at [`SAMPLES`] points; a sample above zero followed by one at
//! or below zero brackets a closing, refined by the Illinois variant of regula falsi to
//! [`EVENT_FRACTION`] of the integrator's relative tolerance times the step (the
//! tolerance is the integrator's), and reported on the closed side. The earliest event
//! of all contacts wins; the driver truncates the step there, applies the jump and
//! restarts the integrator (Adams at order 1). A contact that starts a step closed
//! (right after an impact) counts only once a sample has seen it open.
//!
//! **Simultaneous contacts: the sequential law.** At an event, among the closed
//! contacts (gap within [`GAP_FRACTION`] of the size of `q`) the one approaching fastest
//! strikes alone (Newton restitution on that contact, every other contact free,
//! docs/theory.md E41 with one contact row), and the pass repeats until no closed contact
//! approaches. Newton's cradle with `e = 1` and equal masses then passes the impulse
//! down the row: one ball in, one ball out. Each strike is one [`Impact`].
//!
//! **Resting contact.** When a strike leaves a contact with a rebound below
//! [`REST_RATIO`] of the largest impact speed it has seen (the bounces of a ball have
//! accumulated), or a contact sinks below its gap tolerance without having opened
//! since its last strike (flights shorter than the dense output resolves), the contact
//! becomes a persistent constraint as long as its normal force $\nu$ is compressive:
//! $D\ddot q = \gamma_c$ is added to the equations of every formulation as the
//! least-action correction of the accelerations ([`ImpactSolver::rest_correction`]),
//! and each accepted state is moved back onto $\delta = 0$, $v_n = 0$. When $\nu$ changes
//! sign in a step, the sign change is located like a gap closing and the contact is
//! released there.

use super::error::SimErrorKind;
use super::stepper::Stepper;
use super::system::System;
use crate::linalg::inf_norm;
use crate::{Impact, ImpactSolver, Info, Mechanism};

/// Points per step at which the gaps are sampled on the dense output.
pub const SAMPLES: usize = 8;

/// Event times are located to this fraction of `rtol × step`.
pub const EVENT_FRACTION: f64 = 1e-3;

/// A contact is closed when its gap is below this fraction of `1 + ‖q‖∞`.
pub const GAP_FRACTION: f64 = 1e-14;

/// A rebound slower than this fraction of the largest impact speed of the contact
/// turns it into a resting contact.
pub const REST_RATIO: f64 = 1e-8;

/// What happened to a contact besides an impact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactEventKind {
    /// The contact became persistent (resting).
    Rest,
    /// The resting contact released: its normal force turned tensile.
    Release,
}

/// A change of a contact's state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactEvent {
    /// Time.
    pub t: f64,
    /// The contact's name.
    pub contact: &'static str,
    /// What happened.
    pub kind: ContactEventKind,
}

/// An event located in a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Found {
    /// A gap closed at `t`.
    Closing { c: usize, t: f64 },
    /// A contact sank without opening since its last strike: rest at `t`.
    Sinking { c: usize, t: f64 },
    /// A resting contact's force turned tensile at `t`.
    Release { c: usize, t: f64 },
}

impl Found {
    pub fn t(self) -> f64 {
        match self {
            Self::Closing { t, .. } | Self::Sinking { t, .. } | Self::Release { t, .. } => t,
        }
    }
}

/// The contact state of a run.
pub(crate) struct Contacts {
    info: &'static Info,
    solver: ImpactSolver,
    rtol: f64,
    resting: Vec<bool>,
    any_resting: bool,
    /// Normal forces of the resting contacts at the last evaluation.
    nu: Vec<f64>,
    nu_left: Vec<f64>,
    /// Gaps at the left end of the current step.
    g_left: Vec<f64>,
    /// Gaps at the samples of a step, `SAMPLES + 1` rows.
    samples: Vec<f64>,
    g: Vec<f64>,
    vn: Vec<f64>,
    an: Vec<f64>,
    /// Largest impact speed per contact.
    v_ref: Vec<f64>,
    /// Whether a sample has seen the contact open since its last strike.
    opened: Vec<bool>,
    y: Vec<f64>,
    y2: Vec<f64>,
    pub impacts: Vec<Impact>,
    pub events: Vec<ContactEvent>,
}

impl std::fmt::Debug for Contacts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Contacts")
            .field("resting", &self.resting)
            .finish_non_exhaustive()
    }
}

fn gap_tol(q: &[f64]) -> f64 {
    GAP_FRACTION * (1.0 + inf_norm(q))
}

impl Contacts {
    /// `None` for a model without contacts.
    pub fn new(info: &'static Info, rtol: f64) -> Result<Option<Self>, crate::Error> {
        let nc = info.ncontacts();
        if nc == 0 {
            return Ok(None);
        }
        let n = info.nq();
        Ok(Some(Self {
            info,
            solver: ImpactSolver::new(info)?,
            rtol,
            resting: vec![false; nc],
            any_resting: false,
            nu: vec![0.0; nc],
            nu_left: vec![0.0; nc],
            g_left: vec![0.0; nc],
            samples: vec![0.0; (SAMPLES + 1) * nc],
            g: vec![0.0; nc],
            vn: vec![0.0; nc],
            an: vec![0.0; nc],
            v_ref: vec![0.0; nc],
            opened: vec![true; nc],
            y: vec![0.0; 2 * n],
            y2: vec![0.0; 2 * n],
            impacts: Vec::new(),
            events: Vec::new(),
        }))
    }

    /// Adds the resting contacts to the accelerations and multipliers of the point.
    pub fn correct<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut super::point::Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        if !self.any_resting {
            return Ok(());
        }
        p.invalidate_solved();
        let (qdd, lambda) = p.solution.split_at_mut(p.q.len());
        let (mech, q, qd) = (p.mech, &p.q, &p.qd);
        self.solver
            .rest_correction(mech, t, q, qd, qdd, lambda, &self.resting, &mut self.nu)
            .map_err(SimErrorKind::Impact)
    }

    fn gaps_at<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
    ) -> Result<(), SimErrorKind> {
        let g = self
            .solver
            .gaps(mech, t, q)
            .map_err(SimErrorKind::from_eval)?;
        self.g.copy_from_slice(g);
        Ok(())
    }

    /// Checks every contact's coefficient of restitution (within $[0, 1]$) and that no
    /// contact starts penetrated: every gap at the initial positions of
    /// `p` is at least $-\varepsilon(1 + \lVert q\rVert_\infty)$ with the consistency
    /// tolerance of a prescribed state ([`crate::assembly::CONSISTENCY_TOLERANCE`]).
    /// A deeper one is an error naming the deepest contact; the resting-contact
    /// projection could not move the state out of it.
    pub fn check_initial<M: Mechanism + ?Sized>(
        &mut self,
        p: &super::point::Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        // A coefficient of restitution outside [0, 1] is refused before the run, not
        // at the first impact after integrating to it.
        for contact in self.info.contacts {
            let value = p.mech.parameter(contact.restitution as usize);
            if !(0.0..=1.0).contains(&value) {
                return Err(SimErrorKind::Impact(crate::ImpactError::Restitution {
                    contact: contact.name,
                    value,
                }));
            }
        }
        self.gaps_at(p.mech, t, &p.q)?;
        let tolerance = crate::assembly::CONSISTENCY_TOLERANCE * (1.0 + inf_norm(&p.q));
        let deepest = (0..self.g.len())
            .filter(|&k| self.g[k] < -tolerance)
            .min_by(|&a, &b| self.g[a].total_cmp(&self.g[b]));
        match deepest {
            None => Ok(()),
            Some(k) => Err(SimErrorKind::InitialPenetration {
                t,
                contact: self.info.contacts[k].name,
                gap: self.g[k],
                tolerance,
            }),
        }
    }

    /// Records the state at the left end of the next step (after an accepted step or
    /// an event); the point holds the kept state at `t`.
    pub fn anchor<M: Mechanism + ?Sized>(
        &mut self,
        p: &super::point::Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        self.gaps_at(p.mech, t, &p.q)?;
        self.g_left.copy_from_slice(&self.g);
        self.nu_left.copy_from_slice(&self.nu);
        Ok(())
    }

    /// Moves the kept state at `t` back onto the resting contacts; returns whether
    /// anything is resting (the driver then hands the state back to the integrator).
    pub fn project<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut super::point::Point<'_, M>,
        t: f64,
    ) -> Result<bool, SimErrorKind> {
        if !self.any_resting {
            return Ok(false);
        }
        self.solver
            .project_rest(p.mech, t, &mut p.q, &mut p.qd, &self.resting)
            .map_err(SimErrorKind::Impact)?;
        p.invalidate();
        Ok(true)
    }

    /// Forgets the resting contacts (a failed event: the record of the state before
    /// it must not use them).
    pub fn clear_resting(&mut self) {
        self.resting.fill(false);
        self.any_resting = false;
    }

    /// The time tolerance of event location in a step of length `h` ending at `t`.
    fn tolerance(&self, h: f64, t: f64) -> f64 {
        (EVENT_FRACTION * self.rtol * h.abs()).max(4.0 * f64::EPSILON * t.abs())
    }
}

/// The first event in the step `[t0, t1]` that the stepper has just accepted (before
/// the driver keeps its end state), if any.
pub(crate) fn locate<M: Mechanism + ?Sized>(
    sys: &mut System<'_, M>,
    stepper: &Stepper,
    t0: f64,
) -> Result<Option<Found>, SimErrorKind> {
    with_contacts(sys, |c, sys| locate_in(c, sys, stepper, t0))
}

/// Runs `f` on the run's contacts, lent out of `sys` for the call (`None` without
/// contacts).
fn with_contacts<M: Mechanism + ?Sized, R>(
    sys: &mut System<'_, M>,
    f: impl FnOnce(&mut Contacts, &mut System<'_, M>) -> Result<Option<R>, SimErrorKind>,
) -> Result<Option<R>, SimErrorKind> {
    let Some(mut c) = sys.contacts.take() else {
        return Ok(None);
    };
    let r = f(&mut c, sys);
    sys.contacts = Some(c);
    r
}

#[allow(clippy::too_many_lines)]
fn locate_in<M: Mechanism + ?Sized>(
    c: &mut Contacts,
    sys: &mut System<'_, M>,
    stepper: &Stepper,
    t0: f64,
) -> Result<Option<Found>, SimErrorKind> {
    let mech = sys.point.mech;
    let info = c.info;
    let (n, nc) = (info.nq(), info.ncontacts());
    let t1 = stepper.t();
    let ode = SimErrorKind::from_ode;
    let tol = c.tolerance(t1 - t0, t1);
    // Gaps at the samples (the left end is the kept state's).
    c.samples[..nc].copy_from_slice(&c.g_left);
    for j in 1..=SAMPLES {
        #[allow(clippy::cast_precision_loss)]
        let tj = if j == SAMPLES {
            t1
        } else {
            t0 + (t1 - t0) * (j as f64 / SAMPLES as f64)
        };
        stepper.interpolate(tj, &mut c.y).map_err(ode)?;
        let g = c
            .solver
            .gaps(mech, tj, &c.y[..n])
            .map_err(SimErrorKind::from_eval)?;
        c.samples[j * nc..(j + 1) * nc].copy_from_slice(g);
    }
    let eps = gap_tol(stepper.y().get(..n).unwrap_or(&[]));
    let mut best: Option<Found> = None;
    for k in 0..nc {
        if c.resting[k] {
            continue;
        }
        let mut opened = c.opened[k] || c.samples[k] > eps;
        let mut bracket = None;
        let mut sank = false;
        for j in 1..=SAMPLES {
            let (ga, gb) = (c.samples[(j - 1) * nc + k], c.samples[j * nc + k]);
            if opened && ga > 0.0 && gb <= 0.0 {
                bracket = Some(j);
                break;
            }
            opened |= gb > eps;
            if !opened && gb < -eps {
                sank = true;
                break;
            }
        }
        if sank {
            let f = Found::Sinking { c: k, t: t0 };
            if best.is_none_or(|b| f.t() < b.t()) {
                best = Some(f);
            }
            continue;
        }
        let Some(j) = bracket else {
            continue;
        };
        #[allow(clippy::cast_precision_loss)]
        let at = |j: usize| {
            if j == SAMPLES {
                t1
            } else {
                t0 + (t1 - t0) * (j as f64 / SAMPLES as f64)
            }
        };
        let (mut a, mut b) = (at(j - 1), at(j));
        if best.is_some_and(|f| f.t() <= a) {
            continue;
        }
        let (mut ga, mut gb) = (c.samples[(j - 1) * nc + k], c.samples[j * nc + k]);
        let mut side = 0i8;
        for _ in 0..200 {
            if (b - a).abs() <= tol {
                break;
            }
            let mut t = (a * gb - b * ga) / (gb - ga);
            if !(t > a.min(b) && t < a.max(b)) {
                t = 0.5 * (a + b);
            }
            stepper.interpolate(t, &mut c.y).map_err(ode)?;
            let gt = c
                .solver
                .gaps(mech, t, &c.y[..n])
                .map_err(SimErrorKind::from_eval)?[k];
            if gt > 0.0 {
                a = t;
                ga = gt;
                if side == -1 {
                    gb *= 0.5;
                }
                side = -1;
            } else {
                b = t;
                gb = gt;
                if side == 1 {
                    ga *= 0.5;
                }
                side = 1;
            }
        }
        let f = Found::Closing { c: k, t: b };
        if best.is_none_or(|x| b < x.t()) {
            best = Some(f);
        }
    }
    for k in 0..nc {
        // The samples saw these contacts open (for the next step's start).
        if !c.resting[k] && best.is_none() {
            c.opened[k] |= (0..=SAMPLES).any(|j| c.samples[j * nc + k] > eps);
        }
    }
    if !c.any_resting {
        return Ok(best);
    }
    // Release: the normal force at the step's end.
    let t_end = best.map_or(t1, Found::t);
    stepper.interpolate(t_end, &mut c.y).map_err(ode)?;
    let nu_at = |c: &mut Contacts, sys: &mut System<'_, M>, t: f64, y: &[f64]| {
        sys.keep(t, y)?;
        sys.form.accelerations(&mut sys.point, t)?;
        c.correct(&mut sys.point, t)
    };
    let y_end = std::mem::take(&mut c.y);
    let r = nu_at(c, sys, t_end, &y_end);
    c.y = y_end;
    r?;
    let Some(k) = (0..nc).find(|&k| c.resting[k] && c.nu[k] < 0.0) else {
        return Ok(best);
    };
    let (mut a, mut b) = (t0, t_end);
    let (mut fa, mut fb) = (c.nu_left[k], c.nu[k]);
    let mut side = 0i8;
    let mut y = std::mem::take(&mut c.y2);
    for _ in 0..200 {
        if (b - a).abs() <= tol || fa <= 0.0 {
            break;
        }
        let mut t = (a * fb - b * fa) / (fb - fa);
        if !(t > a.min(b) && t < a.max(b)) {
            t = 0.5 * (a + b);
        }
        if let Err(e) = stepper.interpolate(t, &mut y) {
            c.y2 = y;
            return Err(ode(e));
        }
        if let Err(e) = nu_at(c, sys, t, &y) {
            c.y2 = y;
            return Err(e);
        }
        let ft = c.nu[k];
        if ft >= 0.0 {
            a = t;
            fa = ft;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            b = t;
            fb = ft;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    c.y2 = y;
    Ok(Some(Found::Release { c: k, t: b }))
}

/// Moves the closing of contact `k` located at `te` on the dense output of the step
/// `[t0, t1]` (which started at `y0`) to where the integrator's own steps put it: the
/// stepper is restarted at `(t0, y0)` and steps to `te`, and `te` moves by the Newton
/// correction `−δ/δ̇` of the gap found there (the rate from the dense output), at most
/// three times. For an integrator whose dense output is less accurate than its steps
/// (RADAU5's collocation polynomial has the stage order 3), this brings the event
/// time to the accuracy of the steps. The stepper ends at the returned time.
pub(crate) fn refine<M: Mechanism + ?Sized>(
    stepper: &mut Stepper,
    sys: &mut System<'_, M>,
    span: (f64, f64),
    y0: &[f64],
    k: usize,
    te: f64,
    y: &mut [f64],
) -> Result<f64, Refined> {
    let (t0, t1) = span;
    let mech = sys.point.mech;
    let n = mech.info().nq();
    let gap = |sys: &mut System<'_, M>, t: f64, q: &[f64]| -> Result<f64, Refined> {
        match sys.contacts.as_mut() {
            Some(c) => c
                .solver
                .gaps(mech, t, q)
                .map(|g| g[k])
                .map_err(|e| Refined::Sim(SimErrorKind::from_eval(e))),
            None => Ok(0.0),
        }
    };
    let a = (te - 1e-3 * (t1 - t0)).max(t0);
    stepper.interpolate(a, y).map_err(Refined::Ode)?;
    let ga = gap(sys, a, &y[..n])?;
    stepper.interpolate(te, y).map_err(Refined::Ode)?;
    let gb = gap(sys, te, &y[..n])?;
    let rate = (gb - ga) / (te - a);
    if !(rate < 0.0 && rate.is_finite()) {
        // Not a closing the dense output resolves: its time stays.
        return Ok(te);
    }
    let mut te = te;
    for iteration in 0..3 {
        stepper
            .reset(sys, t0, y0, Some(te - t0))
            .map_err(Refined::Ode)?;
        while stepper.t() < te {
            stepper.step(sys, Some(te)).map_err(Refined::Ode)?;
        }
        y.copy_from_slice(stepper.y());
        let g = gap(sys, te, &y[..n])?;
        if g.abs() <= gap_tol(&y[..n]) || iteration == 2 {
            break;
        }
        let next = te - g / rate;
        if next.is_nan() || next <= t0 || (next - te).abs() <= 4.0 * f64::EPSILON * te.abs() {
            break;
        }
        te = next;
    }
    Ok(te)
}

/// A failure while refining an event time: of the integrator, or of an evaluation.
#[derive(Debug)]
pub(crate) enum Refined {
    Ode(crate::ode::OdeError),
    Sim(SimErrorKind),
}

/// Handles an event (or, with `None`, the contacts closed at the start) at `t`, the
/// point holding the kept state there: the impacts of the sequential law, then the
/// contacts that come to rest or release. Returns the first step to restart with
/// (a quarter of the shortest flight of a contact that has just left its surface).
pub(crate) fn handle<M: Mechanism + ?Sized>(
    sys: &mut System<'_, M>,
    found: Option<Found>,
    t: f64,
) -> Result<Option<f64>, SimErrorKind> {
    with_contacts(sys, |c, sys| handle_in(c, sys, found, t))
}

#[allow(clippy::too_many_lines)]
fn handle_in<M: Mechanism + ?Sized>(
    c: &mut Contacts,
    sys: &mut System<'_, M>,
    found: Option<Found>,
    t: f64,
) -> Result<Option<f64>, SimErrorKind> {
    let mech = sys.point.mech;
    let info = c.info;
    let nc = info.ncontacts();
    let eval = SimErrorKind::from_eval;
    let mut forced = None;
    let mut sinking = None;
    match found {
        Some(Found::Release { c: k, t }) => {
            c.resting[k] = false;
            c.any_resting = c.resting.iter().any(|&r| r);
            c.opened[k] = false;
            c.events.push(ContactEvent {
                t,
                contact: info.contacts[k].name,
                kind: ContactEventKind::Release,
            });
        }
        Some(Found::Closing { c: k, .. }) => forced = Some(k),
        Some(Found::Sinking { c: k, .. }) => sinking = Some(k),
        None => {}
    }
    // The sequential law: the closed contact approaching fastest strikes alone, until
    // none approaches.
    let mut threshold = None;
    // Contacts struck in this event whose own rebound was negligible.
    let mut dead = [false; 64];
    for _ in 0..64 * nc {
        let p = &mut sys.point;
        c.gaps_at(mech, t, &p.q)?;
        let eps = gap_tol(&p.q);
        c.solver
            .normal_velocities(mech, t, &p.q, &p.qd, &mut c.vn)
            .map_err(eval)?;
        let closed = |k: usize| !c.resting[k] && (c.g[k] <= eps || forced == Some(k));
        let vmax = (0..nc)
            .filter(|&k| closed(k))
            .map(|k| -c.vn[k])
            .fold(0.0_f64, f64::max);
        let eps_v = *threshold.get_or_insert(1e-9 * vmax);
        let Some(k) = (0..nc)
            .filter(|&k| closed(k) && c.vn[k] < -eps_v && c.vn[k] < 0.0)
            .min_by(|&a, &b| c.vn[a].total_cmp(&c.vn[b]))
        else {
            break;
        };
        let impact = c
            .solver
            .solve(mech, t, &p.q, &p.qd, &[k])
            .map_err(SimErrorKind::Impact)?;
        p.qd.copy_from_slice(&impact.qd_after);
        p.invalidate();
        c.v_ref[k] = c.v_ref[k].max(-c.vn[k]);
        c.opened[k] = false;
        if let Some(d) = dead.get_mut(k) {
            *d = impact.normal_velocity_after[0].abs() <= REST_RATIO * c.v_ref[k];
        }
        forced = None;
        c.impacts.push(impact);
    }
    // Rest: closed contacts whose rebound is negligible, or that sank without opening.
    let p = &mut sys.point;
    c.gaps_at(mech, t, &p.q)?;
    let eps = gap_tol(&p.q);
    c.solver
        .normal_velocities(mech, t, &p.q, &p.qd, &mut c.vn)
        .map_err(eval)?;
    let v_floor = 1e-12 * (1.0 + inf_norm(&p.qd));
    let mut candidates = Vec::new();
    for k in 0..nc {
        if c.resting[k] || c.g[k] > eps && sinking != Some(k) {
            continue;
        }
        // A rebound below the rest ratio, a contact that sank, or at the start a closed
        // contact without normal velocity. (A contact left at rest by another strike,
        // like the balls of a cradle, is not one.)
        let rebound = dead.get(k).copied().unwrap_or(false);
        let at_start = found.is_none() && c.vn[k].abs() <= v_floor;
        if rebound || at_start || sinking == Some(k) {
            candidates.push(k);
        }
    }
    if !candidates.is_empty() {
        for &k in &candidates {
            c.resting[k] = true;
        }
        c.any_resting = true;
        // Drop candidates pulled away from their surface, weakest first.
        loop {
            sys.form.accelerations(&mut sys.point, t)?;
            c.correct(&mut sys.point, t)?;
            let floor = 1e-9 * (1.0 + inf_norm(sys.point.ws.forces()));
            let Some(k) = candidates
                .iter()
                .copied()
                .filter(|&k| c.resting[k] && c.nu[k] <= floor)
                .min_by(|&a, &b| c.nu[a].total_cmp(&c.nu[b]))
            else {
                break;
            };
            c.resting[k] = false;
            c.any_resting = c.resting.iter().any(|&r| r);
            if !c.any_resting {
                break;
            }
        }
        for &k in &candidates {
            if c.resting[k] {
                c.events.push(ContactEvent {
                    t,
                    contact: info.contacts[k].name,
                    kind: ContactEventKind::Rest,
                });
            }
        }
        let p = &mut sys.point;
        if c.any_resting {
            c.solver
                .project_rest(mech, t, &mut p.q, &mut p.qd, &c.resting)
                .map_err(SimErrorKind::Impact)?;
            p.invalidate();
        }
    }
    if let Some(k) = sinking.filter(|&k| !c.resting[k]) {
        // A sinking contact that is not pushed onto its surface: stop its approach.
        let p = &mut sys.point;
        c.solver
            .normal_velocities(mech, t, &p.q, &p.qd, &mut c.vn)
            .map_err(eval)?;
        if c.vn[k] < 0.0 {
            let impact = c
                .solver
                .solve(mech, t, &p.q, &p.qd, &[k])
                .map_err(SimErrorKind::Impact)?;
            p.qd.copy_from_slice(&impact.qd_after);
            p.invalidate();
            c.impacts.push(impact);
        }
        c.opened[k] = true;
    }
    if found.is_none() {
        // The start: a contact counts as open once its gap exceeds the tolerance.
        let p = &sys.point;
        c.gaps_at(mech, t, &p.q)?;
        let eps = gap_tol(&p.q);
        for k in 0..nc {
            c.opened[k] = c.g[k] > eps;
        }
    }
    // The first step after the event: a quarter of the shortest flight.
    sys.form.accelerations(&mut sys.point, t)?;
    c.correct(&mut sys.point, t)?;
    let p = &sys.point;
    c.solver
        .normal_velocities(mech, t, &p.q, &p.qd, &mut c.vn)
        .map_err(eval)?;
    c.solver
        .normal_accelerations(mech, t, &p.q, &p.qd, p.qdd(), &mut c.an)
        .map_err(eval)?;
    c.gaps_at(mech, t, &p.q)?;
    let eps = gap_tol(&p.q);
    let mut h0: Option<f64> = None;
    for k in 0..nc {
        if !c.resting[k] && c.g[k] <= eps && c.vn[k] > 0.0 && c.an[k] < 0.0 {
            let h = 0.5 * c.vn[k] / -c.an[k];
            h0 = Some(h0.map_or(h, |x| x.min(h)));
        }
    }
    Ok(h0)
}

/// Takes the impacts and contact events of the run.
pub(crate) fn take<M: Mechanism + ?Sized>(sys: &System<'_, M>) -> (Vec<Impact>, Vec<ContactEvent>) {
    sys.contacts
        .as_ref()
        .map(|c| (c.impacts.clone(), c.events.clone()))
        .unwrap_or_default()
}
