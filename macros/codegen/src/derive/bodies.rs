//! The body level: frames, points, bodies, joints and force elements → the
//! generalized-coordinate level.
//!
//! Input: the model's body-level declarations, in order (each may use the frames and
//! points above it). Output: [`BodyLevel`], which adds to what the generalized-coordinate
//! level derives from: every rigid body's mass matrix and inertia forces by Kane's method
//! (from the partial velocities of its centre of mass and of its angular velocity, both
//! derived from the kinematics; see `Builder::kane`), its kinetic energy for the
//! reported energy, the potential of
//! gravity and springs, the applied generalized forces of force elements (by virtual
//! power, `Q_i = F·∂v_P/∂q̇_i`), and named constraint rows: joints expand to holonomic
//! rows, rolling and knife edges to non-holonomic ones, and every frame oriented by Euler
//! parameters adds its normalization `θᵀθ − 1 = 0`.
//!
//! Constructors are struct literals, e.g. `Revolute { a: crank, at_a: [0.0, 0.0], b: ground }`;
//! an omitted `b` is the ground and an omitted point is the frame's origin.

use std::collections::HashMap;

#[path = "deformable.rs"]
mod deformable;

use proc_macro2::Span;
use quote::ToTokens;
use syn::spanned::Spanned;

use super::contacts::ContactRow;
use super::drawing::{Attachment, DrawingOut, UserShape, DRAWING_KINDS};
use super::Row;
use crate::ctxt::{suggest, Ctxt};
use crate::model::expr::{Context, Translator};
use crate::model::value::{
    add_v, cross, dot, mat_mat, mat_vec, scale_v, sub_v, time_derivative, FrameValue,
    FrameVelocity, InParent, Value,
};
use crate::parse::{Decl, DeclKind};
use crate::sym::{diff, transform, Deps, ExprId, Func, Graph, Var};

/// A frame as exported in `Info`.
#[derive(Debug)]
pub struct FrameOut {
    pub name: String,
    pub docs: String,
    pub parent: Option<u32>,
    pub normalization: Option<u32>,
    pub value: FrameValue,
}

/// A named point.
#[derive(Debug)]
pub struct PointOut {
    pub name: String,
    pub docs: String,
    pub frame: u32,
    pub position: Vec<ExprId>,
}

/// A body: its name, frame and mass.
#[derive(Debug)]
pub struct BodyOut {
    pub name: String,
    pub docs: String,
    pub frame: u32,
    /// The mass expression (parameters), for `body_masses`.
    pub mass: ExprId,
}

/// A joint with its rows (indices among the body level's own rows).
#[derive(Debug)]
pub struct JointOut {
    pub name: String,
    pub docs: String,
    /// The `pfaff::JointKind` variant.
    pub kind: &'static str,
    pub frames: [Option<u32>; 2],
    pub holonomic: (u32, u32),
    pub nonholonomic: (u32, u32),
}

/// What the body level adds to the model.
#[derive(Debug)]
pub struct BodyLevel {
    pub frames: Vec<FrameOut>,
    pub points: Vec<PointOut>,
    pub bodies: Vec<BodyOut>,
    pub joints: Vec<JointOut>,
    pub holonomic: Vec<Row>,
    pub nonholonomic: Vec<Row>,
    /// The kinetic energy of every body (for the energy the run reports).
    pub kinetic: ExprId,
    /// The part of [`Self::kinetic`] whose mass matrix and quadratic velocity forces come
    /// from Lagrange's equations (deformable bodies); rigid bodies give theirs in
    /// [`Self::mass`] and [`Self::inertial`] instead.
    pub lagrange_kinetic: ExprId,
    /// The rigid bodies' mass matrix by Kane's method, `(row, column, entry)` with both
    /// triangles, in row-major order, structural zeros left out.
    pub mass: Vec<(u32, u32, ExprId)>,
    /// The rigid bodies' generalized inertia forces at `q̈ = 0` (the quadratic velocity
    /// vector with its sign in `M q̈ = Q`), length `n`.
    pub inertial: Vec<ExprId>,
    pub potential: ExprId,
    /// Applied generalized forces of force elements, length `n`.
    pub applied: Vec<ExprId>,
    /// Whether a force element applies a non-potential force.
    pub has_applied: bool,
    /// Per frame, the origin (3) and the rotation matrix (3×3, row-major); planar frames
    /// embedded in the x–y plane.
    pub poses: Vec<ExprId>,
    /// Per point, its global position (3; `z = 0` in planar models).
    pub point_roots: Vec<ExprId>,
    /// How the model is drawn.
    pub drawing: DrawingOut,
    /// Contacts between points and surfaces (`Contact` items), as gaps.
    pub contacts: Vec<ContactRow>,
}

/// The inertia of a rigid motion in [`Builder::kane`].
enum Inertia {
    /// A mass (or a planar moment of inertia): the same for every component.
    Scalar(ExprId),
    /// A symmetric inertia tensor, row-major.
    Matrix(Vec<ExprId>),
}

fn idx(i: usize) -> u32 {
    u32::try_from(i).expect("model size fits u32")
}

/// The fields of a constructor `Name { field: expr, .. }`.
struct Fields<'a> {
    kind: String,
    span: Span,
    map: HashMap<String, &'a syn::Expr>,
}

impl<'a> Fields<'a> {
    fn get(&self, name: &str) -> Option<&'a syn::Expr> {
        self.map.get(name).copied()
    }
}

fn fields<'a>(
    cx: &Ctxt,
    e: &'a syn::Expr,
    kinds: &[(&str, &[&str], &[&str])],
    what: &str,
) -> Option<Fields<'a>> {
    let syn::Expr::Struct(s) = e else {
        let names: Vec<String> = kinds
            .iter()
            .map(|k| format!("`{} {{ .. }}`", k.0))
            .collect();
        cx.error_spanned_by(e, format!("expected {what}: {}", names.join(", ")));
        return None;
    };
    let kind = s
        .path
        .segments
        .last()
        .map(|x| x.ident.to_string())
        .unwrap_or_default();
    let Some(&(_, required, optional)) = kinds.iter().find(|k| k.0 == kind) else {
        let hint = suggest(&kind, kinds.iter().map(|k| k.0))
            .map(|n| format!("; did you mean `{n}`?"))
            .unwrap_or_default();
        let names: Vec<String> = kinds.iter().map(|k| format!("`{}`", k.0)).collect();
        cx.error_spanned_by(
            &s.path,
            format!(
                "unknown {what} `{kind}`, expected one of {}{hint}",
                names.join(", ")
            ),
        );
        return None;
    };
    if let Some(rest) = &s.rest {
        cx.error_spanned_by(rest, "`..` is not needed: optional fields have defaults");
    }
    let mut map = HashMap::new();
    let mut ok = true;
    for f in &s.fields {
        let name = match &f.member {
            syn::Member::Named(i) => i.to_string(),
            syn::Member::Unnamed(_) => String::new(),
        };
        if !required.contains(&name.as_str()) && !optional.contains(&name.as_str()) {
            let all = required.iter().chain(optional.iter()).copied();
            let hint = suggest(&name, all)
                .map(|n| format!("; did you mean `{n}`?"))
                .unwrap_or_default();
            let list: Vec<String> = required
                .iter()
                .chain(optional.iter())
                .map(|n| format!("`{n}`"))
                .collect();
            cx.error_spanned_by(
                &f.member,
                format!(
                    "`{kind}` has no field `{name}` (its fields: {}){hint}",
                    list.join(", ")
                ),
            );
            ok = false;
            continue;
        }
        if map.insert(name.clone(), &f.expr).is_some() {
            cx.error_spanned_by(&f.member, format!("duplicate field `{name}`"));
            ok = false;
        }
    }
    for r in required {
        if !map.contains_key(*r) {
            cx.error_spanned_by(&s.path, format!("`{kind}` needs the field `{r}`"));
            ok = false;
        }
    }
    ok.then_some(Fields {
        kind,
        span: s.path.span(),
        map,
    })
}

const FRAME_KINDS: &[(&str, &[&str], &[&str])] =
    &[("Frame", &["origin"], &["parent", "angle", "rotation"])];
const POINT_KINDS: &[(&str, &[&str], &[&str])] = &[("Point", &["frame"], &["at"])];
const BODY_KINDS: &[(&str, &[&str], &[&str])] = &[
    (
        "Body",
        &["mass"],
        &[
            "frame", "parent", "origin", "angle", "rotation", "inertia", "com",
        ],
    ),
    (
        "Deformable",
        &["elastic"],
        &[
            "data",
            "parent",
            "origin",
            "angle",
            "rotation",
            "mass",
            "com",
            "inertia",
            "span",
            "position",
            "displacement",
            "density",
            "invariants",
            "stiffness",
            "axial_rigidity",
            "bending_rigidity",
            "stiffening",
            "damping",
        ],
    ),
];
const JOINT_KINDS: &[(&str, &[&str], &[&str])] = &[
    (
        "Revolute",
        &["a"],
        &["at_a", "b", "at_b", "axis_a", "axis_b"],
    ),
    ("Spherical", &["a"], &["at_a", "b", "at_b"]),
    (
        "Universal",
        &["a", "axis_a", "axis_b"],
        &["at_a", "b", "at_b"],
    ),
    (
        "Cylindrical",
        &["a", "axis_a", "axis_b"],
        &["at_a", "b", "at_b"],
    ),
    (
        "Prismatic",
        &["a", "axis_a"],
        &["at_a", "b", "at_b", "axis_b", "angle"],
    ),
    ("Fixed", &["a"], &["at_a", "b", "at_b", "angle"]),
    ("Distance", &["a", "length"], &["at_a", "b", "at_b"]),
    ("Driver", &["value", "motion"], &[]),
    ("ZeroVelocity", &["a", "along"], &["at_a"]),
    ("KnifeEdge", &["a", "lateral"], &["at_a"]),
    ("RollingWheel", &["a", "axis", "radius"], &["center", "up"]),
];
/// Contacts between a point and a surface: the gap is the signed distance, positive
/// apart.
const CONTACT_KINDS: &[(&str, &[&str], &[&str])] = &[
    (
        "PointPlane",
        &["point", "normal", "restitution"],
        &["offset", "radius"],
    ),
    (
        "PointSphere",
        &["point", "center", "radius", "restitution"],
        &[],
    ),
];
const FORCE_KINDS: &[(&str, &[&str], &[&str])] = &[
    ("Gravity", &["acceleration"], &[]),
    (
        "SpringDamper",
        &["a", "stiffness", "rest_length"],
        &["at_a", "b", "at_b", "damping"],
    ),
    ("PointForce", &["a", "force"], &["at_a"]),
    ("Torque", &["a", "torque"], &[]),
];

struct Builder<'t, 'a> {
    cx: &'a Ctxt,
    tr: &'t mut Translator<'a>,
    defaults: Vec<f64>,
    out: BodyLevel,
    kinetic: Vec<ExprId>,
    lagrange_kinetic: Vec<ExprId>,
    /// Kane's mass-matrix terms per `(row, column)`, upper triangle.
    kane_mass: std::collections::BTreeMap<(u32, u32), Vec<ExprId>>,
    /// Kane's generalized inertia force terms per coordinate.
    kane_forces: Vec<Vec<ExprId>>,
    potential: Vec<ExprId>,
    /// `(mass, centre of mass)` of each body, for gravity.
    masses: Vec<(ExprId, Vec<ExprId>)>,
    gravity: Option<(Vec<ExprId>, Span)>,
    attachments: Vec<Attachment>,
    shapes: Vec<UserShape>,
    /// The up direction of a `Scene` item.
    up: Option<Vec<ExprId>>,
}

/// Expands the body-level declarations of the model translated by `tr`.
pub fn expand<'a>(
    cx: &'a Ctxt,
    tr: &mut Translator<'a>,
    decls: &[Decl],
    defaults: &[f64],
) -> Option<BodyLevel> {
    let zero = tr.g.constant(0.0);
    let n = tr.nq();
    let mut b = Builder {
        cx,
        tr,
        defaults: defaults.to_vec(),
        out: BodyLevel {
            frames: Vec::new(),
            points: Vec::new(),
            bodies: Vec::new(),
            joints: Vec::new(),
            holonomic: Vec::new(),
            nonholonomic: Vec::new(),
            kinetic: zero,
            lagrange_kinetic: zero,
            mass: Vec::new(),
            inertial: vec![zero; n],
            potential: zero,
            applied: vec![zero; n],
            has_applied: false,
            poses: Vec::new(),
            point_roots: Vec::new(),
            drawing: DrawingOut::default(),
            contacts: Vec::new(),
        },
        kinetic: Vec::new(),
        lagrange_kinetic: Vec::new(),
        kane_mass: std::collections::BTreeMap::new(),
        kane_forces: vec![Vec::new(); n],
        potential: Vec::new(),
        masses: Vec::new(),
        gravity: None,
        attachments: Vec::new(),
        shapes: Vec::new(),
        up: None,
    };
    let mut ok = true;
    for d in decls {
        let done = match d.kind {
            DeclKind::Frame => b.frame(d, None),
            DeclKind::Body => b.body(d),
            DeclKind::Point => b.point(d),
            DeclKind::Joint => b.joint(d),
            DeclKind::Force => b.force(d),
            DeclKind::Drawing => b.drawing(d),
            DeclKind::Contact => b.contact(d),
        };
        ok &= done.is_some();
        if done.is_none() && matches!(d.kind, DeclKind::Frame | DeclKind::Body) {
            // Keep indices aligned so later declarations resolve (their errors would be
            // consequences of this one).
            return None;
        }
    }
    if let Some((gv, span)) = b.gravity.clone() {
        if b.masses.is_empty() {
            cx.error_at(span, "gravity acts on bodies, and the model declares none");
            ok = false;
        }
        let dim = gv.len();
        for (m, r) in b.masses.clone() {
            if r.len() != dim {
                cx.error_at(
                    span,
                    format!(
                        "gravity is a {dim}-vector but the bodies are {}-dimensional",
                        r.len()
                    ),
                );
                return None;
            }
            let w = dot(b.tr.g, &gv, &r);
            let mw = b.tr.g.mul(vec![m, w]);
            b.potential.push(b.tr.g.neg(mw));
        }
    }
    if !ok {
        return None;
    }
    let g = &mut *b.tr.g;
    let (one, zero) = (g.constant(1.0), g.constant(0.0));
    for f in &b.out.frames {
        let v = &f.value;
        if v.dim == 2 {
            let r = &v.rotation;
            b.out.poses.extend([v.origin[0], v.origin[1], zero]);
            b.out
                .poses
                .extend([r[0], r[1], zero, r[2], r[3], zero, zero, zero, one]);
        } else {
            b.out.poses.extend(v.origin.iter().copied());
            b.out.poses.extend(v.rotation.iter().copied());
        }
    }
    for p in &b.out.points {
        b.out.point_roots.extend(p.position.iter().copied());
        if p.position.len() == 2 {
            b.out.point_roots.push(zero);
        }
    }
    let origins: Vec<Vec<ExprId>> = b
        .out
        .frames
        .iter()
        .map(|f| f.value.origin.clone())
        .collect();
    let bodies: Vec<(String, u32)> = b
        .out
        .bodies
        .iter()
        .map(|x| (x.name.clone(), x.frame))
        .collect();
    let points: Vec<(String, u32, Vec<ExprId>)> = b
        .out
        .points
        .iter()
        .map(|p| (p.name.clone(), p.frame, p.position.clone()))
        .collect();
    b.out.drawing = super::drawing::build(
        g,
        &origins,
        &bodies,
        &points,
        &b.attachments,
        &b.shapes,
        b.up.as_deref(),
    );
    b.out.kinetic = g.add(std::mem::take(&mut b.kinetic));
    b.out.lagrange_kinetic = g.add(std::mem::take(&mut b.lagrange_kinetic));
    for (i, terms) in std::mem::take(&mut b.kane_forces).into_iter().enumerate() {
        b.out.inertial[i] = g.add(terms);
    }
    let mut mass = Vec::new();
    for ((i, j), terms) in std::mem::take(&mut b.kane_mass) {
        let m = g.add(terms);
        if g.is_canonical() && g.is_zero(m) {
            continue;
        }
        mass.push((i, j, m));
        if i != j {
            mass.push((j, i, m));
        }
    }
    mass.sort_by_key(|&(i, j, _)| (i, j));
    b.out.mass = mass;
    b.out.potential = g.add(std::mem::take(&mut b.potential));
    Some(b.out)
}

impl<'a> Builder<'_, 'a> {
    fn g(&mut self) -> &mut Graph {
        self.tr.g
    }

    fn scalar(&mut self, e: &syn::Expr, ctx: Context) -> Option<ExprId> {
        self.tr.field_scalar(e, ctx)
    }

    fn vector(&mut self, e: &syn::Expr, dim: usize, ctx: Context) -> Option<Vec<ExprId>> {
        match self.tr.field_value(e, ctx)? {
            Value::Vector(v) if v.len() == dim => Some(v),
            other => {
                self.cx.error_spanned_by(
                    e,
                    format!("expected a {dim}-vector; this is {}", other.describe()),
                );
                None
            }
        }
    }

    fn frame_of(&mut self, e: &syn::Expr) -> Option<Option<usize>> {
        match self.tr.field_value(e, Context::Kinematics)? {
            Value::Frame(f) => Some(f),
            other => {
                self.cx.error_spanned_by(
                    e,
                    format!(
                        "expected a frame or body name (or `ground`); this is {}",
                        other.describe()
                    ),
                );
                None
            }
        }
    }

    fn dim_of(&self, f: Option<usize>) -> usize {
        f.map_or_else(|| self.tr.model_dim(), |k| self.tr.frames[k].dim)
    }

    /// An optional point field in frame coordinates (the origin when omitted).
    fn at(&mut self, fl: &Fields<'_>, name: &str, dim: usize) -> Option<Vec<ExprId>> {
        match fl.get(name) {
            Some(e) => self.vector(e, dim, Context::Kinematics),
            None => Some(vec![self.g().constant(0.0); dim]),
        }
    }

    /// Defines frame `d.name` from the fields `fl` (of a `Frame` or an inline `Body`).
    fn define_frame(&mut self, d: &Decl, fl: &Fields<'_>) -> Option<usize> {
        let parent = match fl.get("parent") {
            Some(p) => self.frame_of(p)?,
            None => None,
        };
        let origin_e = fl.get("origin")?;
        let origin = match self.tr.field_value(origin_e, Context::Kinematics)? {
            Value::Vector(v) => v,
            other => {
                self.cx.error_spanned_by(
                    origin_e,
                    format!(
                        "the origin is a 2-vector (planar) or a 3-vector (spatial); this is {}",
                        other.describe()
                    ),
                );
                return None;
            }
        };
        let dim = origin.len();
        if let Some(p) = parent {
            if self.tr.frames[p].dim != dim {
                self.cx
                    .error_spanned_by(origin_e, "a frame has the dimension of its parent");
                return None;
            }
        }
        if let Some(first) = self.tr.frames.first() {
            if first.dim != dim {
                self.cx.error_spanned_by(
                    origin_e,
                    format!("the model's frames are {}-dimensional; planar and spatial frames do not mix", first.dim),
                );
                return None;
            }
        }
        let pv = self.tr.frame_value(parent, dim);
        let mut euler = None;
        let mut normalization = None;
        let (rel_rotation, rel_angle) = if dim == 2 {
            if fl.get("rotation").is_some() {
                self.cx.error_at(
                    fl.span,
                    "a planar frame is oriented by `angle`, not `rotation`",
                );
                return None;
            }
            let Some(a) = fl.get("angle") else {
                self.cx.error_at(
                    fl.span,
                    "a planar frame needs `angle` (use `angle: 0.0` for a translating frame)",
                );
                return None;
            };
            let a = self.scalar(a, Context::Kinematics)?;
            (crate::model::value::rot2(self.g(), a), Some(a))
        } else {
            if fl.get("angle").is_some() {
                self.cx.error_at(
                    fl.span,
                    "a spatial frame is oriented by `rotation`, not `angle`",
                );
                return None;
            }
            let Some(r) = fl.get("rotation") else {
                self.cx.error_at(fl.span, "a spatial frame needs `rotation` (e.g. `euler_parameters(e0, e1, e2, e3)` or `rot_z(psi) * rot_x(phi)`)");
                return None;
            };
            if let syn::Expr::Call(c) = r {
                if matches!(&*c.func, syn::Expr::Path(p) if p.path.is_ident("euler_parameters"))
                    && c.args.len() == 4
                {
                    let mut e = Vec::new();
                    for a in &c.args {
                        e.push(self.scalar(a, Context::Kinematics)?);
                    }
                    let e = [e[0], e[1], e[2], e[3]];
                    if parent.is_none() {
                        euler = Some(e);
                    }
                    let sq = dot(self.g(), &e, &e);
                    let one = self.g().constant(1.0);
                    let c = self.g().sub(sq, one);
                    normalization = Some(idx(self.out.holonomic.len()));
                    self.out.holonomic.push(Row {
                        name: format!("{}.normalization", d.name),
                        docs: format!("Euler-parameter normalization θᵀθ − 1 = 0 of `{}`.", d.name),
                        span: d.name.span(),
                        expr: c,
                        velocity: None,
                    });
                }
            }
            match self.tr.field_value(r, Context::Kinematics)? {
                Value::Matrix(3, m) => (m, None),
                other => {
                    self.cx.error_spanned_by(
                        r,
                        format!("a rotation is a 3×3 matrix; this is {}", other.describe()),
                    );
                    return None;
                }
            }
        };
        let mut exact_rates = pv.exact_rates;
        let mut omega_in_parent = None;
        let omega = match (dim, fl.get("rotation"), &pv.omega) {
            (3, Some(r), Some(w)) => {
                let (w, wp, exact) = self.relative_rate(r, &rel_rotation, w)?;
                exact_rates &= exact;
                omega_in_parent = Some(wp);
                Some(w)
            }
            _ => None,
        };
        let velocity = match (&pv.velocity, &pv.omega, &omega, parent) {
            (Some(_), Some(_), Some(_), None) => {
                let base = origin
                    .iter()
                    .map(|&x| time_derivative(self.g(), x))
                    .collect();
                let z = self.g().constant(0.0);
                Some(FrameVelocity {
                    base,
                    relative: vec![z; 3],
                    in_parent: None,
                })
            }
            (Some(pvel), Some(wp), Some(_), Some(_)) => {
                let od: Vec<ExprId> = origin
                    .iter()
                    .map(|&x| time_derivative(self.g(), x))
                    .collect();
                let wo = cross(self.g(), wp, &origin);
                let s1 = add_v(self.g(), &pvel.relative, &wo);
                let rp = add_v(self.g(), &s1, &od);
                let rt = crate::model::value::transpose(3, &rel_rotation);
                let relative = mat_vec(self.g(), 3, &rt, &rp);
                Some(FrameVelocity {
                    base: pvel.base.clone(),
                    relative,
                    in_parent: Some(InParent {
                        velocity: rp,
                        rotation: pv.rotation.clone(),
                        omega: wp.clone(),
                        relative: rel_rotation.clone(),
                        frame_omega: omega_in_parent.clone().expect("spatial frame"),
                    }),
                })
            }
            _ => None,
        };
        let po = mat_vec(self.g(), dim, &pv.rotation, &origin);
        let origin = add_v(self.g(), &pv.origin, &po);
        let rotation = if parent.is_some() {
            mat_mat(self.g(), dim, &pv.rotation, &rel_rotation)
        } else {
            rel_rotation
        };
        let angle = match (rel_angle, pv.angle) {
            (Some(a), Some(p)) if parent.is_some() => Some(self.g().add(vec![a, p])),
            (Some(a), _) => Some(a),
            _ => None,
        };
        if dim == 3 && exact_rates {
            if let Some(w) = &omega {
                // `Ȧ = A ω̃`: three operations an entry instead of the forward rate of
                // the product of the rotations down the tree.
                let g = self.g();
                let zero = g.constant(0.0);
                let nw: Vec<ExprId> = w.iter().map(|&x| g.neg(x)).collect();
                let skew = [zero, nw[2], w[1], w[2], zero, nw[0], nw[1], w[0], zero];
                let ad = mat_mat(g, 3, &rotation, &skew);
                // Sums only: a product's forward rate is as short, and other
                // expressions share product nodes (`cos φ cos θ`) whose own rates
                // simplify better.
                for (&e, &r) in rotation.iter().zip(&ad) {
                    if matches!(g.node(e), crate::sym::Node::Add(_)) {
                        diff::declare_rate(g, e, r);
                    }
                }
            }
        }
        let value = FrameValue {
            dim,
            origin,
            rotation: if dim == 2 {
                match angle {
                    Some(a) if parent.is_some() => crate::model::value::rot2(self.g(), a),
                    _ => rotation,
                }
            } else {
                rotation
            },
            angle,
            euler,
            omega,
            velocity,
            exact_rates,
        };
        self.tr.frames.push(value.clone());
        self.out.frames.push(FrameOut {
            name: d.name.to_string(),
            docs: d.docs.clone(),
            parent: parent.map(idx),
            normalization,
            value,
        });
        Some(self.tr.frames.len() - 1)
    }

    /// The angular velocity in the frame's components of a frame turned by `rotation`
    /// (the user's expression, translated: `rel`) relative to a parent whose angular
    /// velocity in its own components is `w`. A product of factors is taken factor by
    /// factor, `ω̄ ← Fᵀ ω̄ + ω̄_F`, with `ω̄_F` the rate `ȧ e_k` of `rot_x/y/z(a)`, `2Ē θ̇`
    /// of `euler_parameters`, zero for a constant factor, and the axial vector of `FᵀḞ`
    /// otherwise (also for a whole rotation that is not a product of 3×3 matrices).
    /// Also returns the same angular velocity in the parent's components
    /// (`ω̄_p + Σ_k F_1⋯F_k ω̄_{F_k}`) and whether every factor is a coordinate-axis
    /// rotation or constant ([`FrameValue::exact_rates`]).
    fn relative_rate(
        &mut self,
        rotation: &syn::Expr,
        rel: &[ExprId],
        w: &[ExprId],
    ) -> Option<(Vec<ExprId>, Vec<ExprId>, bool)> {
        fn flatten<'e>(e: &'e syn::Expr, out: &mut Vec<&'e syn::Expr>) {
            match e {
                syn::Expr::Paren(p) => flatten(&p.expr, out),
                syn::Expr::Group(p) => flatten(&p.expr, out),
                syn::Expr::Binary(b) if matches!(b.op, syn::BinOp::Mul(_)) => {
                    flatten(&b.left, out);
                    flatten(&b.right, out);
                }
                _ => out.push(e),
            }
        }
        let mut list = Vec::new();
        flatten(rotation, &mut list);
        let mut factors = Vec::new();
        for f in &list {
            match self.tr.field_value(f, Context::Kinematics)? {
                Value::Matrix(3, m) => factors.push((Some(*f), m)),
                _ => {
                    factors = vec![(None, rel.to_vec())];
                    break;
                }
            }
        }
        let mut w_parent = w.to_vec();
        let mut w = w.to_vec();
        let mut exact = true;
        let (o, z) = (self.g().constant(1.0), self.g().constant(0.0));
        let mut prefix = vec![o, z, z, z, o, z, z, z, o];
        for (e, m) in factors {
            let (own, elementary) = self.factor_rate(e, &m)?;
            exact &= elementary;
            prefix = mat_mat(self.g(), 3, &prefix, &m);
            let seen = mat_vec(self.g(), 3, &prefix, &own);
            w_parent = add_v(self.g(), &w_parent, &seen);
            let mt = crate::model::value::transpose(3, &m);
            let turned = mat_vec(self.g(), 3, &mt, &w);
            w = add_v(self.g(), &turned, &own);
        }
        Some((w, w_parent, exact))
    }

    /// `ω̄_F` of one factor `F = m` of a rotation (see [`Self::relative_rate`]).
    fn factor_rate(&mut self, e: Option<&syn::Expr>, m: &[ExprId]) -> Option<(Vec<ExprId>, bool)> {
        let zero = self.g().constant(0.0);
        let moving = m.iter().any(|&x| {
            let d = self.tr.g.deps(x);
            d.has(Deps::Q) || d.has(Deps::TIME)
        });
        if !moving {
            return Some((vec![zero; 3], true));
        }
        if let Some(syn::Expr::Call(c)) = e {
            let name = match &*c.func {
                syn::Expr::Path(p) => p.path.get_ident().map(ToString::to_string),
                _ => None,
            };
            let axis = match name.as_deref() {
                Some("rot_x") => Some(0),
                Some("rot_y") => Some(1),
                Some("rot_z") => Some(2),
                _ => None,
            };
            if let (Some(k), 1) = (axis, c.args.len()) {
                let a = self.scalar(&c.args[0], Context::Kinematics)?;
                let r = time_derivative(self.g(), a);
                let mut out = vec![zero; 3];
                out[k] = r;
                return Some((out, true));
            }
            if name.as_deref() == Some("euler_parameters") && c.args.len() == 4 {
                let mut p = Vec::new();
                for a in &c.args {
                    p.push(self.scalar(a, Context::Kinematics)?);
                }
                let fv = FrameValue {
                    dim: 3,
                    origin: Vec::new(),
                    rotation: Vec::new(),
                    angle: None,
                    euler: Some([p[0], p[1], p[2], p[3]]),
                    omega: None,
                    velocity: None,
                    exact_rates: false,
                };
                return Some((fv.body_angular_velocity(self.g()), false));
            }
        }
        let md: Vec<ExprId> = m.iter().map(|&x| time_derivative(self.g(), x)).collect();
        let mt = crate::model::value::transpose(3, m);
        let x = mat_mat(self.g(), 3, &mt, &md);
        Some((vec![x[7], x[2], x[3]], false))
    }

    fn frame(&mut self, d: &Decl, _: Option<()>) -> Option<()> {
        let fl = fields(self.cx, &d.expr, FRAME_KINDS, "frame")?;
        self.define_frame(d, &fl).map(|_| ())
    }

    fn body(&mut self, d: &Decl) -> Option<()> {
        let fl = fields(self.cx, &d.expr, BODY_KINDS, "body")?;
        if fl.kind == "Deformable" {
            return self.deformable(d, &fl);
        }
        let k = if let Some(f) = fl.get("frame") {
            for other in ["parent", "origin", "angle", "rotation"] {
                if let Some(e) = fl.get(other) {
                    self.cx
                        .error_spanned_by(e, format!("a body given a `frame` takes no `{other}`"));
                    return None;
                }
            }
            let Some(src) = self.frame_of(f)? else {
                self.cx
                    .error_spanned_by(f, "a body moves: its frame is not the ground");
                return None;
            };
            let value = self.tr.frames[src].clone();
            self.tr.frames.push(value.clone());
            self.out.frames.push(FrameOut {
                name: d.name.to_string(),
                docs: d.docs.clone(),
                parent: self.out.frames[src].parent,
                normalization: self.out.frames[src].normalization,
                value,
            });
            self.tr.frames.len() - 1
        } else {
            if fl.get("origin").is_none() {
                self.cx.error_at(fl.span, "a body needs its frame: `frame: f`, or `origin` with `angle` (planar) or `rotation` (spatial)");
                return None;
            }
            self.define_frame(d, &fl)?
        };
        let fv = self.tr.frames[k].clone();
        let dim = fv.dim;
        let mass = self.scalar(fl.get("mass")?, Context::Kinematics)?;
        let com = self.at(&fl, "com", dim)?;
        let rc = fv.point(self.g(), &com);
        let half = self.g().constant(0.5);
        let mut terms = Vec::new();
        let split = match (&fv.velocity, &fv.omega) {
            (Some(vel), Some(w)) => {
                // `v_c = b + A_e u`: the base in global components, the rest in those of
                // the parent frame when the centre of mass is the origin (no rotation by
                // the joint's own angle), else of the body's frame.
                let com_zero = com.iter().all(|&x| self.tr.g.is_zero(x));
                let (rot, omega_e, u) = match (&vel.in_parent, com_zero) {
                    (Some(p), true) => (p.rotation.clone(), p.omega.clone(), p.velocity.clone()),
                    _ => {
                        let wc = cross(self.g(), w, &com);
                        let u = add_v(self.g(), &vel.relative, &wc);
                        (fv.rotation.clone(), w.clone(), u)
                    }
                };
                Some((vel.base.clone(), rot, omega_e, u))
            }
            _ => None,
        };
        let vc: Vec<ExprId> = rc.iter().map(|&x| time_derivative(self.g(), x)).collect();
        let vv = dot(self.g(), &vc, &vc);
        terms.push(self.g().mul(vec![half, mass, vv]));
        let global = |b: &mut Self| b.kane(&vc, &Inertia::Scalar(mass), None);
        match split {
            Some((base, rot, omega_e, u)) => {
                // Whichever form of the products is smaller for this body.
                let saved = (self.kane_mass.clone(), self.kane_forces.clone());
                let added = |b: &Self| -> Vec<ExprId> {
                    let mut r: Vec<ExprId> = b
                        .kane_forces
                        .iter()
                        .zip(&saved.1)
                        .flat_map(|(now, before)| now[before.len()..].to_vec())
                        .collect();
                    for (k, v) in &b.kane_mass {
                        let n0 = saved.0.get(k).map_or(0, Vec::len);
                        r.extend_from_slice(&v[n0..]);
                    }
                    r
                };
                self.kane_translation(mass, &base, &rot, &omega_e, &u);
                let split_ops = transform::op_count(self.tr.g, &added(self));
                (self.kane_mass, self.kane_forces) = saved.clone();
                global(self);
                let global_ops = transform::op_count(self.tr.g, &added(self));
                if split_ops < global_ops {
                    (self.kane_mass, self.kane_forces) = saved.clone();
                    self.kane_translation(mass, &base, &rot, &omega_e, &u);
                }
            }
            None => global(self),
        }
        let mut principal = Vec::new();
        if let Some(ie) = fl.get("inertia") {
            if dim == 2 {
                let i = self.scalar(ie, Context::Kinematics)?;
                principal.push(i);
                let Value::Scalar(w) = fv.angular_velocity(self.g()) else {
                    unreachable!("planar frames have a scalar rate")
                };
                terms.push(self.g().mul(vec![half, i, w, w]));
                self.kane(&[w], &Inertia::Scalar(i), None);
            } else {
                let inertia = match self.tr.field_value(ie, Context::Kinematics)? {
                    Value::Matrix(3, m) => m,
                    Value::Vector(v) if v.len() == 3 => {
                        let z = self.g().constant(0.0);
                        vec![v[0], z, z, z, v[1], z, z, z, v[2]]
                    }
                    other => {
                        self.cx.error_spanned_by(ie, format!("the inertia of a spatial body is a 3×3 matrix (or the 3-vector of its diagonal); this is {}", other.describe()));
                        return None;
                    }
                };
                for i in 0..3 {
                    for j in 0..i {
                        let (a, b) = (inertia[3 * i + j], inertia[3 * j + i]);
                        // Checked in the canonical graph only: a raw graph (the naive
                        // operation count) does not simplify `a − a` to zero.
                        let diff = self.g().sub(a, b);
                        if self.g().is_canonical() && !self.g().is_zero(diff) {
                            self.cx.error_spanned_by(ie, format!("the inertia tensor is not symmetric: entries ({i}, {j}) and ({j}, {i}) differ"));
                            return None;
                        }
                    }
                }
                principal.extend([inertia[0], inertia[4], inertia[8]]);
                // An inertia the joint's rotation leaves unchanged (a wheel spinning on
                // its axle) is taken in the parent's components, where the spin angle
                // does not enter: `Ī_p = F Ī Fᵀ`, the rate `F ω̄`, and the gyroscopic
                // term with the parent's angular velocity, `ω̄_p × Ī_p ω`.
                let parent_view = fv.velocity.as_ref().and_then(|v| v.in_parent.clone());
                if let Some(p) = parent_view {
                    let g = self.g();
                    let fi = mat_mat(g, 3, &p.relative, &inertia);
                    let ft = crate::model::value::transpose(3, &p.relative);
                    let ip = mat_mat(g, 3, &fi, &ft);
                    let constant = ip.iter().all(|&x| {
                        let d = g.deps(x);
                        !d.has(Deps::Q) && !d.has(Deps::TIME)
                    });
                    if constant {
                        let w = p.frame_omega.clone();
                        let iw = mat_vec(g, 3, &ip, &w);
                        let wiw = dot(g, &w, &iw);
                        terms.push(g.mul(vec![half, wiw]));
                        let gyroscopic = cross(g, &p.omega, &iw);
                        self.kane(&w, &Inertia::Matrix(ip), Some(&gyroscopic));
                        return self.finish_body(d, k, mass, rc, principal, terms);
                    }
                }
                let w = fv.body_angular_velocity(self.g());
                let iw = mat_vec(self.g(), 3, &inertia, &w);
                let wiw = dot(self.g(), &w, &iw);
                terms.push(self.g().mul(vec![half, wiw]));
                let gyroscopic = cross(self.g(), &w, &iw);
                self.kane(&w, &Inertia::Matrix(inertia.clone()), Some(&gyroscopic));
            }
        }
        self.finish_body(d, k, mass, rc, principal, terms)
    }

    /// Records a rigid body's energy, gravity, drawing and output entry.
    fn finish_body(
        &mut self,
        d: &Decl,
        k: usize,
        mass: ExprId,
        rc: Vec<ExprId>,
        principal: Vec<ExprId>,
        terms: Vec<ExprId>,
    ) -> Option<()> {
        let t = self.g().add(terms);
        self.kinetic.push(t);
        self.masses.push((mass, rc));
        self.attachments.push(Attachment::Mass {
            frame: idx(k),
            mass,
            inertia: principal,
        });
        self.out.bodies.push(BodyOut {
            name: d.name.to_string(),
            docs: d.docs.clone(),
            frame: idx(k),
            mass,
        });
        Some(())
    }

    /// Kane's method for a centre of mass of mass `m` whose velocity is `b + A u`: the
    /// base `b` in global components, `u` in those of a frame with rotation `A` and
    /// angular velocity `ω̄` (its own components). With the partial velocities
    /// `J_i = ∂b/∂q̇_i`, `U_i = ∂u/∂q̇_i` and `K_i = Aᵀ J_i`, the mass matrix gains
    /// `m (J_i·J_j + K_i·U_j + U_i·K_j + U_i·U_j)` and the forces
    /// `−m (J_i·a_b + K_i·a_u + U_i·(Aᵀ a_b + a_u))`, with the accelerations at `q̈ = 0`
    /// `a_b = ḃ` and `a_u = u̇ + ω̄ × u` (rates of the components). Each product is taken
    /// in the components its factors are sparse in: a translation `ẋ` of the base has
    /// `J = e_x`, `K` a row of `A`, and no `U`.
    fn kane_translation(
        &mut self,
        m: ExprId,
        b: &[ExprId],
        a: &[ExprId],
        w: &[ExprId],
        u: &[ExprId],
    ) {
        type Cols = std::collections::BTreeMap<u32, Vec<ExprId>>;
        let nq = self.tr.nq();
        let g = &mut *self.tr.g;
        let zero = g.constant(0.0);
        let partials = |g: &mut Graph, v: &[ExprId]| {
            let mut cols = Cols::new();
            for (c, &x) in v.iter().enumerate() {
                diff::for_each_partial(g, x, nq, Var::Qd, &mut |_, j, d| {
                    cols.entry(j).or_insert_with(|| vec![zero; 3])[c] = d;
                });
            }
            cols
        };
        let jb = partials(g, b);
        let ju = partials(g, u);
        let at = crate::model::value::transpose(3, a);
        let kb: Cols = jb
            .iter()
            .map(|(&j, c)| (j, mat_vec(g, 3, &at, c)))
            .collect();
        let ab: Vec<ExprId> = b.iter().map(|&x| time_derivative(g, x)).collect();
        let ud: Vec<ExprId> = u.iter().map(|&x| time_derivative(g, x)).collect();
        let wu = cross(g, w, u);
        let au = add_v(g, &ud, &wu);
        let abl = mat_vec(g, 3, &at, &ab);
        let au_total = add_v(g, &abl, &au);
        let keys: std::collections::BTreeSet<u32> = jb.keys().chain(ju.keys()).copied().collect();
        let dot_opt = |g: &mut Graph, x: Option<&Vec<ExprId>>, y: &[ExprId]| match x {
            Some(x) => dot(g, x, y),
            None => zero,
        };
        let dot2 = |g: &mut Graph, x: Option<&Vec<ExprId>>, y: Option<&Vec<ExprId>>| match (x, y) {
            (Some(x), Some(y)) => dot(g, x, y),
            _ => zero,
        };
        for &i in &keys {
            let f1 = dot_opt(g, jb.get(&i), &ab);
            let f2 = dot_opt(g, kb.get(&i), &au);
            let f3 = dot_opt(g, ju.get(&i), &au_total);
            let f = g.add(vec![f1, f2, f3]);
            let mf = g.mul(vec![m, f]);
            let neg = g.neg(mf);
            self.kane_forces[i as usize].push(neg);
            for &j in keys.range(i..) {
                let t1 = dot2(g, jb.get(&i), jb.get(&j));
                let t2 = dot2(g, kb.get(&i), ju.get(&j));
                let t3 = dot2(g, ju.get(&i), kb.get(&j));
                let t4 = dot2(g, ju.get(&i), ju.get(&j));
                let s = g.add(vec![t1, t2, t3, t4]);
                if g.is_canonical() && g.is_zero(s) {
                    continue;
                }
                let mij = g.mul(vec![m, s]);
                self.kane_mass.entry((i, j)).or_default().push(mij);
            }
        }
    }

    /// Adds one rigid motion's generalized inertia forces by Kane's method. `u` is a
    /// velocity linear in `q̇` (a centre of mass's, or an angular velocity in body axes)
    /// with the inertia `inertia`, and `gyroscopic` the force that does not come from
    /// `u̇` (`ω̄ × Īω̄`). With the partial velocities `J = ∂u/∂q̇` and `a = ∂u/∂q q̇ + ∂u/∂t`
    /// (`u̇` at `q̈ = 0`), it adds `J_iᵀ K J_j` to `M` and `−J_iᵀ (K a + gyroscopic)` to the
    /// forces. For independent coordinates this equals Lagrange's `∂T/∂q − Ṁq̇`; for Euler
    /// parameters the two differ by a multiple of the normalization's gradient, which its
    /// multiplier absorbs.
    fn kane(&mut self, u: &[ExprId], inertia: &Inertia, gyroscopic: Option<&[ExprId]>) {
        let nq = self.tr.nq();
        let k = u.len();
        let g = &mut *self.tr.g;
        let zero = g.constant(0.0);
        let mut cols: std::collections::BTreeMap<u32, Vec<ExprId>> =
            std::collections::BTreeMap::new();
        for (c, &uc) in u.iter().enumerate() {
            diff::for_each_partial(g, uc, nq, Var::Qd, &mut |_, j, d| {
                cols.entry(j).or_insert_with(|| vec![zero; k])[c] = d;
            });
        }
        let apply = |g: &mut Graph, v: &[ExprId]| match inertia {
            Inertia::Scalar(m) => scale_v(g, *m, v),
            Inertia::Matrix(m) => mat_vec(g, k, m, v),
        };
        let bias: Vec<ExprId> = u.iter().map(|&x| time_derivative(g, x)).collect();
        let mut f = apply(g, &bias);
        if let Some(h) = gyroscopic {
            f = add_v(g, &f, h);
        }
        let weighted: Vec<(u32, Vec<ExprId>)> =
            cols.iter().map(|(&j, c)| (j, apply(g, c))).collect();
        for (&i, ci) in &cols {
            let fi = dot(g, ci, &f);
            let neg = g.neg(fi);
            self.kane_forces[i as usize].push(neg);
            for (j, kcj) in &weighted {
                if *j >= i {
                    let mij = dot(g, ci, kcj);
                    self.kane_mass.entry((i, *j)).or_default().push(mij);
                }
            }
        }
    }

    fn point(&mut self, d: &Decl) -> Option<()> {
        let fl = fields(self.cx, &d.expr, POINT_KINDS, "point")?;
        let f = self.frame_of(fl.get("frame")?)?;
        let dim = self.dim_of(f);
        let u = self.at(&fl, "at", dim)?;
        let fv = self.tr.frame_value(f, dim);
        let p = fv.point(self.g(), &u);
        self.tr.points.push(p.clone());
        let Some(frame) = f else {
            self.cx.error_spanned_by(
                &d.name,
                "a named point is fixed in a moving frame; a ground point is a constant vector",
            );
            return None;
        };
        self.out.points.push(PointOut {
            name: d.name.to_string(),
            docs: d.docs.clone(),
            frame: idx(frame),
            position: p,
        });
        Some(())
    }

    /// A unit vector along the constant `axis` and two unit vectors completing it to a
    /// right-handed orthonormal basis.
    fn basis(
        &mut self,
        e: &syn::Expr,
        axis: &[ExprId],
    ) -> Option<(Vec<ExprId>, Vec<ExprId>, Vec<ExprId>)> {
        let defaults = &self.defaults;
        let values = transform::eval(self.tr.g, axis, &|v| match v {
            Var::Param(i) => defaults.get(i as usize).copied().unwrap_or(f64::NAN),
            _ => f64::NAN,
        });
        if values.iter().any(|v| !v.is_finite()) {
            self.cx.error_spanned_by(
                e,
                "an axis is constant: it may use numbers and parameters, not coordinates or time",
            );
            return None;
        }
        let len = values.iter().map(|v| v * v).sum::<f64>().sqrt();
        if len == 0.0 || !len.is_normal() {
            self.cx.error_spanned_by(e, "this axis has zero length");
            return None;
        }
        let sq = dot(self.g(), axis, axis);
        let norm = self.g().call(Func::Sqrt, sq);
        let one = self.g().constant(1.0);
        let inv = self.g().div(one, norm);
        let u = scale_v(self.g(), inv, axis);
        if axis.len() == 2 {
            let nu = self.g().neg(u[1]);
            let p = vec![nu, u[0]];
            return Some((u, p.clone(), p));
        }
        // The coordinate axis least aligned with `axis` (at the parameters' defaults).
        let k = (0..3)
            .min_by(|&i, &j| values[i].abs().total_cmp(&values[j].abs()))
            .expect("three components");
        let (o, z) = (self.g().constant(1.0), self.g().constant(0.0));
        let ek: Vec<ExprId> = (0..3).map(|i| if i == k { o } else { z }).collect();
        let c = cross(self.g(), &u, &ek);
        let csq = dot(self.g(), &c, &c);
        let cn = self.g().call(Func::Sqrt, csq);
        let cinv = self.g().div(o, cn);
        let p1 = scale_v(self.g(), cinv, &c);
        let p2 = cross(self.g(), &u, &p1);
        Some((u, p1, p2))
    }

    fn push_rows(&mut self, d: &Decl, rows: Vec<(&str, ExprId)>, nonholonomic: bool) -> (u32, u32) {
        let list = if nonholonomic {
            &mut self.out.nonholonomic
        } else {
            &mut self.out.holonomic
        };
        let start = idx(list.len());
        for (suffix, expr) in &rows {
            list.push(Row {
                name: if suffix.is_empty() {
                    d.name.to_string()
                } else {
                    format!("{}.{suffix}", d.name)
                },
                docs: d.docs.clone(),
                span: d.name.span(),
                expr: *expr,
                velocity: None,
            });
        }
        (start, idx(rows.len()))
    }

    fn joint(&mut self, d: &Decl) -> Option<()> {
        let fl = fields(self.cx, &d.expr, JOINT_KINDS, "joint")?;
        let kind = fl.kind.clone();
        if kind == "Driver" {
            let v = self.scalar(fl.get("value")?, Context::Kinematics)?;
            let m = self.scalar(fl.get("motion")?, Context::Kinematics)?;
            let r = self.g().sub(v, m);
            let h = self.push_rows(d, vec![("", r)], false);
            self.out.joints.push(JointOut {
                name: d.name.to_string(),
                docs: d.docs.clone(),
                kind: "Driver",
                frames: [None, None],
                holonomic: h,
                nonholonomic: (idx(self.out.nonholonomic.len()), 0),
            });
            return Some(());
        }
        let a_e = fl.get("a")?;
        let a = self.frame_of(a_e)?;
        let b = match fl.get("b") {
            Some(e) => self.frame_of(e)?,
            None => None,
        };
        if a.is_none() && !matches!(kind.as_str(), "Driver") {
            self.cx.error_spanned_by(
                a_e,
                "the first frame of a joint moves: it is not the ground (give the ground as `b`)",
            );
            return None;
        }
        if a == b && fl.get("b").is_some() {
            self.cx.error_spanned_by(
                fl.get("b")?,
                format!(
                    "joint `{}` joins `{}` to itself",
                    d.name,
                    a_e.to_token_stream()
                ),
            );
            return None;
        }
        let dim = self.dim_of(a);
        let fa = self.tr.frame_value(a, dim);
        let fb = self.tr.frame_value(b, dim);
        let at_a = self.at(&fl, "at_a", dim)?;
        let at_b = self.at(&fl, "at_b", dim)?;
        let pa = fa.point(self.g(), &at_a);
        let pb = fb.point(self.g(), &at_b);
        let sep = sub_v(self.g(), &pa, &pb);
        let xyz = ["x", "y", "z"];
        let position_rows = |sep: &[ExprId]| -> Vec<(&'static str, ExprId)> {
            sep.iter().enumerate().map(|(i, &e)| (xyz[i], e)).collect()
        };
        let axis = |s: &mut Self, name: &str| -> Option<(Vec<ExprId>, Vec<ExprId>, Vec<ExprId>)> {
            let e = fl.get(name)?;
            let v = s.vector(e, dim, Context::Kinematics)?;
            s.basis(e, &v)
        };
        let rot = |s: &mut Self, f: &FrameValue, v: &[ExprId]| mat_vec(s.g(), dim, &f.rotation, v);
        let relative_angle = |s: &mut Self| -> Option<ExprId> {
            let (Some(x), Some(y)) = (fa.angle, fb.angle) else {
                unreachable!("planar frames have angles")
            };
            let r = s.g().sub(x, y);
            Some(match fl.get("angle") {
                Some(e) => {
                    let a0 = s.scalar(e, Context::Kinematics)?;
                    s.g().sub(r, a0)
                }
                None => r,
            })
        };
        let planar = dim == 2;
        let mut contact_rate = None;
        let mut h: Vec<(&str, ExprId)> = Vec::new();
        let mut nh: Vec<(&str, ExprId)> = Vec::new();
        let variant: &'static str = match (kind.as_str(), planar) {
            ("Revolute", true) => {
                for n in ["axis_a", "axis_b"] {
                    if let Some(e) = fl.get(n) {
                        self.cx.error_spanned_by(
                            e,
                            "a planar revolute joint turns about z and takes no axis",
                        );
                        return None;
                    }
                }
                h = position_rows(&sep);
                "PlanarRevolute"
            }
            ("Revolute", false)
            | ("Universal", false)
            | ("Cylindrical", false)
            | ("Prismatic", false) => {
                // Only the revolute joint leaves `axis_a` optional (a planar one takes none).
                if fl.get("axis_a").is_none() {
                    self.cx.error_spanned_by(
                        &d.expr,
                        format!(
                            "a spatial `{kind}` joint needs `axis_a`, the axis it turns about in `a`'s frame"
                        ),
                    );
                    return None;
                }
                let (ua, p1a, p2a) = axis(self, "axis_a")?;
                let (ub, p1b, p2b) = match fl.get("axis_b") {
                    Some(_) => axis(self, "axis_b")?,
                    None => (ua.clone(), p1a.clone(), p2a.clone()),
                };
                let wa = rot(self, &fa, &ua);
                let wb = rot(self, &fb, &ub);
                match kind.as_str() {
                    "Universal" => {
                        h = position_rows(&sep);
                        let c = dot(self.g(), &wa, &wb);
                        h.push(("cross", c));
                        "Universal"
                    }
                    _ => {
                        let q1 = rot(self, &fb, &p1b);
                        let q2 = rot(self, &fb, &p2b);
                        let c1 = dot(self.g(), &wa, &q1);
                        let c2 = dot(self.g(), &wa, &q2);
                        if kind == "Revolute" {
                            h = position_rows(&sep);
                        } else {
                            let r1 = rot(self, &fa, &p1a);
                            let r2 = rot(self, &fa, &p2a);
                            let d1 = dot(self.g(), &sep, &r1);
                            let d2 = dot(self.g(), &sep, &r2);
                            h.push(("n1", d1));
                            h.push(("n2", d2));
                        }
                        h.push(("axis1", c1));
                        h.push(("axis2", c2));
                        if kind == "Prismatic" {
                            let r1 = rot(self, &fa, &p1a);
                            let tw = dot(self.g(), &r1, &q2);
                            h.push(("twist", tw));
                            "Prismatic"
                        } else if kind == "Revolute" {
                            "Revolute"
                        } else {
                            "Cylindrical"
                        }
                    }
                }
            }
            ("Spherical", false) => {
                h = position_rows(&sep);
                "Spherical"
            }
            ("Prismatic", true) => {
                let (_, n, _) = axis(self, "axis_a")?;
                if let Some(e) = fl.get("axis_b") {
                    self.cx
                        .error_spanned_by(e, "a planar prismatic joint slides along `axis_a` only");
                    return None;
                }
                let nn = rot(self, &fa, &n);
                let c = dot(self.g(), &sep, &nn);
                h.push(("normal", c));
                if b.is_none() {
                    self.attachments.push(Attachment::Guide {
                        name: d.name.to_string(),
                        point: pb.clone(),
                        normal: nn.clone(),
                    });
                }
                let r = relative_angle(self)?;
                h.push(("angle", r));
                "PlanarPrismatic"
            }
            ("Fixed", true) => {
                h = position_rows(&sep);
                let r = relative_angle(self)?;
                h.push(("angle", r));
                "PlanarFixed"
            }
            ("Fixed", false) => {
                if let Some(e) = fl.get("angle") {
                    self.cx.error_spanned_by(
                        e,
                        "a spatial fixed joint keeps the frames aligned and takes no `angle`",
                    );
                    return None;
                }
                h = position_rows(&sep);
                let cols = |f: &FrameValue, k: usize| {
                    (0..3).map(|i| f.rotation[3 * i + k]).collect::<Vec<_>>()
                };
                for (name, i, j) in [("yz", 1, 2), ("zx", 2, 0), ("xy", 0, 1)] {
                    let x = cols(&fa, i);
                    let y = cols(&fb, j);
                    let c = dot(self.g(), &x, &y);
                    h.push((name, c));
                }
                "Fixed"
            }
            ("Distance", _) => {
                let l = self.scalar(fl.get("length")?, Context::Kinematics)?;
                let s2 = dot(self.g(), &sep, &sep);
                let l2 = self.g().mul(vec![l, l]);
                h.push(("", self.g().sub(s2, l2)));
                "Distance"
            }
            ("ZeroVelocity", _) | ("KnifeEdge", _) => {
                if fl.get("b").is_some() {
                    unreachable!("no field `b`")
                }
                let along = if kind == "KnifeEdge" {
                    let e = fl.get("lateral")?;
                    let v = self.vector(e, dim, Context::Kinematics)?;
                    rot(self, &fa, &v)
                } else {
                    self.vector(fl.get("along")?, dim, Context::Kinematics)?
                };
                let v: Vec<ExprId> = pa.iter().map(|&x| time_derivative(self.g(), x)).collect();
                nh.push(("", dot(self.g(), &v, &along)));
                "ZeroVelocity"
            }
            ("RollingWheel", false) => {
                let ax_e = fl.get("axis")?;
                let axv = self.vector(ax_e, 3, Context::Kinematics)?;
                let (u, _, _) = self.basis(ax_e, &axv)?;
                let up = match fl.get("up") {
                    Some(e) => {
                        let v = self.vector(e, 3, Context::Kinematics)?;
                        self.basis(e, &v)?
                    }
                    None => {
                        let (o, z) = (self.g().constant(1.0), self.g().constant(0.0));
                        (vec![z, z, o], vec![o, z, z], vec![z, o, z])
                    }
                };
                let radius = self.scalar(fl.get("radius")?, Context::Kinematics)?;
                let center = self.at(&fl, "center", 3)?;
                let c = fa.point(self.g(), &center);
                let wheel_frame = a;
                let a = rot(self, &fa, &u);
                // Direction from the centre to the contact point: minus the part of `up`
                // normal to the wheel's axis, normalized.
                let na = dot(self.g(), &up.0, &a);
                let proj = scale_v(self.g(), na, &a);
                let w = sub_v(self.g(), &up.0, &proj);
                // |w|² = 1 − (n·a)² for unit `n` and `a`; `a` is a unit vector for every
                // `q` when the frame's rotation is built from axis rotations.
                let wsq = if fa.exact_rates {
                    let one = self.g().constant(1.0);
                    let na2 = self.g().mul(vec![na, na]);
                    self.g().sub(one, na2)
                } else {
                    dot(self.g(), &w, &w)
                };
                let wn = self.g().call(Func::Sqrt, wsq);
                let mr = self.g().neg(radius);
                let s = self.g().div(mr, wn);
                let down = scale_v(self.g(), s, &w);
                let p = add_v(self.g(), &c, &down);
                h.push(("contact", dot(self.g(), &p, &up.0)));
                if let Some(frame) = wheel_frame {
                    self.attachments.push(Attachment::Wheel {
                        name: d.name.to_string(),
                        frame: idx(frame),
                        center: c.clone(),
                        axis: a.clone(),
                        radius,
                        contact: p.clone(),
                        up: up.0.clone(),
                    });
                }
                let vc = fa.point_velocity(self.g(), &center);
                let Value::Vector(omega) = fa.angular_velocity(self.g()) else {
                    unreachable!("spatial frames have a vector rate")
                };
                let spin = cross(self.g(), &omega, &down);
                let vp = add_v(self.g(), &vc, &spin);
                // The contact height is the lowest of the rim's points, so its rate is
                // that of the material point there (the envelope theorem): `Ċ = v_p·n`.
                if fa.exact_rates {
                    contact_rate = Some(dot(self.g(), &vp, &up.0));
                }
                nh.push(("longitudinal", dot(self.g(), &vp, &up.1)));
                nh.push(("lateral", dot(self.g(), &vp, &up.2)));
                "RollingWheel"
            }
            (k, planar) => {
                self.cx.error_at(
                    fl.span,
                    format!(
                        "`{k}` is a {} joint; this model is {}",
                        if planar { "spatial" } else { "planar" },
                        if planar { "planar" } else { "spatial" }
                    ),
                );
                return None;
            }
        };
        match (variant, a) {
            ("ZeroVelocity", Some(frame)) => self.attachments.push(Attachment::Edge {
                name: d.name.to_string(),
                frame: idx(frame),
                point: pa.clone(),
            }),
            ("RollingWheel", _) => {}
            _ => self.attachments.push(Attachment::Joint {
                name: d.name.to_string(),
                kind: variant,
                frames: [a.map(idx), b.map(idx)],
                points: [pa.clone(), pb.clone()],
            }),
        }
        let hr = self.push_rows(d, h, false);
        if contact_rate.is_some() {
            self.out.holonomic[hr.0 as usize].velocity = contact_rate;
        }
        let nr = self.push_rows(d, nh, true);
        self.out.joints.push(JointOut {
            name: d.name.to_string(),
            docs: d.docs.clone(),
            kind: variant,
            frames: [a.map(idx), b.map(idx)],
            holonomic: hr,
            nonholonomic: nr,
        });
        Some(())
    }

    /// A vector field of a `Drawing` item, in the coordinates of `frame` (global when
    /// `None`), returned in global coordinates; `direction`: rotated only.
    fn draw_vector(
        &mut self,
        e: &syn::Expr,
        frame: Option<usize>,
        dim: &mut Option<usize>,
        direction: bool,
    ) -> Option<Vec<ExprId>> {
        let v = match self.tr.field_value(e, Context::Kinematics)? {
            Value::Vector(v) if matches!(v.len(), 2 | 3) && dim.is_none_or(|d| d == v.len()) => v,
            other => {
                let want = dim.map_or("a 2- or 3-vector".to_owned(), |d| format!("a {d}-vector"));
                self.cx
                    .error_spanned_by(e, format!("expected {want}; this is {}", other.describe()));
                return None;
            }
        };
        *dim = Some(v.len());
        let fv = self.tr.frame_value(frame, v.len());
        Some(if direction {
            mat_vec(self.g(), v.len(), &fv.rotation, &v)
        } else {
            fv.point(self.g(), &v)
        })
    }

    /// `static name: Drawing = Link { points: [..], frame?, color? }` and the other
    /// shapes of [`DRAWING_KINDS`].
    fn drawing(&mut self, d: &Decl) -> Option<()> {
        let fl = fields(self.cx, &d.expr, DRAWING_KINDS, "shape")?;
        if fl.kind == super::drawing::SCENE {
            return self.scene(d, &fl);
        }
        let kind = super::drawing::shape_kind(&fl.kind)?;
        let frame = match fl.get("frame") {
            Some(e) => self.frame_of(e)?,
            None => None,
        };
        let mut dim = frame.map(|k| self.tr.frames[k].dim);
        let mut points = Vec::new();
        match fl.get("points") {
            Some(e) => {
                let syn::Expr::Array(list) = e else {
                    self.cx.error_spanned_by(
                        e,
                        "expected an array of points, e.g. `[[0.0, 0.0], [x, y]]`",
                    );
                    return None;
                };
                if list.elems.is_empty() || (kind == "Spring" && list.elems.len() != 2) {
                    let want = if kind == "Spring" {
                        "two points"
                    } else {
                        "at least one point"
                    };
                    self.cx
                        .error_spanned_by(e, format!("a `{}` takes {want}", fl.kind));
                    return None;
                }
                for p in &list.elems {
                    points.push(self.draw_vector(p, frame, &mut dim, false)?);
                }
            }
            None => {
                let e = fl.get("center").or_else(|| fl.get("at"))?;
                points.push(self.draw_vector(e, frame, &mut dim, false)?);
            }
        }
        let normal = match fl.get("normal").or_else(|| fl.get("axis")) {
            Some(e) => Some(self.draw_vector(e, frame, &mut dim, true)?),
            None => None,
        };
        let radius = match fl.get("radius") {
            Some(e) => Some(self.scalar(e, Context::Kinematics)?),
            None => None,
        };
        let color = match fl.get("color") {
            Some(syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            })) => Some(s.value()),
            Some(e) => {
                self.cx
                    .error_spanned_by(e, "a colour is a string literal, e.g. `\"#c0392b\"`");
                return None;
            }
            None => None,
        };
        self.shapes.push(UserShape {
            name: d.name.to_string(),
            kind,
            frame: frame.map(idx),
            points,
            normal,
            radius,
            color,
        });
        Some(())
    }

    /// A vector field of a `Contact` item (global coordinates), of the dimension of the
    /// item's first vector.
    fn contact_vector(&mut self, e: &syn::Expr, dim: &mut Option<usize>) -> Option<Vec<ExprId>> {
        match self.tr.field_value(e, Context::Kinematics)? {
            Value::Vector(v) if matches!(v.len(), 2 | 3) && dim.is_none_or(|d| d == v.len()) => {
                *dim = Some(v.len());
                Some(v)
            }
            other => {
                let want = dim.map_or("a 2- or 3-vector".to_owned(), |d| format!("a {d}-vector"));
                self.cx
                    .error_spanned_by(e, format!("expected {want}; this is {}", other.describe()));
                None
            }
        }
    }

    /// `static name: Contact = PointPlane { point, normal, restitution, offset?, radius? }`
    /// (the gap `n̂·p − offset − radius`: a point, or a ball of `radius` about it, above
    /// the plane `n̂·x = offset`) or `PointSphere { point, center, radius, restitution }`
    /// (the gap `|p − c| − radius`: a point outside a sphere, a disc in a planar model).
    /// The vectors are global and may be expressions of the coordinates and time (a body
    /// point `rod.point([..])`, another body's centre), not of the velocities; the
    /// restitution is a parameter's name. A plane fixed in the ground is drawn.
    fn contact(&mut self, d: &Decl) -> Option<()> {
        let fl = fields(self.cx, &d.expr, CONTACT_KINDS, "contact")?;
        let re = fl.get("restitution")?;
        let name = match re {
            syn::Expr::Path(p) => p.path.get_ident().map(ToString::to_string),
            _ => None,
        };
        let Some(name) = name else {
            self.cx.error_spanned_by(
                re,
                "the coefficient of restitution is the name of a parameter, e.g. \
                 `restitution: e` with `const e: f64 = 0.5;`",
            );
            return None;
        };
        let Some(restitution) = self.tr.param_index(&name) else {
            let names = self.tr.param_names();
            let hint = suggest(&name, names.iter().map(String::as_str))
                .map(|s| format!("; did you mean `{s}`?"))
                .unwrap_or_default();
            self.cx.error_spanned_by(
                re,
                format!(
                    "`restitution: {name}` names no parameter: the coefficient of restitution \
                     is a parameter (`const {name}: f64 = 0.5;`){hint}"
                ),
            );
            return None;
        };
        let mut dim = None;
        let p = self.contact_vector(fl.get("point")?, &mut dim)?;
        let zero = self.g().constant(0.0);
        let opt_scalar = |b: &mut Self, key: &str| match fl.get(key) {
            Some(e) => b.scalar(e, Context::Kinematics),
            None => Some(zero),
        };
        let gap = if fl.kind == "PointPlane" {
            let ne = fl.get("normal")?;
            let n = self.contact_vector(ne, &mut dim)?;
            let nn = dot(self.g(), &n, &n);
            if self.g().is_zero(nn) {
                self.cx
                    .error_spanned_by(ne, "the normal of a contact plane is the zero vector");
                return None;
            }
            let len = self.g().call(Func::Sqrt, nn);
            let offset = opt_scalar(self, "offset")?;
            let radius = opt_scalar(self, "radius")?;
            let np = dot(self.g(), &n, &p);
            let dist = self.g().div(np, len);
            let off = self.g().add(vec![offset, radius]);
            let gap = self.g().sub(dist, off);
            // A plane fixed in the ground is drawn, like a guide.
            let fixed = [&n[..], &[offset]].concat().iter().all(|&x| {
                let deps = self.tr.g.deps(x);
                !deps.has(Deps::Q) && !deps.has(Deps::TIME) && !deps.has(Deps::QD)
            });
            if fixed {
                let inv = self.g().div(offset, len);
                let unit: Vec<ExprId> = n.iter().map(|&x| self.g().div(x, len)).collect();
                let at = scale_v(self.g(), inv, &unit);
                self.attachments.push(Attachment::Guide {
                    name: d.name.to_string(),
                    point: at,
                    normal: unit,
                });
            }
            gap
        } else {
            let c = self.contact_vector(fl.get("center")?, &mut dim)?;
            let radius = self.scalar(fl.get("radius")?, Context::Kinematics)?;
            let r = sub_v(self.g(), &p, &c);
            let rr = dot(self.g(), &r, &r);
            let dist = self.g().call(Func::Sqrt, rr);
            self.g().sub(dist, radius)
        };
        if self.tr.g.deps(gap).has(Deps::QD) {
            self.cx.error_at(
                fl.span,
                format!(
                    "contact `{}`: a gap depends on the coordinates and time, not on velocities",
                    d.name
                ),
            );
            return None;
        }
        self.out.contacts.push(ContactRow {
            row: Row {
                name: d.name.to_string(),
                docs: d.docs.clone(),
                span: d.name.span(),
                expr: gap,
                velocity: None,
            },
            restitution,
            restitution_span: re.span(),
        });
        Some(())
    }

    /// `static name: Drawing = Scene { up: [..] }`: the direction that is up, a constant
    /// vector (numbers and parameters) of the model's dimension, declared once.
    fn scene(&mut self, d: &Decl, fl: &Fields<'_>) -> Option<()> {
        let e = fl.get("up")?;
        if self.up.is_some() {
            self.cx.error_spanned_by(
                &d.name,
                "the scene is declared twice: one `Scene` item says which way is up",
            );
            return None;
        }
        // Without frames, the drawing's own points say whether the model is drawn in
        // 2-D or 3-D; either vector is accepted.
        let v = if self.tr.frames.is_empty() {
            let mut dim = None;
            self.draw_vector(e, None, &mut dim, true)?
        } else {
            let dim = self.tr.model_dim();
            self.vector(e, dim, Context::Kinematics)?
        };
        let moving = v.iter().any(|&x| {
            let deps = self.tr.g.deps(x);
            deps.has(Deps::Q) || deps.has(Deps::TIME)
        });
        if moving {
            self.cx.error_spanned_by(
                e,
                "the `up` direction of a scene is constant: numbers and parameters, not \
                 coordinates or time",
            );
            return None;
        }
        if v.iter().all(|&x| self.tr.g.is_zero(x)) {
            self.cx
                .error_spanned_by(e, "the `up` direction of a scene is the zero vector");
            return None;
        }
        self.up = Some(v);
        Some(())
    }

    fn add_applied(&mut self, q: Vec<ExprId>) {
        for (i, c) in q.into_iter().enumerate() {
            let s = self.out.applied[i];
            self.out.applied[i] = self.g().add(vec![s, c]);
        }
        self.out.has_applied = true;
    }

    fn force(&mut self, d: &Decl) -> Option<()> {
        let fl = fields(self.cx, &d.expr, FORCE_KINDS, "force element")?;
        let nq = self.tr.nq();
        match fl.kind.as_str() {
            "Gravity" => {
                let e = fl.get("acceleration")?;
                let v = match self.tr.field_value(e, Context::Kinematics)? {
                    Value::Vector(v) => v,
                    other => {
                        self.cx.error_spanned_by(
                            e,
                            format!("gravity is a vector; this is {}", other.describe()),
                        );
                        return None;
                    }
                };
                if self.gravity.is_some() {
                    self.cx
                        .error_spanned_by(&d.name, "gravity is declared twice");
                    return None;
                }
                self.gravity = Some((v, e.span()));
            }
            "SpringDamper" => {
                let a = self.frame_of(fl.get("a")?)?;
                let b = match fl.get("b") {
                    Some(e) => self.frame_of(e)?,
                    None => None,
                };
                let dim = self.dim_of(a);
                let (fa, fb) = (self.tr.frame_value(a, dim), self.tr.frame_value(b, dim));
                let at_a = self.at(&fl, "at_a", dim)?;
                let at_b = self.at(&fl, "at_b", dim)?;
                let pa = fa.point(self.g(), &at_a);
                let pb = fb.point(self.g(), &at_b);
                self.attachments.push(Attachment::Spring {
                    name: d.name.to_string(),
                    frames: [a.map(idx), b.map(idx)],
                    points: [pa.clone(), pb.clone()],
                });
                let sep = sub_v(self.g(), &pa, &pb);
                let l2 = dot(self.g(), &sep, &sep);
                let l = self.g().call(Func::Sqrt, l2);
                let k = self.scalar(fl.get("stiffness")?, Context::Kinematics)?;
                let l0 = self.scalar(fl.get("rest_length")?, Context::Kinematics)?;
                let ext = self.g().sub(l, l0);
                let half = self.g().constant(0.5);
                let v = self.g().mul(vec![half, k, ext, ext]);
                self.potential.push(v);
                if let Some(ce) = fl.get("damping") {
                    let c = self.scalar(ce, Context::Kinematics)?;
                    let ld = time_derivative(self.g(), l);
                    let q = (0..nq)
                        .map(|i| {
                            let dl = diff::differentiate(self.g(), l, Var::Q(idx(i)));
                            let m = self.g().mul(vec![c, ld, dl]);
                            self.g().neg(m)
                        })
                        .collect();
                    self.add_applied(q);
                }
            }
            "PointForce" => {
                let a = self.frame_of(fl.get("a")?)?;
                let dim = self.dim_of(a);
                let fa = self.tr.frame_value(a, dim);
                let at = self.at(&fl, "at_a", dim)?;
                let p = fa.point(self.g(), &at);
                let f = self.vector(fl.get("force")?, dim, Context::Force)?;
                let q = (0..nq)
                    .map(|i| {
                        let dp: Vec<ExprId> = p
                            .iter()
                            .map(|&x| diff::differentiate(self.g(), x, Var::Q(idx(i))))
                            .collect();
                        dot(self.g(), &f, &dp)
                    })
                    .collect();
                self.add_applied(q);
            }
            "Torque" => {
                let a = self.frame_of(fl.get("a")?)?;
                let dim = self.dim_of(a);
                let fa = self.tr.frame_value(a, dim);
                let te = fl.get("torque")?;
                let w = fa.angular_velocity(self.g());
                let q: Vec<ExprId> = match w {
                    Value::Scalar(w) => {
                        let tau = self.scalar(te, Context::Force)?;
                        (0..nq)
                            .map(|i| {
                                let dw = diff::differentiate(self.g(), w, Var::Qd(idx(i)));
                                self.g().mul(vec![tau, dw])
                            })
                            .collect()
                    }
                    Value::Vector(w) => {
                        let tau = self.vector(te, 3, Context::Force)?;
                        (0..nq)
                            .map(|i| {
                                let dw: Vec<ExprId> = w
                                    .iter()
                                    .map(|&x| diff::differentiate(self.g(), x, Var::Qd(idx(i))))
                                    .collect();
                                dot(self.g(), &tau, &dw)
                            })
                            .collect()
                    }
                    _ => unreachable!("angular velocities are scalars or vectors"),
                };
                self.add_applied(q);
            }
            _ => unreachable!("force kinds are listed"),
        }
        Some(())
    }
}
