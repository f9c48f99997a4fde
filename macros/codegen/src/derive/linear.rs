//! The linearization Jacobian, derived only for `#[mechanism(linearize)]`.
//!
//! Input: the derived M, Q, C_q, C_t, γ_h, G, g, γ_nh. Output: the sparse Jacobian with
//! respect to `[q; q̇]` of the stacked residuals (docs/theory.md §constraints)
//!
//! ```text
//! rows 0..n            M(q) u_a + C_qᵀ u_λ + Gᵀ u_μ − Q(q, q̇, t)
//! rows n..n+m_h        C_q u_a − γ_h(q, q̇, t)
//! rows ..+m_nh         G u_a − γ_nh(q, q̇, t)
//! rows ..+m_h          C_q q̇ + C_t
//! rows ..+m_nh         G q̇ + g
//! ```
//!
//! where `u = [u_a; u_λ; u_μ]` is a vector the caller passes at run time (the
//! accelerations and multipliers of the operating point, as `Var::Input`). Evaluated at a
//! solution of the index-1 equations, these are exactly the partial derivatives the
//! linearized equations of motion need: the runtime (`pfaff::linearize`) eliminates the
//! dependent coordinates, velocities, accelerations and multipliers from them with linear
//! solves, so the state matrix is exact up to rounding instead of a difference quotient.
//! Columns `0..n` are `∂/∂q`, columns `n..2n` are `∂/∂q̇`.

use super::{idx, Derived, Entry};
use crate::sym::{diff, Graph, Var};

/// The derived Jacobian.
#[derive(Debug)]
pub struct Linear {
    /// Structurally non-zero entries, row by row.
    pub entries: Vec<Entry>,
    /// Length of the input vector `u`: `n + m_h + m_nh`.
    pub inputs: usize,
    /// Number of residual rows: `n + 2 m_h + 2 m_nh`.
    pub rows: usize,
}

/// Derives the Jacobian of the stacked residuals of the module docs.
pub fn derive(g: &mut Graph, d: &Derived, n: usize) -> Linear {
    let (mh, mnh) = (d.c.len(), d.gb.len());
    let u: Vec<_> = (0..n + mh + mnh)
        .map(|k| g.var(Var::Input(idx(k))))
        .collect();
    let qd: Vec<_> = (0..n).map(|j| g.var(Var::Qd(idx(j)))).collect();
    let mut terms: Vec<Vec<_>> = vec![Vec::new(); n + 2 * (mh + mnh)];
    for e in &d.mass {
        terms[e.row as usize].push(g.mul(vec![e.expr, u[e.col as usize]]));
    }
    for e in &d.cq {
        let (r, c) = (e.row as usize, e.col as usize);
        terms[c].push(g.mul(vec![e.expr, u[n + r]]));
        terms[n + r].push(g.mul(vec![e.expr, u[c]]));
        terms[n + mh + mnh + r].push(g.mul(vec![e.expr, qd[c]]));
    }
    for e in &d.gm {
        let (r, c) = (e.row as usize, e.col as usize);
        terms[c].push(g.mul(vec![e.expr, u[n + mh + r]]));
        terms[n + mh + r].push(g.mul(vec![e.expr, u[c]]));
        terms[n + 2 * mh + mnh + r].push(g.mul(vec![e.expr, qd[c]]));
    }
    for i in 0..n {
        terms[i].push(g.neg(d.forces[i]));
    }
    for r in 0..mh {
        terms[n + r].push(g.neg(d.gamma_h[r]));
        terms[n + mh + mnh + r].push(d.ct[r]);
    }
    for r in 0..mnh {
        terms[n + mh + r].push(g.neg(d.gamma_nh[r]));
        terms[n + 2 * mh + mnh + r].push(d.gb[r]);
    }
    let rows = terms.len();
    let mut entries = Vec::new();
    for (r, t) in terms.into_iter().enumerate() {
        let residual = g.add(t);
        // Columns: the coordinates, then the velocities (only those present).
        for (offset, var) in [(0, Var::Q as fn(u32) -> Var), (n, Var::Qd)] {
            for (j, e) in diff::gradient(g, residual, n, var) {
                entries.push(Entry {
                    row: idx(r),
                    col: idx(offset + j as usize),
                    expr: e,
                });
            }
        }
    }
    Linear {
        entries,
        inputs: n + mh + mnh,
        rows,
    }
}
