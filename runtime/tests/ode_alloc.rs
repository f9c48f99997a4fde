//! No integrator allocates while stepping: a counting global allocator wraps `System`
//! and counts, on the test's own thread only, the allocations made during 1000 steps
//! (each followed by a dense-output evaluation) after a warm-up.

// A global allocator is an `unsafe impl`; it only forwards to `System`.
#![allow(unsafe_code)]

use pfaff::ode::samples::Kepler;
use pfaff::ode::{Adams, Dop853, Dopri5, Integrator, OdeOptions, Radau5, Rk4};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn note() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by 1000 steps of `ode` after 10 warm-up steps.
fn allocations_in_1000_steps<I: Integrator>(mut ode: I) -> u64 {
    let mut sys = Kepler { e: 0.5 };
    let y0 = sys.y0();
    ode.reset(&mut sys, 0.0, &y0, None).unwrap();
    let mut out = [0.0; 4];
    for _ in 0..10 {
        ode.step(&mut sys, None).unwrap();
    }
    ALLOCATIONS.store(0, Ordering::Relaxed);
    COUNTING.with(|c| c.set(true));
    for i in 0..1000 {
        let t = ode.step(&mut sys, None).unwrap();
        let mid = 0.5 * (ode.t_prev() + t);
        ode.interpolate(mid, &mut out).unwrap();
        if i % 100 == 0 {
            let y: [f64; 4] = std::array::from_fn(|j| ode.y()[j]);
            ode.set_state(&y).unwrap();
        }
    }
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.load(Ordering::Relaxed)
}

#[test]
fn stepping_does_not_allocate() {
    let o = OdeOptions::with_tol(1e-9);
    let counts = [
        ("rk4", allocations_in_1000_steps(Rk4::new(4, 1e-3).unwrap())),
        (
            "dopri5",
            allocations_in_1000_steps(Dopri5::new(4, o.clone()).unwrap()),
        ),
        (
            "dop853",
            allocations_in_1000_steps(Dop853::new(4, o.clone()).unwrap()),
        ),
        (
            "radau5",
            allocations_in_1000_steps(Radau5::new(4, o.clone()).unwrap()),
        ),
        (
            "adams",
            allocations_in_1000_steps(Adams::new(4, o).unwrap()),
        ),
        // Tolerances near round-off switch on compensated summation.
        (
            "adams 1e-13",
            allocations_in_1000_steps(Adams::new(4, OdeOptions::with_tol(1e-13)).unwrap()),
        ),
    ];
    // The counter works: an allocation on this thread is seen.
    ALLOCATIONS.store(0, Ordering::Relaxed);
    COUNTING.with(|c| c.set(true));
    let v = std::hint::black_box(vec![1u8; 16]);
    COUNTING.with(|c| c.set(false));
    drop(v);
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed), 1);
    for (name, n) in counts {
        println!("{name}: {n} allocations in 1000 steps");
        assert_eq!(n, 0, "{name} allocated while stepping");
    }
}
