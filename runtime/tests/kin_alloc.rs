//! The hot paths do not allocate after warm-up: a counting global allocator around the
//! acceleration solve (the model's generated one, dense and sparse), K1 and K2.
#![allow(unsafe_code)] // a global allocator cannot be written without it

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use common::{Chain, SliderCrank};
use pfaff::{
    Dynamics, DynamicsParams, Kinematics, KinematicsParams, LinearSolver, Mechanism, SolverPath,
    Workspace,
};

struct Counting;

thread_local! {
    static ACTIVE: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

fn note() {
    let _ = ACTIVE.try_with(|a| {
        if a.get() {
            let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        }
    });
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `f` on this thread.
fn count(f: impl FnOnce()) -> usize {
    COUNT.with(|c| c.set(0));
    ACTIVE.with(|a| a.set(true));
    f();
    ACTIVE.with(|a| a.set(false));
    COUNT.with(Cell::get)
}

fn accelerations_do_not_allocate<M: Mechanism>(
    mech: &M,
    q: &[f64],
    qd: &[f64],
    solver: LinearSolver,
    path: SolverPath,
) {
    let info = mech.info();
    let mut ws = Workspace::new(info).unwrap();
    let params = DynamicsParams {
        solver,
        ..Default::default()
    };
    let mut d = Dynamics::new(info, params).unwrap();
    let (mut a, mut l) = (vec![0.0; info.nq()], vec![0.0; info.nh() + info.nnh()]);
    let mut qd = qd.to_vec();
    let stats = d
        .accelerations(mech, &mut ws, 0.0, q, &qd, &mut a, &mut l)
        .unwrap();
    assert_eq!(stats.path, path);
    let n = count(|| {
        for k in 0..100 {
            for v in qd.iter_mut() {
                *v *= 1.0 + 1e-3 * f64::from(k % 3);
            }
            d.accelerations(mech, &mut ws, 0.0, q, &qd, &mut a, &mut l)
                .unwrap();
        }
    });
    assert_eq!(
        n, 0,
        "{} ({path:?}): {n} allocations in 100 solves",
        info.name
    );
}

/// A double pendulum in Cartesian coordinates (two rods, 4 coordinates), for the
/// model's generated solve of the augmented system.
#[pfaff::mechanism]
mod double_pendulum {
    /// Mass of each bob [kg].
    const m: f64 = 1.0;
    /// Length of each rod [m].
    const l: f64 = 1.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;

    /// First bob, x [m].
    static x1: Coordinate = Coordinate { q0: l };
    /// First bob, y [m].
    static y1: Coordinate = Coordinate {};
    /// Second bob, x [m].
    static x2: Coordinate = Coordinate { q0: 2.0 * l };
    /// Second bob, y [m].
    static y2: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m * (x1.dot().powi(2) + y1.dot().powi(2) + x2.dot().powi(2) + y2.dot().powi(2))
    }

    fn potential_energy() -> f64 {
        m * g * (y1 + y2)
    }

    /// The first rod, from the pivot.
    #[holonomic]
    fn rod1() -> f64 {
        x1.powi(2) + y1.powi(2) - l.powi(2)
    }

    /// The second rod, between the bobs.
    #[holonomic]
    fn rod2() -> f64 {
        (x2 - x1).powi(2) + (y2 - y1).powi(2) - l.powi(2)
    }
}

#[test]
fn hot_paths_do_not_allocate_after_warm_up() {
    let dp = double_pendulum::Model::default();
    let (q, qd) = ([0.6, -0.8, 1.4, -1.4], [0.8, 0.6, 0.9, 0.7]);
    accelerations_do_not_allocate(&dp, &q, &qd, LinearSolver::Auto, SolverPath::Generated);
    let sc = SliderCrank::new(true);
    let q = sc.configuration(std::f64::consts::FRAC_PI_6);
    let qd = [0.1; 9];
    accelerations_do_not_allocate(&sc, &q, &qd, LinearSolver::Dense, SolverPath::Dense);
    accelerations_do_not_allocate(&sc, &q, &qd, LinearSolver::Sparse, SolverPath::SparseLdlt);
    accelerations_do_not_allocate(&sc, &q, &qd, LinearSolver::SparseLu, SolverPath::Sparse);
    let chain = Chain::new(40);
    let (q, qd) = chain.state();
    accelerations_do_not_allocate(&chain, &q, &qd, LinearSolver::Auto, SolverPath::SparseLdlt);
    accelerations_do_not_allocate(&chain, &q, &qd, LinearSolver::SparseLu, SolverPath::Sparse);
    accelerations_do_not_allocate(&chain, &q, &qd, LinearSolver::Dense, SolverPath::Dense);

    // K1 and K2 on the free slider-crank, with an existing partition.
    let free = SliderCrank::new(false);
    let info = free.info();
    let mut ws = Workspace::new(info).unwrap();
    let mut kin = Kinematics::new(info, KinematicsParams::default());
    let mut q = free.configuration(0.5);
    kin.repartition(&free, &mut ws, 0.0, &q).unwrap();
    let mut qd = [0.0; 9];
    qd[2] = 1.0;
    let mut iterations = 0;
    let n = count(|| {
        for k in 0..50 {
            q[2] = 0.5 + 0.01 * f64::from(k);
            iterations += kin
                .position(&free, &mut ws, 0.0, &mut q)
                .unwrap()
                .iterations;
            kin.velocity(&free, &mut ws, 0.0, &q, &mut qd).unwrap();
            kin.monitor(&free, &mut ws, 0.0, &q).unwrap();
        }
    });
    assert!(iterations > 50);
    assert_eq!(n, 0, "K1/K2/monitor: {n} allocations");
}
