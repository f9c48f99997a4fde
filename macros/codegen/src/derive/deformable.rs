//! Deformable bodies in the floating frame of reference (docs/theory.md §floating-frame).
//!
//! `static rod: Body = Deformable { origin, angle | rotation, elastic: [q1, ..], .. }`
//! declares a body whose material point `ξ` sits at `R + A (ū_o(ξ) + N(ξ) q_f)`. Unlike a
//! rigid body (Kane's method) it adds kinetic energy, whose mass matrix and quadratic
//! velocity vector come from Lagrange's equations: from the inertia shape
//! integrals (E10) `m, Ī₁, S̄, I_kl, Ī_kl, S̄_kl` (symbolic leaves: numbers, parameter
//! expressions) it forms
//!
//! `T = ½ m Ṙ·Ṙ + Ṙ·A(ω̄ × ū_c + S̄ q̇_f) + ½ ω̄ᵀ Ī_θθ ω̄ + ω̄·Ī_θf q̇_f + ½ q̇_fᵀ M_ff q̇_f`
//!
//! with `ū_c = Ī₁ + S̄ q_f`, `U_kl = I_kl + (Ī_kl + Ī_lk) q_f + q_fᵀ S̄_kl q_f`,
//! `Ī_θθ = tr(U) I − U`, `(Ī_θf q̇_f)_1 = ∫ρ(u₂N₃ − u₃N₂) q̇_f …` (E11, E12; planar: the
//! rate `θ̇`, `U₁₁ + U₂₂` and `∫ρ(u₁N₂ − u₂N₁)`, E13), so `M` and `Q_v` come out of the
//! same Lagrange derivation as for rigid bodies. The elastic energy `½ q_fᵀ K_ff q_f`
//! joins `V`, damping `−D q̇_f` joins `Q_e`.
//!
//! The invariants are given (`invariants: Invariants { s_bar, i_bar, s_bar_kl }` and the
//! rigid `mass`, `com`, `inertia`, as a finite-element program exports them) or
//! integrated at compile time ([`super::integrate`]) from the closures
//! `position: |xi| ū_o(ξ)`, `displacement: |xi| N(ξ) q_f` and `density: ρ(ξ)` (mass
//! per unit of `ξ`) over `span: x0..x1`. The stiffness is given (`stiffness: [[..]]`) or
//! the Euler–Bernoulli strain energy `½∫(EA u'² + EI w''²) dx` of the displacement
//! (`axial_rigidity`, `bending_rigidity`; the body's x axis along the beam), with the
//! geometric stiffening of `stiffening: s` as the nonlinear axial strain
//! `ε = u' + ½ w'²`, i.e. the extra energy `s · ½ EA ∫ (u' w'² + ¼ w'⁴) dx`.
//!
//! A body built from beam elements (`data: slot`, a `Beam`/`SpatialBeam` slot) reads
//! its invariants, `K_ff`, its nodes (`body.node(k)`: `x_k + T_k q_f`; the small
//! elastic rotation of node k's section, `body.node_rotation(k)`, from the rotation
//! rows of `T_k`) and, with `stiffening: s`, the centrifugal geometric stiffness `K_Ω`
//! from the slot: the force `−s (ω̄_y² + ω̄_z²) K_Ω q_f` (planar `−s θ̇² K_Ω q_f`).
//! The nonlinear axial strain is not used there: the modes of a free-ended beam have no
//! axial strain at the tip, so they cannot take up the foreshortening `−½ w'²` of the
//! bent beam and its `¼ EA w'⁴` locks the bending (the spin-up beam with 16 elements, 4
//! bending and 3 axial modes, reached 0.28 m of tip deflection against 0.53 m from the
//! shape functions' cubic axial ansatz).

use proc_macro2::Span;

use super::{fields, idx, BodyOut, Builder, Fields};
use crate::derive::integrate::{integrate, XI};
use crate::model::expr::Context;
use crate::model::value::{cross, dot, mat_vec, time_derivative, Closure, Material, Nodes, Value};
use crate::parse::Decl;
use crate::sym::{diff, Deps, ExprId, Graph, Var};

/// The inertia shape integrals of E10, flattened row-major.
struct Invariants {
    m: ExprId,
    /// `Ī₁` (dim).
    i1: Vec<ExprId>,
    /// `I_kl` (dim × dim).
    i_kl: Vec<ExprId>,
    /// `S̄` (dim × nf).
    s_bar: Vec<ExprId>,
    /// `Ī_kl` (dim × dim × nf).
    i_bar: Vec<ExprId>,
    /// `S̄_kl` (dim × dim × nf × nf).
    s_kl: Vec<ExprId>,
    /// Read from a data slot: `M_ff q̇_f` is formed block by block ([`mff_times`]).
    from_data: bool,
}

/// The shape functions at the placeholder `ξ`.
struct Shapes {
    /// `ū_o(ξ)` (dim).
    position: Option<Vec<ExprId>>,
    /// `N(ξ)` (dim × nf).
    n: Option<Vec<ExprId>>,
    /// `ρ(ξ)`.
    density: Option<ExprId>,
    span: Option<(f64, f64)>,
}

const INVARIANT_KINDS: &[(&str, &[&str], &[&str])] =
    &[("Invariants", &[], &["s_bar", "i_bar", "s_bar_kl"])];
const DAMPING_KINDS: &[(&str, &[&str], &[&str])] = &[("Rayleigh", &[], &["mass", "stiffness"])];

fn closure(cx: &crate::ctxt::Ctxt, e: &syn::Expr) -> Option<Closure> {
    let syn::Expr::Closure(c) = e else {
        cx.error_spanned_by(
            e,
            "expected a function of the material coordinate, e.g. `|xi| [l * xi, 0.0]`",
        );
        return None;
    };
    let pat = match c.inputs.first() {
        Some(syn::Pat::Type(t)) => &*t.pat,
        Some(p) => p,
        None => {
            cx.error_spanned_by(e, "the closure takes the material coordinate: `|xi| ..`");
            return None;
        }
    };
    let syn::Pat::Ident(id) = pat else {
        cx.error_spanned_by(
            pat,
            "the material coordinate is a plain name, e.g. `|xi| ..`",
        );
        return None;
    };
    if c.inputs.len() != 1 {
        cx.error_spanned_by(
            &c.inputs,
            "the closure takes one argument, the material coordinate",
        );
        return None;
    }
    // rustfmt writes a long closure body as a block: `|xi| { [..] }`.
    let mut body = &*c.body;
    while let syn::Expr::Block(b) = body {
        match (b.block.stmts.as_slice(), &b.label) {
            ([syn::Stmt::Expr(e, None)], None) => body = e,
            _ => {
                cx.error_spanned_by(body, "the closure's body is one expression (no statements)");
                return None;
            }
        }
    }
    Some(Closure {
        var: id.ident.to_string(),
        body: body.clone(),
    })
}

/// Where an error about a field points: the field's expression, or the constructor.
#[derive(Clone, Copy)]
struct At<'e>(Option<&'e syn::Expr>, Span);

impl At<'_> {
    fn error(self, cx: &crate::ctxt::Ctxt, msg: String) {
        match self.0 {
            Some(e) => cx.error_spanned_by(e, msg),
            None => cx.error_at(self.1, msg),
        }
    }
}

impl Builder<'_, '_> {
    fn invariant_scalar(&mut self, e: &syn::Expr) -> Option<ExprId> {
        let x = self.tr.field_scalar(e, Context::Kinematics)?;
        let d = self.tr.g.deps(x);
        if d.has(Deps::Q) || d.has(Deps::QD) || d.has(Deps::TIME) {
            self.cx.error_spanned_by(
                e,
                "an invariant is constant: it may use numbers and parameters, not coordinates or time",
            );
            return None;
        }
        Some(x)
    }

    /// A nested array of the given shape (a scalar `0.0` stands for a zero block);
    /// `what` names the field and its dimensions, for messages.
    fn table(
        &mut self,
        e: &syn::Expr,
        shape: &[usize],
        what: &str,
        out: &mut Vec<ExprId>,
    ) -> Option<()> {
        let Some((&first, rest)) = shape.split_first() else {
            out.push(self.invariant_scalar(e)?);
            return Some(());
        };
        let syn::Expr::Array(a) = e else {
            if let Some(x) = self.invariant_scalar(e) {
                if self.tr.g.is_zero(x) {
                    let z = self.tr.g.constant(0.0);
                    out.extend(std::iter::repeat_n(z, shape.iter().product()));
                    return Some(());
                }
            }
            self.cx.error_spanned_by(
                e,
                format!("{what}: expected an array of {first} entries here (or `0.0` for zeros)"),
            );
            return None;
        };
        if a.elems.len() != first {
            self.cx.error_spanned_by(
                e,
                format!(
                    "{what}: expected {first} entries here; this has {}",
                    a.elems.len()
                ),
            );
            return None;
        }
        let mut ok = true;
        for x in &a.elems {
            ok &= self.table(x, rest, what, out).is_some();
        }
        ok.then_some(())
    }

    fn table_of(
        &mut self,
        e: &syn::Expr,
        shape: &[usize],
        name: &str,
        meaning: &str,
    ) -> Option<Vec<ExprId>> {
        let dims: Vec<String> = shape.iter().map(ToString::to_string).collect();
        let what = format!("`{name}` is a {} array ({meaning})", dims.join(" × "));
        let mut out = Vec::new();
        self.table(e, shape, &what, &mut out)?;
        Some(out)
    }

    fn elastic(&mut self, e: &syn::Expr) -> Option<Vec<u32>> {
        let syn::Expr::Array(a) = e else {
            self.cx
                .error_spanned_by(e, "the elastic coordinates are a list: `elastic: [q1, q2]`");
            return None;
        };
        if a.elems.is_empty() {
            self.cx.error_spanned_by(
                e,
                "a deformable body has at least one elastic coordinate (a rigid one is a `Body`)",
            );
            return None;
        }
        let mut out = Vec::new();
        for x in &a.elems {
            let id = self.tr.field_scalar(x, Context::Kinematics)?;
            match self.tr.g.node(id) {
                crate::sym::Node::Var(Var::Q(i)) if !out.contains(i) => out.push(*i),
                crate::sym::Node::Var(Var::Q(_)) => {
                    self.cx
                        .error_spanned_by(x, "this elastic coordinate is listed twice");
                    return None;
                }
                _ => {
                    self.cx
                        .error_spanned_by(x, "an elastic coordinate is the name of a coordinate");
                    return None;
                }
            }
        }
        Some(out)
    }

    /// A closure or a plain expression, at the placeholder `ξ`.
    fn at_xi(&mut self, e: &syn::Expr, dim: Option<usize>) -> Option<Value> {
        let xi = self.tr.g.var(XI);
        match e {
            syn::Expr::Closure(_) => {
                let c = closure(self.cx, e)?;
                self.tr.in_context(Context::Kinematics, |t| {
                    t.with_binding(&c.var, Value::Scalar(xi), |t| match dim {
                        Some(d) => t.vector(&c.body, Some(d)).map(Value::Vector),
                        None => t.expr(&c.body).map(Value::Scalar),
                    })
                })
            }
            _ if dim.is_none() => self.tr.field_value(e, Context::Kinematics),
            _ => {
                closure(self.cx, e)?;
                None
            }
        }
    }

    fn integral(
        &mut self,
        e: ExprId,
        span: Option<(f64, f64)>,
        at: At<'_>,
        what: &str,
    ) -> Option<ExprId> {
        let Some((a, b)) = span else {
            at.error(
                self.cx,
                format!("{what} is integrated over the material coordinate: give its range, e.g. `span: 0.0..1.0`"),
            );
            return None;
        };
        match integrate(self.tr.g, e, a, b) {
            Ok(x) => Some(x),
            Err(msg) => {
                at.error(
                    self.cx,
                    format!("{what} cannot be integrated in closed form: it contains {msg}"),
                );
                None
            }
        }
    }

    fn span_of(&mut self, e: &syn::Expr) -> Option<(f64, f64)> {
        let syn::Expr::Range(r) = e else {
            self.cx
                .error_spanned_by(e, "the range of the material coordinate is `x0..x1`");
            return None;
        };
        let (Some(a), Some(b)) = (&r.start, &r.end) else {
            self.cx
                .error_spanned_by(e, "the range needs both ends: `x0..x1`");
            return None;
        };
        let mut ends = [0.0; 2];
        for (k, x) in [a, b].into_iter().enumerate() {
            let id = self.tr.field_scalar(x, Context::Kinematics)?;
            let Some(v) = self.tr.g.as_const(id) else {
                self.cx
                    .error_spanned_by(x, "the ends of the material range are numbers");
                return None;
            };
            ends[k] = v;
        }
        if ends[0] >= ends[1] || ends.iter().any(|x| !x.is_finite()) {
            self.cx
                .error_spanned_by(e, "the material range `x0..x1` needs x0 < x1");
            return None;
        }
        Some((ends[0], ends[1]))
    }

    /// `static name: Body = Deformable { .. }`.
    pub(super) fn deformable(&mut self, d: &Decl, fl: &Fields<'_>) -> Option<()> {
        if fl.get("origin").is_none() {
            self.cx.error_at(
                fl.span,
                "a deformable body needs its reference frame: `origin` with `angle` (planar) or `rotation` (spatial)",
            );
            return None;
        }
        let k = self.define_frame(d, fl)?;
        let fv = self.tr.frames[k].clone();
        let dim = fv.dim;
        let qf = self.elastic(fl.get("elastic")?)?;
        let nf = qf.len();
        let position = match fl.get("position") {
            Some(e) => Some(closure(self.cx, e)?),
            None => None,
        };
        let displacement = match fl.get("displacement") {
            Some(e) => Some(closure(self.cx, e)?),
            None => None,
        };
        let nodes = match fl.get("data") {
            Some(e) => {
                let model = self.tr.model();
                let l = crate::derive::data::slot_leaves(self.cx, model, self.tr.g, e, dim, nf)?;
                l.beam.map(|b| Nodes {
                    elements: b.elements,
                    dofs_per_node: b.dofs_per_node,
                    length: b.length,
                    basis: b.basis,
                    qf: qf.clone(),
                })
            }
            None => None,
        };
        self.tr.materials.push((
            k,
            Material {
                dim,
                position,
                displacement,
                nodes,
            },
        ));
        let span = match fl.get("span") {
            Some(e) => Some(self.span_of(e)?),
            None => None,
        };
        // The shape functions at the placeholder ξ.
        let pos = match fl.get("position") {
            Some(e) => match self.at_xi(e, Some(dim))? {
                Value::Vector(v) => Some(v),
                _ => unreachable!("asked for a vector"),
            },
            None => None,
        };
        let n = match fl.get("displacement") {
            Some(e) => {
                let Value::Vector(u) = self.at_xi(e, Some(dim))? else {
                    unreachable!("asked for a vector")
                };
                Some(self.shape_matrix(e, &u, &qf)?)
            }
            None => None,
        };
        let density = match fl.get("density") {
            Some(e) => match self.at_xi(e, None)? {
                Value::Scalar(x) => Some(x),
                other => {
                    self.cx.error_spanned_by(
                        e,
                        format!("the density is a scalar (mass per unit of the material coordinate); this is {}", other.describe()),
                    );
                    return None;
                }
            },
            None => None,
        };
        let shapes = Shapes {
            position: pos,
            n,
            density,
            span,
        };
        let inv = self.invariants(fl, &shapes, dim, nf)?;
        let t = self.deformable_kinetic(&fv, &inv, &qf);
        self.kinetic.push(t);
        self.lagrange_kinetic.push(t);

        // Elastic energy and damping.
        let qv: Vec<ExprId> = qf.iter().map(|&i| self.tr.g.var(Var::Q(i))).collect();
        let kff = self.stiffness(fl, &shapes, k, &qf, nf, &qv)?;
        if let Some(kff) = &kff {
            let kq = mat_vec_rect(self.tr.g, kff, nf, &qv);
            let e = dot(self.tr.g, &qv, &kq);
            let half = self.tr.g.constant(0.5);
            let v = self.tr.g.mul(vec![half, e]);
            self.potential.push(v);
        }
        if let Some(de) = fl.get("damping") {
            let dq = if let syn::Expr::Struct(_) = de {
                let dl = fields(self.cx, de, DAMPING_KINDS, "damping")?;
                let z = self.tr.g.constant(0.0);
                let alpha = match dl.get("mass") {
                    Some(e) => self.invariant_scalar(e)?,
                    None => z,
                };
                let beta = match dl.get("stiffness") {
                    Some(e) => self.invariant_scalar(e)?,
                    None => z,
                };
                if !self.tr.g.is_zero(beta) && kff.is_none() {
                    self.cx.error_spanned_by(
                        de,
                        "stiffness-proportional damping needs the body's stiffness",
                    );
                    return None;
                }
                let qd: Vec<ExprId> = qf.iter().map(|&i| self.tr.g.var(Var::Qd(i))).collect();
                let g = &mut *self.tr.g;
                let mq = mff_times(g, &inv, dim, nf, &qd);
                let kq = match &kff {
                    Some(kf) => mat_vec_rect(g, kf, nf, &qd),
                    None => vec![z; nf],
                };
                (0..nf)
                    .map(|i| {
                        let a = g.mul(vec![alpha, mq[i]]);
                        let b = g.mul(vec![beta, kq[i]]);
                        g.add(vec![a, b])
                    })
                    .collect()
            } else {
                let dmat =
                    self.table_of(de, &[nf, nf], "damping", "elastic × elastic coordinates")?;
                let qd: Vec<ExprId> = qf.iter().map(|&i| self.tr.g.var(Var::Qd(i))).collect();
                mat_vec_rect(self.tr.g, &dmat, nf, &qd)
            };
            let zero = self.tr.g.constant(0.0);
            let mut q = vec![zero; self.tr.nq()];
            for (j, &i) in qf.iter().enumerate() {
                q[i as usize] = self.tr.g.neg(dq[j]);
            }
            self.add_applied(q);
        }

        // Gravity's potential is `−g·∫ρ r = −g·(m R + A ū_c)`: pushed as a unit mass at
        // the first moment.
        let uc = centre(self.tr.g, &inv, &qv, dim, nf);
        let auc = mat_vec(self.tr.g, dim, &fv.rotation, &uc);
        let first: Vec<ExprId> = (0..dim)
            .map(|i| {
                let mr = self.tr.g.mul(vec![inv.m, fv.origin[i]]);
                self.tr.g.add(vec![mr, auc[i]])
            })
            .collect();
        let one = self.tr.g.constant(1.0);
        self.masses.push((one, first));
        self.out.bodies.push(BodyOut {
            name: d.name.to_string(),
            docs: d.docs.clone(),
            frame: idx(k),
            mass: inv.m,
        });
        Some(())
    }

    /// `N = ∂u/∂q_f` of the displacement `u`, checked linear in the elastic coordinates.
    fn shape_matrix(&mut self, e: &syn::Expr, u: &[ExprId], qf: &[u32]) -> Option<Vec<ExprId>> {
        let g = &mut *self.tr.g;
        let mut n = Vec::new();
        for &ui in u {
            let mut back = Vec::new();
            for &j in qf {
                let nij = diff::differentiate(g, ui, Var::Q(j));
                let dd = g.deps(nij);
                if dd.has(Deps::Q) || dd.has(Deps::QD) || dd.has(Deps::TIME) {
                    self.cx.error_spanned_by(e, "the displacement is `N(ξ) q_f`: linear in the elastic coordinates, with shape functions of the material coordinate and parameters only");
                    return None;
                }
                let q = g.var(Var::Q(j));
                back.push(g.mul(vec![nij, q]));
                n.push(nij);
            }
            let sum = g.add(back);
            let rest = g.sub(ui, sum);
            if !g.is_zero(rest) {
                self.cx.error_spanned_by(e, "the displacement is `N(ξ) q_f`: linear in the elastic coordinates (no constant part, no other coordinates)");
                return None;
            }
        }
        Some(n)
    }

    fn invariants(
        &mut self,
        fl: &Fields<'_>,
        sh: &Shapes,
        dim: usize,
        nf: usize,
    ) -> Option<Invariants> {
        if let Some(e) = fl.get("data") {
            // A beam-element body or exported invariants, read at run time.
            for other in [
                "mass",
                "com",
                "inertia",
                "invariants",
                "density",
                "position",
            ] {
                if let Some(x) = fl.get(other) {
                    self.cx.error_spanned_by(
                        x,
                        format!("`{other}` is part of the invariants, which `data` already gives"),
                    );
                    return None;
                }
            }
            let model = self.tr.model();
            let l = crate::derive::data::slot_leaves(self.cx, model, self.tr.g, e, dim, nf)?;
            return Some(Invariants {
                m: l.m,
                i1: l.i1,
                i_kl: l.i_kl,
                s_bar: l.s_bar,
                i_bar: l.i_bar,
                s_kl: l.s_kl,
                from_data: true,
            });
        }
        let span = fl.span;
        // Where an integral that fails points: the closure that brought the bad term.
        let field_span = |name: &str| At(fl.get(name), span);
        let (rho_at, pos_at, disp_at) = (
            field_span("density"),
            field_span("position"),
            field_span("displacement"),
        );
        // The rigid part: given like a rigid body's, or integrated.
        let (m, i1, i_kl) = if let Some(me) = fl.get("mass") {
            let m = self.invariant_scalar(me)?;
            let c = match fl.get("com") {
                Some(e) => self.vector(e, dim, Context::Kinematics)?,
                None => vec![self.tr.g.constant(0.0); dim],
            };
            let i1: Vec<ExprId> = c.iter().map(|&x| self.tr.g.mul(vec![m, x])).collect();
            let z = self.tr.g.constant(0.0);
            let cc = dot(self.tr.g, &c, &c);
            let i_kl = if dim == 2 {
                // Only I₁₁ + I₂₂ (the polar moment about the frame origin) enters.
                let jc = match fl.get("inertia") {
                    Some(e) => self.invariant_scalar(e)?,
                    None => z,
                };
                let mcc = self.tr.g.mul(vec![m, cc]);
                let jo = self.tr.g.add(vec![jc, mcc]);
                vec![jo, z, z, z]
            } else {
                let ic = match fl.get("inertia") {
                    Some(e) => match self.tr.field_value(e, Context::Kinematics)? {
                        Value::Matrix(3, v) => v,
                        Value::Vector(v) if v.len() == 3 => {
                            vec![v[0], z, z, z, v[1], z, z, z, v[2]]
                        }
                        other => {
                            self.cx.error_spanned_by(e, format!("the inertia of a spatial body is a 3×3 matrix (or its diagonal); this is {}", other.describe()));
                            return None;
                        }
                    },
                    None => vec![z; 9],
                };
                // J_O = I_c + m(|c|² I − c cᵀ); I_kl = ½ tr(J_O) I − J_O.
                let mut jo = Vec::new();
                for a in 0..3 {
                    for b in 0..3 {
                        let ccab = self.tr.g.mul(vec![c[a], c[b]]);
                        let s = if a == b {
                            self.tr.g.sub(cc, ccab)
                        } else {
                            self.tr.g.neg(ccab)
                        };
                        let ms = self.tr.g.mul(vec![m, s]);
                        jo.push(self.tr.g.add(vec![ic[3 * a + b], ms]));
                    }
                }
                let tr = self.tr.g.add(vec![jo[0], jo[4], jo[8]]);
                let half = self.tr.g.constant(0.5);
                let ht = self.tr.g.mul(vec![half, tr]);
                (0..9)
                    .map(|i| {
                        if i % 4 == 0 {
                            self.tr.g.sub(ht, jo[i])
                        } else {
                            self.tr.g.neg(jo[i])
                        }
                    })
                    .collect()
            };
            (m, i1, i_kl)
        } else {
            let (Some(rho), Some(pos)) = (sh.density, sh.position.clone()) else {
                self.cx.error_at(
                    span,
                    "a deformable body needs its rigid inertia: `mass` (with `com`, `inertia`), or `density` and `position` to integrate",
                );
                return None;
            };
            let m = self.integral(rho, sh.span, rho_at, "the mass")?;
            let mut i1 = Vec::new();
            for &x in &pos {
                let e = self.tr.g.mul(vec![rho, x]);
                i1.push(self.integral(e, sh.span, pos_at, "the first moment")?);
            }
            let mut i_kl = Vec::new();
            for a in 0..dim {
                for b in 0..dim {
                    let e = self.tr.g.mul(vec![rho, pos[a], pos[b]]);
                    i_kl.push(self.integral(e, sh.span, pos_at, "the second moment")?);
                }
            }
            (m, i1, i_kl)
        };
        let given = match fl.get("invariants") {
            Some(e) => Some(fields(self.cx, e, INVARIANT_KINDS, "invariants")?),
            None => None,
        };
        let get = |name: &str| given.as_ref().and_then(|g| g.get(name));
        let need_shapes =
            get("s_bar").is_none() || get("i_bar").is_none() || get("s_bar_kl").is_none();
        let (rho, n) = if need_shapes {
            let (Some(rho), Some(n)) = (sh.density, sh.n.clone()) else {
                self.cx.error_at(
                    span,
                    "a deformable body needs its shape integrals: `invariants: Invariants { s_bar, i_bar, s_bar_kl }`, or `displacement` and `density` to integrate",
                );
                return None;
            };
            (Some(rho), Some(n))
        } else {
            (None, None)
        };
        let s_bar = match get("s_bar") {
            Some(e) => self.table_of(e, &[dim, nf], "s_bar", "dimension × elastic coordinates")?,
            None => {
                let (rho, n) = (rho?, n.clone()?);
                let mut out = Vec::new();
                for &x in &n {
                    let e = self.tr.g.mul(vec![rho, x]);
                    out.push(self.integral(e, sh.span, disp_at, "S̄")?);
                }
                out
            }
        };
        let i_bar = match get("i_bar") {
            Some(e) => self.table_of(
                e,
                &[dim, dim, nf],
                "i_bar",
                "dimension × dimension × elastic coordinates",
            )?,
            None => {
                let (rho, n) = (rho?, n.clone()?);
                let Some(pos) = sh.position.clone() else {
                    self.cx
                        .error_at(span, "integrating Ī_kl needs `position: |xi| [..]`");
                    return None;
                };
                let mut out = Vec::new();
                for a in 0..dim {
                    for b in 0..dim {
                        for j in 0..nf {
                            let e = self.tr.g.mul(vec![rho, pos[a], n[b * nf + j]]);
                            out.push(self.integral(e, sh.span, disp_at, "Ī_kl")?);
                        }
                    }
                }
                out
            }
        };
        let s_kl = match get("s_bar_kl") {
            Some(e) => self.table_of(
                e,
                &[dim, dim, nf, nf],
                "s_bar_kl",
                "dimension × dimension × elastic × elastic coordinates",
            )?,
            None => {
                let (rho, n) = (rho?, n?);
                let mut out = Vec::new();
                for a in 0..dim {
                    for b in 0..dim {
                        for i in 0..nf {
                            for j in 0..nf {
                                let e = self.tr.g.mul(vec![rho, n[a * nf + i], n[b * nf + j]]);
                                out.push(self.integral(e, sh.span, disp_at, "S̄_kl")?);
                            }
                        }
                    }
                }
                out
            }
        };
        Some(Invariants {
            m,
            i1,
            i_kl,
            s_bar,
            i_bar,
            s_kl,
            from_data: false,
        })
    }

    fn deformable_kinetic(
        &mut self,
        fv: &crate::model::value::FrameValue,
        inv: &Invariants,
        qf: &[u32],
    ) -> ExprId {
        let g = &mut *self.tr.g;
        let dim = fv.dim;
        let nf = qf.len();
        let qv: Vec<ExprId> = qf.iter().map(|&i| g.var(Var::Q(i))).collect();
        let qd: Vec<ExprId> = qf.iter().map(|&i| g.var(Var::Qd(i))).collect();
        let half = g.constant(0.5);
        let uc = centre(g, inv, &qv, dim, nf);
        // U_kl and P_kl = ∫ρ u_k N_l q̇_f.
        let mut u = Vec::new();
        let mut p = Vec::new();
        for a in 0..dim {
            for b in 0..dim {
                let ib_ab = &inv.i_bar[(a * dim + b) * nf..(a * dim + b + 1) * nf];
                let ib_ba = &inv.i_bar[(b * dim + a) * nf..(b * dim + a + 1) * nf];
                let s_ab = &inv.s_kl[(a * dim + b) * nf * nf..(a * dim + b + 1) * nf * nf];
                let lin1 = dot(g, ib_ab, &qv);
                let lin2 = dot(g, ib_ba, &qv);
                let sq = mat_vec_rect(g, s_ab, nf, &qv);
                let quad = dot(g, &qv, &sq);
                u.push(g.add(vec![inv.i_kl[a * dim + b], lin1, lin2, quad]));
                let pl = dot(g, ib_ab, &qd);
                let sqd = mat_vec_rect(g, s_ab, nf, &qd);
                let pq = dot(g, &qv, &sqd);
                p.push(g.add(vec![pl, pq]));
            }
        }
        let rd: Vec<ExprId> = fv.origin.iter().map(|&x| time_derivative(g, x)).collect();
        let sqd = mat_vec_rect(g, &inv.s_bar, nf, &qd);
        let mut terms = Vec::new();
        let rr = dot(g, &rd, &rd);
        terms.push(g.mul(vec![half, inv.m, rr]));
        let mq = mff_times(g, inv, dim, nf, &qd);
        let ff = dot(g, &qd, &mq);
        terms.push(g.mul(vec![half, ff]));
        if dim == 2 {
            let Value::Scalar(w) = fv.angular_velocity(g) else {
                unreachable!("planar frames have a scalar rate")
            };
            // ω̄ × ū_c = w (−u_c2, u_c1)
            let m1 = g.neg(uc[1]);
            let wu = [g.mul(vec![w, m1]), g.mul(vec![w, uc[0]])];
            let b: Vec<ExprId> = (0..2).map(|i| g.add(vec![wu[i], sqd[i]])).collect();
            let ab = mat_vec(g, 2, &fv.rotation, &b);
            terms.push(dot(g, &rd, &ab));
            let j = g.add(vec![u[0], u[3]]);
            terms.push(g.mul(vec![half, w, w, j]));
            let h = g.sub(p[1], p[2]);
            terms.push(g.mul(vec![w, h]));
        } else {
            let w = fv.body_angular_velocity(g);
            let wu = cross(g, &w, &uc);
            let b: Vec<ExprId> = (0..3).map(|i| g.add(vec![wu[i], sqd[i]])).collect();
            let ab = mat_vec(g, 3, &fv.rotation, &b);
            terms.push(dot(g, &rd, &ab));
            // ½ ω̄ᵀ (tr U I − U) ω̄ = ½ (tr U |ω̄|² − ω̄ᵀ U ω̄)
            let tr = g.add(vec![u[0], u[4], u[8]]);
            let ww = dot(g, &w, &w);
            let uw = mat_vec(g, 3, &u, &w);
            let wuw = dot(g, &w, &uw);
            let a = g.mul(vec![tr, ww]);
            let diffe = g.sub(a, wuw);
            terms.push(g.mul(vec![half, diffe]));
            let h = [g.sub(p[5], p[7]), g.sub(p[6], p[2]), g.sub(p[1], p[3])];
            terms.push(dot(g, &w, &h));
        }
        g.add(terms)
    }

    #[allow(clippy::too_many_arguments)]
    fn stiffness(
        &mut self,
        fl: &Fields<'_>,
        sh: &Shapes,
        frame: usize,
        qf: &[u32],
        nf: usize,
        qv: &[ExprId],
    ) -> Option<Option<Vec<ExprId>>> {
        let dim = self.tr.frames[frame].dim;
        if let Some(e) = fl.get("data") {
            for other in ["stiffness", "axial_rigidity", "bending_rigidity"] {
                if let Some(x) = fl.get(other) {
                    self.cx.error_spanned_by(
                        x,
                        format!("`{other}`: the stiffness comes with the body's `data`"),
                    );
                    return None;
                }
            }
            let model = self.tr.model();
            let l = crate::derive::data::slot_leaves(self.cx, model, self.tr.g, e, dim, nf)?;
            if let Some(se) = fl.get("stiffening") {
                let Some(beam) = &l.beam else {
                    self.cx.error_spanned_by(
                        se,
                        "geometric stiffening needs the body's elements: `data` names a `Beam` or `SpatialBeam` slot, not one set by the program",
                    );
                    return None;
                };
                let s = self.invariant_scalar(se)?;
                // −s (ω̄_y² + ω̄_z²) K_Ω q_f (planar: −s θ̇² K_Ω q_f).
                let nq = self.tr.nq();
                let frame = self.tr.frames[frame].clone();
                let g = &mut *self.tr.g;
                let w2 = if dim == 2 {
                    let Value::Scalar(w) = frame.angular_velocity(g) else {
                        unreachable!("planar frames have a scalar rate")
                    };
                    g.powi(w, 2)
                } else {
                    let w = frame.body_angular_velocity(g);
                    let wy = g.powi(w[1], 2);
                    let wz = g.powi(w[2], 2);
                    g.add(vec![wy, wz])
                };
                let kq = mat_vec_rect(g, &beam.k_spin, nf, qv);
                let zero = g.constant(0.0);
                let mut q = vec![zero; nq];
                let minus = g.constant(-1.0);
                for (j, &i) in qf.iter().enumerate() {
                    q[i as usize] = g.mul(vec![minus, s, w2, kq[j]]);
                }
                self.add_applied(q);
            }
            return Some(Some(l.k_ff));
        }
        if let Some(e) = fl.get("stiffness") {
            for other in ["axial_rigidity", "bending_rigidity", "stiffening"] {
                if let Some(x) = fl.get(other) {
                    self.cx.error_spanned_by(
                        x,
                        format!("`{other}` derives the stiffness, which `stiffness` already gives"),
                    );
                    return None;
                }
            }
            return Some(Some(self.table_of(
                e,
                &[nf, nf],
                "stiffness",
                "elastic × elastic coordinates",
            )?));
        }
        let ea = fl.get("axial_rigidity");
        let ei = fl.get("bending_rigidity");
        if ea.is_none() && ei.is_none() {
            if let Some(x) = fl.get("stiffening") {
                self.cx
                    .error_spanned_by(x, "geometric stiffening needs `axial_rigidity`");
                return None;
            }
            return Some(None);
        }
        let at = At(fl.get("displacement"), fl.span);
        let pos_at = At(fl.get("position"), fl.span);
        let (Some(n), Some(pos)) = (sh.n.clone(), sh.position.clone()) else {
            self.cx.error_at(
                fl.span,
                "a beam's stiffness is derived from `displacement` and `position`",
            );
            return None;
        };
        let z = self.tr.g.constant(0.0);
        let ea = match ea {
            Some(e) => self.invariant_scalar(e)?,
            None => z,
        };
        let ei = match ei {
            Some(e) => self.invariant_scalar(e)?,
            None => z,
        };
        let xp = diff::differentiate(self.tr.g, pos[0], XI);
        if self.tr.g.depends_on(xp, XI) || self.tr.g.is_zero(xp) {
            pos_at.error(self.cx, "a beam lies along its frame's x axis: `position: |xi| [l * xi, 0.0]` (x linear in the material coordinate)".into());
            return None;
        }
        for c in 1..dim {
            if self.tr.g.depends_on(pos[c], XI) {
                pos_at.error(self.cx, "a beam lies along its frame's x axis: its position's other components are constant".into());
                return None;
            }
        }
        let g = &mut *self.tr.g;
        // Derivatives along the material coordinate.
        let n1: Vec<ExprId> = n.iter().map(|&x| diff::differentiate(g, x, XI)).collect();
        let n2: Vec<ExprId> = n1.iter().map(|&x| diff::differentiate(g, x, XI)).collect();
        let one = g.constant(1.0);
        let xinv = g.div(one, xp);
        // K_ij = ∫ EA N0i' N0j' / x' + EI Σ_c Nci'' Ncj'' / x'^3 dξ
        let ea_x = g.mul(vec![ea, xinv]);
        let x3 = g.powi(xinv, 3);
        let ei_x = g.mul(vec![ei, x3]);
        let mut k = vec![z; nf * nf];
        for i in 0..nf {
            for j in i..nf {
                let g = &mut *self.tr.g;
                let mut parts = vec![g.mul(vec![ea_x, n1[i], n1[j]])];
                for c in 1..dim {
                    parts.push(g.mul(vec![ei_x, n2[c * nf + i], n2[c * nf + j]]));
                }
                let e = g.add(parts);
                let v = self.integral(e, sh.span, at, "the strain energy")?;
                k[i * nf + j] = v;
                k[j * nf + i] = v;
            }
        }
        if let Some(se) = fl.get("stiffening") {
            let s = self.invariant_scalar(se)?;
            // G_jk(ξ) = Σ_c Ncj' Nck' (lateral slopes).
            let mut gjk = Vec::new();
            for j in 0..nf {
                for kk in j..nf {
                    let g = &mut *self.tr.g;
                    let parts: Vec<ExprId> = (1..dim)
                        .map(|c| g.mul(vec![n1[c * nf + j], n1[c * nf + kk]]))
                        .collect();
                    let e = g.add(parts);
                    if !g.is_zero(e) {
                        let mult = if j == kk { 1.0 } else { 2.0 };
                        gjk.push((j, kk, e, mult));
                    }
                }
            }
            let x2 = self.tr.g.powi(xinv, 2);
            let mut terms = Vec::new();
            // ∫ u_ξ w_ξ² / x'² dξ = Σ_i Σ_{j≤k} mult q_i q_j q_k ∫ N0i' G_jk
            for i in 0..nf {
                if self.tr.g.is_zero(n1[i]) {
                    continue;
                }
                for &(j, kk, e, mult) in &gjk {
                    let f = self.tr.g.mul(vec![n1[i], e]);
                    let v = self.integral(f, sh.span, at, "the stiffening energy")?;
                    if self.tr.g.is_zero(v) {
                        continue;
                    }
                    let c = self.tr.g.constant(mult);
                    terms.push(self.tr.g.mul(vec![c, x2, v, qv[i], qv[j], qv[kk]]));
                }
            }
            // ¼ ∫ w_ξ⁴ / x'³ dξ = ¼ Σ_{(jk),(lm)} mult mult' q_j q_k q_l q_m ∫ G_jk G_lm
            let x3 = self.tr.g.powi(xinv, 3);
            let quarter = self.tr.g.constant(0.25);
            for (a, &(j, kk, e1, m1)) in gjk.iter().enumerate() {
                for &(l, mm, e2, m2) in &gjk[a..] {
                    let f = self.tr.g.mul(vec![e1, e2]);
                    let v = self.integral(f, sh.span, at, "the stiffening energy")?;
                    if self.tr.g.is_zero(v) {
                        continue;
                    }
                    let pair = if (j, kk) == (l, mm) { 1.0 } else { 2.0 };
                    let c = self.tr.g.constant(m1 * m2 * pair);
                    terms.push(
                        self.tr
                            .g
                            .mul(vec![quarter, c, x3, v, qv[j], qv[kk], qv[l], qv[mm]]),
                    );
                }
            }
            let sum = self.tr.g.add(terms);
            let half = self.tr.g.constant(0.5);
            let energy = self.tr.g.mul(vec![half, s, ea, sum]);
            self.potential.push(energy);
        }
        Some(Some(k))
    }
}

/// `ū_c = Ī₁ + S̄ q_f`.
fn centre(g: &mut Graph, inv: &Invariants, qv: &[ExprId], dim: usize, nf: usize) -> Vec<ExprId> {
    let sq = mat_vec_rect(g, &inv.s_bar, nf, qv);
    (0..dim).map(|k| g.add(vec![inv.i1[k], sq[k]])).collect()
}

/// `M_ff v` with `M_ff = Σ_k S̄_kk`. For invariants read from a data slot, as
/// `Σ_k (S̄_kk v)`: a product of each block with `v`, so that each row stays one
/// contraction per block (emitted as a loop, `sched::runs`) instead of a sum of
/// `(Σ_k S̄_kk,ij) v_j`.
fn mff_times(g: &mut Graph, inv: &Invariants, dim: usize, nf: usize, v: &[ExprId]) -> Vec<ExprId> {
    if !inv.from_data {
        let m: Vec<ExprId> = (0..nf * nf)
            .map(|e| {
                let parts: Vec<ExprId> = (0..dim)
                    .map(|k| inv.s_kl[(k * dim + k) * nf * nf + e])
                    .collect();
                g.add(parts)
            })
            .collect();
        return mat_vec_rect(g, &m, nf, v);
    }
    let blocks: Vec<Vec<ExprId>> = (0..dim)
        .map(|k| {
            let b = &inv.s_kl[(k * dim + k) * nf * nf..(k * dim + k + 1) * nf * nf];
            mat_vec_rect(g, b, nf, v)
        })
        .collect();
    (0..nf)
        .map(|i| {
            let parts: Vec<ExprId> = blocks.iter().map(|b| b[i]).collect();
            g.add(parts)
        })
        .collect()
}

/// `A v` for a row-major `A` with `cols` columns.
fn mat_vec_rect(g: &mut Graph, a: &[ExprId], cols: usize, v: &[ExprId]) -> Vec<ExprId> {
    a.chunks(cols).map(|row| dot(g, row, v)).collect()
}
