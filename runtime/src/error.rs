//! The crate-level error: every module's error enum, joined with `#[from]`.

use crate::assembly::AssemblyError;
use crate::dynamics::DynamicsError;
use crate::free_motion::FreeMotionError;
use crate::kinematics::KinematicsError;
use crate::linearize::LinearizeError;
use crate::partition::PartitionError;
use crate::workspace::EvalError;

/// Any error of the runtime's analyses.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Error {
    /// Evaluation of the model.
    #[error(transparent)]
    Eval(#[from] EvalError),
    /// Coordinate partitioning.
    #[error(transparent)]
    Partition(#[from] PartitionError),
    /// Position or velocity analysis.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// Assembly of initial conditions.
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
    /// Accelerations and multipliers.
    #[error(transparent)]
    Dynamics(#[from] DynamicsError),
    /// Free-motion analysis.
    #[error(transparent)]
    FreeMotion(#[from] FreeMotionError),
    /// Linearization.
    #[error(transparent)]
    Linearize(#[from] LinearizeError),
    /// The impulse solve of an impact.
    #[error(transparent)]
    Impact(#[from] crate::impact::ImpactError),
    /// Building or reducing a deformable body.
    #[error(transparent)]
    Flex(#[from] crate::flex::FlexError),
}
