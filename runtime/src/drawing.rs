//! How a model asks to be drawn: shapes over drawing points.
//!
//! The generator derives a default drawing from the bodies, joints and force elements
//! (a body as the segments between its joint points, a rolling wheel as a disc, a spring
//! as a zigzag, a guide or a rolling plane as ground), and a model adds its own with
//! `static name: Drawing = ..` items (see the README). The static part is a [`Drawing`];
//! the positions of its points and the values of its radii are written by
//! [`Mechanism::drawing_values`](crate::Mechanism::drawing_values), as functions of
//! `(t, q)` like every other generated quantity. A `static name: Drawing = Scene { up }`
//! item says which way is up (the viewer's camera and ground follow it), for models
//! whose axes are not the default `+z` up (spatial) or `+y` up (planar).

/// What a shape is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShapeKind {
    /// An open chain of segments through its points (a link, a rod).
    Link,
    /// A closed polygon through its points (a body's outline).
    Outline,
    /// A disc about its first point, of its radius, normal to its `normal` direction
    /// (a wheel; in a planar model, a circle).
    Disc,
    /// A zigzag between its two points (a spring).
    Spring,
    /// A fixed surface through its first point, normal to its `normal` direction: a line
    /// in a planar model (a guide, the floor), a plane in a spatial one.
    Ground,
    /// A dot at each of its points (a named point, a particle).
    Marker,
}

/// A point of a drawing: a position (or, for [`Shape::normal`], a direction) written by
/// [`Mechanism::drawing_values`](crate::Mechanism::drawing_values).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawPoint {
    /// A name for it (`joint.a`, `joint.b`, `spring.a`, a named point, …).
    pub name: &'static str,
    /// The frame it is fixed in, when it is (`None`: fixed in the ground, or given in
    /// global coordinates).
    pub frame: Option<u32>,
}

/// One shape of a drawing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    /// The name of the declaration it comes from (a body, a joint, a force element, a
    /// `Drawing` item).
    pub name: &'static str,
    /// What it is.
    pub kind: ShapeKind,
    /// The frame (body) it moves with, for its default colour (`None`: the ground).
    pub frame: Option<u32>,
    /// Its points, indices into [`Drawing::points`].
    pub points: &'static [u32],
    /// The direction a disc or a ground is normal to, an index into [`Drawing::points`].
    pub normal: Option<u32>,
    /// Its radius (discs; a marker's size), an index into the scalars of
    /// [`Mechanism::drawing_values`](crate::Mechanism::drawing_values).
    pub radius: Option<u32>,
    /// A CSS colour (`"#c0392b"`, `"steelblue"`); `None`: chosen per body.
    pub color: Option<&'static str>,
}

/// The static part of a drawing.
///
/// [`Mechanism::drawing_values`](crate::Mechanism::drawing_values) writes
/// `3 * points.len() + scalars` values: the global coordinates of each point (`z = 0` in
/// planar models), then the scalars (radii).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Drawing {
    /// The points the shapes refer to.
    pub points: &'static [DrawPoint],
    /// The number of scalars after the points.
    pub scalars: u32,
    /// The shapes, drawn in order.
    pub shapes: &'static [Shape],
    /// Which way is up, declared by a `Scene { up }` item: the index of the first of
    /// three scalars holding the direction (global coordinates; `z = 0` in planar
    /// models). `None`: the default, `+z` in spatial models and `+y` in planar ones.
    pub up: Option<u32>,
}

impl Drawing {
    /// Nothing to draw.
    pub const EMPTY: Drawing = Drawing {
        points: &[],
        scalars: 0,
        shapes: &[],
        up: None,
    };

    /// The number of values [`Mechanism::drawing_values`](crate::Mechanism::drawing_values)
    /// writes.
    #[must_use]
    pub const fn len(&self) -> usize {
        3 * self.points.len() + self.scalars as usize
    }

    /// No shapes.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }
}

impl ShapeKind {
    /// The name used in the trajectory format (`link`, `outline`, `disc`, `spring`,
    /// `ground`, `marker`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            ShapeKind::Link => "link",
            ShapeKind::Outline => "outline",
            ShapeKind::Disc => "disc",
            ShapeKind::Spring => "spring",
            ShapeKind::Ground => "ground",
            ShapeKind::Marker => "marker",
        }
    }
}
