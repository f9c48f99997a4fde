//! A workspace or an analysis used with another model than the one it was made for:
//! a typed error, not an index out of bounds inside the model's functions.

mod common;

use common::Chain;
use pfaff::{
    Dynamics, DynamicsError, DynamicsParams, EvalError, Kinematics, KinematicsError,
    KinematicsParams, Mechanism, PartitionError, Workspace,
};

fn is_model(e: &EvalError) -> bool {
    matches!(e, EvalError::Model { .. })
}

#[test]
fn a_mismatched_model_is_a_typed_error() {
    // Two chains: the same name, 4 and 6 coordinates. Each case used to panic.
    let (a, b) = (Chain::new(2), Chain::new(3));
    let (na, nb) = (a.info().nq(), b.info().nq());

    // Workspace of `a`, model `b` (and `a`'s lengths).
    let mut ws = Workspace::new(a.info()).unwrap();
    let mut kin = Kinematics::new(a.info(), KinematicsParams::default());
    let mut q = vec![0.1; na];
    let err = kin.position(&b, &mut ws, 0.0, &mut q).unwrap_err();
    assert!(
        matches!(&err, KinematicsError::Partition(PartitionError::Eval(e)) if is_model(e)),
        "{err}"
    );
    let err = ws.eval_constraints(&b, 0.0, &q).unwrap_err();
    assert!(is_model(&err), "{err}");

    // Analyses of `a`, workspace and model `b`.
    let mut ws = Workspace::new(b.info()).unwrap();
    let mut kin = Kinematics::new(a.info(), KinematicsParams::default());
    let mut q = vec![0.1; nb];
    let err = kin
        .repartition(&b, &mut ws, 0.0, &q)
        .map(|_| ())
        .unwrap_err();
    assert!(
        matches!(&err, PartitionError::Eval(e) if is_model(e)),
        "{err}"
    );
    let err = kin.position(&b, &mut ws, 0.0, &mut q).unwrap_err();
    assert!(
        matches!(&err, KinematicsError::Eval(e) if is_model(e)),
        "{err}"
    );
    let mut qd = vec![0.0; nb];
    let err = kin.velocity(&b, &mut ws, 0.0, &q, &mut qd).unwrap_err();
    assert!(
        matches!(&err, KinematicsError::Eval(e) if is_model(e)),
        "{err}"
    );
    let mut dynamics = Dynamics::new(a.info(), DynamicsParams::default()).unwrap();
    let (q, qd) = (vec![0.1; na], vec![0.0; na]);
    let m = a.info().nh() + a.info().nnh();
    let (mut qdd, mut lambda) = (vec![0.0; na], vec![0.0; m]);
    let err = dynamics
        .accelerations(&b, &mut ws, 0.0, &q, &qd, &mut qdd, &mut lambda)
        .unwrap_err();
    assert!(
        matches!(&err, DynamicsError::Eval(e) if is_model(e)),
        "{err}"
    );

    // A buffer of the wrong length passed to the workspace directly.
    let err = ws.eval_constraints(&b, 0.0, &q).unwrap_err();
    assert!(
        matches!(err, EvalError::Length { found, expected, .. } if found == na && expected == nb),
        "{err}"
    );
}
