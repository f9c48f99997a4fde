//! Linearization of the reduced (independent-state) equations of motion.
//!
//! Input: a model, an operating point $(q, \dot q, t)$, and optionally the names of
//! coordinates that are ignorable in the motion studied (the position and heading of a
//! sleigh running straight). Output: the state matrix $A = \partial f/\partial y$ of the
//! reduced system $\dot y = f(y)$ and its eigenvalues.
//!
//! **Reduced state.** Coordinate partitioning (Algorithm P) splits
//! $q = [\beta; \eta; \gamma]$. The independent state is
//! $y = [p;\ \dot\gamma]$ with $p = [\eta; \gamma]$, of dimension
//! $(n - m_h) + (n - m_h - m_{nh})$. For a perturbed $y$, the map
//! $f$ solves K1 for $\beta$ (Newton started from the operating point), K2 for
//! $[\dot\beta; \dot\eta]$, the augmented system (E31) for $\ddot q$, and returns
//! $f(y) = [\dot\eta;\ \dot\gamma;\ \ddot\gamma]$. The partition is computed once, at the
//! operating point, keeping the ignorable coordinates independent.
//!
//! **Ignorable coordinates.** Their rows and columns are removed from $A$. If the
//! remaining rows do not depend on them (a cyclic coordinate, or a derivative that
//! vanishes at the operating point), $A$ is block triangular and the dropped
//! eigenvalues are exactly the zeros of the removed block, so the eigenvalues returned
//! are the ones that remain. [`Linearization::dropped_coupling`] reports
//! $\max |\partial f_w/\partial c|$ over the kept rows $w$ and dropped columns $c$, so a
//! caller can see whether the removal was legitimate.
//!
//! **Generated derivatives.** A model declared `#[mechanism(linearize)]` emits
//! [`Mechanism::linearization_jacobian`], the exact partial derivatives of the equations
//! of motion and of the constraints at every level. The state matrix is then the tangent
//! of the reduced map obtained from them by three linear solves (see `generated.rs`):
//! exact up to rounding, with no step to choose, and [`LinearizeMethod::Auto`] (the
//! default) uses it. Other models, or [`LinearizeMethod::Differences`], take the
//! difference path below.
//!
//! **Difference step.** Column $j$ of $A$ is the central difference
//! $(f(y + h_j e_j) - f(y - h_j e_j)) / 2h_j$ with
//! $h_j = \varepsilon^{1/3}\max(|y_j|, s_j)$, $\varepsilon$ = [`f64::EPSILON`], where
//! $s_j$ is the scale of the component's kind, so that the steps follow the units of
//! the model: $\lVert q\rVert_\infty$ for the positions, and for the velocities the
//! larger of $\lVert\dot q\rVert_\infty$ and $\lVert q\rVert_\infty\omega$, with
//! $\omega^2 = \max|\partial\ddot\gamma/\partial p|$ from the position columns (a
//! pendulum at rest: $\sqrt{g l}$). For unit-sized states
//! $h_j \approx 6\cdot10^{-6}$ relative. The truncation error is
//! $h_j^2 |f'''|/6 \approx 6\cdot10^{-12}|f'''|$ and the rounding error
//! $\approx \varepsilon |f| / h_j \approx 4\cdot10^{-11}|f|$; $\varepsilon^{1/3}$ balances
//! the two. K1 runs to a relative tolerance of $10^{-14}$ so that Newton's residual
//! error ($\lesssim 10^{-14}/h_j \approx 2\cdot10^{-9}$ relative at worst, in practice
//! far smaller since Newton converges quadratically) stays below both. The matrix is
//! also computed with the steps $2h_j$; [`Linearization::error_estimate`] is
//! $\max |A_h - A_{2h}|$, which is three times the truncation error of $A_h$ when that
//! dominates. Eigenvalues of a non-defective $A$ move by at most
//! $\kappa(V)\,\lVert\delta A\rVert$ ($V$ the eigenvectors; Bauer–Fike).

mod generated;

use crate::dynamics::{Dynamics, DynamicsError, DynamicsParams};
use crate::kinematics::{Kinematics, KinematicsError, KinematicsParams, NewtonParams};
use crate::linalg::inf_norm;
use crate::partition::{Partition, PartitionError, PartitionParams, Preferences};
use crate::workspace::{check_state, EvalError, Workspace};
use crate::Mechanism;

/// How the state matrix is obtained.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinearizeMethod {
    /// The generated derivatives when the model has them, differences otherwise.
    #[default]
    Auto,
    /// The generated derivatives ([`Mechanism::linearization_jacobian`]); an error for a
    /// model without them.
    Generated,
    /// Central differences of the reduced map (see the module docs).
    Differences,
}

impl std::fmt::Display for LinearizeMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Auto => "auto",
            Self::Generated => "generated derivatives",
            Self::Differences => "central differences",
        })
    }
}

/// Tuning of [`linearize`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearizeParams {
    /// Generated derivatives or differences.
    pub method: LinearizeMethod,
    /// Relative difference step $h_j / \max(|y_j|, s_j)$ (see the module docs); default
    /// $\varepsilon^{1/3}$.
    pub relative_step: f64,
    /// Position and velocity analysis (the default Newton tolerance is $10^{-14}$).
    pub kinematics: KinematicsParams,
    /// The acceleration solve.
    pub dynamics: DynamicsParams,
}

impl Default for LinearizeParams {
    fn default() -> Self {
        Self {
            method: LinearizeMethod::Auto,
            relative_step: f64::EPSILON.cbrt(),
            kinematics: KinematicsParams {
                newton: NewtonParams {
                    tolerance: 1e-14,
                    max_iterations: 50,
                },
                // Redundant holonomic constraints are left out of K1 and K2, as in a
                // simulation; the acceleration solve handles them.
                partition: PartitionParams {
                    allow_redundant: true,
                    ..PartitionParams::default()
                },
            },
            dynamics: DynamicsParams::default(),
        }
    }
}

/// An eigenvalue $\lambda = \mathrm{re} + i\,\mathrm{im}$.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eigenvalue {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
}

/// One component of the reduced state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateComponent {
    /// The coordinate.
    pub coordinate: &'static str,
    /// `false` for the coordinate itself, `true` for its velocity.
    pub velocity: bool,
}

impl std::fmt::Display for StateComponent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}{}",
            self.coordinate,
            if self.velocity { "'" } else { "" }
        )
    }
}

/// The linearized reduced system $\delta\dot y = A\,\delta y$ at an operating point.
#[derive(Clone, Debug)]
pub struct Linearization {
    /// The reduced state, in the order of the rows and columns of the state matrix.
    pub states: Vec<StateComponent>,
    /// $A$ (row-major, `states.len()` squared).
    pub state_matrix: Vec<f64>,
    /// Eigenvalues of $A$, sorted by real part, then imaginary part.
    pub eigenvalues: Vec<Eigenvalue>,
    /// The method used ([`LinearizeMethod::Generated`] or
    /// [`LinearizeMethod::Differences`]).
    pub method: LinearizeMethod,
    /// With differences, $\max |A_h - A_{2h}|$ (see the module docs); with generated
    /// derivatives 0, the matrix being exact up to rounding.
    pub error_estimate: f64,
    /// $\max |\partial f_w / \partial c|$ over kept rows and dropped coordinates (0 when
    /// nothing is dropped).
    pub dropped_coupling: f64,
    /// The partition used: names of $\beta$, $\eta$, $\gamma$.
    pub partition: [Vec<&'static str>; 3],
    /// The operating point after K1/K2 (coordinates).
    pub q: Vec<f64>,
    /// The operating point after K1/K2 (velocities).
    pub qd: Vec<f64>,
}

impl Linearization {
    /// $A_{ij}$.
    #[must_use]
    pub fn entry(&self, i: usize, j: usize) -> f64 {
        self.state_matrix[i * self.states.len() + j]
    }
}

/// Errors of [`linearize`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LinearizeError {
    /// An ignorable name is not a coordinate of the model.
    #[error("unknown coordinate `{name}` among the ignorable ones, expected one of {expected:?}")]
    UnknownCoordinate {
        /// The name given.
        name: String,
        /// The model's coordinates.
        expected: Vec<&'static str>,
    },
    /// An ignorable coordinate is dependent at the operating point.
    #[error("ignorable coordinate `{name}` cannot be kept independent: {source}")]
    DependentIgnorable {
        /// The name given.
        name: &'static str,
        /// Why.
        source: PartitionError,
    },
    /// [`LinearizeMethod::Generated`] was asked of a model without the derivatives.
    #[error("model `{model}` emits no linearization derivatives: declare it `#[mechanism(linearize)]`, or use differences")]
    NotGenerated {
        /// The model.
        model: &'static str,
    },
    /// A stage of the generated tangent map is singular at the operating point.
    #[error("the linearized {stage} is singular at the operating point")]
    SingularTangent {
        /// Which solve.
        stage: &'static str,
    },
    /// The relative difference step is not a positive finite number.
    #[error("invalid relative difference step {0:e}, expected a positive finite value")]
    InvalidStep(f64),
    /// Algorithm P failed.
    #[error(transparent)]
    Partition(#[from] PartitionError),
    /// K1 or K2 failed at a perturbed state.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// The acceleration solve failed.
    #[error(transparent)]
    Dynamics(#[from] DynamicsError),
    /// Evaluation failed.
    #[error(transparent)]
    Eval(#[from] EvalError),
    /// The mass matrix at the operating point has a direction of negative kinetic
    /// energy ([`crate::inertia`]): the linearization would describe no physical motion.
    #[error("the kinetic energy is negative in a direction of `{coordinate}` at the operating point: {}", crate::inertia::explain(*ratio))]
    NegativeMass {
        /// The coordinate whose pivot is negative.
        coordinate: &'static str,
        /// The pivot over its diagonal.
        ratio: f64,
    },
    /// The eigenvalue decomposition did not converge.
    #[error("eigenvalue decomposition of the {dim}x{dim} state matrix did not converge")]
    Eigen {
        /// Dimension of $A$.
        dim: usize,
    },
}

/// The reduced map $f(y)$ and its scratch.
struct Reduced<'a, M: Mechanism + ?Sized> {
    mech: &'a M,
    t: f64,
    ws: Workspace,
    kin: Kinematics,
    dynamics: Dynamics,
    /// Operating point (the Newton start of every evaluation).
    q0: Vec<f64>,
    qd0: Vec<f64>,
    /// $p = [\eta; \gamma]$ (indices into $q$).
    p: Vec<usize>,
    /// $\gamma$.
    gamma: Vec<usize>,
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    lambda: Vec<f64>,
}

impl<M: Mechanism + ?Sized> Reduced<'_, M> {
    fn state(&self) -> Vec<f64> {
        let mut y: Vec<f64> = self.p.iter().map(|&i| self.q0[i]).collect();
        y.extend(self.gamma.iter().map(|&i| self.qd0[i]));
        y
    }

    /// Writes $f(y)$ into `out`.
    fn eval(&mut self, y: &[f64], out: &mut [f64]) -> Result<(), LinearizeError> {
        let np = self.p.len();
        self.q.copy_from_slice(&self.q0);
        self.qd.copy_from_slice(&self.qd0);
        for (k, &i) in self.p.iter().enumerate() {
            self.q[i] = y[k];
        }
        for (k, &i) in self.gamma.iter().enumerate() {
            self.qd[i] = y[np + k];
        }
        self.kin
            .position(self.mech, &mut self.ws, self.t, &mut self.q)?;
        self.kin
            .velocity(self.mech, &mut self.ws, self.t, &self.q, &mut self.qd)?;
        self.dynamics.accelerations(
            self.mech,
            &mut self.ws,
            self.t,
            &self.q,
            &self.qd,
            &mut self.qdd,
            &mut self.lambda,
        )?;
        // ṗ = [η̇; γ̇], then γ̈.
        for (k, &i) in self.p.iter().enumerate() {
            out[k] = self.qd[i];
        }
        for (k, &i) in self.gamma.iter().enumerate() {
            out[np + k] = self.qdd[i];
        }
        Ok(())
    }

    /// The difference steps $h_j = \epsilon_r s_j$ (see the module docs): positions on
    /// the size of $q$, velocities on the size of $\dot q$ or the velocity scale
    /// $\lVert q\rVert_\infty\,\omega$ of the position columns,
    /// $\omega^2 = \max|\partial\ddot\gamma/\partial p|$.
    fn steps(&mut self, y0: &[f64], rel: f64) -> Result<Vec<f64>, LinearizeError> {
        let (d, np) = (y0.len(), self.p.len());
        let positive = |x: f64, fallback: f64| {
            if x > 0.0 && x.is_finite() {
                x
            } else {
                fallback
            }
        };
        let size_q = positive(inf_norm(&self.q0), 1.0);
        let mut h: Vec<f64> = y0.iter().map(|y| rel * y.abs().max(size_q)).collect();
        let a = self.columns(y0, &h[..np], 1.0)?;
        let omega2 = (np..d)
            .flat_map(|i| (0..np).map(move |j| (i, j)))
            .fold(0.0_f64, |m, (i, j)| m.max(a[i * np + j].abs()));
        let speed = inf_norm(&self.qd0).max(size_q * omega2.sqrt());
        let speed = positive(speed, size_q);
        for j in np..d {
            h[j] = rel * y0[j].abs().max(speed);
        }
        Ok(h)
    }

    /// Central-difference Jacobian with steps `scale` × `h` (row-major).
    fn jacobian(&mut self, y0: &[f64], h: &[f64], scale: f64) -> Result<Vec<f64>, LinearizeError> {
        self.columns(y0, h, scale)
    }

    /// The first `h.len()` columns of the central-difference Jacobian (row-major,
    /// `d × h.len()`) with steps `scale` × `h`.
    fn columns(&mut self, y0: &[f64], h: &[f64], scale: f64) -> Result<Vec<f64>, LinearizeError> {
        let (d, c) = (y0.len(), h.len());
        let mut a = vec![0.0; d * c];
        let (mut fp, mut fm) = (vec![0.0; d], vec![0.0; d]);
        let mut y = y0.to_vec();
        for j in 0..c {
            let h = scale * h[j];
            // Use the representable step so that the divisor matches the perturbation.
            let (yp, ym) = (y0[j] + h, y0[j] - h);
            y[j] = yp;
            self.eval(&y, &mut fp)?;
            y[j] = ym;
            self.eval(&y, &mut fm)?;
            y[j] = y0[j];
            for i in 0..d {
                a[i * c + j] = (fp[i] - fm[i]) / (yp - ym);
            }
        }
        Ok(a)
    }
}

/// Linearizes the reduced equations of motion at $(q, \dot q, t)$.
///
/// The dependent parts of $(q, \dot q)$ are first recomputed from the independent ones
/// (K1, K2), so a point that is consistent to the usual tolerances is made exact. The
/// coordinates named in `ignorable` are kept independent and their rows and columns are
/// removed (their velocities stay). See the module docs for the state, the step and the
/// error.
///
/// # Errors
/// An unknown or dependent ignorable coordinate, a failure of partitioning, of K1/K2 or
/// of the acceleration solve at a perturbed state, or an eigensolver failure.
///
/// ```
/// use pfaff::{linearize, LinearizeParams};
/// # #[pfaff::mechanism]
/// # pub mod pendulum {
/// #     const m: f64 = 1.0;
/// #     const l: f64 = 1.0;
/// #     const g: f64 = 9.81;
/// #     static x: Coordinate = Coordinate { q0: l, qd0: 0.0 };
/// #     static y: Coordinate = Coordinate {};
/// #     fn kinetic_energy() -> f64 { 0.5 * m * (x.dot().powi(2) + y.dot().powi(2)) }
/// #     fn potential_energy() -> f64 { m * g * y }
/// #     #[holonomic]
/// #     fn rod() -> f64 { x.powi(2) + y.powi(2) - l.powi(2) }
/// # }
/// // The pendulum hanging at rest: δẍ = −(g/l) δx, eigenvalues ±i√(g/l).
/// let model = pendulum::Model::default();
/// let lin = linearize(&model, 0.0, &[0.0, -1.0], &[0.0, 0.0], &[], &LinearizeParams::default())?;
/// assert_eq!(lin.states.len(), 2);
/// assert!((lin.eigenvalues[1].im - 9.81f64.sqrt()).abs() < 1e-7);
/// # Ok::<(), pfaff::LinearizeError>(())
/// ```
pub fn linearize<M: Mechanism + ?Sized>(
    mech: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
    ignorable: &[&str],
    params: &LinearizeParams,
) -> Result<Linearization, LinearizeError> {
    linearize_with(
        mech,
        t,
        q,
        qd,
        States {
            ignorable,
            velocities: &[],
        },
        params,
    )
}

/// The choice of the reduced state beyond what the partition decides.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct States<'a> {
    /// Coordinates kept independent and dropped from the state matrix (see
    /// [`linearize`]).
    pub ignorable: &'a [&'a str],
    /// Coordinates whose velocities must be independent (states of the reduced system):
    /// the lean and steer rates of a bicycle, say, rather than the yaw rate.
    pub velocities: &'a [&'a str],
}

/// [`linearize`] with a choice of the independent velocities.
///
/// # Errors
/// As [`linearize`]; an unknown name in `states.velocities` is
/// [`LinearizeError::UnknownCoordinate`].
pub fn linearize_with<M: Mechanism + ?Sized>(
    mech: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
    states: States<'_>,
    params: &LinearizeParams,
) -> Result<Linearization, LinearizeError> {
    let ignorable = states.ignorable;
    let info = mech.info();
    check_state(info, t, q, Some(qd))?;
    let rel = params.relative_step;
    if !(rel.is_finite() && rel > 0.0) {
        return Err(LinearizeError::InvalidStep(rel));
    }
    let dropped: Vec<usize> = ignorable
        .iter()
        .map(|&name| {
            info.coordinate_index(name)
                .ok_or_else(|| LinearizeError::UnknownCoordinate {
                    name: name.to_owned(),
                    expected: info.coordinates.iter().map(|s| s.name).collect(),
                })
        })
        .collect::<Result<_, _>>()?;
    let velocities: Vec<usize> = states
        .velocities
        .iter()
        .map(|&name| {
            info.coordinate_index(name)
                .ok_or_else(|| LinearizeError::UnknownCoordinate {
                    name: name.to_owned(),
                    expected: info.coordinates.iter().map(|s| s.name).collect(),
                })
        })
        .collect::<Result<_, _>>()?;
    if let Some(found) = crate::inertia::negative_direction(mech, t, q, qd)? {
        return Err(LinearizeError::NegativeMass {
            coordinate: info.coordinates[found.coordinate].name,
            ratio: found.ratio,
        });
    }
    let mut ws = Workspace::new(info)?;
    let prefs = Preferences {
        coordinates: &dropped,
        velocities: &velocities,
    };
    let partition = Partition::compute(mech, &mut ws, t, q, prefs, &params.kinematics.partition)
        .map_err(|e| match e {
            PartitionError::PrescribedCoordinate { coordinate, .. } => {
                LinearizeError::DependentIgnorable {
                    name: coordinate,
                    source: e,
                }
            }
            other => other.into(),
        })?;
    let names = partition.names();
    let gamma = partition.independent().to_vec();
    let p: Vec<usize> = partition
        .dependent_velocity()
        .iter()
        .chain(&gamma)
        .copied()
        .collect();
    let generated = match (params.method, info.linearization) {
        (LinearizeMethod::Differences, _) => None,
        (_, Some(pattern)) => Some((pattern, partition.clone())),
        (LinearizeMethod::Generated, None) => {
            return Err(LinearizeError::NotGenerated { model: info.name })
        }
        (LinearizeMethod::Auto, None) => None,
    };
    let mut kin = Kinematics::new(info, params.kinematics);
    kin.set_partition(partition);
    let (mut q0, mut qd0) = (q.to_vec(), qd.to_vec());
    kin.position(mech, &mut ws, t, &mut q0)?;
    kin.velocity(mech, &mut ws, t, &q0, &mut qd0)?;
    let n = info.nq();
    let m = info.nh() + info.nnh();
    let mut reduced = Reduced {
        mech,
        t,
        ws,
        kin,
        dynamics: Dynamics::new(info, params.dynamics)?,
        q: q0.clone(),
        qd: qd0.clone(),
        q0,
        qd0,
        p,
        gamma,
        qdd: vec![0.0; n],
        lambda: vec![0.0; m],
    };
    let (a_h, error_estimate, method) = if let Some((pattern, partition)) = generated {
        let r = &mut reduced;
        r.dynamics.accelerations(
            r.mech,
            &mut r.ws,
            t,
            &r.q0,
            &r.qd0,
            &mut r.qdd,
            &mut r.lambda,
        )?;
        let a = generated::state_matrix(
            mech, pattern, &partition, t, &r.q0, &r.qd0, &r.qdd, &r.lambda,
        )?;
        (a, 0.0, LinearizeMethod::Generated)
    } else {
        let y0 = reduced.state();
        let h = reduced.steps(&y0, rel)?;
        let a_h = reduced.jacobian(&y0, &h, 1.0)?;
        let a_2h = reduced.jacobian(&y0, &h, 2.0)?;
        let error_estimate = a_h
            .iter()
            .zip(&a_2h)
            .fold(0.0_f64, |e, (x, y)| e.max((x - y).abs()));
        (a_h, error_estimate, LinearizeMethod::Differences)
    };

    // Reduced state components; keep all but the dropped coordinates.
    let mut all: Vec<StateComponent> = reduced
        .p
        .iter()
        .map(|&i| StateComponent {
            coordinate: info.coordinates[i].name,
            velocity: false,
        })
        .collect();
    all.extend(reduced.gamma.iter().map(|&i| StateComponent {
        coordinate: info.coordinates[i].name,
        velocity: true,
    }));
    let d = all.len();
    let is_dropped = |k: usize| k < reduced.p.len() && dropped.contains(&reduced.p[k]);
    let kept: Vec<usize> = (0..d).filter(|&k| !is_dropped(k)).collect();
    let mut dropped_coupling = 0.0_f64;
    for &i in &kept {
        for j in (0..d).filter(|&j| is_dropped(j)) {
            dropped_coupling = dropped_coupling.max(a_h[i * d + j].abs());
        }
    }
    let dk = kept.len();
    let state_matrix: Vec<f64> = kept
        .iter()
        .flat_map(|&i| kept.iter().map(move |&j| (i, j)))
        .map(|(i, j)| a_h[i * d + j])
        .collect();
    let eigenvalues = eigenvalues(&state_matrix, dk)?;
    Ok(Linearization {
        states: kept.iter().map(|&k| all[k]).collect(),
        state_matrix,
        eigenvalues,
        method,
        error_estimate,
        dropped_coupling,
        partition: names,
        q: reduced.q0,
        qd: reduced.qd0,
    })
}

/// Eigenvalues of the dense row-major `d × d` matrix `a`, sorted by real part, then
/// imaginary part.
fn eigenvalues(a: &[f64], d: usize) -> Result<Vec<Eigenvalue>, LinearizeError> {
    if d == 0 {
        return Ok(Vec::new());
    }
    let mat = faer::Mat::<f64>::from_fn(d, d, |i, j| a[i * d + j]);
    let values = mat
        .eigenvalues()
        .map_err(|_| LinearizeError::Eigen { dim: d })?;
    let mut out: Vec<Eigenvalue> = values
        .iter()
        .map(|z| Eigenvalue { re: z.re, im: z.im })
        .collect();
    out.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    Ok(out)
}
