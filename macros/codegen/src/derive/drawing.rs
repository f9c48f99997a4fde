//! How a model is drawn (`pfaff::Drawing`): default shapes from the bodies, joints and
//! force elements, and the model's own `static name: Drawing = ..` items.
//!
//! Input: what the body level met while it expanded ([`Attachment`]s: the global
//! positions of joint points, spring ends, wheels, guides) and the user's shapes. Output:
//! [`DrawingOut`], drawing points (global 3-vectors, functions of `q` and `t` like every
//! other generated quantity; equal expressions are one point, by hash-consing), scalars
//! (radii) and shapes over them.
//!
//! Defaults: a body is the chain of segments through its joint points, spring ends and
//! named points (a closed outline from three on), or the segment from its origin to its
//! one joint point, or a block at its origin whose half-size is the body's own (the
//! half-side of the uniform box of its mass and inertia: $\sqrt{3J/2m}$ planar,
//! $\sqrt{\operatorname{tr} I/2m}$ spatial), so that nothing is sized from the extent of
//! a run; a `Distance` joint is a rod; a spring is a zigzag; a rolling wheel is a disc
//! on a ground plane; a guide (a prismatic joint to the ground) is a ground line; a
//! revolute joint to the ground is a support marker. A `Drawing` item with a `frame`
//! replaces that frame's default shape. A `Scene { up }` item gives the direction that
//! is up (three scalars, [`DrawingOut::up`]).

use std::collections::HashMap;

use crate::sym::{ExprId, Func, Graph};

/// A drawing point: a global 3-vector (a position, or a direction for a normal).
#[derive(Debug)]
pub struct DrawPointOut {
    pub name: String,
    pub frame: Option<u32>,
    pub value: Vec<ExprId>,
}

/// A shape over drawing points.
#[derive(Debug)]
pub struct ShapeOut {
    pub name: String,
    /// The `pfaff::ShapeKind` variant.
    pub kind: &'static str,
    pub frame: Option<u32>,
    pub points: Vec<u32>,
    pub normal: Option<u32>,
    pub radius: Option<u32>,
    pub color: Option<String>,
}

/// The drawing of a model.
#[derive(Debug, Default)]
pub struct DrawingOut {
    pub points: Vec<DrawPointOut>,
    pub scalars: Vec<ExprId>,
    pub shapes: Vec<ShapeOut>,
    /// The index of the first of three scalars holding the up direction, when the
    /// model declares one.
    pub up: Option<u32>,
}

/// What a joint or a force element adds to the drawing; vectors are global, in the
/// model's dimension.
#[derive(Debug)]
pub enum Attachment {
    /// A joint's point on each of its frames.
    Joint {
        name: String,
        /// Its `pfaff::JointKind` variant.
        kind: &'static str,
        frames: [Option<u32>; 2],
        points: [Vec<ExprId>; 2],
    },
    /// A point of frame `frame` constrained in its velocity (a knife edge).
    Edge {
        name: String,
        frame: u32,
        point: Vec<ExprId>,
    },
    /// A guide fixed in the ground, or the plane of a `PointPlane` contact fixed in the
    /// ground: a line (plane) through `point` normal to `normal`.
    Guide {
        name: String,
        point: Vec<ExprId>,
        normal: Vec<ExprId>,
    },
    /// A wheel of frame `frame` rolling on the ground plane through `contact` normal to
    /// `up`.
    Wheel {
        name: String,
        frame: u32,
        center: Vec<ExprId>,
        axis: Vec<ExprId>,
        radius: ExprId,
        contact: Vec<ExprId>,
        up: Vec<ExprId>,
    },
    /// A body's mass and inertia (planar: `[J]`; spatial: the diagonal of its tensor),
    /// which size its default block.
    Mass {
        frame: u32,
        mass: ExprId,
        inertia: Vec<ExprId>,
    },
    /// A spring between two frames.
    Spring {
        name: String,
        frames: [Option<u32>; 2],
        points: [Vec<ExprId>; 2],
    },
}

/// A shape the model declares (`static name: Drawing = ..`), in global coordinates.
#[derive(Debug)]
pub struct UserShape {
    pub name: String,
    pub kind: &'static str,
    pub frame: Option<u32>,
    pub points: Vec<Vec<ExprId>>,
    pub normal: Option<Vec<ExprId>>,
    pub radius: Option<ExprId>,
    pub color: Option<String>,
}

/// The kinds of `Drawing` items with their required and optional fields.
pub const DRAWING_KINDS: &[(&str, &[&str], &[&str])] = &[
    ("Link", &["points"], &["frame", "color"]),
    ("Outline", &["points"], &["frame", "color"]),
    ("Disc", &["center", "radius"], &["frame", "axis", "color"]),
    ("Spring", &["points"], &["frame", "color"]),
    ("Ground", &["at", "normal"], &["color"]),
    ("Marker", &["points"], &["frame", "radius", "color"]),
    ("Scene", &["up"], &[]),
];

/// The `Drawing` kind that is not a shape: what the scene is (which way is up).
pub const SCENE: &str = "Scene";

/// The `pfaff::ShapeKind` variant of a `Drawing` kind.
pub fn shape_kind(kind: &str) -> Option<&'static str> {
    DRAWING_KINDS
        .iter()
        .map(|k| k.0)
        .find(|k| *k == kind && *k != SCENE)
}

struct Collector<'g> {
    g: &'g mut Graph,
    out: DrawingOut,
    index: HashMap<Vec<ExprId>, u32>,
}

impl Collector<'_> {
    /// The index of the drawing point of value `v` (padded to 3 components), added with
    /// `name` and `frame` when new.
    fn point(&mut self, name: &str, frame: Option<u32>, v: &[ExprId]) -> u32 {
        let mut v = v.to_vec();
        while v.len() < 3 {
            v.push(self.g.constant(0.0));
        }
        if let Some(&k) = self.index.get(&v) {
            return k;
        }
        let k = u32::try_from(self.out.points.len()).expect("drawing size fits u32");
        self.index.insert(v.clone(), k);
        self.out.points.push(DrawPointOut {
            name: name.to_owned(),
            frame,
            value: v,
        });
        k
    }

    fn scalar(&mut self, s: ExprId) -> u32 {
        let k = u32::try_from(self.out.scalars.len()).expect("drawing size fits u32");
        self.out.scalars.push(s);
        k
    }

    fn shape(&mut self, name: &str, kind: &'static str, frame: Option<u32>, points: Vec<u32>) {
        self.out.shapes.push(ShapeOut {
            name: name.to_owned(),
            kind,
            frame,
            points,
            normal: None,
            radius: None,
            color: None,
        });
    }
}

/// The half-size of the uniform box of `mass` and `inertia` (see the module's doc), or
/// `None` without an inertia.
fn block_size(g: &mut Graph, mass: ExprId, inertia: &[ExprId]) -> Option<ExprId> {
    let factor = match inertia.len() {
        1 => 1.5,
        3 => 0.5,
        _ => return None,
    };
    let trace = g.add(inertia.to_vec());
    if g.is_zero(trace) {
        return None;
    }
    let k = g.constant(factor);
    let kt = g.mul(vec![k, trace]);
    let s = g.div(kt, mass);
    Some(g.call(Func::Sqrt, s))
}

/// The drawing of a model with `frames` (each with its origin) and `bodies` (their
/// frames), named points `(name, frame, position)`, the attachments, the user's
/// shapes and the declared up direction.
pub fn build(
    g: &mut Graph,
    origins: &[Vec<ExprId>],
    bodies: &[(String, u32)],
    points: &[(String, u32, Vec<ExprId>)],
    attachments: &[Attachment],
    user: &[UserShape],
    up: Option<&[ExprId]>,
) -> DrawingOut {
    let mut c = Collector {
        g,
        out: DrawingOut::default(),
        index: HashMap::new(),
    };
    if let Some(u) = up {
        let zero = c.g.constant(0.0);
        let first = c.scalar(u[0]);
        c.scalar(u[1]);
        c.scalar(u.get(2).copied().unwrap_or(zero));
        c.out.up = Some(first);
    }
    // Grounds first (drawn below everything), one per distinct plane.
    let mut grounds: Vec<(Vec<ExprId>, Vec<ExprId>)> = Vec::new();
    for a in attachments {
        let (name, point, normal) = match a {
            Attachment::Guide {
                name,
                point,
                normal,
            } => (name, point, normal),
            Attachment::Wheel {
                name, contact, up, ..
            } => (name, contact, up),
            _ => continue,
        };
        // One ground per rolling plane, and per distinct guide or contact plane.
        let wheel = matches!(a, Attachment::Wheel { .. });
        if grounds
            .iter()
            .any(|(p, n)| n == normal && (wheel || p == point))
        {
            continue;
        }
        grounds.push((point.clone(), normal.clone()));
        let p = c.point(&format!("{name}.ground"), None, point);
        let n = c.point(&format!("{name}.normal"), None, normal);
        c.shape(name, "Ground", None, vec![p]);
        if let Some(s) = c.out.shapes.last_mut() {
            s.normal = Some(n);
        }
    }
    let replaced: Vec<u32> = user.iter().filter_map(|u| u.frame).collect();
    // Each body: its joint points, spring ends and named points, in declaration order.
    for (name, frame) in bodies {
        if replaced.contains(frame) {
            continue;
        }
        let mut anchors: Vec<u32> = Vec::new();
        let mut add = |c: &mut Collector<'_>, label: String, v: &[ExprId]| {
            let k = c.point(&label, Some(*frame), v);
            if !anchors.contains(&k) {
                anchors.push(k);
            }
        };
        for a in attachments {
            match a {
                Attachment::Joint {
                    name: j,
                    kind,
                    frames,
                    points,
                } if *kind != "RollingWheel" => {
                    for (side, (f, p)) in ["a", "b"].iter().zip(frames.iter().zip(points)) {
                        if *f == Some(*frame) {
                            add(&mut c, format!("{j}.{side}"), p);
                        }
                    }
                }
                Attachment::Spring {
                    name: s,
                    frames,
                    points,
                } => {
                    for (side, (f, p)) in ["a", "b"].iter().zip(frames.iter().zip(points)) {
                        if *f == Some(*frame) {
                            add(&mut c, format!("{s}.{side}"), p);
                        }
                    }
                }
                Attachment::Edge {
                    name: e,
                    frame: f,
                    point,
                } if f == frame => add(&mut c, e.clone(), point),
                _ => {}
            }
        }
        for (p, f, v) in points {
            if f == frame {
                add(&mut c, p.clone(), v);
            }
        }
        let origin = origins.get(*frame as usize).cloned().unwrap_or_default();
        let wheel = attachments
            .iter()
            .any(|a| matches!(a, Attachment::Wheel { frame: f, .. } if f == frame));
        match anchors.len() {
            _ if wheel && anchors.is_empty() => {}
            0 => {
                let o = c.point(&format!("{name}.origin"), Some(*frame), &origin);
                c.shape(name, "Marker", Some(*frame), vec![o]);
                let size = attachments.iter().find_map(|a| match a {
                    Attachment::Mass {
                        frame: f,
                        mass,
                        inertia,
                    } if f == frame => block_size(c.g, *mass, inertia),
                    _ => None,
                });
                if let Some(s) = size {
                    let r = c.scalar(s);
                    if let Some(shape) = c.out.shapes.last_mut() {
                        shape.radius = Some(r);
                    }
                }
            }
            1 => {
                let o = c.point(&format!("{name}.origin"), Some(*frame), &origin);
                if o == anchors[0] {
                    c.shape(name, "Marker", Some(*frame), vec![o]);
                } else {
                    c.shape(name, "Link", Some(*frame), vec![o, anchors[0]]);
                }
            }
            2 => c.shape(name, "Link", Some(*frame), anchors),
            _ => c.shape(name, "Outline", Some(*frame), anchors),
        }
    }
    for a in attachments {
        match a {
            Attachment::Wheel {
                name,
                frame,
                center,
                axis,
                radius,
                ..
            } => {
                let p = c.point(&format!("{name}.center"), Some(*frame), center);
                let n = c.point(&format!("{name}.axis"), Some(*frame), axis);
                let r = c.scalar(*radius);
                c.shape(name, "Disc", Some(*frame), vec![p]);
                if let Some(s) = c.out.shapes.last_mut() {
                    s.normal = Some(n);
                    s.radius = Some(r);
                }
            }
            Attachment::Spring {
                name,
                frames,
                points,
            } => {
                let a = c.point(&format!("{name}.a"), frames[0], &points[0]);
                let b = c.point(&format!("{name}.b"), frames[1], &points[1]);
                c.shape(name, "Spring", frames[0], vec![a, b]);
            }
            Attachment::Joint {
                name,
                kind,
                frames,
                points,
            } => match (*kind, frames[1]) {
                ("Distance", _) => {
                    let a = c.point(&format!("{name}.a"), frames[0], &points[0]);
                    let b = c.point(&format!("{name}.b"), frames[1], &points[1]);
                    c.shape(name, "Link", None, vec![a, b]);
                }
                ("PlanarRevolute" | "Revolute" | "Spherical" | "Universal", None) => {
                    let b = c.point(&format!("{name}.b"), None, &points[1]);
                    c.shape(name, "Marker", None, vec![b]);
                }
                _ => {}
            },
            _ => {}
        }
    }
    for u in user {
        let pts: Vec<u32> = u
            .points
            .iter()
            .enumerate()
            .map(|(i, v)| c.point(&format!("{}.{i}", u.name), u.frame, v))
            .collect();
        let normal = u
            .normal
            .as_ref()
            .map(|v| c.point(&format!("{}.normal", u.name), u.frame, v));
        let radius = u.radius.map(|r| c.scalar(r));
        c.out.shapes.push(ShapeOut {
            name: u.name.clone(),
            kind: u.kind,
            frame: u.frame,
            points: pts,
            normal,
            radius,
            color: u.color.clone(),
        });
    }
    c.out
}
