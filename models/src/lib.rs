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
//! | [`chain10`] | `x_i y_i z_i e0_i … e3_i`, `i = 0 … 9` | 40 holonomic (10 ball joints, 10 normalizations) |
//! | [`window_row`] | `xc_i yc_i pc_i` (`i = 0 … 4`), `xb_i yb_i pb_i` (`i = 0 … 3`) | 26 holonomic (13 revolute joints) |
//! | [`bouncing_ball`] | `y` | 1 contact |
//! | [`falling_rod`] | `x y phi` | 2 contacts |
//! | [`pendulum_floor`] | `x1 y1 phi1 x2 y2 phi2` | 4 holonomic, 1 contact (math-spec V15) |
//! | [`sleigh_wall`] | `x y phi` | 1 non-holonomic, 1 contact (math-spec V16) |
//! | [`body_impact`] | `x y phi` | 1 contact (math-spec V13) |
//! | [`two_body_impact`] | `x1 y1 phi1 x2 y2 phi2` | 1 contact (math-spec V14) |
//! | [`newtons_cradle`] | `theta1 theta2 theta3` | 2 contacts |
//! | [`flexible_crank`] | `phi1 phi2 x3 q1 q2 q3 q4` | 3 holonomic (one rheonomic driver); an elastic rod |
//! | [`spinup_beam`] | `w1 w2 w3 w4 u1 u2 u3` | none (prescribed hub angle); geometric stiffening switchable |
//! | [`flexible_crank_shapes`] | as `flexible_crank`, the rod integrated from its shape functions | 3 holonomic |
//! | [`flexible_pendulum`] | `e0 e1 e2 e3 p1 p2 p3 p4` | 1 holonomic (Euler-parameter normalization); a bar of spatial beam elements |
//!
//! [`chain100`] (`i = 0 … 99`: 700 coordinates, 400 holonomic) is built for scaling
//! measurements (the `rhs` bench, its test) but not listed by `find`: a sweep of every
//! formulation and integrator over it would take the command-line tests minutes.
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
#[path = "body_impact.rs"]
mod body_impact_model;
#[path = "bouncing_ball.rs"]
mod bouncing_ball_model;
#[path = "bricard.rs"]
mod bricard_model;
#[path = "car_axis.rs"]
mod car_axis_model;
#[path = "chain.rs"]
mod chain_models;
#[path = "falling_rod.rs"]
mod falling_rod_model;
#[path = "flexible_crank.rs"]
mod flexible_crank_model;
#[path = "flexible_pendulum.rs"]
mod flexible_pendulum_model;
#[path = "free_body.rs"]
mod free_body_model;
#[path = "newtons_cradle.rs"]
mod newtons_cradle_model;
#[path = "parallelogram.rs"]
mod parallelogram_model;
#[path = "pendulum_floor.rs"]
mod pendulum_floor_model;
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
#[path = "sleigh_wall.rs"]
mod sleigh_wall_model;
#[path = "slider_crank_bodies.rs"]
mod slider_crank_bodies_model;
#[path = "slider_crank.rs"]
mod slider_crank_model;
#[path = "spatial_four_bar.rs"]
mod spatial_four_bar_model;
#[path = "spinup_beam.rs"]
mod spinup_beam_model;
#[path = "window_row.rs"]
mod window_row_model;

pub use andrews_model::andrews;
pub use bicycle_model::bicycle;
pub use body_impact_model::{body_impact, two_body_impact};
pub use bouncing_ball_model::bouncing_ball;
pub use bricard_model::bricard;
pub use car_axis_model::car_axis;
pub use chain_models::{chain10, chain100};
pub use falling_rod_model::falling_rod;
pub use flexible_crank_model::{flexible_crank, flexible_crank_shapes};
pub use flexible_pendulum_model::flexible_pendulum;
pub use free_body_model::free_body;
pub use newtons_cradle_model::newtons_cradle;
pub use parallelogram_model::parallelogram;
pub use pendulum_floor_model::pendulum_floor;
pub use pendulum_model::pendulum;
pub use rolling_disk_model::rolling_disk;
pub use seed2_example1_model::seed2_example1;
pub use seed2_example2_model::seed2_example2;
pub use sleigh_bodies_model::sleigh_bodies;
pub use sleigh_model::sleigh;
pub use sleigh_wall_model::sleigh_wall;
pub use slider_crank_bodies_model::slider_crank_bodies;
pub use slider_crank_model::slider_crank;
pub use spatial_four_bar_model::spatial_four_bar;
pub use spinup_beam_model::spinup_beam;
pub use window_row_model::window_row;

/// A built-in model as listed by the command-line program.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// The model's name (its module name, and `Info::name`).
    pub name: &'static str,
    /// One line saying what the model is.
    pub summary: &'static str,
    /// Builds the model with its default parameters.
    pub make: fn() -> Box<dyn pfaff::Mechanism>,
    /// Stiff (elastic modes far above the motion's frequencies): the command simulates
    /// it with Radau5 by default and sweeps only Radau5 in `work-precision`, whose
    /// reference is a Radau5 run; explicit methods are held to their stability limit.
    pub stiff: bool,
}

static ALL: &[Entry] = &[
    Entry {
        name: "pendulum",
        summary: "simple pendulum in redundant Cartesian coordinates (IFToMM A01)",
        make: || Box::new(pendulum::Model::default()),
        stiff: false,
    },
    Entry {
        name: "slider_crank",
        summary: "planar slider-crank in absolute coordinates, driven crank (math-spec V10)",
        make: || Box::new(slider_crank::Model::default()),
        stiff: false,
    },
    Entry {
        name: "slider_crank_bodies",
        summary: "the slider-crank of `slider_crank` from bodies and joints",
        make: || Box::new(slider_crank_bodies::Model::default()),
        stiff: false,
    },
    Entry {
        name: "sleigh_bodies",
        summary: "the Chaplygin sleigh of `sleigh` from a body and a knife edge",
        make: || Box::new(sleigh_bodies::Model::default()),
        stiff: false,
    },
    Entry {
        name: "free_body",
        summary: "torque-free spatial rigid body with Euler parameters (math-spec V12)",
        make: || Box::new(free_body::Model::default()),
        stiff: false,
    },
    Entry {
        name: "rolling_disk",
        summary: "thin uniform disk rolling without slip on a plane",
        make: || Box::new(rolling_disk::Model::default()),
        stiff: false,
    },
    Entry {
        name: "bicycle",
        summary: "Whipple bicycle benchmark (Meijaard, Papadopoulos, Ruina, Schwab 2007)",
        make: || Box::new(bicycle::Model::default()),
        stiff: false,
    },
    Entry {
        name: "spatial_four_bar",
        summary: "spatial four-bar (revolute, spherical, universal) with Euler parameters",
        make: || Box::new(spatial_four_bar::Model::default()),
        stiff: false,
    },
    Entry {
        name: "bricard",
        summary: "Bricard's overconstrained 6R loop, rank-deficient everywhere (IFToMM A04)",
        make: || Box::new(bricard::Model::default()),
        stiff: false,
    },
    Entry {
        name: "andrews",
        summary: "Andrews' squeezing mechanism, seven bodies (Hairer & Wanner II §VII.7)",
        make: || Box::new(andrews::Model::default()),
        stiff: false,
    },
    Entry {
        name: "car_axis",
        summary: "car axle with rheonomic constraints (Rentrop, Roche, Steinebach 1989)",
        make: || Box::new(car_axis::Model::default()),
        stiff: false,
    },
    Entry {
        name: "sleigh",
        summary: "Chaplygin sleigh, non-holonomic knife edge (math-spec V11)",
        make: || Box::new(sleigh::Model::default()),
        stiff: false,
    },
    Entry {
        name: "seed2_example1",
        summary: "free motion with redundant coordinates, example 1 (math-spec §8.8, V2)",
        make: || Box::new(seed2_example1::Model::default()),
        stiff: false,
    },
    Entry {
        name: "seed2_example2",
        summary: "free motion with redundant coordinates, example 2 (math-spec §8.8, V4)",
        make: || Box::new(seed2_example2::Model::default()),
        stiff: false,
    },
    Entry {
        name: "parallelogram",
        summary: "parallelogram linkage with a redundant third crank (reactions of redundant constraints)",
        make: || Box::new(parallelogram::Model::default()),
        stiff: false,
    },
    Entry {
        name: "bouncing_ball",
        summary: "ball bouncing on the ground until the impacts accumulate, then resting",
        make: || Box::new(bouncing_ball::Model::default()),
        stiff: false,
    },
    Entry {
        name: "falling_rod",
        summary: "uniform rod falling at an angle onto a smooth floor (two end contacts)",
        make: || Box::new(falling_rod::Model::default()),
        stiff: false,
    },
    Entry {
        name: "pendulum_floor",
        summary: "double pendulum striking a floor, impulsive joint reactions (math-spec V15)",
        make: || Box::new(pendulum_floor::Model::default()),
        stiff: false,
    },
    Entry {
        name: "sleigh_wall",
        summary: "Chaplygin sleigh striking a wall, jump of the non-holonomic reaction (math-spec V16)",
        make: || Box::new(sleigh_wall::Model::default()),
        stiff: false,
    },
    Entry {
        name: "body_impact",
        summary: "free planar body striking a floor with a corner (math-spec V13)",
        make: || Box::new(body_impact::Model::default()),
        stiff: false,
    },
    Entry {
        name: "two_body_impact",
        summary: "two free planar bodies colliding, a disk and a rod (math-spec V14)",
        make: || Box::new(two_body_impact::Model::default()),
        stiff: false,
    },
    Entry {
        name: "newtons_cradle",
        summary: "Newton's cradle, three balls on strings (sequential impacts)",
        make: || Box::new(newtons_cradle::Model::default()),
        stiff: false,
    },
    Entry {
        name: "flexible_crank",
        summary: "slider crank with an elastic rod in the floating frame (Simeon's test-set invariants)",
        make: || Box::new(flexible_crank::Model::default()),
        stiff: true,
    },
    Entry {
        name: "flexible_crank_shapes",
        summary: "the flexible slider crank with the rod's invariants integrated from its shape functions",
        make: || Box::new(flexible_crank_shapes::Model::default()),
        stiff: true,
    },
    Entry {
        name: "flexible_pendulum",
        summary: "spatial flexible pendulum: a bar of 8 spatial beam elements, 4 modes, on a ball joint",
        make: || Box::new(flexible_pendulum::Model::default()),
        stiff: false,
    },
    Entry {
        name: "spinup_beam",
        summary: "spin-up of a cantilever beam, geometric stiffening switched by `stiffening` (Kane, Ryan & Banerjee 1987)",
        make: || Box::new(spinup_beam::Model::default()),
        stiff: true,
    },
    Entry {
        name: "chain10",
        summary: "spatial chain of 10 rods on ball joints, Euler parameters (scaling, n = 70)",
        make: || Box::new(chain10::Model::default()),
        stiff: false,
    },
    Entry {
        name: "window_row",
        summary: "a row of 4 parallelogram windows (9 bars, 13 revolute joints) swinging under gravity, written with arrays",
        make: || Box::new(window_row::Model::default()),
        stiff: false,
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
