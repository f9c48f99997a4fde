//! Built-in pfaff mechanisms.
//!
//! Each model lives in its own file as an inline module annotated with
//! `#[pfaff::mechanism]`; the module name is the model name, and coordinate and parameter
//! names follow the references (`benchmark-models.md`, `math-spec.md`) so that results can
//! be compared by name. [`all`] lists them for the command-line program.
//!
//! | model | coordinates | constraints |
//! |---|---|---|
//! | [`pendulum`] | `x y` | 1 holonomic |
//! | [`slider_crank`] | `x1 y1 phi1 x2 y2 phi2 x3 y3 phi3` | 9 holonomic (one rheonomic driver) |
//! | [`andrews`] | `beta theta gamma phi delta omega epsilon` | 6 holonomic |
//! | [`car_axis`] | `xl yl xr yr` | 2 holonomic (rheonomic) |
//! | [`sleigh`] | `x y phi` | 1 non-holonomic |
//! | [`seed2_example1`] | `q1 q2 q3` | 1 holonomic (rheonomic) |
//! | [`seed2_example2`] | `q1 q2 q3` | 1 holonomic (rheonomic) |
//! | [`parallelogram`] | `th1 th2 th3 x y phi` | 6 holonomic (one redundant) |
//! | [`slider_crank_bodies`] | as `slider_crank`, from bodies and joints | 9 holonomic |
//! | [`sleigh_bodies`] | as `sleigh`, from a body and a knife edge | 1 non-holonomic |
//! | [`free_body`] | `x y z e0 e1 e2 e3` | 1 holonomic (Euler-parameter normalization) |
//!
//! ```
//! use pfaff::Mechanism;
//!
//! let entry = pfaff_models::find("pendulum").unwrap();
//! let model = (entry.make)();
//! let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
//! model.initial_state(&mut q, &mut qd);
//! assert_eq!(q, [1.0, 0.0]);
//! ```

// The macro needs an inline module, and the model's module name is its public name, so
// each file holds `pub mod <name> { … }` and is mounted under a private name here.
#[path = "andrews.rs"]
mod andrews_model;
#[path = "bicycle.rs"]
mod bicycle_model;
#[path = "car_axis.rs"]
mod car_axis_model;
#[path = "free_body.rs"]
mod free_body_model;
#[path = "parallelogram.rs"]
mod parallelogram_model;
#[path = "pendulum.rs"]
mod pendulum_model;
#[path = "rolling_disk.rs"]
mod rolling_disk_model;
#[path = "seed2_example1.rs"]
mod seed2_example1_model;
#[path = "seed2_example2.rs"]
mod seed2_example2_model;
#[path = "sleigh_bodies.rs"]
mod sleigh_bodies_model;
#[path = "sleigh.rs"]
mod sleigh_model;
#[path = "slider_crank_bodies.rs"]
mod slider_crank_bodies_model;
#[path = "slider_crank.rs"]
mod slider_crank_model;
#[path = "spatial_four_bar.rs"]
mod spatial_four_bar_model;

pub use andrews_model::andrews;
pub use bicycle_model::bicycle;
pub use car_axis_model::car_axis;
pub use free_body_model::free_body;
pub use parallelogram_model::parallelogram;
pub use pendulum_model::pendulum;
pub use rolling_disk_model::rolling_disk;
pub use seed2_example1_model::seed2_example1;
pub use seed2_example2_model::seed2_example2;
pub use sleigh_bodies_model::sleigh_bodies;
pub use sleigh_model::sleigh;
pub use slider_crank_bodies_model::slider_crank_bodies;
pub use slider_crank_model::slider_crank;
pub use spatial_four_bar_model::spatial_four_bar;

/// A built-in model as listed by the command-line program.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// The model's name (its module name, and `Info::name`).
    pub name: &'static str,
    /// One line saying what the model is.
    pub summary: &'static str,
    /// Builds the model with its default parameters.
    pub make: fn() -> Box<dyn pfaff::Mechanism>,
}

static ALL: &[Entry] = &[
    Entry {
        name: "pendulum",
        summary: "simple pendulum in redundant Cartesian coordinates (IFToMM A01)",
        make: || Box::new(pendulum::Model::default()),
    },
    Entry {
        name: "slider_crank",
        summary: "planar slider-crank in absolute coordinates, driven crank (math-spec V10)",
        make: || Box::new(slider_crank::Model::default()),
    },
    Entry {
        name: "slider_crank_bodies",
        summary: "the slider-crank of `slider_crank` from bodies and joints",
        make: || Box::new(slider_crank_bodies::Model::default()),
    },
    Entry {
        name: "sleigh_bodies",
        summary: "the Chaplygin sleigh of `sleigh` from a body and a knife edge",
        make: || Box::new(sleigh_bodies::Model::default()),
    },
    Entry {
        name: "free_body",
        summary: "torque-free spatial rigid body with Euler parameters (math-spec V12)",
        make: || Box::new(free_body::Model::default()),
    },
    Entry {
        name: "rolling_disk",
        summary: "thin uniform disk rolling without slip on a plane",
        make: || Box::new(rolling_disk::Model::default()),
    },
    Entry {
        name: "bicycle",
        summary: "Whipple bicycle benchmark (Meijaard, Papadopoulos, Ruina, Schwab 2007)",
        make: || Box::new(bicycle::Model::default()),
    },
    Entry {
        name: "spatial_four_bar",
        summary: "spatial four-bar (revolute, spherical, universal) with Euler parameters",
        make: || Box::new(spatial_four_bar::Model::default()),
    },
    Entry {
        name: "andrews",
        summary: "Andrews' squeezing mechanism, seven bodies (Hairer & Wanner II §VII.7)",
        make: || Box::new(andrews::Model::default()),
    },
    Entry {
        name: "car_axis",
        summary: "car axle with rheonomic constraints (Rentrop, Roche, Steinebach 1989)",
        make: || Box::new(car_axis::Model::default()),
    },
    Entry {
        name: "sleigh",
        summary: "Chaplygin sleigh, non-holonomic knife edge (math-spec V11)",
        make: || Box::new(sleigh::Model::default()),
    },
    Entry {
        name: "seed2_example1",
        summary: "free motion with redundant coordinates, example 1 (math-spec §8.8, V2)",
        make: || Box::new(seed2_example1::Model::default()),
    },
    Entry {
        name: "seed2_example2",
        summary: "free motion with redundant coordinates, example 2 (math-spec §8.8, V4)",
        make: || Box::new(seed2_example2::Model::default()),
    },
    Entry {
        name: "parallelogram",
        summary: "parallelogram linkage with a redundant third crank (reactions of redundant constraints)",
        make: || Box::new(parallelogram::Model::default()),
    },
];

/// All built-in models, in the order the command-line program lists them.
#[must_use]
pub fn all() -> &'static [Entry] {
    ALL
}

/// The built-in model called `name`, if there is one.
#[must_use]
pub fn find(name: &str) -> Option<&'static Entry> {
    ALL.iter().find(|entry| entry.name == name)
}
