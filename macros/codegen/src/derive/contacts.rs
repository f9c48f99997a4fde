//! Contacts: `#[contact(e)] fn name() -> f64 { gap }` and the body level's
//! `static name: Contact = PointPlane { .. }` (`PointSphere`) → the gap, its normal
//! Jacobian and what resting contact needs (docs/theory.md §impacts).
//!
//! Input: the model's contact items, translated in [`Context::Contact`] (coordinates,
//! parameters and time; no velocities), then the body level's contacts, whose gaps the
//! body level wrote as the signed distance of a point to a surface. Output: per contact the gap $\delta(q, t)$, its
//! time partial $\delta_t$ and $\gamma_c = -(D\dot q)_q\dot q - 2D_t\dot q - \delta_{tt}$
//! (so that $D\ddot q = \gamma_c$ keeps a closed contact closed, as $\gamma_h$ does for a
//! holonomic row), and the normal Jacobian $D = \partial\delta/\partial q$ with its
//! sparsity. The impact's normal velocity is $v_n = D\dot q + \delta_t$.
//!
//! Checks: a restitution parameter whose default lies outside $[0, 1]$, a gap that
//! does not depend on the coordinates (no motion can close it) are
//! spanned errors, and so is a derived constant that is not finite.

use proc_macro2::Span;

use super::{checks, idx, Entry, Row};
use crate::ctxt::Ctxt;
use crate::model::expr::{Context, Translator};
use crate::model::Model;
use crate::sym::{diff, Deps, ExprId, Graph, Var};

/// One contact, derived.
#[derive(Clone, Debug)]
pub struct Contact {
    pub name: String,
    pub docs: String,
    /// Index of the restitution parameter.
    pub restitution: u32,
    /// The gap $\delta(q, t)$.
    pub gap: ExprId,
    /// $\partial\delta/\partial t$.
    pub rate: ExprId,
    /// $\gamma_c$, with $D\ddot q = \gamma_c$ along a closed contact.
    pub gamma: ExprId,
}

/// The contacts of a model with their normal Jacobian.
#[derive(Clone, Debug, Default)]
pub struct Contacts {
    pub list: Vec<Contact>,
    /// The entries of $D$, row-major (row = contact).
    pub jacobian: Vec<Entry>,
}

/// A contact to derive: its gap and its restitution parameter, from a `#[contact(e)]`
/// function or a body-level `Contact` item.
#[derive(Clone, Debug)]
pub struct ContactRow {
    /// The gap, named.
    pub row: Row,
    /// Index of the restitution parameter.
    pub restitution: u32,
    /// The tokens naming it, for errors.
    pub restitution_span: Span,
}

/// Translates the gap functions (while the translator is alive).
pub fn translate(tr: &mut Translator<'_>, model: &Model) -> Vec<Option<ContactRow>> {
    model
        .contacts
        .iter()
        .map(|(e, f)| {
            let expr = tr.block(&f.block, Context::Contact)?;
            let restitution_span = match &f.role {
                crate::parse::Role::Contact(ident) => ident.span(),
                _ => f.name.span(),
            };
            Some(ContactRow {
                row: Row {
                    name: f.name.to_string(),
                    docs: f.docs.clone(),
                    span: f.name.span(),
                    expr,
                    velocity: None,
                },
                restitution: *e,
                restitution_span,
            })
        })
        .collect()
}

/// Differentiates the translated gaps. `None` when an error was recorded.
pub fn derive(
    cx: &Ctxt,
    model: &Model,
    g: &mut Graph,
    rows: Vec<Option<ContactRow>>,
    param_defaults: &[f64],
    checking: bool,
) -> Option<Contacts> {
    let n = model.nq();
    let qv: Vec<ExprId> = (0..n).map(|i| g.var(Var::Qd(idx(i)))).collect();
    let mut out = Contacts::default();
    let mut ok = true;
    for c in rows.iter().flatten() {
        let v = param_defaults
            .get(c.restitution as usize)
            .copied()
            .unwrap_or(0.0);
        if checking && !(0.0..=1.0).contains(&v) {
            let e = model
                .params
                .get(c.restitution as usize)
                .map(|p| p.name.to_string())
                .unwrap_or_default();
            cx.error_at(
                c.restitution_span,
                format!(
                    "the coefficient of restitution `{e}` of contact `{}` defaults to {v}, \
                     outside [0, 1]",
                    c.row.name
                ),
            );
            ok = false;
        }
    }
    for c in rows {
        let Some(ContactRow {
            row, restitution, ..
        }) = c
        else {
            ok = false;
            continue;
        };
        let gap = row.expr;
        if checking && !g.deps(gap).has(Deps::Q) {
            cx.error_at(
                row.span,
                format!(
                    "contact `{}`: the gap does not depend on the coordinates, so no motion \
                     can close it",
                    row.name
                ),
            );
            ok = false;
            continue;
        }
        let r = out.list.len();
        let mut rate_terms = Vec::new();
        let mut roots = vec![gap];
        for j in 0..n {
            let d = diff::differentiate(g, gap, Var::Q(idx(j)));
            if !g.is_zero(d) {
                out.jacobian.push(Entry {
                    row: idx(r),
                    col: idx(j),
                    expr: d,
                });
                rate_terms.push(g.mul(vec![d, qv[j]]));
                roots.push(d);
            }
        }
        let rate = diff::differentiate(g, gap, Var::Time);
        rate_terms.push(rate);
        let vn = g.add(rate_terms);
        let s = diff::rate(g, vn);
        let gamma = g.neg(s);
        roots.extend([rate, gamma]);
        if checking {
            let what = format!("contact `{}` or its derivatives", row.name);
            ok &= checks::finite(cx, g, &roots, &what, row.span);
        }
        out.list.push(Contact {
            name: row.name,
            docs: row.docs,
            restitution,
            gap,
            rate,
            gamma,
        });
    }
    ok.then_some(out)
}
