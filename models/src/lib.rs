//! Built-in pfaff mechanisms.
//!
//! Each model lives in its own file as an inline module annotated with
//! `#[pfaff::mechanism]`; the module name is the model name, and coordinate and parameter
//! names follow the references (`docs/models.md`, `docs/theory.md`) so that results can
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
//! | [`parallelogram_row`] | `th1 … th5 x y phi` | 10 holonomic (three redundant; rank drops at the flat configurations) |
//! | [`slider_crank_bodies`] | as `slider_crank`, from bodies and joints | 9 holonomic |
//! | [`sleigh_bodies`] | as `sleigh`, from a body and a knife edge | 1 non-holonomic |
//! | [`free_body`] | `x y z e0 e1 e2 e3` | 1 holonomic (Euler-parameter normalization) |
//! | [`chain10`] | `x_i y_i z_i e0_i … e3_i`, `i = 0 … 9` | 40 holonomic (10 ball joints, 10 normalizations) |
//! | [`window_row`] | `xc_i yc_i pc_i` (`i = 0 … 4`), `xb_i yb_i pb_i` (`i = 0 … 3`) | 26 holonomic (13 revolute joints) |
//! | [`bouncing_ball`] | `y` | 1 contact |
//! | [`falling_rod`] | `x y phi` | 2 contacts |
//! | [`pendulum_floor`] | `x1 y1 phi1 x2 y2 phi2` | 4 holonomic, 1 contact (docs/theory.md V15) |
//! | [`sleigh_wall`] | `x y phi` | 1 non-holonomic, 1 contact (docs/theory.md V16) |
//! | [`body_impact`] | `x y phi` | 1 contact (docs/theory.md V13) |
//! | [`two_body_impact`] | `x1 y1 phi1 x2 y2 phi2` | 1 contact (docs/theory.md V14) |
//! | [`newtons_cradle`] | `theta1 theta2 theta3` | 2 contacts |
//! | [`flexible_crank`] | `phi1 phi2 x3 q1 q2 q3 q4` | 3 holonomic (one rheonomic driver); an elastic rod |
//! | [`spinup_beam`] | `w1 w2 w3 w4 u1 u2 u3` | none (prescribed hub angle); geometric stiffening switchable |
//! | [`flexible_crank_shapes`] | as `flexible_crank`, the rod integrated from its shape functions | 3 holonomic |
//! | [`flexible_sleigh`] | `x y phi p1 p2 p3` | 1 non-holonomic at a material point of an elastic tail (beam elements) |
//! | [`flexible_sleigh_wall`] | as `flexible_sleigh` | 1 non-holonomic, 1 contact |
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
#[path = "flexible_sleigh.rs"]
mod flexible_sleigh_model;
#[path = "free_body.rs"]
mod free_body_model;
#[path = "newtons_cradle.rs"]
mod newtons_cradle_model;
#[path = "parallelogram.rs"]
mod parallelogram_model;
#[path = "parallelogram_row.rs"]
mod parallelogram_row_model;
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
pub use flexible_sleigh_model::{flexible_sleigh, flexible_sleigh_wall};
pub use free_body_model::free_body;
pub use newtons_cradle_model::newtons_cradle;
pub use parallelogram_model::parallelogram;
pub use parallelogram_row_model::parallelogram_row;
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

pub use pfaff_cli::{Entry, Scene, Steady};

/// The closed forms and impact times the entries carry.
mod exact;

/// The built-in models with what the command knows about each (span, steady motion,
/// closed form, source): a model is added here, in one place.
static ALL: &[Entry] = &[
    Entry::new(
        "pendulum",
        "simple pendulum in redundant Cartesian coordinates (IFToMM A01)",
        || Box::new(pendulum::Model::default()),
    )
        // Three periods 4K(1/2)√(l/g) = 2.36784194757624 s.
        .span(7.103_525_842_728_72, "three periods")
        .steady(Steady {
            coordinates: &[("x", 0.0), ("y", -1.0)],
            velocities: &[],
            speed: None,
            speed_ratio: None,
            independent_velocities: &[],
            ignorable: &[],
            summary: "hanging at rest",
        })
        .closed_form(exact::pendulum_exact)
        .source(include_str!("pendulum.rs")),
    Entry::new(
        "slider_crank",
        "planar slider-crank in absolute coordinates, driven crank (docs/theory.md V10)",
        || Box::new(slider_crank::Model::default()),
    )
        .span(std::f64::consts::TAU / 10.0, "one crank revolution")
        .source(include_str!("slider_crank.rs")),
    Entry::new(
        "slider_crank_bodies",
        "the slider-crank of `slider_crank` from bodies and joints",
        || Box::new(slider_crank_bodies::Model::default()),
    )
        .source(include_str!("slider_crank_bodies.rs")),
    Entry::new(
        "sleigh_bodies",
        "the Chaplygin sleigh of `sleigh` from a body and a knife edge",
        || Box::new(sleigh_bodies::Model::default()),
    )
        .source(include_str!("sleigh_bodies.rs")),
    Entry::new(
        "free_body",
        "torque-free spatial rigid body with Euler parameters (docs/theory.md V12)",
        || Box::new(free_body::Model::default()),
    )
        .source(include_str!("free_body.rs")),
    Entry::new(
        "rolling_disk",
        "thin uniform disk rolling without slip on a plane",
        || Box::new(rolling_disk::Model::default()),
    )
        .span(5.0, "several turns of a leaning disk")
        .steady(Steady {
            coordinates: &[
                ("x", 0.0),
                ("y", 0.0),
                ("psi", 0.0),
                ("phi", 0.0),
                ("theta", 0.0),
            ],
            velocities: &[("psi", 0.0), ("phi", 0.0)],
            // Upright rolling along x: the centre moves at theta' · radius.
            speed: Some(("theta", 2.0)),
            speed_ratio: Some(|m| 1.0 / exact::parameter(m, "radius")),
            independent_velocities: &["psi", "phi", "theta"],
            ignorable: &["x", "y", "psi", "theta"],
            summary: "upright rolling along x",
        })
        .source(include_str!("rolling_disk.rs")),
    Entry::new(
        "bicycle",
        "Whipple bicycle benchmark (Meijaard, Papadopoulos, Ruina, Schwab 2007)",
        || Box::new(bicycle::Model::default()),
    )
        .span(5.0, "5 s of riding from a lean-rate disturbance")
        .steady(Steady {
            coordinates: &[
                ("x", 0.0),
                ("y", 0.0),
                ("psi", 0.0),
                ("phi", 0.0),
                ("delta", 0.0),
                ("theta_r", 0.0),
                ("theta_f", 0.0),
            ],
            velocities: &[("phi", 0.0), ("delta", 0.0)],
            // Upright straight running: the rear wheel spins at −v / r_r.
            speed: Some(("theta_r", 5.0)),
            speed_ratio: Some(|m| -1.0 / exact::parameter(m, "r_r")),
            independent_velocities: &["phi", "delta", "theta_r"],
            ignorable: &["x", "y", "psi", "theta_r", "theta_f"],
            summary: "upright straight running",
        })
        .source(include_str!("bicycle.rs")),
    Entry::new(
        "spatial_four_bar",
        "spatial four-bar (revolute, spherical, universal) with Euler parameters",
        || Box::new(spatial_four_bar::Model::default()),
    )
        .span(2.0, "2 s of swinging")
        .source(include_str!("spatial_four_bar.rs")),
    Entry::new(
        "bricard",
        "Bricard's overconstrained 6R loop, rank-deficient everywhere (IFToMM A04)",
        || Box::new(bricard::Model::default()),
    )
        .span(10.0, "the 10 s of the IFToMM A04 benchmark")
        .source(include_str!("bricard.rs")),
    Entry::new(
        "andrews",
        "Andrews' squeezing mechanism, seven bodies (Hairer & Wanner II §VII.7)",
        || Box::new(andrews::Model::default()),
    )
        .span(0.03, "the reference span of Hairer & Wanner")
        .source(include_str!("andrews.rs")),
    Entry::new(
        "car_axis",
        "car axle with rheonomic constraints (Rentrop, Roche, Steinebach 1989)",
        || Box::new(car_axis::Model::default()),
    )
        .span(3.0, "the reference span")
        .source(include_str!("car_axis.rs")),
    Entry::new(
        "sleigh",
        "Chaplygin sleigh, non-holonomic knife edge (docs/theory.md V11)",
        || Box::new(sleigh::Model::default()),
    )
        .span(5.0, "the span of docs/theory.md V11")
        .steady(Steady {
            coordinates: &[("x", 0.0), ("y", 0.0), ("phi", 0.0)],
            velocities: &[("phi", 0.0)],
            speed: Some(("x", 1.0)),
            speed_ratio: None,
            independent_velocities: &[],
            ignorable: &["x", "y", "phi"],
            summary: "straight motion along x",
        })
        .closed_form(exact::sleigh_exact)
        .source(include_str!("sleigh.rs")),
    Entry::new(
        "seed2_example1",
        "free motion with redundant coordinates, example 1 (docs/theory.md §free-motion-examples, V2)",
        || Box::new(seed2_example1::Model::default()),
    )
        .span(2.0, "the span of docs/theory.md V2")
        .closed_form(exact::seed2_example1_exact)
        .source(include_str!("seed2_example1.rs")),
    Entry::new(
        "seed2_example2",
        "free motion with redundant coordinates, example 2 (docs/theory.md §free-motion-examples, V4)",
        || Box::new(seed2_example2::Model::default()),
    )
        .span(1.0, "the span of docs/theory.md V4")
        .source(include_str!("seed2_example2.rs")),
    Entry::new(
        "parallelogram",
        "parallelogram linkage with a redundant third crank (reactions of redundant constraints)",
        || Box::new(parallelogram::Model::default()),
    )
        // Falling from θ = π/3, the cranks reach the horizontal at t ≈ 0.497 s: there all
        // three pin_x constraints coincide (a dead-centre, where the linkage can change
        // branch and C_q loses rank). Partitioning and projection cross it; Baumgarte's
        // state, off the constraints by its drift, can make the redundant rows disagree
        // at such points.
        .span(0.45, "the swing down to just before the horizontal dead-centre at 0.497 s")
        .source(include_str!("parallelogram.rs")),
    Entry::new(
        "parallelogram_row",
        "row of four parallelogram windows on one coupler, turning through flat configurations (isolated rank drops)",
        || Box::new(parallelogram_row::Model::default()),
    )
        // Turning full circles from θ = π/3 at 6 rad/s: the flat configurations θ = 0, π
        // (all links collinear, C_q one rank down) are crossed twice per turn, five times
        // in 2 s (θ(2) = 16.83).
        .span(2.0, "about two and a half turns, five flat crossings")
        .source(include_str!("parallelogram_row.rs")),
    Entry::new(
        "bouncing_ball",
        "ball bouncing on the ground until the impacts accumulate, then resting",
        || Box::new(bouncing_ball::Model::default()),
    )
        .span(1.0, "the first two bounces; --t-end 2 shows the accumulation at 1.3546 s and the rest")
        .closed_form(exact::bouncing_ball_exact)
        .impact_times(exact::bouncing_ball_impacts)
        .source(include_str!("bouncing_ball.rs")),
    Entry::new(
        "falling_rod",
        "uniform rod falling at an angle onto a smooth floor (two end contacts)",
        || Box::new(falling_rod::Model::default()),
    )
        .span(0.08, "the first impact and the flight after it")
        .closed_form(exact::falling_rod_exact)
        .impact_times(exact::falling_rod_impacts)
        .source(include_str!("falling_rod.rs")),
    Entry::new(
        "pendulum_floor",
        "double pendulum striking a floor, impulsive joint reactions (docs/theory.md V15)",
        || Box::new(pendulum_floor::Model::default()),
    )
        .span(1.0, "1 s from the impact of its docs/theory.md case")
        .source(include_str!("pendulum_floor.rs")),
    Entry::new(
        "sleigh_wall",
        "Chaplygin sleigh striking a wall, jump of the non-holonomic reaction (docs/theory.md V16)",
        || Box::new(sleigh_wall::Model::default()),
    )
        .span(1.0, "1 s from the impact of its docs/theory.md case")
        .source(include_str!("sleigh_wall.rs")),
    Entry::new(
        "body_impact",
        "free planar body striking a floor with a corner (docs/theory.md V13)",
        || Box::new(body_impact::Model::default()),
    )
        .span(1.0, "1 s from the impact of its docs/theory.md case")
        .source(include_str!("body_impact.rs")),
    Entry::new(
        "two_body_impact",
        "two free planar bodies colliding, a disk and a rod (docs/theory.md V14)",
        || Box::new(two_body_impact::Model::default()),
    )
        .span(1.0, "1 s from the impact of its docs/theory.md case")
        .source(include_str!("body_impact.rs")),
    Entry::new(
        "newtons_cradle",
        "Newton's cradle, three balls on strings (sequential impacts)",
        || Box::new(newtons_cradle::Model::default()),
    )
        .span(2.0, "a few swings")
        .source(include_str!("newtons_cradle.rs")),
    Entry::new(
        "flexible_crank",
        "slider crank with an elastic rod in the floating frame (Simeon's test-set invariants)",
        || Box::new(flexible_crank::Model::default()),
    )
        .stiff()
        .span(0.1, "the test set's span")
        .source(include_str!("flexible_crank.rs")),
    Entry::new(
        "flexible_crank_shapes",
        "the flexible slider crank with the rod's invariants integrated from its shape functions",
        || Box::new(flexible_crank_shapes::Model::default()),
    )
        .stiff()
        .span(0.1, "the test set's span")
        .source(include_str!("flexible_crank.rs")),
    Entry::new(
        "flexible_pendulum",
        "spatial flexible pendulum: a bar of 8 spatial beam elements, 4 modes, on a ball joint",
        || Box::new(flexible_pendulum::Model::default()),
    )
        // About three swings: 2π/√(3g/2l) = 1.64 s for the rigid bar.
        .span(5.0, "about three swings")
        .source(include_str!("flexible_pendulum.rs")),
    Entry::new(
        "spinup_beam",
        "spin-up of a cantilever beam, geometric stiffening switched by `stiffening` (Kane, Ryan & Banerjee 1987)",
        || Box::new(spinup_beam::Model::default()),
    )
        .stiff()
        .span(20.0, "the benchmark's span: spin-up over 15 s, then 5 s at constant rate")
        .source(include_str!("spinup_beam.rs")),
    Entry::new(
        "flexible_sleigh",
        "Chaplygin sleigh whose blade is at the free end of an elastic tail of beam elements",
        || Box::new(flexible_sleigh::Model::default()),
    )
        .span(2.0, "about 22 periods of the tail's first mode")
        .source(include_str!("flexible_sleigh.rs")),
    Entry::new(
        "flexible_sleigh_wall",
        "the sleigh of `flexible_sleigh` striking a wall with its front tip",
        || Box::new(flexible_sleigh_wall::Model::default()),
    )
        .span(1.0, "1 s from the impact")
        .source(include_str!("flexible_sleigh.rs")),
    Entry::new(
        "chain10",
        "spatial chain of 10 rods on ball joints, Euler parameters (scaling, n = 70)",
        || Box::new(chain10::Model::default()),
    )
        .span(0.5, "the first swing down from the horizontal")
        .source(include_str!("chain.rs")),
    Entry::new(
        "window_row",
        "a row of 4 parallelogram windows (9 bars, 13 revolute joints) swinging under gravity, written with arrays",
        || Box::new(window_row::Model::default()),
    )
        .source(include_str!("window_row.rs")),
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
