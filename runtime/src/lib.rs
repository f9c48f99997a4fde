//! # pfaff: constrained multibody dynamics from declarative models
//!
//! A model is written as an inline module annotated with [`mechanism`]. At compile time
//! the macro derives the mass matrix, the generalized forces, the constraint Jacobians
//! and the acceleration right-hand sides symbolically, and emits allocation-free Rust
//! that implements [`Mechanism`]. This crate holds the numerical machinery that turns
//! those functions into motion.
//!
//! Principal types:
//! - [`Mechanism`]: the trait generated code implements; [`Info`] describes a model.
//! - [`MechanismExt`]: dense matrices, energy, constraint residuals, derivative checks.
//! - [`Workspace`]: the per-model buffers, allocated once.
//! - [`Partition`]: generalized coordinate partitioning (Algorithm P).
//! - [`Kinematics`]: position (K1) and velocity (K2) analysis, the partition monitor,
//!   and [assembly](Kinematics::assemble) of consistent initial conditions.
//! - [`Dynamics`]: accelerations and multipliers from the augmented system, dense or
//!   sparse, with minimum-norm multipliers for redundant constraints.
//! - [`ReactionAnalysis`]: multipliers and generalized constraint forces per named
//!   constraint ([`Reactions`]), at a state or along a trajectory; per joint, the force
//!   and torque it transmits ([`JointReactions`]).
//! - [`FreeMotion`]: the explicit multiplier formula and free-motion analysis of the
//!   second seed paper, with the inverse problems ([`free_motion`]).
//! - [`ode`]: integrators (RK4, DOPRI5, DOP853, variable-order Adams) over any
//!   [`ode::OdeSystem`], with dense output, restarts and statistics.
//! - [`sim`]: simulation of a mechanism ([`sim::Simulation`]): assembly, coordinate
//!   partitioning, projection or Baumgarte stabilization, any integrator, output at
//!   requested times, monitors and work-precision sweeps.
//! - [`ImpactSolver`]: the generalized impulse–momentum solve of an impact with
//!   holonomic and non-holonomic constraints ([`Impact`]), augmented and partitioned.
//! - [`linearize()`]: the linearized reduced system and its eigenvalues.
//! - [`PoseExt`]: frame poses and points as nalgebra types ([`nalgebra`] is re-exported).
//! - [`math`]: the sine and cosine generated code calls (fdlibm's kernels, inlinable).
//! - [`replay`]: the JSON trajectory format (times, poses, outputs, the drawing) for
//!   viewers and other tools.
//! - [`flex`]: deformable bodies from beam elements: inertia shape integrals and
//!   stiffness, reference conditions, modal reduction and Craig–Bampton, done once
//!   before a run.
//! - [`Error`]: every module's error, joined.

/// nalgebra, in the version whose types [`PoseExt`] returns.
pub use nalgebra;
pub use pfaff_macros::mechanism;

mod assembly;
mod drawing;
mod dynamics;
mod error;
mod ext;
pub mod flex;
pub mod free_motion;
mod impact;
pub mod inertia;
mod joint_reactions;
mod kinematics;
mod linalg;
mod linearize;
pub mod math;
mod mechanism;
pub mod ode;
mod partition;
mod pose;
mod reactions;
pub mod replay;
mod scale;
pub mod sim;
mod workspace;

pub use assembly::{
    AssemblyError, AssemblyReport, MovedGuess, OverriddenVelocity, Prescription, StateLevel,
    Violation, CONSISTENCY_TOLERANCE, GUESS_NUDGE,
};
pub use drawing::{DrawPoint, Drawing, Shape, ShapeKind};
pub use dynamics::{
    AccelerationStats, Dynamics, DynamicsError, DynamicsParams, LinearSolver, SolverPath,
    DEFAULT_CROSSOVER, NEARLY_DEPENDENT,
};
pub use error::Error;
pub use ext::{DerivativeCheck, MechanismExt, Residuals};
pub use free_motion::{
    AppliedForces, FreeMotion, FreeMotionError, FreeMotionParams, FreeMotionPoint, FreeMotionReport,
};
pub use impact::{Impact, ImpactError, ImpactSolver};
pub use joint_reactions::{JointReaction, JointReactions, Wrench};
pub use kinematics::{Kinematics, KinematicsError, KinematicsParams, NewtonParams, NewtonStats};
pub use linearize::{
    linearize, linearize_with, Eigenvalue, Linearization, LinearizeError, LinearizeMethod,
    LinearizeParams, StateComponent, States,
};
pub use mechanism::{
    AugmentedSolve, Body, Contact, DataError, DataSlot, DynamicsTerms, Frame, Info, Joint,
    JointKind, Mechanism, Parameter, Pattern, Point, Symbol, TimeDependence,
};
pub use partition::{
    Condition, Partition, PartitionError, PartitionParams, Preferences, Role, RANK_PIVOT,
};
pub use pose::{isometry2_from_raw, isometry_from_raw, quaternion_from_raw, PoseExt};
pub use reactions::{
    ConstraintKind, ConstraintReaction, ReactionAnalysis, ReactionHistory, Reactions,
};
pub use workspace::{
    scatter_row_major, EvalError, PatternDefect, Quantity, VelocityCorrection, Workspace,
};

/// Items used by generated code. Not part of the public API.
#[doc(hidden)]
pub mod __private {
    pub use crate::drawing::{DrawPoint, Drawing, Shape, ShapeKind};
    pub use crate::flex;
    pub use crate::mechanism::{
        AugmentedSolve, Body, Contact, DataError, DataSlot, DynamicsTerms, Frame, Info, Joint,
        JointKind, Mechanism, Parameter, Point, Symbol, TimeDependence,
    };
    pub use crate::scale::norm_step;

    /// `Σ_k a[k·stride] x[k]`: a contraction of a run-time data slot with consecutive
    /// coordinates or velocities, which generated code calls instead of unrolling the
    /// products (a deformable body's invariant blocks against `q_f`, `q̇_f`). Four
    /// partial sums, so that the additions do not wait for each other. Not inlined: a
    /// 64-mode body makes about 1,600 of these calls per evaluation, and as many copies
    /// of the loop in one generated function are what the compiler takes long over.
    ///
    /// # Panics
    /// If `a` has fewer than `(x.len() − 1)·stride + 1` entries.
    #[inline(never)]
    pub fn dot_strided(a: &[f64], stride: usize, x: &[f64]) -> f64 {
        let mut s = [0.0; 4];
        let (chunks, rest) = x.split_at(x.len() - x.len() % 4);
        if stride == 1 {
            let a = &a[..x.len()];
            for (ca, cx) in a.chunks_exact(4).zip(chunks.chunks_exact(4)) {
                for ((s, a), x) in s.iter_mut().zip(ca).zip(cx) {
                    *s += a * x;
                }
            }
        } else {
            for (k, cx) in chunks.chunks_exact(4).enumerate() {
                let at = 4 * k * stride;
                for (l, (s, x)) in s.iter_mut().zip(cx).enumerate() {
                    *s += a[at + l * stride] * x;
                }
            }
        }
        let base = chunks.len();
        let tail: f64 = rest
            .iter()
            .enumerate()
            .map(|(l, x)| a[(base + l) * stride] * x)
            .sum();
        (s[0] + s[1]) + (s[2] + s[3]) + tail
    }

    #[cfg(test)]
    mod tests {
        /// Against the sum written out, for lengths around the unrolling and both
        /// kinds of stride (a row and a column of a row-major block).
        #[test]
        fn dot_strided_is_the_strided_sum() {
            let a: Vec<f64> = (0..200).map(|k| (k as f64 * 0.37).sin()).collect();
            for len in [1, 3, 4, 7, 8, 13, 16] {
                let x: Vec<f64> = (0..len).map(|k| 1.0 + k as f64 / 3.0).collect();
                for stride in [1, 5, 13] {
                    let want: f64 = (0..len).map(|k| a[k * stride] * x[k]).sum();
                    let got = super::dot_strided(&a[..(len - 1) * stride + 1], stride, &x);
                    assert!((got - want).abs() <= 1e-14 * want.abs().max(1.0));
                }
            }
        }
    }
}
