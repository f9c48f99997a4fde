//! The JSON trajectory format (`pfaff::replay`): write, read, compare.

use pfaff::replay::{Event, Replay, ReplayError, ReplayOptions};
use pfaff::sim::{Method, Simulation};
use pfaff::{Mechanism, PoseExt};
use pfaff_models::{free_body, slider_crank_bodies};
use serde_json::{json, Map};

fn replay_of(model: &dyn Mechanism, t_end: f64, opts: &ReplayOptions) -> Replay {
    let run = Simulation::new(model)
        .integrator(Method::Dop853)
        .tolerances(1e-10, 1e-12)
        .output_every(t_end / 2000.0)
        .run(t_end)
        .expect("the model runs");
    let mut meta = Map::new();
    meta.insert("integrator".into(), json!("dop853"));
    Replay::from_run(model, &run, meta, opts)
}

/// Full precision: what is read back equals what was written, value for value (JSON
/// numbers written by serde_json round-trip `f64` exactly; the runtime enables its
/// correctly rounded parser, `float_roundtrip`).
#[test]
fn the_format_round_trips_exactly() {
    for (model, t_end) in [
        (
            Box::new(slider_crank_bodies::Model::default()) as Box<dyn Mechanism>,
            0.6,
        ),
        (Box::new(free_body::Model::default()), 3.0),
    ] {
        let mut replay = replay_of(model.as_ref(), t_end, &ReplayOptions::default());
        replay.events.push(Event {
            t: 0.25,
            kind: "impact".into(),
            name: Some("floor".into()),
            detail: None,
        });
        assert!(replay.len() >= 600, "{} samples", replay.len());
        let text = replay.to_json();
        let back = Replay::from_json(&text).expect("reads back");
        // Not `assert_eq!`: the Debug print of a replay is megabytes.
        assert!(back == replay, "{} does not round-trip", model.info().name);
        let mut bytes = Vec::new();
        replay.write(&mut bytes).expect("writes");
        assert!(Replay::read(bytes.as_slice()).expect("reads") == replay);
    }
}

/// Seven significant digits (what the HTML view embeds): every value within a relative
/// 5e-7 of the full-precision one, and the poses are those of `PoseExt`.
#[test]
fn rounded_values_and_poses() {
    let model = slider_crank_bodies::Model::default();
    let full = replay_of(&model, 0.6, &ReplayOptions::default());
    let opts = ReplayOptions {
        digits: Some(7),
        ..ReplayOptions::default()
    };
    let short = Replay::from_json(&replay_of(&model, 0.6, &opts).to_json()).expect("reads");
    assert_eq!(short.times.len(), full.times.len());
    let close = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 5e-7 * x.abs().max(1e-300))
    };
    assert!(close(&full.times, &short.times));
    for (f, s) in full.frames.iter().zip(&short.frames) {
        assert!(close(&f.position, &s.position) && close(&f.orientation, &s.orientation));
    }
    assert!(close(&full.energy, &short.energy));
    assert!(full.to_json().len() > short.to_json().len() * 3 / 2);
    // The samples are rows of the run, and their poses those of the model.
    let mut q = vec![0.0; 9];
    for k in [0, full.len() / 2, full.len() - 1] {
        for (i, c) in full.coordinates.iter().enumerate() {
            q[i] = c.values[k];
        }
        let t = full.times[k];
        for f in 0..full.frames.len() {
            let a = full.frame_pose(f, k);
            let b = model.frame_pose(t, &q, f);
            assert!((a.translation.vector - b.translation.vector).norm() < 1e-15);
            assert!(a.rotation.angle_to(&b.rotation) < 1e-12);
        }
        assert_eq!(full.point_position(0, k), model.point_position(t, &q, 0));
    }
}

/// A reader refuses another format and arrays of the wrong length.
#[test]
fn bad_files_are_refused() {
    let model = slider_crank_bodies::Model::default();
    let replay = replay_of(&model, 0.1, &ReplayOptions::default());
    let mut other = replay.clone();
    other.version = 99;
    assert!(matches!(
        Replay::from_json(&other.to_json()),
        Err(ReplayError::Version { version: 99, .. })
    ));
    let mut short = replay.clone();
    short.frames[1].orientation.pop();
    let err = Replay::from_json(&short.to_json()).unwrap_err();
    assert!(err.to_string().contains("frames[1].orientation"), "{err}");
    assert!(matches!(
        Replay::from_json("{\"format\": 1}"),
        Err(ReplayError::Json(_))
    ));
}

/// The bouncing ball's impacts become `impact` events (then `rest` when they have
/// accumulated), each kept as samples: at an impact's time the replay holds the rows
/// before and after, the drawn ball (a disc of radius 0.05 h resting on its lowest
/// point, the gap `y`) touches the floor there, and the energy drops across it (e = 0.5
/// keeps a quarter of the kinetic energy).
#[test]
fn impacts_are_events_and_samples() {
    use pfaff_models::bouncing_ball;
    let model = bouncing_ball::Model::default();
    let run = Simulation::new(&model)
        .integrator(Method::Dop853)
        .tolerances(1e-10, 1e-12)
        .output_every(0.001)
        .run(2.0)
        .expect("the ball bounces");
    assert!(run.impacts.len() >= 3, "{} impacts", run.impacts.len());
    let replay = Replay::from_run(&model, &run, Map::new(), &ReplayOptions::default());
    let impacts: Vec<&Event> = replay
        .events
        .iter()
        .filter(|e| e.kind == "impact")
        .collect();
    assert_eq!(impacts.len(), run.impacts.len());
    assert!(replay.events.iter().any(|e| e.kind == "rest"));
    let first = impacts[0];
    assert_eq!(first.t, run.impacts[0].t);
    assert_eq!(first.name.as_deref(), Some("floor"));
    let at: Vec<usize> = (0..replay.len())
        .filter(|&k| replay.times[k] == first.t)
        .collect();
    assert_eq!(at.len(), 2, "the states before and after the first impact");
    let (before, after) = (replay.energy[at[0]], replay.energy[at[1]]);
    let mgh = 9.81;
    // Closed form: all of m g h is kinetic at the floor; a quarter of it remains.
    assert!(
        (before - mgh).abs() < 1e-6 && (after - 0.25 * mgh).abs() < 1e-6,
        "{before} {after}"
    );
    let disc = replay
        .drawing
        .shapes
        .iter()
        .find(|s| s.kind == "disc")
        .expect("the ball");
    let r = disc.radius.expect("a radius");
    let centre = &replay.drawing.points[disc.points[0]].position;
    let k = at[0];
    assert!(
        (centre[3 * k + 1] - r).abs() < 1e-9,
        "the ball touches the floor"
    );
}

/// Which way is up: the bicycle declares the benchmark's z down (`Scene { up: [0, 0,
/// −1] }`), the other models take the default of their dimension (+z spatial, +y
/// planar); the key round-trips, and a file without it reads back as `None` (the
/// default for readers).
#[test]
fn the_up_direction_is_declared_or_the_default() {
    let bicycle = pfaff_models::bicycle::Model::default();
    for (model, up) in [
        (Box::new(bicycle) as Box<dyn Mechanism>, [0.0, 0.0, -1.0]),
        (Box::new(free_body::Model::default()), [0.0, 0.0, 1.0]),
        (
            Box::new(slider_crank_bodies::Model::default()),
            [0.0, 1.0, 0.0],
        ),
    ] {
        let replay = replay_of(model.as_ref(), 0.1, &ReplayOptions::default());
        assert_eq!(replay.drawing.up, Some(up), "{}", model.info().name);
        let back = Replay::from_json(&replay.to_json()).expect("reads back");
        assert_eq!(back.drawing.up, Some(up));
        let mut v: serde_json::Value = serde_json::from_str(&replay.to_json()).expect("JSON");
        v["drawing"]
            .as_object_mut()
            .expect("an object")
            .remove("up");
        let old = Replay::from_json(&v.to_string()).expect("a file without `up` reads");
        assert_eq!(old.drawing.up, None);
    }
}
