//! Derivation: the model's expressions → every quantity the runtime needs.
//!
//! Input: a lowered [`Model`] and a canonical [`Graph`]. Output: [`Derived`], the
//! symbolic mass matrix, generalized forces, constraint functions, Jacobians and
//! acceleration right-hand sides, with their sparsity (an entry is kept only when its
//! canonical expression is not the constant 0) and the model's structural flags.
//!
//! The mechanics follow math-spec §4, §5 and §8:
//! - `M = ∂²T/∂q̇²`, after checking that `T` is at most quadratic in `q̇`;
//! - `Q = Q_e + Q_v − ∂V/∂q`, `Q_v = ∂T/∂q − (∂²T/∂q̇∂q) q̇ − ∂²T/∂q̇∂t`;
//! - `γ_h = −(d/dt)(C_q q̇ + C_t)|_{q̈=0} = −(C_q q̇)_q q̇ − 2 C_qt q̇ − C_tt`;
//! - `G = ∂N/∂q̇` (checked independent of `q̇`), `g = N|_{q̇=0}`,
//!   `γ_nh = −(∂N/∂q) q̇ − ∂N/∂t = −(G q̇)_q q̇ − G_t q̇ − g_q q̇ − g_t`.
//!
//! Checks that need the derivatives (quadratic kinetic energy, linear non-holonomic
//! constraints and virtual work, symmetric mass matrix, non-trivial constraints) are
//! reported here with the span of the offending item.

mod checks;
pub mod free_motion;

use crate::ctxt::Ctxt;
use crate::model::expr::{Context, Translator};
use crate::model::Model;
use crate::sym::{diff, transform, Deps, ExprId, Graph, Var};

/// A structurally non-zero matrix entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Entry {
    pub row: u32,
    pub col: u32,
    pub expr: ExprId,
}

/// Explicit time dependence of each part of the model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[allow(clippy::struct_excessive_bools)]
pub struct TimeDeps {
    pub mass: bool,
    pub forces: bool,
    pub holonomic: bool,
    pub nonholonomic: bool,
}

/// Everything derived from a model.
#[derive(Debug)]
#[allow(clippy::struct_excessive_bools)]
pub struct Derived {
    pub param_defaults: Vec<f64>,
    /// Initial coordinates and velocities (in terms of parameters); `None` when the
    /// model declares none.
    pub initial: Option<(Vec<ExprId>, Vec<ExprId>)>,
    pub mass: Vec<Entry>,
    pub forces: Vec<ExprId>,
    /// The declared applied forces (`#[force]` items and virtual work), part of `forces`.
    pub applied: Vec<ExprId>,
    pub kinetic: ExprId,
    pub potential: ExprId,
    pub c: Vec<ExprId>,
    pub cq: Vec<Entry>,
    pub ct: Vec<ExprId>,
    pub gamma_h: Vec<ExprId>,
    pub gm: Vec<Entry>,
    pub gb: Vec<ExprId>,
    pub gamma_nh: Vec<ExprId>,
    pub time: TimeDeps,
    pub homogeneous: bool,
    pub conservative: bool,
    /// The free-motion residuals, when the mass matrix has a printable inverse.
    pub free_motion: Option<free_motion::FreeMotion>,
}

fn idx(i: usize) -> u32 {
    u32::try_from(i).expect("model size fits u32")
}

/// Derives every output of `model` in `g`. Returns `None` when a user error was
/// recorded in `cx`. In a raw graph (used only to measure the naive operation count)
/// the checks are skipped.
pub fn derive(cx: &Ctxt, model: &Model, g: &mut Graph) -> Option<Derived> {
    let n = model.nq();
    let checking = g.is_canonical();
    let mut tr = Translator::new(cx, model, g);
    tr.definitions();

    let param_defaults = checks::param_defaults(cx, model, &mut tr);

    let initial = if model
        .coords
        .iter()
        .any(|c| c.q0.is_some() || c.qd0.is_some())
    {
        let mut q0 = Vec::new();
        let mut qd0 = Vec::new();
        for c in &model.coords {
            for (slot, out) in [(&c.q0, &mut q0), (&c.qd0, &mut qd0)] {
                let id = match slot {
                    Some(e) => tr.standalone(e, Context::Initial),
                    None => Some(tr.g.constant(0.0)),
                };
                out.push(id.unwrap_or_else(|| tr.g.constant(0.0)));
            }
        }
        Some((q0, qd0))
    } else {
        None
    };

    let kinetic = if let Some(k) = &model.kinetic {
        tr.block(&k.block, Context::Kinetic)
    } else if let Some(m) = &model.mass_matrix {
        checks::kinetic_from_mass_matrix(cx, model, m, &mut tr, checking, &param_defaults)
    } else {
        None
    };
    let potential = match &model.potential {
        Some(p) => tr.block(&p.block, Context::Potential),
        None => Some(tr.g.constant(0.0)),
    };
    let mut applied: Vec<Option<ExprId>> = vec![Some(tr.g.constant(0.0)); n];
    for (i, f) in &model.forces {
        let v = tr.block(&f.block, Context::Force);
        let slot = &mut applied[*i as usize];
        *slot = match (*slot, v) {
            (Some(a), Some(b)) => Some(tr.g.add(vec![a, b])),
            _ => None,
        };
    }
    let virtual_work: Vec<(usize, Option<ExprId>)> = model
        .virtual_work
        .iter()
        .enumerate()
        .map(|(k, f)| (k, tr.block(&f.block, Context::VirtualWork)))
        .collect();
    let holonomic: Vec<Option<ExprId>> = model
        .holonomic
        .iter()
        .map(|f| tr.block(&f.block, Context::Holonomic))
        .collect();
    let nonholonomic: Vec<Option<ExprId>> = model
        .nonholonomic
        .iter()
        .map(|f| tr.block(&f.block, Context::Nonholonomic))
        .collect();
    drop(tr);

    // From here on every expression has been translated; stop at the first batch of
    // user errors so later checks don't report their consequences.
    if checking && cx.has_errors() {
        return None;
    }
    let t_kin = kinetic?;
    let v_pot = potential?;
    let qv: Vec<ExprId> = (0..n).map(|i| g.var(Var::Qd(idx(i)))).collect();
    let qd_pairs: Vec<(Var, ExprId)> = (0..n).map(|i| (Var::Q(idx(i)), qv[i])).collect();

    // Mass matrix and quadratic-velocity forces from T.
    let momenta: Vec<ExprId> = (0..n)
        .map(|i| diff::differentiate(g, t_kin, Var::Qd(idx(i))))
        .collect();
    let mut mass = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let m = diff::differentiate(g, momenta[i], Var::Qd(idx(j)));
            if checking && j >= i && g.deps(m).has(Deps::QD) {
                checks::not_quadratic(cx, model, g, m, i, j);
                return None;
            }
            if !g.is_zero(m) {
                mass.push(Entry {
                    row: idx(i),
                    col: idx(j),
                    expr: m,
                });
            }
        }
    }
    let mut forces = Vec::with_capacity(n);
    let mut applied_forces = Vec::with_capacity(n);
    for i in 0..n {
        let qi = Var::Q(idx(i));
        let dt_dq = diff::differentiate(g, t_kin, qi);
        let conv = diff::directional(g, momenta[i], &qd_pairs);
        let dp_dt = diff::differentiate(g, momenta[i], Var::Time);
        let dv_dq = diff::differentiate(g, v_pot, qi);
        let qe = applied[i]?;
        let neg_conv = g.neg(conv);
        let neg_dpdt = g.neg(dp_dt);
        let neg_dv = g.neg(dv_dq);
        forces.push(g.add(vec![qe, dt_dq, neg_conv, neg_dpdt, neg_dv]));
        applied_forces.push(qe);
    }
    let mut has_virtual_work = false;
    for (k, w) in virtual_work {
        let w = w?;
        has_virtual_work = true;
        let coefficients = checks::virtual_work(cx, model, g, k, w, checking)?;
        for (i, c) in coefficients.into_iter().enumerate() {
            forces[i] = g.add(vec![forces[i], c]);
            applied_forces[i] = g.add(vec![applied_forces[i], c]);
        }
    }

    // Holonomic constraints.
    let mut c = Vec::new();
    let mut cq = Vec::new();
    let mut ct = Vec::new();
    let mut gamma_h = Vec::new();
    for (r, h) in holonomic.into_iter().enumerate() {
        let h = h?;
        if checking && !checks::holonomic(cx, &model.holonomic[r], g, h) {
            continue;
        }
        let mut rate_terms = Vec::new();
        for j in 0..n {
            let d = diff::differentiate(g, h, Var::Q(idx(j)));
            if !g.is_zero(d) {
                cq.push(Entry {
                    row: idx(r),
                    col: idx(j),
                    expr: d,
                });
                rate_terms.push(g.mul(vec![d, qv[j]]));
            }
        }
        let h_t = diff::differentiate(g, h, Var::Time);
        rate_terms.push(h_t);
        let cdot = g.add(rate_terms);
        let along = diff::directional(g, cdot, &qd_pairs);
        let dt = diff::differentiate(g, cdot, Var::Time);
        let s = g.add(vec![along, dt]);
        c.push(h);
        ct.push(h_t);
        gamma_h.push(g.neg(s));
    }

    // Non-holonomic constraints.
    let mut gm = Vec::new();
    let mut gb = Vec::new();
    let mut gamma_nh = Vec::new();
    for (r, nh) in nonholonomic.into_iter().enumerate() {
        let nh = nh?;
        let mut row = Vec::new();
        for j in 0..n {
            let d = diff::differentiate(g, nh, Var::Qd(idx(j)));
            if checking && g.deps(d).has(Deps::QD) {
                checks::not_linear(cx, model, g, r, d);
                return None;
            }
            if !g.is_zero(d) {
                row.push(Entry {
                    row: idx(r),
                    col: idx(j),
                    expr: d,
                });
            }
        }
        if checking && !checks::nonholonomic(cx, &model.nonholonomic[r], g, nh, row.is_empty()) {
            continue;
        }
        gm.extend(row);
        let bias = transform::substitute(g, nh, &mut |g, v| match v {
            Var::Qd(_) => Some(g.constant(0.0)),
            _ => None,
        });
        gb.push(bias);
        let along = diff::directional(g, nh, &qd_pairs);
        let dt = diff::differentiate(g, nh, Var::Time);
        let s = g.add(vec![along, dt]);
        gamma_nh.push(g.neg(s));
    }
    if checking && cx.has_errors() {
        return None;
    }

    let timed = |g: &Graph, ids: &mut dyn Iterator<Item = ExprId>| {
        let mut any = false;
        for e in ids {
            any |= g.deps(e).has(Deps::TIME);
        }
        any
    };
    let time = TimeDeps {
        mass: timed(g, &mut mass.iter().map(|e| e.expr)),
        forces: timed(g, &mut forces.iter().copied()),
        holonomic: timed(g, &mut c.iter().copied()),
        nonholonomic: timed(g, &mut gm.iter().map(|e| e.expr).chain(gb.iter().copied())),
    };
    let homogeneous = gb.iter().all(|&b| g.is_zero(b));
    let t_at_rest = transform::substitute(g, t_kin, &mut |g, v| match v {
        Var::Qd(_) => Some(g.constant(0.0)),
        _ => None,
    });
    let gyroscopic_free = g.is_zero(t_at_rest)
        && momenta.iter().all(|&p| {
            let p0 = transform::substitute(g, p, &mut |g, v| match v {
                Var::Qd(_) => Some(g.constant(0.0)),
                _ => None,
            });
            g.is_zero(p0)
        });
    let conservative = model.forces.is_empty()
        && !has_virtual_work
        && gyroscopic_free
        && homogeneous
        && !g.deps(t_kin).has(Deps::TIME)
        && !g.deps(v_pot).has(Deps::TIME)
        && !time.holonomic
        && !time.nonholonomic;

    let rows = (0..c.len())
        .map(|r| (row_of(&cq, r), gamma_h[r]))
        .chain((0..gb.len()).map(|r| (row_of(&gm, r), gamma_nh[r])))
        .collect();
    let free_motion = free_motion::derive(
        g,
        &free_motion::Inputs {
            n,
            mass: &mass,
            forces: &forces,
            applied: &applied_forces,
            rows,
        },
    );

    Some(Derived {
        param_defaults,
        initial,
        mass,
        forces,
        applied: applied_forces,
        kinetic: t_kin,
        potential: v_pot,
        c,
        cq,
        ct,
        gamma_h,
        gm,
        gb,
        gamma_nh,
        time,
        homogeneous,
        conservative,
        free_motion,
    })
}

/// The entries of row `r` of a pattern-ordered matrix.
fn row_of(entries: &[Entry], r: usize) -> Vec<Entry> {
    entries
        .iter()
        .filter(|e| e.row == idx(r))
        .copied()
        .collect()
}
