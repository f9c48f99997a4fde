//! Assembly: consistent initial conditions (docs/theory.md §initial-conditions).
//!
//! Input: a guess $(q, \dot q)$ and a [`Prescription`] of coordinates and velocities by
//! name (e.g. `phi1 = π/6`, `phi1' = 10`). Output: $q$ with $C(q,t) = 0$ and $\dot q$
//! with $C_q\dot q + C_t = 0$, $G\dot q + g = 0$, the prescribed values untouched.
//!
//! Steps: write the prescribed values; run Algorithm P keeping the prescribed
//! coordinates out of $\beta$ and the coordinates with prescribed velocities in
//! $\gamma$ (an error names the coordinate and the constraints that make this
//! impossible); Newton K1 on $\beta$; the velocity solve K2 with the non-prescribed
//! independent velocities taken from the guess.
//!
//! **A singular guess.** Holding a coordinate can leave the others undetermined at the
//! guess itself: a pendulum in Cartesian coordinates with `x` held at 0.6 and `y` at
//! its guess 0, where $\partial C/\partial y = 2y$ vanishes. When Algorithm P cannot
//! keep a prescribed coordinate independent, the free coordinates whose column of
//! $C_q$ vanishes at the guess are moved by [`GUESS_NUDGE`] (relative) and the
//! partition is tried once more; those it leaves independent go back to their guesses,
//! Newton solves for the others from the moved values, and
//! [`AssemblyReport::moved_guesses`] lists them. A guess moves toward the lower
//! potential energy where the potential depends on it (the pendulum's `y` down, to the
//! branch $y = -0.8$ it hangs on), up otherwise; the branch reached follows the move.
//! If the partition fails again, the first error stands.
//!
//! **A full state.** When every coordinate is prescribed there is nothing to solve: the
//! values are checked against the constraints instead, each row $i$ within
//! [`CONSISTENCY_TOLERANCE`] of its scale,
//! $|C_i| \le \varepsilon\,(1 + \lVert q\rVert_\infty)\max_j |\partial C_i/\partial q_j|$
//! (the coordinates are within a relative $\varepsilon$ of meeting the row), and kept
//! as given; a violation is an [`AssemblyError::Inconsistent`] naming every violated
//! constraint with its residual. Likewise when every velocity is prescribed, with
//! $|J_i\dot q + c_i| \le \varepsilon\,(\sum_j |J_{ij}\dot q_j| + |c_i|)$ (up to
//! round-off when all terms vanish).

use crate::kinematics::{Kinematics, KinematicsError, NewtonStats};
use crate::partition::{PartitionError, Preferences};
use crate::workspace::{check_state, EvalError, Workspace};
use crate::Mechanism;

/// Relative tolerance $\varepsilon$ of the consistency check of a fully prescribed
/// state (see the module docs): values typed with about ten significant digits pass, a
/// state off the constraints by more than a hundred-millionth of its size does not.
pub const CONSISTENCY_TOLERANCE: f64 = 1e-8;

/// Which level of a fully prescribed state violates the constraints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateLevel {
    /// The coordinates $q$: $C(q, t) = 0$.
    Positions,
    /// The velocities $\dot q$: $C_q\dot q + C_t = 0$, $G\dot q + g = 0$.
    Velocities,
}

impl std::fmt::Display for StateLevel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Positions => "coordinates",
            Self::Velocities => "velocities",
        })
    }
}

/// A constraint violated by a fully prescribed state.
#[derive(Clone, Debug, PartialEq)]
pub struct Violation {
    /// The constraint's name.
    pub constraint: &'static str,
    /// Its residual ($C_i$, or $J_i\dot q + c_i$).
    pub residual: f64,
    /// The largest residual the check accepted for it.
    pub tolerance: f64,
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "`{}` by {:.3e} (tolerance {:.1e})",
            self.constraint, self.residual, self.tolerance
        )
    }
}

/// Prescribed values by coordinate name.
#[derive(Clone, Copy, Debug, Default)]
pub struct Prescription<'a> {
    /// `(name, value)` of prescribed coordinates.
    pub coordinates: &'a [(&'a str, f64)],
    /// `(name, value)` of prescribed velocities.
    pub velocities: &'a [(&'a str, f64)],
}

/// Outcome of an assembly.
#[derive(Clone, Debug, PartialEq)]
pub struct AssemblyReport {
    /// The position solve.
    pub newton: NewtonStats,
    /// $\lVert q - q_{guess}\rVert_\infty$ (after writing the prescribed values).
    pub position_correction: f64,
    /// $\lVert \dot q - \dot q_{guess}\rVert_\infty$ (after writing the prescribed values).
    pub velocity_correction: f64,
    /// $\lVert [C_q\dot q + C_t;\ G\dot q + g]\rVert_\infty$ at the result.
    pub velocity_residual: f64,
    /// Guesses of free coordinates moved off a configuration where the constraints do
    /// not determine them, so that the prescribed coordinates could be held (module
    /// docs, "A singular guess"); empty when the guess served as given.
    pub moved_guesses: Vec<MovedGuess>,
}

/// The relative size of the move of a singular guess: a coordinate's guess $g$ moves
/// to $g \pm 10^{-3}\max(1, |g|)$ (module docs, "A singular guess").
pub const GUESS_NUDGE: f64 = 1e-3;

/// A guess moved by the assembly (see [`AssemblyReport::moved_guesses`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MovedGuess {
    /// The coordinate.
    pub coordinate: &'static str,
    /// Its guess.
    pub guess: f64,
    /// Where the guess was moved before the Newton iteration.
    pub moved_to: f64,
}

impl std::fmt::Display for MovedGuess {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the guess of `{}` was moved from {} to {}: the constraints do not determine it there, \
             and the prescribed coordinates needed it to be solved for",
            self.coordinate, self.guess, self.moved_to
        )
    }
}

/// A declared initial velocity that the constraints determine from the others (see
/// [`Kinematics::assemble_declared`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverriddenVelocity {
    /// The coordinate.
    pub coordinate: &'static str,
    /// The velocity declared.
    pub declared: f64,
    /// The velocity the constraints gave it.
    pub used: f64,
}

impl std::fmt::Display for OverriddenVelocity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the declared initial velocity of `{}` ({}) is determined by the constraints from the others: {} was used",
            self.coordinate, self.declared, self.used
        )
    }
}

/// Errors of assembly.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AssemblyError {
    /// A prescribed name is not a coordinate of the model.
    #[error("unknown coordinate `{name}` in the prescription, expected one of {expected:?}")]
    UnknownCoordinate {
        /// The name given.
        name: String,
        /// The model's coordinates.
        expected: Vec<&'static str>,
    },
    /// A coordinate is prescribed twice.
    #[error("coordinate `{name}` is prescribed twice")]
    Duplicate {
        /// The name.
        name: &'static str,
    },
    /// The prescription cannot be honoured, or the constraints are redundant.
    #[error("impossible prescription: {0}")]
    Partition(#[from] PartitionError),
    /// Newton could not meet the constraints from the guess, or a solve failed.
    #[error("cannot assemble from the guess: {0}")]
    Kinematics(#[from] KinematicsError),
    /// Every coordinate (or velocity) is prescribed and the values violate the
    /// constraints.
    #[error("the prescribed {level} violate the constraints: {}", list(.violated))]
    Inconsistent {
        /// Coordinates or velocities.
        level: StateLevel,
        /// The violated constraints, in row order.
        violated: Vec<Violation>,
    },
    /// Evaluation failed.
    #[error(transparent)]
    Eval(#[from] EvalError),
}

fn list(v: &[Violation]) -> String {
    v.iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

fn resolve(
    info: &'static crate::Info,
    quantity: crate::Quantity,
    t: f64,
    list: &[(&str, f64)],
    seen: &mut Vec<usize>,
) -> Result<Vec<(usize, f64)>, AssemblyError> {
    seen.clear();
    list.iter()
        .map(|&(name, v)| {
            let i =
                info.coordinate_index(name)
                    .ok_or_else(|| AssemblyError::UnknownCoordinate {
                        name: name.to_owned(),
                        expected: info.coordinates.iter().map(|s| s.name).collect(),
                    })?;
            if seen.contains(&i) {
                return Err(AssemblyError::Duplicate {
                    name: info.coordinates[i].name,
                });
            }
            seen.push(i);
            if !v.is_finite() {
                return Err(EvalError::NonFinite {
                    quantity,
                    t,
                    row: i,
                    col: None,
                    value: v,
                }
                .into());
            }
            Ok((i, v))
        })
        .collect()
}

/// Writes the prescribed values into `(q, q̇)` without solving anything (for a
/// formulation that does not enforce the constraints).
pub(crate) fn write_prescription(
    info: &'static crate::Info,
    t: f64,
    q: &mut [f64],
    qd: &mut [f64],
    prescription: &Prescription<'_>,
) -> Result<(), AssemblyError> {
    let mut seen = Vec::new();
    let pos = resolve(
        info,
        crate::Quantity::Coordinates,
        t,
        prescription.coordinates,
        &mut seen,
    )?;
    let vel = resolve(
        info,
        crate::Quantity::Velocities,
        t,
        prescription.velocities,
        &mut seen,
    )?;
    for (i, v) in pos {
        q[i] = v;
    }
    for (i, v) in vel {
        qd[i] = v;
    }
    Ok(check_state(info, t, q, Some(qd))?)
}

impl Kinematics {
    /// Makes $(q, \dot q)$ consistent at time `t`, holding the prescribed values; the
    /// partition used becomes current (it is not counted as a re-partition).
    pub fn assemble<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &mut [f64],
        qd: &mut [f64],
        prescription: &Prescription<'_>,
    ) -> Result<AssemblyReport, AssemblyError> {
        let info = ws.info();
        check_state(info, t, q, Some(qd))?;
        let mut seen = Vec::new();
        let pos = resolve(
            info,
            crate::Quantity::Coordinates,
            t,
            prescription.coordinates,
            &mut seen,
        )?;
        let vel = resolve(
            info,
            crate::Quantity::Velocities,
            t,
            prescription.velocities,
            &mut seen,
        )?;
        for &(i, v) in &pos {
            q[i] = v;
        }
        for &(i, v) in &vel {
            qd[i] = v;
        }
        let (q0, qd0) = (q.to_vec(), qd.to_vec());
        let n = info.nq();
        // A full state is checked, not solved for (module docs).
        let (all_q, all_qd) = (pos.len() == n, vel.len() == n);
        if all_q {
            check_positions(mech, ws, t, q)?;
        }
        let pos_idx: Vec<usize> = if all_q {
            Vec::new()
        } else {
            pos.iter().map(|p| p.0).collect()
        };
        let vel_idx: Vec<usize> = if all_qd {
            Vec::new()
        } else {
            vel.iter().map(|p| p.0).collect()
        };
        let previous = self.partition.take();
        let prefs = Preferences {
            coordinates: &pos_idx,
            velocities: &vel_idx,
        };
        let mut moved_guesses = Vec::new();
        if let Err(e) = self.repartition_with(mech, ws, t, q, prefs) {
            let retried = matches!(e, PartitionError::PrescribedCoordinate { .. })
                && move_singular_guesses(mech, ws, t, q, &pos_idx, &mut moved_guesses)?
                && self.repartition_with(mech, ws, t, q, prefs).is_ok();
            if !retried {
                q.copy_from_slice(&q0);
                self.partition = previous;
                return Err(e.into());
            }
            self.keep_solved_guesses(info, q, &mut moved_guesses);
        }
        let newton = if all_q {
            ws.eval_constraints(mech, t, q)?;
            NewtonStats {
                iterations: 0,
                residual: crate::linalg::inf_norm(ws.constraints()),
                step: 0.0,
            }
        } else {
            match self.position(mech, ws, t, q) {
                Ok(stats) => stats,
                // A guess where C_q vanishes in the free coordinates that the constraint
                // needs (a Cartesian pendulum with `x` held at 0 from `y` = 0: the rod's
                // row is all zeros there, so Algorithm P sets it aside as dependent on
                // the others and Newton never moves `y`): the same move of the singular
                // guesses as when the partition fails, then once more.
                Err(e @ KinematicsError::NewtonFailed { .. }) if moved_guesses.is_empty() => {
                    q.copy_from_slice(&q0);
                    let retried =
                        move_singular_guesses(mech, ws, t, q, &pos_idx, &mut moved_guesses)?
                            && self.repartition_with(mech, ws, t, q, prefs).is_ok();
                    if retried {
                        self.keep_solved_guesses(info, q, &mut moved_guesses);
                    }
                    match retried.then(|| self.position(mech, ws, t, q)) {
                        Some(Ok(stats)) => stats,
                        _ => {
                            q.copy_from_slice(&q0);
                            return Err(e.into());
                        }
                    }
                }
                Err(e) => return Err(e.into()),
            }
        };
        if all_qd {
            check_velocities(mech, ws, t, q, qd)?;
        } else {
            self.velocity(mech, ws, t, q, qd)?;
        }
        let velocity_residual = velocity_residual(ws, mech, t, q, qd)?;
        let diff = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .fold(0.0_f64, |acc, (x, y)| acc.max((x - y).abs()))
        };
        Ok(AssemblyReport {
            newton,
            position_correction: diff(q, &q0),
            velocity_correction: diff(qd, &qd0),
            velocity_residual,
            moved_guesses,
        })
    }
}

impl Kinematics {
    /// Only the moved guesses Newton solves for need the move: the others (left
    /// independent by the current partition) go back to their values.
    fn keep_solved_guesses(
        &self,
        info: &crate::Info,
        q: &mut [f64],
        moved_guesses: &mut Vec<MovedGuess>,
    ) {
        let dependent = &self
            .partition
            .as_ref()
            .expect("partitioned above")
            .dependent;
        moved_guesses.retain(|m| {
            let j = info.coordinate_index(m.coordinate).expect("a coordinate");
            let solved = dependent.contains(&j);
            if !solved {
                q[j] = m.guess;
            }
            solved
        });
    }
}

/// Moves the guesses of the free coordinates (not in `held`, in some holonomic
/// constraint) whose column of $C_q$ vanishes at `q` by [`GUESS_NUDGE`], recording
/// them in `moved`; whether any was moved (module docs, "A singular guess").
fn move_singular_guesses<M: Mechanism + ?Sized>(
    mech: &M,
    ws: &mut Workspace,
    t: f64,
    q: &mut [f64],
    held: &[usize],
    moved: &mut Vec<MovedGuess>,
) -> Result<bool, EvalError> {
    let info = ws.info();
    let (n, mh) = (info.nq(), info.nh());
    if mh == 0 {
        return Ok(false);
    }
    ws.eval_jacobian(mech, t, q)?;
    let cq = &ws.jacobian()[..mh * n];
    let largest = cq.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    // Coordinates in no constraint (a free body's position) are never solved for.
    let constrained = |j: usize| info.holonomic_pattern.iter().any(|&(_, c)| c as usize == j);
    for j in (0..n).filter(|&j| !held.contains(&j) && constrained(j)) {
        let column = (0..mh).fold(0.0_f64, |a, i| a.max(cq[i * n + j].abs()));
        if column <= 1e-12 * largest {
            // Toward the lower potential energy (a pendulum's guess moves down, to the
            // branch it hangs on); up where the potential does not depend on it.
            let guess = q[j];
            let delta = GUESS_NUDGE * guess.abs().max(1.0);
            let mut potential = |x: f64| {
                q[j] = x;
                mech.potential_energy(t, q)
            };
            let (up, down) = (potential(guess + delta), potential(guess - delta));
            q[j] = if down < up {
                guess - delta
            } else {
                guess + delta
            };
            moved.push(MovedGuess {
                coordinate: info.coordinates[j].name,
                guess,
                moved_to: q[j],
            });
        }
    }
    Ok(!moved.is_empty())
}

impl Kinematics {
    /// [`assemble`](Self::assemble), also holding the non-zero velocities of the guess
    /// (a model's declared `qd0`) where the constraints allow it, and reporting the
    /// ones they determine from the others with the value used. Without this, K2 keeps
    /// the velocities of whichever coordinates Algorithm P leaves independent, and a
    /// declared velocity of a dependent coordinate is silently replaced (a model `x`
    /// with `qd0: 1` tied to `y` by `y - x = 0` would start at rest).
    ///
    /// Greedy: after the plain assembly, each declared velocity that it changed is
    /// added to the prescription if the assembly still succeeds with it, in the order
    /// of the coordinates; the prescription's own values always come first.
    ///
    /// # Errors
    /// As [`assemble`](Self::assemble) with `prescription` alone.
    pub fn assemble_declared<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &mut [f64],
        qd: &mut [f64],
        prescription: &Prescription<'_>,
    ) -> Result<(AssemblyReport, Vec<OverriddenVelocity>), AssemblyError> {
        let info = ws.info();
        check_state(info, t, q, Some(qd))?;
        let declared: Vec<(&'static str, f64)> = info
            .coordinates
            .iter()
            .zip(qd.iter())
            .filter(|&(c, &v)| v != 0.0 && !prescription.velocities.iter().any(|g| g.0 == c.name))
            .map(|(c, &v)| (c.name, v))
            .collect();
        let (q0, qd0) = (q.to_vec(), qd.to_vec());
        let changed = |qd: &[f64], (name, v): (&'static str, f64)| {
            let i = info
                .coordinate_index(name)
                .expect("a coordinate of the model");
            ((qd[i] - v).abs() > 1e-9 * v.abs()).then_some(OverriddenVelocity {
                coordinate: name,
                declared: v,
                used: qd[i],
            })
        };
        let mut report = self.assemble(mech, ws, t, q, qd, prescription)?;
        let mut velocities: Vec<(&str, f64)> = prescription.velocities.to_vec();
        // The velocities of the last successful assembly.
        let mut assembled = qd.to_vec();
        // Whether `q`, `qd`, the partition and `report` are those of the assembly with
        // `velocities` (the assembly is a function of `q0`, `qd0` and the
        // prescription, so a successful last trial needs no repetition).
        let mut current = true;
        for &d in &declared {
            if changed(&assembled, d).is_none() {
                continue;
            }
            velocities.push(d);
            let held = Prescription {
                coordinates: prescription.coordinates,
                velocities: &velocities,
            };
            q.copy_from_slice(&q0);
            qd.copy_from_slice(&qd0);
            if let Ok(r) = self.assemble(mech, ws, t, q, qd, &held) {
                assembled.copy_from_slice(qd);
                report = r;
                current = true;
            } else {
                velocities.pop();
                current = false;
            }
        }
        if !current {
            // The last trial failed: assemble once more with what held, which leaves
            // its partition current.
            let held = Prescription {
                coordinates: prescription.coordinates,
                velocities: &velocities,
            };
            q.copy_from_slice(&q0);
            qd.copy_from_slice(&qd0);
            report = self.assemble(mech, ws, t, q, qd, &held)?;
        }
        let overridden = declared
            .into_iter()
            .filter_map(|d| changed(qd, d))
            .collect();
        Ok((report, overridden))
    }
}

/// The position check of a full state (module docs).
fn check_positions<M: Mechanism + ?Sized>(
    mech: &M,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
) -> Result<(), AssemblyError> {
    let info = ws.info();
    let n = info.nq();
    ws.eval_constraints_with_jacobian(mech, t, q)?;
    ws.scatter_jacobian();
    let size = 1.0 + crate::linalg::inf_norm(q);
    let violated: Vec<Violation> = (0..info.nh())
        .filter_map(|i| {
            let slope = crate::linalg::inf_norm(&ws.jacobian[i * n..(i + 1) * n]);
            let tolerance = CONSISTENCY_TOLERANCE * size * slope;
            let residual = ws.c[i];
            (residual.abs() > tolerance).then_some(Violation {
                constraint: info.holonomic[i].name,
                residual,
                tolerance,
            })
        })
        .collect();
    if violated.is_empty() {
        Ok(())
    } else {
        Err(AssemblyError::Inconsistent {
            level: StateLevel::Positions,
            violated,
        })
    }
}

/// The velocity check of a full state (module docs).
fn check_velocities<M: Mechanism + ?Sized>(
    mech: &M,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Result<(), AssemblyError> {
    let info = ws.info();
    let (n, mh) = (info.nq(), info.nh());
    ws.eval_jacobian(mech, t, q)?;
    ws.eval_rates(mech, t, q)?;
    let violated: Vec<Violation> = (0..mh + info.nnh())
        .filter_map(|i| {
            let c = if i < mh { ws.ct[i] } else { ws.bias[i - mh] };
            let row = &ws.jacobian[i * n..(i + 1) * n];
            let residual = row.iter().zip(qd).map(|(a, b)| a * b).sum::<f64>() + c;
            let scale = row.iter().zip(qd).map(|(a, b)| (a * b).abs()).sum::<f64>() + c.abs();
            let tolerance = CONSISTENCY_TOLERANCE * scale + f64::MIN_POSITIVE;
            let name = if i < mh {
                info.holonomic[i].name
            } else {
                info.nonholonomic[i - mh].name
            };
            (residual.abs() > tolerance).then_some(Violation {
                constraint: name,
                residual,
                tolerance,
            })
        })
        .collect();
    if violated.is_empty() {
        Ok(())
    } else {
        Err(AssemblyError::Inconsistent {
            level: StateLevel::Velocities,
            violated,
        })
    }
}

/// $\lVert [C_q\dot q + C_t;\ G\dot q + g]\rVert_\infty$ using the workspace buffers.
pub(crate) fn velocity_residual<M: Mechanism + ?Sized>(
    ws: &mut Workspace,
    mech: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Result<f64, EvalError> {
    let info = ws.info();
    let (n, mh) = (info.nq(), info.nh());
    ws.eval_jacobian(mech, t, q)?;
    ws.eval_rates(mech, t, q)?;
    let mut r = 0.0_f64;
    for i in 0..mh + info.nnh() {
        let c = if i < mh { ws.ct[i] } else { ws.bias[i - mh] };
        let row = &ws.jacobian[i * n..(i + 1) * n];
        let v: f64 = row.iter().zip(qd).map(|(a, b)| a * b).sum::<f64>() + c;
        r = r.max(v.abs());
    }
    Ok(r)
}
