//! Defines a Cartesian pendulum with `#[pfaff::mechanism]` and simulates it with each
//! formulation, printing a few rows and the monitors.
//!
//! `cargo run --release -p pfaff --example cartesian_pendulum`

use pfaff::sim::{Formulation, Method, Simulation};

/// A point mass on a rigid link of length `l`, in Cartesian coordinates.
#[pfaff::mechanism]
pub mod pendulum {
    /// Mass of the bob [kg].
    const m: f64 = 1.0;
    /// Length of the link [m].
    const l: f64 = 1.0;
    /// Gravity along −y [m/s²].
    const g: f64 = 9.81;

    /// Horizontal position [m].
    static x: Coordinate = Coordinate { q0: l, qd0: 0.0 };
    /// Vertical position [m].
    static y: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m * (x.dot().powi(2) + y.dot().powi(2))
    }

    fn potential_energy() -> f64 {
        m * g * y
    }

    /// The link.
    #[holonomic]
    fn rod() -> f64 {
        x.powi(2) + y.powi(2) - l.powi(2)
    }
}

fn main() -> Result<(), pfaff::sim::SimError> {
    let model = pendulum::Model::default();
    for form in Formulation::ALL {
        let run = Simulation::new(&model)
            .formulation(form)
            .integrator(Method::Adams)
            .tolerances(1e-9, 1e-11)
            .output_every(0.5)
            .run(10.0)?;
        println!("{} ({:?})", form.name(), run.stats);
        let tr = &run.trajectory;
        for i in (0..tr.len()).step_by(5) {
            println!(
                "  t = {:5.2}  x = {:+.9}  y = {:+.9}  lambda = {:+.6}",
                tr.t[i],
                tr.q(i)[0],
                tr.q(i)[1],
                tr.lambda(i)[0]
            );
        }
        let m = &run.monitors;
        println!(
            "  max |C| {:.1e}, max |C_q q'| {:.1e}, energy drift {:.1e}",
            m.max_position_violation,
            m.max_velocity_violation,
            m.max_energy_drift.unwrap_or(0.0)
        );
    }
    Ok(())
}
