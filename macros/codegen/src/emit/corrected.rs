//! `Mechanism::dynamics_terms_corrected`: the fused dynamics terms with the
//! velocities corrected between the position terms and the velocity terms.
//!
//! Input: the roots of `dynamics_terms` (`C`, `M`, `Q`, `C_q`, `γ_h`, `G`, `γ_nh`). Output: one
//! function whose body is the schedule of `dynamics_terms` split in two: the loads of
//! `t`, `q`, the parameters and data, every temporary and output that does not depend on
//! a velocity (so `C_q` and `G`, and the sines and cosines of the angles), then a call
//! of the runtime's correction with `C_q` and `G` (which may change `q̇`), then the loads
//! of `q̇` and everything that depends on it. Coordinate partitioning projects the
//! velocities onto the constraints at the corrected positions with `C_q` and `G` and
//! needs `M`, `Q` and `γ` at the projected velocities: in one call, what the two share
//! is computed once (on `andrews`, the sines and cosines of `holonomic_jacobian`).
//! Every temporary is still computed once; the split only orders them (a temporary that
//! does not depend on `q̇` never depends on one that does). What only `C` needs comes
//! last, under the same guard as in `dynamics_terms`: computed only when asked for.

use proc_macro2::{Ident, Span, TokenStream};
use quote::quote;

use super::expr::Printer;
use super::{
    arg, data_slots, dynamics_roots, guard_constraints, read_var, reads_data_inline, store_term,
    ModelNames, MAX_LETS,
};
use crate::derive::Derived;
use crate::sched;
use crate::sym::{Deps, ExprId, Graph, Var};

/// The trait method, or nothing (the trait's default, which evaluates `C_q` and `G`
/// on their own, then `dynamics_terms`) when the model has no constraint rows, when no
/// output depends on a velocity, or when `dynamics_terms` has more than [`MAX_LETS`]
/// temporaries: the function repeats `dynamics_terms`, and for the largest models
/// (long chains, many elastic modes) compiling it twice costs more than the shared
/// sines save.
pub(super) fn dynamics_terms_corrected(g: &Graph, names: &ModelNames, d: &Derived) -> TokenStream {
    if d.cq.is_empty() && d.gm.is_empty() {
        return TokenStream::new();
    }
    let (roots, slots) = dynamics_roots(d);
    // The schedule of `super::body`: contractions of data slots become loops.
    let prog = sched::schedule_with(g, &roots, &data_slots(names));
    if !prog.reads(|v| matches!(v, Var::Qd(_))) || prog.lets.len() > MAX_LETS {
        return TokenStream::new();
    }
    let inline_data = reads_data_inline(&prog);
    // Which nodes depend on a velocity: the graph's dependency summary of each node.
    let moving = |id: ExprId| g.deps(id).has(Deps::QD);
    // What only `C` needs (it depends on no velocity) goes under the guard at the end.
    let optional = d.c.len();
    let (needed, needed_vars) = prog.needed(g, &roots[optional..]);
    let c = Ident::new(&names.out_c, Span::call_site());

    // At most MAX_LETS temporaries: each is a `let` (see `super::body`).
    let printer = Printer {
        g,
        prog: &prog,
        names,
        array: None,
        inline_data,
    };
    let mut before = TokenStream::new();
    let mut after = TokenStream::new();
    let mut guarded = TokenStream::new();
    for v in &prog.vars {
        if inline_data && matches!(v, Var::Data(_)) {
            continue;
        }
        let read = read_var(names, *v);
        if !needed_vars.contains(v) {
            guarded.extend(read);
        } else if matches!(v, Var::Qd(_)) {
            after.extend(read);
        } else {
            before.extend(read);
        }
    }
    for (k, &id) in prog.lets.iter().enumerate() {
        // A sine–cosine pair shares its argument's dependencies: both on one side.
        let stmt = printer.define(k, id);
        if !needed[id.index()] {
            guarded.extend(stmt);
        } else if moving(id) {
            after.extend(stmt);
        } else {
            before.extend(stmt);
        }
    }
    for (k, &r) in roots.iter().enumerate() {
        let (ts, _) = printer.expr(r, false);
        let stmt = store_term(&slots[k], &c, ts);
        if k < optional {
            guarded.extend(stmt);
        } else if moving(r) {
            after.extend(stmt);
        } else {
            before.extend(stmt);
        }
    }
    let guarded = guard_constraints(&c, guarded);
    let t = arg(&prog, "t", |v| *v == Var::Time);
    let q = arg(&prog, "q", |v| matches!(v, Var::Q(_)));
    // Contractions read `qd` as a slice: after the correction, like the loads.
    quote! {
        fn dynamics_terms_corrected(
            &self,
            #t: f64,
            #q: &[f64],
            qd: &mut [f64],
            out: ::pfaff::__private::DynamicsTerms<'_>,
            correct: &mut dyn ::core::ops::FnMut(&[f64], &[f64], &mut [f64]),
        ) {
            #before
            correct(out.holonomic_jacobian, out.nonholonomic_matrix, qd);
            #after
            #guarded
        }
    }
}
