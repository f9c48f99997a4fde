//! The generic check of one model: every generated function against its [`Reference`]
//! at seeded random states, with the tolerances below, plus the static [`Info`].
//!
//! Errors are measured relative to the size of what was compared: for a quantity `x`
//! computed from primal values `f` (the energies, the constraint values),
//! `err = max|x_gen − x_ref| / (max|x_ref| + |f|)`. The `|f|` term is the scale of the
//! rounding error of the difference quotients (see `util`), and it keeps quantities
//! that vanish at a state (structural zeros, `C_t` of a scleronomic model) comparable.
//! The models' variables are O(1) at the sampled states, so the two terms have
//! comparable size.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use pfaff::{Info, Mechanism, Pattern, TimeDependence};

use super::reference::Reference;
use super::util::{dense, max_abs, max_diff};

/// Direct evaluations (`T`, `V`, `C`, `g`): the generated code evaluates the same
/// expressions in another order (shared subexpressions, folded constants), which costs a
/// few ulps per operation relative to the value: 1e-12 ≈ 4500 ε.
pub const TOL_EVAL: f64 = 1e-12;
/// First differences (`C_q`, `C_t`, `G`, `γ_nh`): `util::d1` errs by about 3e-13 |f|
/// (rounding) + 3e-14 |f⁽⁵⁾| (truncation). The largest fifth derivatives among the
/// sampled models come from the road of `car_axis` (r w⁵ = 10⁴ in t), giving 3e-10 at
/// worst; 1e-8 leaves a factor of 30.
pub const TOL_D1: f64 = 1e-8;
/// Nested first differences (`M = ∂²T/∂q̇²` and the Lagrange operator `Q`): rounding
/// (18/12)² ε |f| / h² ≈ 5e-10 |f| dominates; 1e-7 leaves a factor of 200.
pub const TOL_D11: f64 = 1e-7;
/// Second differences (`γ_h`): `util::d2` errs by about 1.2e-9 |f| (rounding) +
/// 1e-14 |f⁽⁶⁾| (truncation, at most 1e-9 for the road of `car_axis`); 1e-7 leaves a
/// factor of 50.
pub const TOL_D2: f64 = 1e-7;
/// A pattern entry counts as seen non-zero once its reference value exceeds this many
/// times the tolerance of its comparison (relative, like the errors).
const SEEN_FACTOR: f64 = 10.0;

/// One random state.
#[derive(Clone, Debug)]
pub struct State {
    pub t: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
}

/// Accumulates the errors of one model over many states and reports them.
#[derive(Debug)]
pub struct Checker {
    label: String,
    info: &'static Info,
    /// Largest normalized error and its tolerance, per quantity.
    errors: BTreeMap<&'static str, (f64, f64)>,
    /// Pattern entries seen non-zero: mass, holonomic, non-holonomic.
    seen: [Vec<bool>; 3],
    failures: Vec<String>,
    states: usize,
}

impl Checker {
    pub fn new(label: impl Into<String>, info: &'static Info) -> Self {
        let mut checker = Self {
            label: label.into(),
            info,
            errors: BTreeMap::new(),
            seen: [
                vec![false; info.mass_pattern.len()],
                vec![false; info.holonomic_pattern.len()],
                vec![false; info.nonholonomic_pattern.len()],
            ],
            failures: Vec::new(),
            states: 0,
        };
        let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
        checker.check_pattern("mass pattern", info.mass_pattern, n, n);
        checker.check_pattern("holonomic pattern", info.holonomic_pattern, mh, n);
        checker.check_pattern("nonholonomic pattern", info.nonholonomic_pattern, mnh, n);
        let p = info.mass_pattern;
        if !p.iter().all(|&(r, c)| p.binary_search(&(c, r)).is_ok()) {
            checker.fail(format!("mass pattern {p:?} is not symmetric"));
        }
        checker
    }

    fn fail(&mut self, message: String) {
        self.failures.push(message);
    }

    /// Sorted row-major without duplicates, inside the matrix.
    fn check_pattern(&mut self, what: &str, p: Pattern, rows: usize, cols: usize) {
        let sorted = p.windows(2).all(|w| w[0] < w[1]);
        let inside = p
            .iter()
            .all(|&(r, c)| (r as usize) < rows && (c as usize) < cols);
        if !sorted || !inside {
            self.fail(format!(
                "{what} {p:?} is not sorted and unique inside {rows}×{cols}"
            ));
        }
    }

    fn record(&mut self, what: &'static str, err: f64, tol: f64, state: &State) {
        let entry = self.errors.entry(what).or_insert((0.0, tol));
        if err.is_nan() || err > entry.0 {
            entry.0 = err;
        }
        if err.is_nan() || err > tol {
            self.failures.push(format!(
                "{what}: error {err:.3e} > {tol:.0e} at t = {}, q = {:?}, q̇ = {:?}",
                state.t, state.q, state.qd
            ));
        }
    }

    /// Compares a vector; `scale` is the magnitude of the primal values behind it.
    fn compare(
        &mut self,
        what: &'static str,
        gen: &[f64],
        r: &[f64],
        scale: f64,
        tol: f64,
        state: &State,
    ) {
        let denom = (max_abs(r) + scale).max(f64::MIN_POSITIVE);
        self.record(what, max_diff(gen, r) / denom, tol, state);
    }

    /// Compares a pattern-valued matrix with a dense reference, marks the entries seen
    /// non-zero, and reports entries outside the pattern that are not zero.
    #[allow(clippy::too_many_arguments)]
    fn compare_matrix(
        &mut self,
        what: &'static str,
        which: usize,
        pattern: Pattern,
        values: &[f64],
        r: &[f64],
        cols: usize,
        scale: f64,
        tol: f64,
        state: &State,
    ) {
        let rows = r.len() / cols.max(1);
        let gen = dense(pattern, values, rows, cols);
        self.compare(what, &gen, r, scale, tol, state);
        let denom = (max_abs(r) + scale).max(f64::MIN_POSITIVE);
        for (k, &(i, j)) in pattern.iter().enumerate() {
            if r[i as usize * cols + j as usize].abs() / denom > SEEN_FACTOR * tol {
                self.seen[which][k] = true;
            }
        }
        for i in 0..rows {
            for j in 0..cols {
                #[allow(clippy::cast_possible_truncation)]
                let key = (i as u32, j as u32);
                let v = r[i * cols + j];
                if v.abs() / denom > tol && pattern.binary_search(&key).is_err() {
                    self.failures.push(format!(
                        "{what}: entry {key:?} = {v:e} is not in the pattern {pattern:?}"
                    ));
                }
            }
        }
    }

    /// Checks every generated function of `model` against `r` at one state.
    #[allow(non_snake_case)]
    pub fn state(&mut self, model: &dyn Mechanism, r: &Reference, s: &State) {
        let info = self.info;
        let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
        assert_eq!(
            (r.nq(), r.nh(), r.nnh()),
            (n, mh, mnh),
            "{}: sizes",
            self.label
        );
        let (t, q, qd) = (s.t, &s.q[..], &s.qd[..]);
        self.states += 1;
        // NaN-filled buffers: an entry the generated code does not write fails.
        let nan = |len: usize| vec![f64::NAN; len];

        let T = r.kinetic_energy(t, q, qd);
        let V = r.potential_energy(t, q);
        self.compare(
            "T",
            &[model.kinetic_energy(t, q, qd)],
            &[T],
            0.0,
            TOL_EVAL,
            s,
        );
        self.compare("V", &[model.potential_energy(t, q)], &[V], 0.0, TOL_EVAL, s);

        let mut M = nan(info.mass_pattern.len());
        model.mass_matrix(t, q, &mut M);
        let M_ref = r.mass_matrix(t, q, qd);
        self.compare_matrix(
            "M",
            0,
            info.mass_pattern,
            &M,
            &M_ref,
            n,
            T.abs(),
            TOL_D11,
            s,
        );

        let mut Q = nan(n);
        model.forces(t, q, qd, &mut Q);
        let Q_scale = T.abs() + V.abs() + r.applied_scale(t, q, qd);
        self.compare("Q", &Q, &r.forces(t, q, qd), Q_scale, TOL_D11, s);

        if mh > 0 {
            let C_ref = r.holonomic_values(t, q);
            let C_scale = max_abs(&C_ref);
            let mut C = nan(mh);
            model.holonomic(t, q, &mut C);
            self.compare("C", &C, &C_ref, 0.0, TOL_EVAL, s);
            let mut Cq = nan(info.holonomic_pattern.len());
            model.holonomic_jacobian(t, q, &mut Cq);
            let Cq_ref = r.holonomic_jacobian(t, q);
            self.compare_matrix(
                "C_q",
                1,
                info.holonomic_pattern,
                &Cq,
                &Cq_ref,
                n,
                C_scale,
                TOL_D1,
                s,
            );
            let mut Ct = nan(mh);
            model.holonomic_rate(t, q, &mut Ct);
            self.compare("C_t", &Ct, &r.holonomic_rate(t, q), C_scale, TOL_D1, s);
            let mut gamma = nan(mh);
            model.holonomic_gamma(t, q, qd, &mut gamma);
            self.compare(
                "gamma_h",
                &gamma,
                &r.holonomic_gamma(t, q, qd),
                C_scale,
                TOL_D2,
                s,
            );
        }

        if mnh > 0 {
            let N_scale = max_abs(&r.nonholonomic_values(t, q, qd));
            let mut G = nan(info.nonholonomic_pattern.len());
            model.nonholonomic_matrix(t, q, &mut G);
            let G_ref = r.nonholonomic_matrix(t, q);
            self.compare_matrix(
                "G",
                2,
                info.nonholonomic_pattern,
                &G,
                &G_ref,
                n,
                N_scale,
                TOL_D1,
                s,
            );
            let mut g = nan(mnh);
            model.nonholonomic_bias(t, q, &mut g);
            let g_ref = r.nonholonomic_bias(t, q);
            // g may vanish identically: compare against the size of the whole expression.
            self.compare("g", &g, &g_ref, N_scale, TOL_EVAL, s);
            let mut gamma = nan(mnh);
            model.nonholonomic_gamma(t, q, qd, &mut gamma);
            self.compare(
                "gamma_nh",
                &gamma,
                &r.nonholonomic_gamma(t, q, qd),
                N_scale,
                TOL_D1,
                s,
            );
        }
    }

    /// Asserts that no check failed and every pattern entry was seen non-zero; prints
    /// the largest errors (run with `--nocapture` to see them).
    pub fn finish(mut self) {
        let names = ["mass", "holonomic", "nonholonomic"];
        let patterns = [
            self.info.mass_pattern,
            self.info.holonomic_pattern,
            self.info.nonholonomic_pattern,
        ];
        for (k, seen) in self.seen.clone().iter().enumerate() {
            for (entry, _) in patterns[k].iter().zip(seen).filter(|(_, s)| !**s) {
                self.fail(format!(
                    "{} pattern entry {entry:?} was zero at all {} states",
                    names[k], self.states
                ));
            }
        }
        let mut line = format!("accuracy {} ({} states):", self.label, self.states);
        for (what, (err, tol)) in &self.errors {
            let _ = write!(line, " {what} {err:.1e} (tol {tol:.0e});");
        }
        println!("{line}");
        assert!(
            self.failures.is_empty(),
            "{}: {} failures:\n{}",
            self.label,
            self.failures.len(),
            self.failures
                .iter()
                .take(30)
                .cloned()
                .collect::<Vec<_>>()
                .join("\n")
        );
    }
}

/// What a model's [`Info`] must say, beside its parameters (see `check_parameters!`).
#[derive(Debug)]
pub struct Expected<'a> {
    pub name: &'a str,
    pub coordinates: &'a [&'a str],
    pub holonomic: &'a [&'a str],
    pub nonholonomic: &'a [&'a str],
    pub time: TimeDependence,
    pub homogeneous: bool,
    pub conservative: bool,
    /// Default initial coordinates and velocities.
    pub q0: &'a [f64],
    pub qd0: &'a [f64],
}

/// Checks names, sizes, flags and default initial state.
pub fn check_info(model: &dyn Mechanism, e: &Expected<'_>) {
    let info = model.info();
    let names = |s: &[pfaff::Symbol]| s.iter().map(|s| s.name).collect::<Vec<_>>();
    assert_eq!(info.name, e.name);
    assert!(
        !info.doc.trim().is_empty(),
        "{}: model doc is empty",
        e.name
    );
    assert_eq!(
        names(info.coordinates),
        e.coordinates,
        "{}: coordinates",
        e.name
    );
    assert_eq!(names(info.holonomic), e.holonomic, "{}: holonomic", e.name);
    assert_eq!(
        names(info.nonholonomic),
        e.nonholonomic,
        "{}: nonholonomic",
        e.name
    );
    for s in info
        .coordinates
        .iter()
        .chain(info.holonomic)
        .chain(info.nonholonomic)
    {
        assert!(!s.doc.is_empty(), "{}: `{}` has no doc", e.name, s.name);
    }
    assert_eq!(
        (info.nq(), info.nh(), info.nnh()),
        (e.coordinates.len(), e.holonomic.len(), e.nonholonomic.len())
    );
    assert_eq!(info.time, e.time, "{}: time dependence", e.name);
    assert_eq!(
        info.nonholonomic_homogeneous, e.homogeneous,
        "{}: homogeneous",
        e.name
    );
    assert_eq!(
        info.conservative, e.conservative,
        "{}: conservative",
        e.name
    );
    let n = info.nq();
    let (mut q, mut qd) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    model.initial_state(&mut q, &mut qd);
    let close = |a: &[f64], b: &[f64]| max_diff(a, b) <= 4.0 * f64::EPSILON * max_abs(b);
    assert!(close(&q, e.q0), "{}: q0 {q:?}, expected {:?}", e.name, e.q0);
    assert!(
        close(&qd, e.qd0),
        "{}: qd0 {qd:?}, expected {:?}",
        e.name,
        e.qd0
    );
}

/// Checks the parameters of the model module in scope (`Model`, `Params`, `INFO`):
/// names and defaults in order (the defaults to 4 ε, since a default may be computed
/// from earlier ones), `Params::default()`, `parameter(i)`, and that `set_parameter(i, …)`
/// writes the field named `INFO.parameters[i].name`.
macro_rules! check_parameters {
    ($($field:ident = $default:expr),* $(,)?) => {{
        use pfaff::Mechanism as _;
        let expected: &[(&str, f64)] = &[$((stringify!($field), $default)),*];
        let close = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * b.abs();
        let listed: Vec<&str> = INFO.parameters.iter().map(|p| p.name).collect();
        let names: Vec<&str> = expected.iter().map(|e| e.0).collect();
        assert_eq!(listed, names, "{}: parameter names", INFO.name);
        let params = Params::default();
        let fields: &[f64] = &[$(params.$field),*];
        let mut model = Model::default();
        for (i, (name, default)) in expected.iter().enumerate() {
            let p = &INFO.parameters[i];
            assert!(close(p.default, *default), "{name}: Info default {} ≠ {default}", p.default);
            assert!(close(fields[i], *default), "{name}: Params default {} ≠ {default}", fields[i]);
            assert_eq!(model.parameter(i).to_bits(), fields[i].to_bits(), "{name}: parameter({i})");
            assert!(!p.doc.is_empty(), "{name}: no doc");
        }
        #[allow(clippy::cast_precision_loss)]
        let marker = |i: usize| 1000.0 + i as f64;
        for i in 0..expected.len() {
            model.set_parameter(i, marker(i));
        }
        let fields: &[f64] = &[$(model.params.$field),*];
        for (i, (name, _)) in expected.iter().enumerate() {
            assert_eq!(fields[i], marker(i), "set_parameter({i}) did not write `{name}`");
            assert_eq!(model.parameter(i), marker(i), "parameter({i}) after set_parameter");
        }
        let rebuilt = Model::new(model.params);
        for i in 0..expected.len() {
            assert_eq!(rebuilt.parameter(i), marker(i), "Model::new keeps parameter {i}");
        }
    }};
}
pub(crate) use check_parameters;

/// Perturbs every parameter of `model` by a random relative amount of at most `spread`,
/// so that the checks also run away from the defaults.
pub fn perturb(model: &mut dyn Mechanism, rng: &mut super::util::Rng, spread: f64) {
    for i in 0..model.info().parameters.len() {
        let v = model.parameter(i);
        model.set_parameter(i, v * (1.0 + rng.range(-spread, spread)));
    }
}
