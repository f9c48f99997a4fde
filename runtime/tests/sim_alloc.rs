//! The simulation loop does not allocate per step: a counting global allocator, read
//! from the progress callback after every accepted step, for every formulation and
//! integrator (rows reserved by `output_every`).
#![allow(unsafe_code)] // a global allocator cannot be written without it

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use common::{Pendulum, Sleigh};
use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::Mechanism;

struct Counting;

static COUNT: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// Whether this thread's allocations are counted: only the simulating thread's,
    /// since the test harness's own thread allocates while it waits (seen under load).
    /// A `const` thread local without destructor never allocates itself.
    static COUNTED: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if COUNTED.try_with(Cell::get).unwrap_or(false) {
        COUNT.fetch_add(1, Ordering::Relaxed);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations between consecutive accepted steps (the first step is excluded: it may
/// warm up lazily sized scratch); returns `(steps observed, allocations)`.
fn per_step(
    mech: &dyn Mechanism,
    q0: &[f64],
    qd0: &[f64],
    form: Formulation,
    method: Method,
) -> (usize, usize) {
    let mut counts = Vec::with_capacity(100_000);
    Simulation::new(mech)
        .formulation(form)
        .integrator(method)
        .tolerances(1e-8, 1e-10)
        .initial_state(q0, qd0)
        .output_every(0.01)
        .on_progress(|_| counts.push(COUNT.load(Ordering::Relaxed)))
        .run(3.0)
        .unwrap();
    let allocations = counts.windows(2).map(|w| w[1] - w[0]).sum();
    (counts.len() - 1, allocations)
}

/// A model with its initial coordinates and velocities.
type Case = (Box<dyn Mechanism>, &'static [f64], &'static [f64]);

#[test]
fn zero_allocations_per_step() {
    COUNTED.with(|c| c.set(true));
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
                let (steps, allocations) = per_step(model.as_ref(), q0, qd0, form, method);
                eprintln!(
                    "{:<8} {:<12} {:<6} steps {steps:>5} allocations {allocations}",
                    model.info().name,
                    form.name(),
                    method.name()
                );
                assert!(steps >= 10);
                assert!(
                    allocations == 0,
                    "{} {form:?} {method:?}: {allocations} allocations in {steps} steps",
                    model.info().name
                );
            }
        }
    }
}
