//! The checks of the derivation stage and their diagnostics.

use proc_macro2::Span;
use quote::ToTokens;

use crate::ctxt::Ctxt;
use crate::model::expr::{Context, Translator};
use crate::model::Model;
use crate::parse::FnItem;

use super::Row;
use crate::sym::{diff, transform, Deps, ExprId, Graph, Node, Var};

use super::idx;

/// Evaluates the parameter defaults in declaration order (each may use those above).
pub fn param_defaults(cx: &Ctxt, model: &Model, tr: &mut Translator<'_>) -> Vec<f64> {
    let mut values: Vec<f64> = Vec::with_capacity(model.params.len());
    for (i, p) in model.params.iter().enumerate() {
        let v = tr
            .standalone(&p.default, Context::ParamDefault(idx(i)))
            .map(|id| {
                let known = values.clone();
                transform::eval(tr.g, &[id], &|v| match v {
                    Var::Param(j) => known[j as usize],
                    _ => f64::NAN,
                })[0]
            });
        match v {
            Some(v) if v.is_finite() => values.push(v),
            Some(v) => {
                cx.error_spanned_by(
                    &p.default,
                    format!("the default of `{}` evaluates to {v}", p.name),
                );
                values.push(0.0);
            }
            None => values.push(0.0),
        }
    }
    values
}

/// A deterministic pseudo-random sample in [-1, 1) (splitmix64).
fn sample(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    #[allow(clippy::cast_precision_loss)]
    let u = (z >> 11) as f64 / (1u64 << 53) as f64;
    2.0 * u - 1.0
}

/// `T = ½ q̇ᵀ M q̇` from a given mass matrix, after checking its shape and symmetry.
pub fn kinetic_from_mass_matrix(
    cx: &Ctxt,
    model: &Model,
    item: &FnItem,
    tr: &mut Translator<'_>,
    checking: bool,
    params: &[f64],
) -> Option<ExprId> {
    let rows = tr.matrix_block(&item.block)?;
    let n = model.nq();
    if rows.len() != n || rows.iter().any(|r| r.len() != n) {
        let shape = rows.iter().map(Vec::len).max().unwrap_or(0);
        cx.error_spanned_by(
            &item.name,
            format!(
                "`mass_matrix` is {}×{} but the mechanism has {n} coordinate{}; it must be {n}×{n}",
                rows.len(),
                shape,
                if n == 1 { "" } else { "s" }
            ),
        );
        return None;
    }
    if checking {
        let mut state = 0x5eed_u64;
        let mut points = Vec::new();
        for _ in 0..3 {
            let q: Vec<f64> = (0..n).map(|_| sample(&mut state)).collect();
            let t = sample(&mut state);
            points.push((q, t));
        }
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (rows[i][j].0, rows[j][i].0);
                if a == b {
                    continue;
                }
                let differs = points.iter().any(|(q, t)| {
                    let v = transform::eval(tr.g, &[a, b], &|v| match v {
                        Var::Q(k) => q[k as usize],
                        Var::Param(k) => params[k as usize],
                        Var::Time => *t,
                        _ => 0.0,
                    });
                    (v[0] - v[1]).abs() > 1e-12 * (1.0 + v[0].abs().max(v[1].abs()))
                });
                if differs {
                    cx.error_spanned_by(
                        &rows[j][i].1,
                        format!(
                            "the mass matrix is not symmetric: entry [{j}][{i}] `{}` differs from entry [{i}][{j}] `{}`",
                            rows[j][i].1.to_token_stream(),
                            rows[i][j].1.to_token_stream()
                        ),
                    );
                    return None;
                }
            }
        }
    }
    let g = &mut *tr.g;
    let half = g.constant(0.5);
    let mut terms = Vec::new();
    for (i, row) in rows.iter().enumerate() {
        for (j, &(m, _)) in row.iter().enumerate() {
            // Use the upper triangle for both halves so T is exactly symmetric.
            let m = if j >= i { m } else { rows[j][i].0 };
            let qi = g.var(Var::Qd(idx(i)));
            let qj = g.var(Var::Qd(idx(j)));
            terms.push(g.mul(vec![half, m, qi, qj]));
        }
    }
    Some(g.add(terms))
}

fn velocity_name(model: &Model, k: usize) -> String {
    format!("{}.dot()", model.coords[k].name)
}

/// The velocity that makes `e` fail a check: the first whose derivative of `e` is not
/// zero, else the first that occurs in `e` at all (through `signum`, whose derivative
/// is taken as zero), else "the velocities". Never an empty name.
fn culprit_velocity(model: &Model, g: &mut Graph, e: ExprId) -> String {
    let by_derivative = (0..model.nq()).find(|&k| {
        let d = diff::differentiate(g, e, Var::Qd(idx(k)));
        !g.is_zero(d)
    });
    let by_occurrence = || {
        transform::post_order(g, &[e])
            .into_iter()
            .filter_map(|id| match g.node(id) {
                Node::Var(Var::Qd(k)) => Some(*k as usize),
                _ => None,
            })
            .min()
    };
    match by_derivative.or_else(by_occurrence) {
        Some(k) => format!("`{}`", velocity_name(model, k)),
        None => "the velocities".to_owned(),
    }
}

/// Reports a kinetic energy whose Hessian entry `(i, j)` still depends on velocities.
pub fn not_quadratic(cx: &Ctxt, model: &Model, g: &mut Graph, m: ExprId, i: usize, j: usize) {
    let culprit = culprit_velocity(model, g, m);
    let span = model
        .kinetic
        .as_ref()
        .map_or_else(|| model.ident.span(), |k| k.name.span());
    cx.error_at(
        span,
        format!(
            "the kinetic energy is not quadratic in the velocities: its second derivative with respect to \
             `{}` and `{}` still depends on {culprit} (T must be T2 + T1 + T0)",
            velocity_name(model, i),
            velocity_name(model, j),
        ),
    );
}

/// The generalized forces `Q_i = ∂W/∂δq_i` of virtual-work item `k`, after checking that
/// `W` is linear and homogeneous in the variations.
pub fn virtual_work(
    cx: &Ctxt,
    model: &Model,
    g: &mut Graph,
    k: usize,
    w: ExprId,
    checking: bool,
) -> Option<Vec<ExprId>> {
    let item = &model.virtual_work[k];
    let mut out = Vec::new();
    for i in 0..model.nq() {
        let c = diff::differentiate(g, w, Var::Delta(idx(i)));
        if checking && g.deps(c).has(Deps::DELTA) {
            cx.error_spanned_by(
                &item.name,
                format!(
                    "virtual work `{}` is not linear in the variations: `delta({})` enters non-linearly",
                    item.name, model.coords[i].name
                ),
            );
            return None;
        }
        out.push(c);
    }
    if checking {
        let rest = transform::substitute(g, w, &mut |g, v| match v {
            Var::Delta(_) => Some(g.constant(0.0)),
            _ => None,
        });
        if !g.is_zero(rest) {
            cx.error_spanned_by(
                &item.name,
                format!(
                    "virtual work `{}` has a term without a variation; every term is a force times `delta(..)`",
                    item.name
                ),
            );
            return None;
        }
        if out.iter().all(|&c| g.is_zero(c)) {
            cx.error_spanned_by(
                &item.name,
                format!("virtual work `{}` is identically zero", item.name),
            );
            return None;
        }
    }
    Some(out)
}

/// Rejects trivial holonomic constraints. Returns whether the constraint is usable.
pub fn holonomic(cx: &Ctxt, row: &Row, g: &Graph) -> bool {
    let h = row.expr;
    if g.is_zero(h) {
        cx.error_at(
            row.span,
            format!("holonomic constraint `{}` is identically zero", row.name),
        );
        return false;
    }
    if !g.deps(h).has(Deps::Q) {
        cx.error_at(
            row.span,
            format!(
                "holonomic constraint `{}` does not depend on the coordinates",
                row.name
            ),
        );
        return false;
    }
    true
}

pub fn not_linear(cx: &Ctxt, model: &Model, g: &mut Graph, row: &Row, d: ExprId) {
    let culprit = culprit_velocity(model, g, d);
    cx.error_at(
        row.span,
        format!(
            "non-holonomic constraint `{}` is not linear in the velocities: {culprit} enters non-linearly",
            row.name
        ),
    );
}

pub fn nonholonomic(cx: &Ctxt, row: &Row, g: &Graph, no_velocity: bool) -> bool {
    if g.is_zero(row.expr) {
        cx.error_at(
            row.span,
            format!(
                "non-holonomic constraint `{}` is identically zero",
                row.name
            ),
        );
        return false;
    }
    if no_velocity {
        cx.error_at(
            row.span,
            format!(
                "non-holonomic constraint `{}` does not depend on the velocities; declare it `#[holonomic]`",
                row.name
            ),
        );
        return false;
    }
    true
}

/// Reports the first derived expression among `roots` that holds a constant which
/// overflowed or underflowed to a non-finite value (`1e308 * x.dot().powi(2)` in `T`
/// gives `M = 2e308 = inf`; a mass of `1e-320` gives an infinite inverse in the
/// free-motion residual), as an error at `span` naming `what` it is. Literal constants
/// are checked where they are written; these come from folding derived ones. Returns
/// whether every constant is finite.
pub fn finite(cx: &Ctxt, g: &Graph, roots: &[ExprId], what: &str, span: Span) -> bool {
    let bad = transform::post_order(g, roots)
        .into_iter()
        .find_map(|id| g.as_const(id).filter(|v| !v.is_finite()));
    match bad {
        None => true,
        Some(v) => {
            cx.error_at(
                span,
                format!(
                    "{what} holds a constant that evaluates to {v}: a derived constant overflows or underflows `f64`"
                ),
            );
            false
        }
    }
}
