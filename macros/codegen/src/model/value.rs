//! Vectors, matrices and frames in expressions.
//!
//! A [`Value`] is what an expression of the description language evaluates to: a
//! scalar, a 2- or 3-vector, a square rotation (or inertia) matrix, or a frame. Vectors
//! and matrices exist only during translation: each component is a scalar node of the
//! graph, so everything downstream (differentiation, scheduling, emission) sees scalars.
//!
//! The operations are those of rigid-body kinematics: `+ - *` and `/` by a scalar,
//! matrix–vector and matrix–matrix products, `a.dot(b)`, `a.cross(b)`, `a.norm()`,
//! `a.normalize()`, `a.x()`/`a[0]`, `m.transpose()`, `a.velocity()` (the time
//! derivative along the motion), rotations `rot2(θ)`, `rot_x(θ)`, `rot_y(θ)`, `rot_z(θ)`,
//! `euler_parameters(e0, e1, e2, e3)`, `diag(a, b, c)`, and on a frame `f`:
//! `f.origin()`, `f.rotation()`, `f.point([..])`, `f.axis([..])`, `f.velocity([..])`,
//! `f.angular_velocity()`, for planar frames `f.angle()`, and for deformable bodies
//! `f.material(ξ)` (the deformed position of material point `ξ` in the body's frame).

use quote::ToTokens;

use super::expr::Translator;
use crate::sym::{diff, ExprId, Graph, Var};

/// The value of an expression.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Scalar(ExprId),
    /// A column vector of 2 or 3 components.
    Vector(Vec<ExprId>),
    /// A square matrix (2×2 or 3×3), row-major.
    Matrix(usize, Vec<ExprId>),
    /// A frame, by index into the translated frames (`None`: the ground).
    Frame(Option<usize>),
}

impl Value {
    /// What the value is, for messages.
    pub fn describe(&self) -> String {
        match self {
            Value::Scalar(_) => "a scalar".into(),
            Value::Vector(v) => format!("a {}-vector", v.len()),
            Value::Matrix(n, _) => format!("a {n}×{n} matrix"),
            Value::Frame(_) => "a frame".into(),
        }
    }
}

/// A translated frame: origin and rotation to the global frame.
#[derive(Clone, Debug)]
pub struct FrameValue {
    /// 2 (planar) or 3 (spatial).
    pub dim: usize,
    pub origin: Vec<ExprId>,
    /// Row-major `dim × dim`.
    pub rotation: Vec<ExprId>,
    /// Planar frames: the absolute angle.
    pub angle: Option<ExprId>,
    /// Frames oriented by Euler parameters: the four parameters.
    pub euler: Option<[ExprId; 4]>,
    /// Spatial frames: the angular velocity in the frame's own components, built down
    /// the frame tree (`ω̄ = Fᵀ ω̄_before + ω̄_F` for each factor `F` of a relative
    /// rotation) rather than from the derivative of the composed rotation matrix.
    pub omega: Option<Vec<ExprId>>,
    /// Spatial frames: the origin's velocity in two pieces, `v_o = b + A r`. The base
    /// `b` (global components) is the velocity of the origin of the topmost frame below
    /// the ground, the rate of its origin expression (`[ẋ, ẏ, ż]` for a body given
    /// by absolute coordinates); `r` is the rest, in the frame's own components, built
    /// down the frame tree: `r = Fᵀ (r_p + ω̄_p × o + ȯ)` with `o` the origin in the
    /// parent's components and `F` the relative rotation. Kane's method dots the pieces
    /// each in its own components (`derive/bodies.rs`).
    pub velocity: Option<FrameVelocity>,
    /// Whether [`Self::omega`] and [`Self::velocity`] are the rates of the rotation and
    /// the origin for every `q`: every factor of the rotations down the tree is a
    /// coordinate-axis rotation or constant. With Euler parameters they are so only on
    /// the normalization's manifold, which is enough for the mass matrix and forces
    /// but not for a Jacobian read from a velocity.
    pub exact_rates: bool,
}

/// The two pieces of a spatial frame's origin velocity (see [`FrameValue::velocity`]).
#[derive(Clone, Debug)]
pub struct FrameVelocity {
    /// `b`, global components.
    pub base: Vec<ExprId>,
    /// `r`, in the frame's components.
    pub relative: Vec<ExprId>,
    /// The frame seen from its parent; `None` below the ground.
    pub in_parent: Option<InParent>,
}

/// A spatial frame's motion in its parent's components (see [`FrameVelocity`]).
#[derive(Clone, Debug)]
pub struct InParent {
    /// `r` before the relative rotation: `r_p + ω̄_p × o + ȯ`.
    pub velocity: Vec<ExprId>,
    /// The parent's global rotation.
    pub rotation: Vec<ExprId>,
    /// The parent's angular velocity (its components).
    pub omega: Vec<ExprId>,
    /// The relative rotation `F` (parent ← frame).
    pub relative: Vec<ExprId>,
    /// This frame's angular velocity in the parent's components, `F ω̄`.
    pub frame_omega: Vec<ExprId>,
}

/// A closure of the description, `|xi| body`: a function of one material coordinate.
#[derive(Clone, Debug)]
pub struct Closure {
    /// The argument's name.
    pub var: String,
    pub body: syn::Expr,
}

/// The material description of a deformable body: the undeformed position `ū_o(ξ)` and
/// the displacement `N(ξ) q_f` of the material point `ξ`, in the body's frame.
#[derive(Clone, Debug)]
pub struct Material {
    pub dim: usize,
    pub position: Option<Closure>,
    pub displacement: Option<Closure>,
    /// A body built from beam elements (`data: beam_slot`): its nodes.
    pub nodes: Option<Nodes>,
}

/// The nodes of a beam-element body: node `k` is at `x_k = k l / elements` on the
/// frame's x axis and moves by the translational rows of the basis `T` times `q_f`.
#[derive(Clone, Debug)]
pub struct Nodes {
    pub elements: usize,
    pub dofs_per_node: usize,
    /// The beam's length (a data leaf).
    pub length: ExprId,
    /// `T` (ndof × n), data leaves.
    pub basis: Vec<ExprId>,
    /// The elastic coordinates.
    pub qf: Vec<u32>,
}

impl Nodes {
    /// Node `k`'s deformed position in the body's frame (`dim` components).
    pub fn at(&self, g: &mut Graph, dim: usize, k: usize) -> Vec<ExprId> {
        let n = self.qf.len();
        let frac = g.constant(k as f64 / self.elements as f64);
        let x = g.mul(vec![frac, self.length]);
        let z = g.constant(0.0);
        let q: Vec<ExprId> = self.qf.iter().map(|&i| g.var(Var::Q(i))).collect();
        (0..dim)
            .map(|c| {
                let row = &self.basis[(k * self.dofs_per_node + c) * n..][..n];
                let u = dot(g, row, &q);
                let x0 = if c == 0 { x } else { z };
                g.add(vec![x0, u])
            })
            .collect()
    }
}

impl Nodes {
    /// Node `k`'s small elastic rotation of its section in the body's frame: planar the
    /// angle `θ_k` (the slope `v'`), spatial `(θx, θy, θz)`; the nodal rotation
    /// coordinates of `T_k q_f`.
    pub fn rotation(&self, g: &mut Graph, dim: usize, k: usize) -> Vec<ExprId> {
        let n = self.qf.len();
        let q: Vec<ExprId> = self.qf.iter().map(|&i| g.var(Var::Q(i))).collect();
        let first = if dim == 2 { 2 } else { 3 };
        (first..self.dofs_per_node)
            .map(|c| {
                let row = &self.basis[(k * self.dofs_per_node + c) * n..][..n];
                dot(g, row, &q)
            })
            .collect()
    }
}

impl Material {
    /// `ū_o(ξ) + N(ξ) q_f` at `xi`, in the body's frame (the current translation context).
    pub fn at(
        &self,
        tr: &mut Translator<'_>,
        at: &dyn ToTokens,
        xi: ExprId,
    ) -> Option<Vec<ExprId>> {
        let Some(p) = &self.position else {
            tr.cx.error_spanned_by(
                at,
                if self.nodes.is_some() {
                    "a body built from beam elements has no material closure: take its nodes, `body.node(k)`"
                } else {
                    "this deformable body declares no `position: |xi| [..]`, so its material points are unknown"
                },
            );
            return None;
        };
        let dim = self.dim;
        let u = tr.with_binding(&p.var, Value::Scalar(xi), |t| t.vector(&p.body, Some(dim)))?;
        let Some(d) = &self.displacement else {
            return Some(u);
        };
        let w = tr.with_binding(&d.var, Value::Scalar(xi), |t| t.vector(&d.body, Some(dim)))?;
        Some(add_v(tr.g, &u, &w))
    }
}

// ---- component algebra on the graph ----

pub fn add_v(g: &mut Graph, a: &[ExprId], b: &[ExprId]) -> Vec<ExprId> {
    a.iter().zip(b).map(|(&x, &y)| g.add(vec![x, y])).collect()
}

pub fn sub_v(g: &mut Graph, a: &[ExprId], b: &[ExprId]) -> Vec<ExprId> {
    a.iter().zip(b).map(|(&x, &y)| g.sub(x, y)).collect()
}

pub fn scale_v(g: &mut Graph, s: ExprId, a: &[ExprId]) -> Vec<ExprId> {
    a.iter().map(|&x| g.mul(vec![s, x])).collect()
}

pub fn dot(g: &mut Graph, a: &[ExprId], b: &[ExprId]) -> ExprId {
    let terms = a.iter().zip(b).map(|(&x, &y)| g.mul(vec![x, y])).collect();
    g.add(terms)
}

pub fn cross(g: &mut Graph, a: &[ExprId], b: &[ExprId]) -> Vec<ExprId> {
    let c = |g: &mut Graph, i: usize, j: usize| {
        let p = g.mul(vec![a[i], b[j]]);
        let q = g.mul(vec![a[j], b[i]]);
        g.sub(p, q)
    };
    vec![c(g, 1, 2), c(g, 2, 0), c(g, 0, 1)]
}

/// The planar cross product `a_x b_y − a_y b_x`.
pub fn cross2(g: &mut Graph, a: &[ExprId], b: &[ExprId]) -> ExprId {
    let p = g.mul(vec![a[0], b[1]]);
    let q = g.mul(vec![a[1], b[0]]);
    g.sub(p, q)
}

pub fn mat_vec(g: &mut Graph, n: usize, m: &[ExprId], v: &[ExprId]) -> Vec<ExprId> {
    (0..n).map(|i| dot(g, &m[i * n..(i + 1) * n], v)).collect()
}

pub fn mat_mat(g: &mut Graph, n: usize, a: &[ExprId], b: &[ExprId]) -> Vec<ExprId> {
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let terms = (0..n)
                .map(|k| g.mul(vec![a[i * n + k], b[k * n + j]]))
                .collect();
            out.push(g.add(terms));
        }
    }
    out
}

pub fn transpose(n: usize, m: &[ExprId]) -> Vec<ExprId> {
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            out.push(m[j * n + i]);
        }
    }
    out
}

/// `d/dt e` along the motion at `q̈ = 0`: `Σ ∂e/∂q_i q̇_i + ∂e/∂t` ([`diff::rate`]).
pub fn time_derivative(g: &mut Graph, e: ExprId) -> ExprId {
    diff::rate(g, e)
}

pub fn rot2(g: &mut Graph, a: ExprId) -> Vec<ExprId> {
    let c = g.call(crate::sym::Func::Cos, a);
    let s = g.call(crate::sym::Func::Sin, a);
    let ms = g.neg(s);
    vec![c, ms, s, c]
}

/// Rotation by `a` about coordinate axis `axis` (0: x, 1: y, 2: z).
pub fn rot_axis(g: &mut Graph, axis: usize, a: ExprId) -> Vec<ExprId> {
    let c = g.call(crate::sym::Func::Cos, a);
    let s = g.call(crate::sym::Func::Sin, a);
    let ms = g.neg(s);
    let (o, z) = (g.constant(1.0), g.constant(0.0));
    match axis {
        0 => vec![o, z, z, z, c, ms, z, s, c],
        1 => vec![c, z, s, z, o, z, ms, z, c],
        _ => vec![c, ms, z, s, c, z, z, z, o],
    }
}

/// The rotation matrix of Euler parameters (docs/theory.md E4):
/// `A = (2θ0² − 1) I + 2 (ϑϑᵀ + θ0 ϑ̃)`.
pub fn euler_rotation(g: &mut Graph, e: [ExprId; 4]) -> Vec<ExprId> {
    let two = g.constant(2.0);
    let e0sq = g.mul(vec![e[0], e[0]]);
    let d = {
        let t = g.mul(vec![two, e0sq]);
        let one = g.constant(1.0);
        g.sub(t, one)
    };
    let v = [e[1], e[2], e[3]];
    let mut out = Vec::with_capacity(9);
    for i in 0..3 {
        for j in 0..3 {
            let mut terms = vec![g.mul(vec![two, v[i], v[j]])];
            if i == j {
                terms.push(d);
            }
            // ϑ̃: [[0, −v3, v2], [v3, 0, −v1], [−v2, v1, 0]]
            let skew = match (i, j) {
                (0, 1) => Some((-1.0, 2)),
                (0, 2) => Some((1.0, 1)),
                (1, 0) => Some((1.0, 2)),
                (1, 2) => Some((-1.0, 0)),
                (2, 0) => Some((-1.0, 1)),
                (2, 1) => Some((1.0, 0)),
                _ => None,
            };
            if let Some((sign, k)) = skew {
                let c = g.constant(2.0 * sign);
                terms.push(g.mul(vec![c, e[0], v[k]]));
            }
            out.push(g.add(terms));
        }
    }
    out
}

/// `Ē` of docs/theory.md E3 (3×4, row-major), so that `ω̄ = 2 Ē θ̇`.
pub fn euler_e_bar(e: [ExprId; 4], g: &mut Graph) -> Vec<ExprId> {
    let n = |g: &mut Graph, x: ExprId| g.neg(x);
    let (t0, t1, t2, t3) = (e[0], e[1], e[2], e[3]);
    let (m1, m2, m3) = (n(g, t1), n(g, t2), n(g, t3));
    vec![m1, t0, t3, m2, m2, m3, t0, t1, m3, t2, m1, t0]
}

/// `E` of docs/theory.md E3 (3×4, row-major), so that `ω = 2 E θ̇`.
pub fn euler_e(e: [ExprId; 4], g: &mut Graph) -> Vec<ExprId> {
    let n = |g: &mut Graph, x: ExprId| g.neg(x);
    let (t0, t1, t2, t3) = (e[0], e[1], e[2], e[3]);
    let (m1, m2, m3) = (n(g, t1), n(g, t2), n(g, t3));
    vec![m1, t0, m3, t2, m2, t3, t0, m1, m3, m2, t1, t0]
}

impl FrameValue {
    /// The global position of the point with frame coordinates `u`.
    pub fn point(&self, g: &mut Graph, u: &[ExprId]) -> Vec<ExprId> {
        let au = mat_vec(g, self.dim, &self.rotation, u);
        add_v(g, &self.origin, &au)
    }

    /// The global velocity of the point with frame coordinates `u`: from the frame
    /// tree's pieces (`b + A_p r_p` at the origin when the frame has a parent, else
    /// `b + A (r + ω̄ × u)`) for spatial frames, else the rate of its position.
    pub fn point_velocity(&self, g: &mut Graph, u: &[ExprId]) -> Vec<ExprId> {
        if let (Some(vel), Some(w), true) = (&self.velocity, &self.omega, self.exact_rates) {
            let at_origin = u.iter().all(|&x| g.is_zero(x));
            let (a, r) = match (&vel.in_parent, at_origin) {
                (Some(p), true) => (p.rotation.clone(), p.velocity.clone()),
                _ => {
                    let wu = cross(g, w, u);
                    (self.rotation.clone(), add_v(g, &vel.relative, &wu))
                }
            };
            let ar = mat_vec(g, 3, &a, &r);
            return add_v(g, &vel.base, &ar);
        }
        let p = self.point(g, u);
        p.iter().map(|&x| time_derivative(g, x)).collect()
    }

    /// The global angular velocity: a scalar rate for planar frames, a 3-vector for
    /// spatial ones (`2 E θ̇` for Euler parameters, else the axial vector of `Ȧ Aᵀ`).
    pub fn angular_velocity(&self, g: &mut Graph) -> Value {
        if let Some(a) = self.angle {
            return Value::Scalar(time_derivative(g, a));
        }
        if let Some(e) = self.euler {
            let ed: Vec<ExprId> = e.iter().map(|&x| time_derivative(g, x)).collect();
            let em = euler_e(e, g);
            let w = (0..3)
                .map(|i| {
                    let d = dot(g, &em[i * 4..i * 4 + 4], &ed);
                    let two = g.constant(2.0);
                    g.mul(vec![two, d])
                })
                .collect();
            return Value::Vector(w);
        }
        let parent = self.velocity.as_ref().and_then(|v| v.in_parent.as_ref());
        if let (Some(p), true) = (parent, self.exact_rates) {
            // In the parent's components the joint's own angle does not enter:
            // `ω = A_p (F ω̄)`, and its rate `A_p ((F ω̄)˙ + ω̄_p × F ω̄)`.
            let out = mat_vec(g, 3, &p.rotation, &p.frame_omega);
            let wd: Vec<ExprId> = p
                .frame_omega
                .iter()
                .map(|&x| time_derivative(g, x))
                .collect();
            let turn = cross(g, &p.omega, &p.frame_omega);
            let local = add_v(g, &wd, &turn);
            let r = mat_vec(g, 3, &p.rotation, &local);
            for (&e, &x) in out.iter().zip(&r) {
                diff::declare_rate(g, e, x);
            }
            return Value::Vector(out);
        }
        if let Some(w) = &self.omega {
            let out = mat_vec(g, 3, &self.rotation, w);
            if self.exact_rates {
                // `d/dt (A ω̄) = A ω̄̇ + A ω̃ ω̄ = A ω̄̇`.
                let wd: Vec<ExprId> = w.iter().map(|&x| time_derivative(g, x)).collect();
                let r = mat_vec(g, 3, &self.rotation, &wd);
                for (&e, &x) in out.iter().zip(&r) {
                    diff::declare_rate(g, e, x);
                }
            }
            return Value::Vector(out);
        }
        let ad: Vec<ExprId> = self
            .rotation
            .iter()
            .map(|&x| time_derivative(g, x))
            .collect();
        let at = transpose(3, &self.rotation);
        let w = mat_mat(g, 3, &ad, &at);
        Value::Vector(vec![w[7], w[2], w[3]])
    }

    /// The angular velocity in frame components (spatial frames): `2 Ē θ̇` for Euler
    /// parameters, else the axial vector of `Aᵀ Ȧ`.
    pub fn body_angular_velocity(&self, g: &mut Graph) -> Vec<ExprId> {
        if let Some(w) = &self.omega {
            return w.clone();
        }
        if let Some(e) = self.euler {
            let ed: Vec<ExprId> = e.iter().map(|&x| time_derivative(g, x)).collect();
            let em = euler_e_bar(e, g);
            return (0..3)
                .map(|i| {
                    let d = dot(g, &em[i * 4..i * 4 + 4], &ed);
                    let two = g.constant(2.0);
                    g.mul(vec![two, d])
                })
                .collect();
        }
        let ad: Vec<ExprId> = self
            .rotation
            .iter()
            .map(|&x| time_derivative(g, x))
            .collect();
        let at = transpose(3, &self.rotation);
        let w = mat_mat(g, 3, &at, &ad);
        vec![w[7], w[2], w[3]]
    }
}

const VECTOR_METHODS: &[&str] = &[
    "dot",
    "cross",
    "norm",
    "normalize",
    "x",
    "y",
    "z",
    "transpose",
    "velocity",
];
const FRAME_METHODS: &[&str] = &[
    "origin",
    "rotation",
    "point",
    "axis",
    "velocity",
    "angular_velocity",
    "angle",
    "material",
    "node",
    "node_rotation",
];
const MATRIX_FUNCTIONS: &[&str] = &[
    "rot2",
    "rot_x",
    "rot_y",
    "rot_z",
    "euler_parameters",
    "diag",
];

impl Translator<'_> {
    /// Translates `e` to a value of any kind. A constant that folds to a non-finite
    /// value is an error at the smallest expression that makes it.
    pub fn value(&mut self, e: &syn::Expr) -> Option<Value> {
        let v = self.value_inner(e)?;
        if let Value::Scalar(id) = v {
            if let Some(c) = self.g.as_const(id) {
                if !c.is_finite() {
                    self.cx.error_spanned_by(
                        e,
                        format!("this expression is constant and evaluates to {c}"),
                    );
                    return None;
                }
            }
        }
        Some(v)
    }

    fn value_inner(&mut self, e: &syn::Expr) -> Option<Value> {
        match e {
            syn::Expr::Paren(p) => self.value(&p.expr),
            syn::Expr::Group(p) => self.value(&p.expr),
            syn::Expr::Array(a) => self.array(a),
            syn::Expr::Path(p) => match p.path.get_ident() {
                Some(ident) => self.named_value(ident),
                None => self.path(p).map(Value::Scalar),
            },
            syn::Expr::Unary(syn::ExprUnary {
                op: syn::UnOp::Neg(_),
                expr,
                ..
            }) => {
                let v = self.value(expr)?;
                let m1 = self.g.constant(-1.0);
                self.scale(e, m1, v)
            }
            syn::Expr::Binary(b) => self.binary(b),
            syn::Expr::Lit(_) => self.scalar_leaf(e).map(Value::Scalar),
            syn::Expr::Index(i) => {
                if let Some(x) = self.data_entry(i) {
                    return x.map(Value::Scalar);
                }
                let v = self.value(&i.expr)?;
                let Value::Vector(c) = v else {
                    self.cx.error_spanned_by(
                        &i.expr,
                        format!("indexing applies to vectors; this is {}", v.describe()),
                    );
                    return None;
                };
                let k = self.component_index(&i.index, c.len())?;
                Some(Value::Scalar(c[k]))
            }
            syn::Expr::MethodCall(m) => self.method_value(m),
            syn::Expr::Call(c) => self.call_value(c),
            _ => self.scalar_leaf(e).map(Value::Scalar),
        }
    }

    /// Translates `e`, which must be a vector of `dim` components (any length when
    /// `dim` is `None`).
    pub fn vector(&mut self, e: &syn::Expr, dim: Option<usize>) -> Option<Vec<ExprId>> {
        match self.value(e)? {
            Value::Vector(v) if dim.is_none_or(|d| d == v.len()) => Some(v),
            other => {
                let want = dim.map_or_else(|| "a vector".to_owned(), |d| format!("a {d}-vector"));
                self.cx.error_spanned_by(
                    e,
                    format!(
                        "expected {want}, as in `[x, y{}]`; this is {}",
                        if dim == Some(3) { ", z" } else { "" },
                        other.describe()
                    ),
                );
                None
            }
        }
    }

    /// Translates `e`, which must be a frame (a frame or body name, or `ground`).
    pub fn frame_ref(&mut self, e: &syn::Expr) -> Option<Option<usize>> {
        match self.value(e)? {
            Value::Frame(f) => Some(f),
            other => {
                self.cx.error_spanned_by(
                    e,
                    format!(
                        "expected a frame or body name; this is {}",
                        other.describe()
                    ),
                );
                None
            }
        }
    }

    fn component_index(&mut self, e: &syn::Expr, len: usize) -> Option<usize> {
        if let syn::Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(i),
            ..
        }) = e
        {
            if let Ok(k) = i.base10_parse::<usize>() {
                if k < len {
                    return Some(k);
                }
            }
        }
        self.cx.error_spanned_by(
            e,
            format!("the index of a {len}-vector is an integer literal below {len}"),
        );
        None
    }

    fn named_value(&mut self, ident: &syn::Ident) -> Option<Value> {
        let s = ident.to_string();
        if let Some(v) = self.local(&s) {
            return Some(v);
        }
        if s == crate::parse::kw::GROUND {
            return Some(Value::Frame(None));
        }
        if let Some(k) = self.frame_names.iter().position(|n| *n == s) {
            if self.frames.len() <= k {
                self.cx.error_spanned_by(
                    ident,
                    format!("frame `{s}` is declared below; a declaration may use only the frames above it"),
                );
                return None;
            }
            return Some(Value::Frame(Some(k)));
        }
        if let Some(k) = self.point_names.iter().position(|n| *n == s) {
            let Some(p) = self.points.get(k) else {
                self.cx.error_spanned_by(
                    ident,
                    format!("point `{s}` is declared below; a declaration may use only the points above it"),
                );
                return None;
            };
            return Some(Value::Vector(p.clone()));
        }
        self.expr_ident(ident).map(Value::Scalar)
    }

    fn array(&mut self, a: &syn::ExprArray) -> Option<Value> {
        let n = a.elems.len();
        if !(n == 2 || n == 3) {
            self.cx
                .error_spanned_by(a, "vectors have 2 or 3 components, matrices 2 or 3 rows");
            return None;
        }
        let mut values = Vec::new();
        let mut ok = true;
        for e in &a.elems {
            match self.value(e) {
                Some(v) => values.push(v),
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        if values.iter().all(|v| matches!(v, Value::Scalar(_))) {
            return Some(Value::Vector(
                values
                    .into_iter()
                    .map(|v| match v {
                        Value::Scalar(x) => x,
                        _ => unreachable!("checked scalar"),
                    })
                    .collect(),
            ));
        }
        let mut m = Vec::new();
        for (v, e) in values.into_iter().zip(&a.elems) {
            match v {
                Value::Vector(r) if r.len() == n => m.extend(r),
                other => {
                    self.cx.error_spanned_by(
                        e,
                        format!(
                            "a row of a {n}×{n} matrix is a {n}-vector; this is {}",
                            other.describe()
                        ),
                    );
                    return None;
                }
            }
        }
        Some(Value::Matrix(n, m))
    }

    fn scale(&mut self, at: &dyn ToTokens, s: ExprId, v: Value) -> Option<Value> {
        Some(match v {
            Value::Scalar(x) => Value::Scalar(self.g.mul(vec![s, x])),
            Value::Vector(c) => Value::Vector(scale_v(self.g, s, &c)),
            Value::Matrix(n, c) => Value::Matrix(n, scale_v(self.g, s, &c)),
            Value::Frame(_) => {
                self.cx.error_spanned_by(
                    at,
                    "a frame is not a number; use `f.origin()` or `f.rotation()`",
                );
                return None;
            }
        })
    }

    fn binary(&mut self, b: &syn::ExprBinary) -> Option<Value> {
        if let Some(sum) = self.sum_chain(b) {
            return sum;
        }
        let lhs = self.value(&b.left);
        let rhs = self.value(&b.right);
        let (lhs, rhs) = (lhs?, rhs?);
        self.combine(b, lhs, rhs)
    }

    /// A chain `a ± b ± c …` of three or more operands (parsed left-nested) whose
    /// operands are all scalars, as one canonical sum. Added pairwise, every operand
    /// rebuilds the partial sum, which is quadratic in the number of terms (a sum of
    /// 6,000 terms took 5 s). `None` when `b` is not such a chain; a chain with vector
    /// operands is combined pairwise as usual (its operands translated once).
    fn sum_chain(&mut self, b: &syn::ExprBinary) -> Option<Option<Value>> {
        let is_sum = |op: &syn::BinOp| matches!(op, syn::BinOp::Add(_) | syn::BinOp::Sub(_));
        if !is_sum(&b.op) {
            return None;
        }
        // The chain's nodes, innermost first.
        let mut nodes = vec![b];
        while let syn::Expr::Binary(inner) = &*nodes[nodes.len() - 1].left {
            if !is_sum(&inner.op) {
                break;
            }
            nodes.push(inner);
        }
        if nodes.len() < 2 {
            return None;
        }
        nodes.reverse();
        let first = self.value(&nodes[0].left);
        let rest: Vec<Option<Value>> = nodes.iter().map(|n| self.value(&n.right)).collect();
        let (Some(first), Some(rest)) = (first, rest.into_iter().collect::<Option<Vec<_>>>())
        else {
            return Some(None);
        };
        let scalars: Option<Vec<ExprId>> = std::iter::once(&first)
            .chain(&rest)
            .map(|v| match v {
                Value::Scalar(x) => Some(*x),
                _ => None,
            })
            .collect();
        if let Some(scalars) = scalars {
            let mut terms = Vec::with_capacity(scalars.len());
            terms.push(scalars[0]);
            for (n, &x) in nodes.iter().zip(&scalars[1..]) {
                terms.push(match n.op {
                    syn::BinOp::Sub(_) => self.g.neg(x),
                    _ => x,
                });
            }
            return Some(Some(Value::Scalar(self.g.add(terms))));
        }
        let mut acc = first;
        for (n, v) in nodes.into_iter().zip(rest) {
            match self.combine(n, acc, v) {
                Some(next) => acc = next,
                None => return Some(None),
            }
        }
        Some(Some(acc))
    }

    /// `lhs op rhs` for translated operands of any kind.
    fn combine(&mut self, b: &syn::ExprBinary, lhs: Value, rhs: Value) -> Option<Value> {
        if let (Value::Scalar(x), Value::Scalar(y)) = (&lhs, &rhs) {
            return self.scalar_binary(b, *x, *y).map(Value::Scalar);
        }
        let mismatch = |t: &mut Self, lhs: &Value, rhs: &Value| {
            t.cx.error_spanned_by(
                b,
                format!(
                    "`{}` does not apply to {} and {}",
                    b.op.to_token_stream(),
                    lhs.describe(),
                    rhs.describe()
                ),
            );
            None
        };
        match (b.op, &lhs, &rhs) {
            (syn::BinOp::Add(_), Value::Vector(x), Value::Vector(y)) if x.len() == y.len() => {
                Some(Value::Vector(add_v(self.g, x, y)))
            }
            (syn::BinOp::Sub(_), Value::Vector(x), Value::Vector(y)) if x.len() == y.len() => {
                Some(Value::Vector(sub_v(self.g, x, y)))
            }
            (syn::BinOp::Add(_), Value::Matrix(n, x), Value::Matrix(k, y)) if n == k => {
                Some(Value::Matrix(*n, add_v(self.g, x, y)))
            }
            (syn::BinOp::Sub(_), Value::Matrix(n, x), Value::Matrix(k, y)) if n == k => {
                Some(Value::Matrix(*n, sub_v(self.g, x, y)))
            }
            (syn::BinOp::Mul(_), Value::Scalar(s), v)
            | (syn::BinOp::Mul(_), v, Value::Scalar(s)) => {
                let (s, v) = (*s, v.clone());
                self.scale(b, s, v)
            }
            (syn::BinOp::Div(_), v, Value::Scalar(s)) => {
                if self.g.is_zero(*s) {
                    self.cx.error_spanned_by(&b.right, "division by zero");
                    return None;
                }
                let one = self.g.constant(1.0);
                let inv = self.g.div(one, *s);
                let v = v.clone();
                self.scale(b, inv, v)
            }
            (syn::BinOp::Mul(_), Value::Matrix(n, m), Value::Vector(v)) if *n == v.len() => {
                Some(Value::Vector(mat_vec(self.g, *n, m, v)))
            }
            (syn::BinOp::Mul(_), Value::Matrix(n, x), Value::Matrix(k, y)) if n == k => {
                Some(Value::Matrix(*n, mat_mat(self.g, *n, x, y)))
            }
            _ => mismatch(self, &lhs, &rhs),
        }
    }

    fn method_value(&mut self, m: &syn::ExprMethodCall) -> Option<Value> {
        let name = m.method.to_string();
        // `x.dot()` without arguments is the velocity of a coordinate.
        if name == crate::parse::kw::DOT && m.args.is_empty() {
            return self.method(m).map(Value::Scalar);
        }
        let is_vector_method = VECTOR_METHODS.contains(&name.as_str());
        let is_frame_method = FRAME_METHODS.contains(&name.as_str());
        if !is_vector_method && !is_frame_method {
            return self.method(m).map(Value::Scalar);
        }
        let recv = self.value(&m.receiver)?;
        if let Value::Frame(f) = recv {
            if !is_frame_method {
                self.cx.error_spanned_by(
                    &m.method,
                    format!(
                        "`{name}` does not apply to a frame; a frame has {}",
                        FRAME_METHODS
                            .iter()
                            .map(|s| format!("`{s}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                );
                return None;
            }
            return self.frame_method(m, f, &name);
        }
        if !is_vector_method {
            self.cx.error_spanned_by(
                &m.method,
                format!("`{name}` applies to frames; this is {}", recv.describe()),
            );
            return None;
        }
        let want = usize::from(matches!(name.as_str(), "dot" | "cross"));
        if m.args.len() != want {
            self.cx.error_spanned_by(
                m,
                format!(
                    "`{name}` takes {want} argument{}",
                    if want == 1 { "" } else { "s" }
                ),
            );
            return None;
        }
        if name == "velocity" {
            if !self.allows_velocity() {
                self.cx.error_spanned_by(
                    m,
                    format!(
                        "`.velocity()` in {}: velocities are not allowed here",
                        self.context_name()
                    ),
                );
                return None;
            }
            return Some(match recv {
                Value::Scalar(x) => Value::Scalar(time_derivative(self.g, x)),
                Value::Vector(c) => {
                    Value::Vector(c.iter().map(|&x| time_derivative(self.g, x)).collect())
                }
                Value::Matrix(n, c) => {
                    Value::Matrix(n, c.iter().map(|&x| time_derivative(self.g, x)).collect())
                }
                Value::Frame(_) => unreachable!("frames handled above"),
            });
        }
        match (name.as_str(), recv) {
            ("transpose", Value::Matrix(n, c)) => Some(Value::Matrix(n, transpose(n, &c))),
            ("x" | "y" | "z", Value::Vector(c)) => {
                let k = match name.as_str() {
                    "x" => 0,
                    "y" => 1,
                    _ => 2,
                };
                if k >= c.len() {
                    self.cx.error_spanned_by(
                        &m.method,
                        format!("a {}-vector has no `{name}` component", c.len()),
                    );
                    return None;
                }
                Some(Value::Scalar(c[k]))
            }
            ("norm", Value::Vector(c)) => {
                let s = dot(self.g, &c, &c);
                Some(Value::Scalar(self.g.call(crate::sym::Func::Sqrt, s)))
            }
            ("normalize", Value::Vector(c)) => {
                let s = dot(self.g, &c, &c);
                if self.g.is_zero(s) {
                    self.cx
                        .error_spanned_by(&m.receiver, "this vector is zero and has no direction");
                    return None;
                }
                let r = self.g.call(crate::sym::Func::Sqrt, s);
                let one = self.g.constant(1.0);
                let inv = self.g.div(one, r);
                Some(Value::Vector(scale_v(self.g, inv, &c)))
            }
            ("dot", Value::Vector(a)) => {
                let b = self.vector(&m.args[0], Some(a.len()))?;
                Some(Value::Scalar(dot(self.g, &a, &b)))
            }
            ("cross", Value::Vector(a)) => {
                let b = self.vector(&m.args[0], Some(a.len()))?;
                Some(if a.len() == 3 {
                    Value::Vector(cross(self.g, &a, &b))
                } else {
                    Value::Scalar(cross2(self.g, &a, &b))
                })
            }
            (_, recv) => {
                self.cx.error_spanned_by(
                    &m.method,
                    format!("`{name}` does not apply to {}", recv.describe()),
                );
                None
            }
        }
    }

    /// The frame with index `f` (`None`: the ground, of dimension `dim`).
    pub fn frame_value(&mut self, f: Option<usize>, dim: usize) -> FrameValue {
        match f {
            Some(k) => self.frames[k].clone(),
            None => {
                let (o, z) = (self.g.constant(1.0), self.g.constant(0.0));
                let rotation = (0..dim * dim)
                    .map(|k| if k % (dim + 1) == 0 { o } else { z })
                    .collect();
                FrameValue {
                    dim,
                    origin: vec![z; dim],
                    rotation,
                    angle: (dim == 2).then_some(z),
                    euler: None,
                    omega: (dim == 3).then(|| vec![z; 3]),
                    velocity: (dim == 3).then(|| FrameVelocity {
                        base: vec![z; 3],
                        relative: vec![z; 3],
                        in_parent: None,
                    }),
                    exact_rates: true,
                }
            }
        }
    }

    /// The dimension of the model's frames (2 when none is declared).
    pub fn model_dim(&self) -> usize {
        self.frames.first().map_or(2, |f| f.dim)
    }

    fn frame_method(
        &mut self,
        m: &syn::ExprMethodCall,
        f: Option<usize>,
        name: &str,
    ) -> Option<Value> {
        let dim = f.map_or_else(|| self.model_dim(), |k| self.frames[k].dim);
        let fv = self.frame_value(f, dim);
        let want = usize::from(matches!(
            name,
            "point" | "axis" | "velocity" | "material" | "node" | "node_rotation"
        ));
        if m.args.len() != want {
            self.cx.error_spanned_by(
                m,
                format!(
                    "`{name}` takes {want} argument{}",
                    if want == 1 { "" } else { "s" }
                ),
            );
            return None;
        }
        if matches!(name, "velocity" | "angular_velocity") && !self.allows_velocity() {
            self.cx.error_spanned_by(
                m,
                format!(
                    "`.{name}()` in {}: velocities are not allowed here",
                    self.context_name()
                ),
            );
            return None;
        }
        Some(match name {
            "origin" => Value::Vector(fv.origin.clone()),
            "rotation" => Value::Matrix(dim, fv.rotation.clone()),
            "angle" => match fv.angle {
                Some(a) => Value::Scalar(a),
                None => {
                    self.cx
                        .error_spanned_by(&m.method, "`angle` applies to planar frames");
                    return None;
                }
            },
            "point" => {
                let u = self.vector(&m.args[0], Some(dim))?;
                Value::Vector(fv.point(self.g, &u))
            }
            "axis" => {
                let u = self.vector(&m.args[0], Some(dim))?;
                Value::Vector(mat_vec(self.g, dim, &fv.rotation, &u))
            }
            "velocity" => {
                let u = self.vector(&m.args[0], Some(dim))?;
                let p = fv.point(self.g, &u);
                Value::Vector(p.iter().map(|&x| time_derivative(self.g, x)).collect())
            }
            "angular_velocity" => fv.angular_velocity(self.g),
            "material" => {
                let material = f.and_then(|k| {
                    self.materials
                        .iter()
                        .find(|(i, _)| *i == k)
                        .map(|(_, m)| (k, m.clone()))
                });
                let Some((k, material)) = material else {
                    self.cx.error_spanned_by(
                        &m.method,
                        "`material` applies to deformable bodies (`Deformable { .. }`)",
                    );
                    return None;
                };
                if self.expanding_materials.contains(&k) {
                    self.cx.error_spanned_by(
                        &m.method,
                        "a deformable body's `position` and `displacement` cannot use its own `material(..)`, which they define",
                    );
                    return None;
                }
                let xi = self.expr(&m.args[0])?;
                self.expanding_materials.push(k);
                let at = material.at(self, &m.args[0], xi);
                self.expanding_materials.pop();
                Value::Vector(at?)
            }
            "node" | "node_rotation" => {
                let nodes = f.and_then(|k| {
                    self.materials
                        .iter()
                        .find(|(i, _)| *i == k)
                        .and_then(|(_, m)| m.nodes.clone())
                });
                let Some(nodes) = nodes else {
                    self.cx.error_spanned_by(
                        &m.method,
                        format!("`{name}` applies to deformable bodies built from beam elements (`Deformable {{ data: beam, .. }}`)"),
                    );
                    return None;
                };
                let mut arg = &m.args[0];
                while let syn::Expr::Group(g) = arg {
                    arg = &g.expr;
                }
                let k = match arg {
                    syn::Expr::Lit(syn::ExprLit {
                        lit: syn::Lit::Int(i),
                        ..
                    }) => i.base10_parse::<usize>().ok(),
                    _ => None,
                };
                let Some(k) = k.filter(|&k| k <= nodes.elements) else {
                    self.cx.error_spanned_by(
                        &m.args[0],
                        format!(
                            "a node is an integer literal from 0 to {} (the beam's nodes)",
                            nodes.elements
                        ),
                    );
                    return None;
                };
                if name == "node_rotation" {
                    let r = nodes.rotation(self.g, dim, k);
                    if dim == 2 {
                        Value::Scalar(r[0])
                    } else {
                        Value::Vector(r)
                    }
                } else {
                    Value::Vector(nodes.at(self.g, dim, k))
                }
            }
            _ => unreachable!("frame methods are listed"),
        })
    }

    fn call_value(&mut self, c: &syn::ExprCall) -> Option<Value> {
        let name = match &*c.func {
            syn::Expr::Path(p) => p.path.get_ident().map(ToString::to_string),
            _ => None,
        };
        let Some(name) = name.filter(|n| MATRIX_FUNCTIONS.contains(&n.as_str())) else {
            return self.call(c).map(Value::Scalar);
        };
        let want = match name.as_str() {
            "euler_parameters" => 4,
            "diag" => 3,
            _ => 1,
        };
        if c.args.len() != want {
            self.cx.error_spanned_by(
                c,
                format!(
                    "`{name}` takes {want} argument{}",
                    if want == 1 { "" } else { "s" }
                ),
            );
            return None;
        }
        let mut args = Vec::new();
        let mut ok = true;
        for a in &c.args {
            match self.expr(a) {
                Some(x) => args.push(x),
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        Some(match name.as_str() {
            "rot2" => Value::Matrix(2, rot2(self.g, args[0])),
            "rot_x" => Value::Matrix(3, rot_axis(self.g, 0, args[0])),
            "rot_y" => Value::Matrix(3, rot_axis(self.g, 1, args[0])),
            "rot_z" => Value::Matrix(3, rot_axis(self.g, 2, args[0])),
            "euler_parameters" => Value::Matrix(
                3,
                euler_rotation(self.g, [args[0], args[1], args[2], args[3]]),
            ),
            _ => {
                let z = self.g.constant(0.0);
                Value::Matrix(3, vec![args[0], z, z, z, args[1], z, z, z, args[2]])
            }
        })
    }
}
