//! The JSON trajectory format: a run as data that other tools can replay.
//!
//! A [`Replay`] holds the times of the samples, the pose of every frame (position and
//! unit quaternion), the named points, the coordinates, the named outputs, the energy and
//! the constraint violations at each sample, the events of the run (re-partitions, and
//! impacts once a model has contacts), the model's metadata (bodies, joints, parameters)
//! and its [drawing](crate::Drawing) with the positions of the drawing's points. It is
//! what `pfaff simulate --animate` embeds in its HTML viewer, and is written as JSON by
//! [`Replay::to_json`] and read back by [`Replay::from_json`]; `docs/trajectory-format.md`
//! describes every key.
//!
//! Arrays of vectors are flat, sample after sample: `position` holds `3 × samples`
//! values `x0 y0 z0 x1 y1 z1 …`, `orientation` holds `4 × samples` values
//! `w0 x0 y0 z0 …` (scalar first).
//!
//! [`Replay::from_run`] decimates a long run to the rate a display can show
//! ([`ReplayOptions`]): samples nearest to a uniform grid of times are kept.

use std::io::{Read, Write};

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::pose::quaternion_from_raw;
use crate::sim::Run;
use crate::{Mechanism, MechanismExt};

/// The value of the key `format`.
pub const FORMAT: &str = "pfaff-trajectory";
/// The version of the format this crate writes and reads.
pub const VERSION: u32 = 1;

/// A failure to read or write a [`Replay`].
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The text is not JSON of the expected shape.
    #[error("not a pfaff trajectory: {0}")]
    Json(#[from] serde_json::Error),
    /// Reading or writing failed.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The `format` or `version` key is not one this crate reads.
    #[error("format `{format}` version {version}: expected `{FORMAT}` version {VERSION}")]
    Version {
        /// The `format` found.
        format: String,
        /// The `version` found.
        version: u32,
    },
    /// An array does not have the length the number of samples asks for.
    #[error("`{what}` holds {found} values, expected {expected}")]
    Length {
        /// The array (`frames[2].orientation`, …).
        what: String,
        /// Its length.
        found: usize,
        /// The length expected.
        expected: usize,
    },
}

/// A body of the model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodyMeta {
    /// Its name.
    pub name: String,
    /// Index of its frame in [`Replay::frames`].
    pub frame: usize,
}

/// A joint of the model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointMeta {
    /// Its name.
    pub name: String,
    /// Its kind (`PlanarRevolute`, `Spherical`, `RollingWheel`, … as
    /// [`JointKind`](crate::JointKind)).
    pub kind: String,
    /// The frames it joins (indices in [`Replay::frames`]; `null`: the ground).
    pub frames: [Option<usize>; 2],
}

/// A named value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Named {
    /// The name.
    pub name: String,
    /// The value.
    pub value: f64,
}

/// What the model is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelMeta {
    /// The model's name.
    pub name: String,
    /// Its doc comment.
    #[serde(default)]
    pub doc: String,
    /// 2 for a planar model (drawn in the x–y plane), 3 for a spatial one.
    pub dimension: u8,
    /// `T + V` is a first integral of the model.
    #[serde(default)]
    pub conservative: bool,
    /// The parameters with the values of the run.
    #[serde(default)]
    pub parameters: Vec<Named>,
    /// The bodies.
    #[serde(default)]
    pub bodies: Vec<BodyMeta>,
    /// The joints.
    #[serde(default)]
    pub joints: Vec<JointMeta>,
}

/// The motion of a frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameTrack {
    /// Its name.
    pub name: String,
    /// The frame it was declared relative to (`null`: the ground). Poses here are
    /// global all the same.
    #[serde(default)]
    pub parent: Option<usize>,
    /// A planar frame (moves in the x–y plane, turns about z).
    #[serde(default)]
    pub planar: bool,
    /// The origin in global coordinates, 3 values per sample.
    pub position: Vec<f64>,
    /// The orientation as a unit quaternion `w x y z` (scalar first), 4 values per
    /// sample: the rotation from frame to global coordinates.
    pub orientation: Vec<f64>,
}

/// The motion of a point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointTrack {
    /// Its name.
    pub name: String,
    /// The frame it is fixed in (`null`: fixed in the ground, or not fixed in a frame).
    #[serde(default)]
    pub frame: Option<usize>,
    /// Global coordinates, 3 values per sample (`z = 0` in planar models).
    pub position: Vec<f64>,
}

/// A named scalar along the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Series {
    /// Its name.
    pub name: String,
    /// One value per sample.
    pub values: Vec<f64>,
}

/// The constraint violations along the run.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct Violations {
    /// `‖C(q, t)‖∞` per sample.
    pub position: Vec<f64>,
    /// `‖[C_q q̇ + C_t; G q̇ + g]‖∞` per sample.
    pub velocity: Vec<f64>,
}

/// Something that happened at one time of the run. Readers ignore kinds they do not
/// know.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// When.
    pub t: f64,
    /// What: `repartition` (the independent coordinates were chosen anew), `impact`
    /// (a contact struck; `name` the contacts, `detail` the normal velocities and the
    /// energy lost), `rest` (a contact came to rest after accumulated impacts),
    /// `release` (a resting contact opened), or a kind added later.
    pub kind: String,
    /// What it concerns (a contact's name), when it concerns something named.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// A human-readable detail.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detail: Option<String>,
}

/// A shape of the drawing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShapeMeta {
    /// The declaration it comes from.
    pub name: String,
    /// `link`, `outline`, `disc`, `spring`, `ground` or `marker` (see
    /// [`ShapeKind`](crate::ShapeKind)).
    pub kind: String,
    /// The frame it moves with (`null`: the ground).
    #[serde(default)]
    pub frame: Option<usize>,
    /// Its points: indices in [`DrawingTrack::points`].
    pub points: Vec<usize>,
    /// The direction a disc or ground is normal to: an index in [`DrawingTrack::points`],
    /// whose `position` holds the direction.
    #[serde(default)]
    pub normal: Option<usize>,
    /// Radius of a disc, size of a marker.
    #[serde(default)]
    pub radius: Option<f64>,
    /// A CSS colour; `null`: chosen per frame by the viewer.
    #[serde(default)]
    pub color: Option<String>,
}

/// The drawing with the motion of its points.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct DrawingTrack {
    /// The drawing's points, 3 values per sample each.
    pub points: Vec<PointTrack>,
    /// The shapes, drawn in order.
    pub shapes: Vec<ShapeMeta>,
    /// The unit vector that points up, for a viewer's camera and ground: the model's
    /// `Scene { up }`, or by default `+z` in 3-D and `+y` in 2-D. Absent in files that
    /// predate it (readers take the default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<[f64; 3]>,
}

/// A run in the JSON trajectory format.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Replay {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// The model.
    pub model: ModelMeta,
    /// How the run was made (formulation, integrator, tolerances, …), free-form.
    #[serde(default)]
    pub run: Map<String, Value>,
    /// The times of the samples, increasing.
    pub times: Vec<f64>,
    /// The frames of the model.
    #[serde(default)]
    pub frames: Vec<FrameTrack>,
    /// The named points of the model.
    #[serde(default)]
    pub points: Vec<PointTrack>,
    /// The generalized coordinates.
    #[serde(default)]
    pub coordinates: Vec<Series>,
    /// The named outputs of the model.
    #[serde(default)]
    pub outputs: Vec<Series>,
    /// `T + V` per sample (conserved only when [`ModelMeta::conservative`]).
    #[serde(default)]
    pub energy: Vec<f64>,
    /// Constraint violations per sample.
    #[serde(default)]
    pub violation: Violations,
    /// Re-partitions, impacts, … in time order.
    #[serde(default)]
    pub events: Vec<Event>,
    /// What to draw.
    #[serde(default)]
    pub drawing: DrawingTrack,
}

/// How [`Replay::from_run`] samples a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReplayOptions {
    /// Samples per second of simulated time: the display rate (60 frames per second)
    /// with room for playing at a quarter of real time.
    pub samples_per_second: f64,
    /// At least this many samples (short runs are played slowed down).
    pub min_samples: usize,
    /// At most this many samples (long runs are played sped up); bounds the file.
    pub max_samples: usize,
    /// Significant digits kept in the values (`None`: all; 7 is below what a screen
    /// resolves and halves the file).
    pub digits: Option<u32>,
}

impl Default for ReplayOptions {
    fn default() -> Self {
        Self {
            samples_per_second: 240.0,
            min_samples: 600,
            max_samples: 6000,
            digits: None,
        }
    }
}

impl ReplayOptions {
    /// The number of samples wanted for a run from `t0` to `t1`.
    #[must_use]
    pub fn samples(&self, t0: f64, t1: f64) -> usize {
        let wanted = ((t1 - t0).abs() * self.samples_per_second).ceil();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let wanted = if wanted.is_finite() {
            wanted.min(1e9) as usize
        } else {
            self.max_samples
        };
        wanted.clamp(
            self.min_samples.min(self.max_samples),
            self.max_samples.max(2),
        )
    }
}

/// The indices of the rows at `times` nearest to a uniform grid of `n` times over their
/// span, increasing and without repeats; the first and last rows are kept. All rows
/// when there are at most `n`.
#[must_use]
pub fn decimate(times: &[f64], n: usize) -> Vec<usize> {
    let len = times.len();
    if len <= n.max(2) {
        return (0..len).collect();
    }
    let (t0, t1) = (times[0], times[len - 1]);
    let mut out = Vec::with_capacity(n);
    let mut i = 0;
    for k in 0..n {
        let target = t0 + (t1 - t0) * k as f64 / (n - 1) as f64;
        while i + 1 < len && times[i + 1] <= target {
            i += 1;
        }
        let pick = if i + 1 < len && (times[i + 1] - target) < (target - times[i]) {
            i + 1
        } else {
            i
        };
        if out.last() != Some(&pick) {
            out.push(pick);
        }
    }
    if out.last() != Some(&(len - 1)) {
        out.push(len - 1);
    }
    out
}

/// A sample of a replay: a row of the trajectory, or a state `(t, q, q̇)` of its own.
#[derive(Clone, Copy)]
enum Sample<'a> {
    Row(usize),
    State(f64, &'a [f64], &'a [f64]),
}

/// `rows` (increasing) with, for each of `times`, the rows at that time (an impact
/// records the state before and after at one time) or else the nearest one, so that a
/// decimated replay shows the moment of each event.
#[must_use]
pub fn keep_rows_at(all: &[f64], mut rows: Vec<usize>, times: &[f64]) -> Vec<usize> {
    if all.is_empty() {
        return rows;
    }
    for &t in times {
        let i = all.partition_point(|&x| x < t);
        let mut j = i;
        while j < all.len() && all[j] == t {
            rows.push(j);
            j += 1;
        }
        if j == i {
            let near = match i {
                0 => 0,
                _ if i == all.len() => i - 1,
                _ if all[i] - t < t - all[i - 1] => i,
                _ => i - 1,
            };
            rows.push(near);
        }
    }
    rows.sort_unstable();
    rows.dedup();
    rows
}

/// The events of a run, in time order.
fn events_of(run: &Run) -> Vec<Event> {
    let mut events: Vec<Event> = run
        .repartition_times
        .iter()
        .map(|&t| Event {
            t,
            kind: "repartition".to_owned(),
            name: None,
            detail: None,
        })
        .collect();
    for imp in &run.impacts {
        events.push(Event {
            t: imp.t,
            kind: "impact".to_owned(),
            name: Some(imp.names.join(", ")),
            detail: Some(format!(
                "normal velocity {} -> {}, kinetic energy lost {:.3e}",
                join(&imp.normal_velocity_before),
                join(&imp.normal_velocity_after),
                imp.energy_lost()
            )),
        });
    }
    for c in &run.contact_events {
        events.push(Event {
            t: c.t,
            kind: match c.kind {
                crate::sim::ContactEventKind::Rest => "rest",
                crate::sim::ContactEventKind::Release => "release",
            }
            .to_owned(),
            name: Some(c.contact.to_owned()),
            detail: None,
        });
    }
    // Stable: the order of the run among events at one time.
    events.sort_by(|a, b| a.t.total_cmp(&b.t));
    events
}

fn join(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x:.4e}")).collect();
    parts.join(", ")
}

/// `x` with `digits` significant digits.
fn round(x: f64, digits: Option<u32>) -> f64 {
    match digits {
        Some(d) if x.is_finite() && x != 0.0 => {
            let d = d.clamp(1, 17) as usize;
            format!("{x:.*e}", d - 1).parse().unwrap_or(x)
        }
        _ => x,
    }
}

fn check(what: impl FnOnce() -> String, found: usize, expected: usize) -> Result<(), ReplayError> {
    if found == expected {
        Ok(())
    } else {
        Err(ReplayError::Length {
            what: what(),
            found,
            expected,
        })
    }
}

impl Replay {
    /// The replay of `run` of `model`, decimated by `opts`. `run_meta` describes how the
    /// run was made (it becomes [`Replay::run`]).
    #[allow(clippy::too_many_lines)]
    #[must_use]
    pub fn from_run(
        model: &dyn Mechanism,
        run: &Run,
        run_meta: Map<String, Value>,
        opts: &ReplayOptions,
    ) -> Replay {
        let info = model.info();
        let tr = &run.trajectory;
        let events = events_of(run);
        let rows = match (tr.t.first(), tr.t.last()) {
            (Some(&a), Some(&b)) => {
                // Many events (a chattering contact) are marks only, not samples.
                // Impacts are samples of their own (below).
                let times: Vec<f64> = if events.len() <= opts.max_samples / 10 {
                    events
                        .iter()
                        .filter(|e| e.kind != "impact")
                        .map(|e| e.t)
                        .collect()
                } else {
                    Vec::new()
                };
                keep_rows_at(&tr.t, decimate(&tr.t, opts.samples(a, b)), &times)
            }
            _ => Vec::new(),
        };
        // The samples: the rows, and the states just before and after each impact (the
        // rows rarely fall on one); rows at an impact's time are left out, since which
        // side of the jump they hold is not recorded.
        let mut samples: Vec<Sample<'_>> = rows
            .into_iter()
            .filter(|&i| !run.impacts.iter().any(|imp| imp.t == tr.t[i]))
            .map(Sample::Row)
            .collect();
        if run.impacts.len() <= opts.max_samples / 10 {
            for imp in &run.impacts {
                samples.push(Sample::State(imp.t, &imp.q, &imp.qd_before));
                samples.push(Sample::State(imp.t, &imp.q, &imp.qd_after));
            }
        }
        let time = |s: &Sample<'_>| match *s {
            Sample::Row(i) => tr.t[i],
            Sample::State(t, _, _) => t,
        };
        samples.sort_by(|a, b| time(a).total_cmp(&time(b)));
        let rows = samples;
        let r = |x: f64| round(x, opts.digits);
        let drawing = model.drawing();
        let (nf, np) = (info.frames.len(), info.points.len());
        let mut poses = vec![0.0; 12 * nf];
        let mut points = vec![0.0; 3 * np];
        let mut values = vec![0.0; drawing.len()];
        let mut outputs = vec![0.0; info.outputs.len()];
        let mut frames: Vec<FrameTrack> = info
            .frames
            .iter()
            .map(|f| FrameTrack {
                name: f.name.to_owned(),
                parent: f.parent.map(|p| p as usize),
                planar: f.planar,
                position: Vec::with_capacity(3 * rows.len()),
                orientation: Vec::with_capacity(4 * rows.len()),
            })
            .collect();
        let mut point_tracks: Vec<PointTrack> = info
            .points
            .iter()
            .map(|p| PointTrack {
                name: p.name.to_owned(),
                frame: Some(p.frame as usize),
                position: Vec::with_capacity(3 * rows.len()),
            })
            .collect();
        let mut draw_points: Vec<PointTrack> = drawing
            .points
            .iter()
            .map(|p| PointTrack {
                name: p.name.to_owned(),
                frame: p.frame.map(|f| f as usize),
                position: Vec::with_capacity(3 * rows.len()),
            })
            .collect();
        let mut coordinates: Vec<Series> = info
            .coordinates
            .iter()
            .map(|c| Series {
                name: c.name.to_owned(),
                values: Vec::with_capacity(rows.len()),
            })
            .collect();
        let mut output_series: Vec<Series> = info
            .outputs
            .iter()
            .map(|c| Series {
                name: c.name.to_owned(),
                values: Vec::with_capacity(rows.len()),
            })
            .collect();
        let mut times = Vec::with_capacity(rows.len());
        let mut energy = Vec::with_capacity(rows.len());
        let mut violation = Violations::default();
        let mut scalars = vec![0.0; drawing.scalars as usize];
        for (k, sample) in rows.iter().enumerate() {
            let (t, q, qd, recorded) = match *sample {
                Sample::Row(i) => (
                    tr.t[i],
                    tr.q(i),
                    tr.qd(i),
                    Some((
                        tr.energy(i),
                        tr.position_violation[i],
                        tr.velocity_violation[i],
                    )),
                ),
                Sample::State(t, q, qd) => (t, q, qd, None),
            };
            let (e, vp, vv) = recorded.unwrap_or_else(|| {
                let res = model.residuals(t, q, qd);
                (None, res.position, res.velocity.max(res.nonholonomic))
            });
            times.push(t);
            energy.push(r(e.unwrap_or_else(|| model.energy(t, q, qd))));
            violation.position.push(r(vp));
            violation.velocity.push(r(vv));
            for (s, &v) in coordinates.iter_mut().zip(q) {
                s.values.push(r(v));
            }
            if !info.outputs.is_empty() {
                model.outputs(t, q, qd, &mut outputs);
                for (s, &v) in output_series.iter_mut().zip(&outputs) {
                    s.values.push(r(v));
                }
            }
            if nf > 0 {
                model.frame_poses(t, q, &mut poses);
                for (f, raw) in frames.iter_mut().zip(poses.chunks_exact(12)) {
                    f.position.extend(raw[..3].iter().map(|&x| r(x)));
                    let u = quaternion_from_raw(raw);
                    let qu = u.quaternion();
                    f.orientation
                        .extend([qu.w, qu.i, qu.j, qu.k].into_iter().map(r));
                }
            }
            if np > 0 {
                model.point_positions(t, q, &mut points);
                for (p, raw) in point_tracks.iter_mut().zip(points.chunks_exact(3)) {
                    p.position.extend(raw.iter().map(|&x| r(x)));
                }
            }
            if !values.is_empty() {
                model.drawing_values(t, q, &mut values);
                for (p, raw) in draw_points.iter_mut().zip(values.chunks_exact(3)) {
                    p.position.extend(raw.iter().map(|&x| r(x)));
                }
                if k == 0 {
                    scalars.copy_from_slice(&values[3 * drawing.points.len()..]);
                }
            }
        }
        let shapes = drawing
            .shapes
            .iter()
            .map(|s| ShapeMeta {
                name: s.name.to_owned(),
                kind: s.kind.name().to_owned(),
                frame: s.frame.map(|f| f as usize),
                points: s.points.iter().map(|&p| p as usize).collect(),
                normal: s.normal.map(|p| p as usize),
                radius: s
                    .radius
                    .and_then(|k| scalars.get(k as usize).copied())
                    .map(r),
                color: s.color.map(str::to_owned),
            })
            .collect();
        let spatial = info.frames.iter().any(|f| !f.planar)
            || (info.frames.is_empty()
                && draw_points
                    .iter()
                    .any(|p| p.position.chunks_exact(3).any(|v| v[2] != 0.0)));
        let declared = drawing.up.and_then(|k| {
            let k = k as usize;
            let v = scalars.get(k..k + 3)?;
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            (n > 0.0 && n.is_finite()).then(|| [v[0] / n, v[1] / n, v[2] / n])
        });
        let up = declared.unwrap_or(if spatial {
            [0.0, 0.0, 1.0]
        } else {
            [0.0, 1.0, 0.0]
        });
        Replay {
            format: FORMAT.to_owned(),
            version: VERSION,
            model: ModelMeta {
                name: info.name.to_owned(),
                doc: info.doc.to_owned(),
                dimension: if spatial { 3 } else { 2 },
                conservative: info.conservative,
                parameters: info
                    .parameters
                    .iter()
                    .enumerate()
                    .map(|(i, p)| Named {
                        name: p.name.to_owned(),
                        value: model.parameter(i),
                    })
                    .collect(),
                bodies: info
                    .bodies
                    .iter()
                    .map(|b| BodyMeta {
                        name: b.name.to_owned(),
                        frame: b.frame as usize,
                    })
                    .collect(),
                joints: info
                    .joints
                    .iter()
                    .map(|j| JointMeta {
                        name: j.name.to_owned(),
                        kind: format!("{:?}", j.kind),
                        frames: j.frames.map(|f| f.map(|f| f as usize)),
                    })
                    .collect(),
            },
            run: run_meta,
            times,
            frames,
            points: point_tracks,
            coordinates,
            outputs: output_series,
            energy,
            violation,
            events,
            drawing: DrawingTrack {
                points: draw_points,
                shapes,
                up: Some(up),
            },
        }
    }

    /// The number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// No samples.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// The pose of frame `frame` at sample `k`.
    ///
    /// # Panics
    /// When there is no such frame or sample.
    #[must_use]
    pub fn frame_pose(&self, frame: usize, k: usize) -> Isometry3<f64> {
        let f = &self.frames[frame];
        let p = &f.position[3 * k..3 * k + 3];
        let o = &f.orientation[4 * k..4 * k + 4];
        Isometry3::from_parts(
            Translation3::new(p[0], p[1], p[2]),
            UnitQuaternion::from_quaternion(Quaternion::new(o[0], o[1], o[2], o[3])),
        )
    }

    /// The position of named point `point` at sample `k`.
    ///
    /// # Panics
    /// When there is no such point or sample.
    #[must_use]
    pub fn point_position(&self, point: usize, k: usize) -> Point3<f64> {
        let p = &self.points[point].position[3 * k..3 * k + 3];
        Point3::new(p[0], p[1], p[2])
    }

    /// Checks that every array has the length the number of samples asks for.
    ///
    /// # Errors
    /// [`ReplayError::Version`] for another format or version, [`ReplayError::Length`]
    /// for an array of the wrong length.
    pub fn validate(&self) -> Result<(), ReplayError> {
        if self.format != FORMAT || self.version != VERSION {
            return Err(ReplayError::Version {
                format: self.format.clone(),
                version: self.version,
            });
        }
        let n = self.times.len();
        for (i, f) in self.frames.iter().enumerate() {
            check(|| format!("frames[{i}].position"), f.position.len(), 3 * n)?;
            check(
                || format!("frames[{i}].orientation"),
                f.orientation.len(),
                4 * n,
            )?;
        }
        for (what, list) in [
            ("points", &self.points),
            ("drawing.points", &self.drawing.points),
        ] {
            for (i, p) in list.iter().enumerate() {
                check(|| format!("{what}[{i}].position"), p.position.len(), 3 * n)?;
            }
        }
        for (what, list) in [
            ("coordinates", &self.coordinates),
            ("outputs", &self.outputs),
        ] {
            for (i, s) in list.iter().enumerate() {
                check(|| format!("{what}[{i}].values"), s.values.len(), n)?;
            }
        }
        check(|| "energy".to_owned(), self.energy.len(), n)?;
        check(
            || "violation.position".to_owned(),
            self.violation.position.len(),
            n,
        )?;
        check(
            || "violation.velocity".to_owned(),
            self.violation.velocity.len(),
            n,
        )?;
        let np = self.drawing.points.len();
        for (i, s) in self.drawing.shapes.iter().enumerate() {
            for &p in s.points.iter().chain(&s.normal) {
                if p >= np {
                    return Err(ReplayError::Length {
                        what: format!("drawing.shapes[{i}] refers to point {p}: drawing.points"),
                        found: np,
                        expected: p + 1,
                    });
                }
            }
        }
        Ok(())
    }

    /// The JSON text (one line).
    #[must_use]
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("a replay serializes")
    }

    /// Writes the JSON text.
    ///
    /// # Errors
    /// When writing fails.
    pub fn write(&self, w: impl Write) -> Result<(), ReplayError> {
        serde_json::to_writer(w, self)?;
        Ok(())
    }

    /// Parses and [validates](Self::validate) a JSON text.
    ///
    /// # Errors
    /// Text that is not a trajectory of this format and version, or arrays of the
    /// wrong lengths.
    pub fn from_json(text: &str) -> Result<Replay, ReplayError> {
        let r: Replay = serde_json::from_str(text)?;
        r.validate()?;
        Ok(r)
    }

    /// Reads, parses and [validates](Self::validate) a JSON text.
    ///
    /// # Errors
    /// As [`from_json`](Self::from_json), and read failures.
    pub fn read(mut r: impl Read) -> Result<Replay, ReplayError> {
        let mut text = String::new();
        r.read_to_string(&mut text)?;
        Self::from_json(&text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_the_ends_and_follows_the_grid() {
        let times: Vec<f64> = (0..=1000).map(|k| f64::from(k) * 0.001).collect();
        let rows = decimate(&times, 11);
        assert_eq!(rows, (0..=10).map(|k| 100 * k).collect::<Vec<_>>());
        assert_eq!(decimate(&times[..5], 11), vec![0, 1, 2, 3, 4]);
        let opts = ReplayOptions::default();
        assert_eq!(opts.samples(0.0, 1.0), 600);
        assert_eq!(opts.samples(0.0, 10.0), 2400);
        assert_eq!(opts.samples(0.0, 1e6), 6000);
    }

    #[test]
    fn event_rows_are_kept() {
        let times = [0.0, 0.1, 0.2, 0.25, 0.25, 0.3, 0.4];
        // Both rows at 0.25 (before and after an impact), the nearest row to 0.37.
        assert_eq!(
            keep_rows_at(&times, vec![0, 2, 6], &[0.25, 0.37]),
            vec![0, 2, 3, 4, 6]
        );
        assert_eq!(keep_rows_at(&times, vec![0, 6], &[-1.0, 9.0]), vec![0, 6]);
        assert_eq!(keep_rows_at(&[], vec![], &[1.0]), Vec::<usize>::new());
    }

    #[test]
    fn rounding_to_significant_digits() {
        assert_eq!(round(0.123_456_789, Some(3)), 0.123);
        assert_eq!(round(-98_765.4, Some(2)), -99_000.0);
        assert_eq!(round(0.123_456_789, None), 0.123_456_789);
        assert_eq!(round(0.0, Some(3)), 0.0);
    }
}
