//! Cost of building a deformable body before a run (`pfaff::flex`): assembly of the
//! nodal invariants, the reference condition and the modal reduction of a uniform
//! cantilever, planar and spatial, for 8 … 64 elements and 4 or 16 kept modes. Best of
//! five runs each (the machine is shared).
//!
//! `cargo bench -p pfaff --bench flex_reduce`.

use std::time::Instant;

use pfaff::flex::{Beam, Dim, Invariants, Reduction, Reference, Section};

fn best_of(runs: usize, f: impl Fn()) -> f64 {
    (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    println!("dim      elements  nodal coords  modes  flat values  reduce [ms]");
    for dim in [Dim::Planar, Dim::Spatial] {
        let section = match dim {
            Dim::Planar => Section::planar(1.2, 2.8e7, 1.4e4),
            Dim::Spatial => Section::spatial(1.2, 2.8e7, 1.4e4, 1.4e4, 1.0e4, 1e-4, 1e-4),
        };
        for elements in [8, 16, 32, 64] {
            for modes in [4, 16] {
                let beam = Beam {
                    dim,
                    elements,
                    length: 10.0,
                    section,
                    reference: Reference::Clamped { node: 0 },
                    reduction: Reduction::Modes(modes),
                };
                let nodal = elements * dim.dofs_per_node();
                if modes > nodal {
                    continue;
                }
                let t = best_of(5, || {
                    std::hint::black_box(beam.reduce().unwrap());
                });
                println!(
                    "{:8} {elements:9} {nodal:13} {modes:6} {:12} {:12.2}",
                    format!("{dim:?}"),
                    Invariants::flat_len(dim.d(), modes),
                    t * 1e3
                );
            }
        }
    }
}
