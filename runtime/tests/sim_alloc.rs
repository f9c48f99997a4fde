//! The simulation loop does not allocate per step: a counting global allocator, read
//! from the progress callback after every accepted step, for every formulation and
//! integrator (rows reserved by `output_every`).
#![allow(unsafe_code)] // a global allocator cannot be written without it

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use common::{Pendulum, Sleigh};
use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::Mechanism;

struct Counting;

static COUNT: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        COUNT.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        COUNT.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations between consecutive accepted steps (the first step is excluded: it may
/// warm up lazily sized scratch); returns `(steps observed, allocations, re-partitions)`.
fn per_step(
    mech: &dyn Mechanism,
    q0: &[f64],
    qd0: &[f64],
    form: Formulation,
    method: Method,
) -> (usize, usize, u64) {
    let mut counts = Vec::with_capacity(100_000);
    let run = Simulation::new(mech)
        .formulation(form)
        .integrator(method)
        .tolerances(1e-8, 1e-10)
        .initial_state(q0, qd0)
        .output_every(0.01)
        .on_progress(|_| counts.push(COUNT.load(Ordering::Relaxed)))
        .run(3.0)
        .unwrap();
    let allocations = counts.windows(2).map(|w| w[1] - w[0]).sum();
    (counts.len() - 1, allocations, run.stats.repartitions)
}

/// A model with its initial coordinates and velocities.
type Case = (Box<dyn Mechanism>, &'static [f64], &'static [f64]);

#[test]
fn zero_allocations_per_step() {
    let models: [Case; 2] = [
        (Box::new(Pendulum::new(false)), &[1.0, 0.0], &[0.0, 0.0]),
        (Box::new(Sleigh::default()), &[0.0; 3], &[1.0, 0.15, 0.5]),
    ];
    for (model, q0, qd0) in &models {
        for form in Formulation::ALL {
            for method in [
                Method::Rk4 { h: 1e-3 },
                Method::Dopri5,
                Method::Dop853,
                Method::Adams,
            ] {
                let (steps, allocations, repartitions) =
                    per_step(model.as_ref(), q0, qd0, form, method);
                eprintln!(
                    "{:<8} {:<12} {:<6} steps {steps:>5} allocations {allocations} repartitions {repartitions}",
                    model.info().name,
                    form.name(),
                    method.name()
                );
                assert!(steps >= 10);
                // A re-partition runs Algorithm P, which allocates its result (a new
                // `Partition` with three index vectors: β, γ and the holonomic rows of
                // β); nothing else in the loop may allocate.
                assert!(
                    allocations <= 3 * repartitions as usize,
                    "{} {form:?} {method:?}: {allocations} allocations in {steps} steps",
                    model.info().name
                );
            }
        }
    }
}
