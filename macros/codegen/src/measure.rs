//! Measurements of the generator's output: operation counts of the emitted code against
//! the naive expression trees, and a readable dump of every derived quantity.
//!
//! The *naive tree* is what differentiating the user's expressions gives with no
//! simplification and no sharing: the same derivation run in a raw graph (which only
//! hash-conses), with every output expanded as a tree. The *emitted* count is what the
//! generated functions evaluate: canonical expressions with each shared node computed
//! once per function.

use std::fmt::Write;

use proc_macro2::TokenStream;

use crate::derive::{self, Derived, Entry};
use crate::sym::{display, transform, ExprId, Graph, Var};
use crate::{ctxt, model, parse, Analysis};

/// Arithmetic operation counts of one model's generated functions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OpCounts {
    /// Operations of the outputs as trees, derived without simplification; `None` where
    /// the model cannot be derived without simplification (shape functions of deformable
    /// bodies, whose linearity in `q_f` only the canonical graph shows).
    pub naive_tree: Option<u128>,
    /// Operations of the simplified outputs as trees (simplification, no sharing).
    pub simplified_tree: u128,
    /// Operations of the emitted straight-line code (simplification and sharing).
    pub emitted: u64,
    /// Operations of one right-hand side: the fused `dynamics_terms` (M, forces, C_q,
    /// γ_h, G, γ_nh evaluated together, each shared node once).
    pub rhs: u64,
}

/// The outputs of each generated function, in emission order.
fn functions(d: &Derived) -> Vec<Vec<ExprId>> {
    let e = |v: &[Entry]| v.iter().map(|e| e.expr).collect::<Vec<_>>();
    vec![
        e(&d.mass),
        d.forces.clone(),
        d.c.clone(),
        e(&d.cq),
        d.ct.clone(),
        d.gamma_h.clone(),
        e(&d.gm),
        d.gb.clone(),
        d.gamma_nh.clone(),
        vec![d.kinetic],
        vec![d.potential],
        d.contacts.list.iter().map(|k| k.gap).collect(),
        e(&d.contacts.jacobian),
        d.contacts.list.iter().map(|k| k.rate).collect(),
        d.contacts.list.iter().map(|k| k.gamma).collect(),
    ]
}

/// Counts the operations of the model in `input` (a `#[mechanism]` module body).
///
/// # Errors
/// The model's diagnostics, as the macro would report them.
pub fn op_counts(args: TokenStream, input: TokenStream) -> syn::Result<OpCounts> {
    let analysis = crate::analyze(args.clone(), input.clone())?;
    let fns = functions(&analysis.derived);
    let all: Vec<ExprId> = fns.iter().flatten().copied().collect();
    let simplified_tree = transform::tree_op_count(&analysis.graph, &all);
    let emitted = fns
        .iter()
        .map(|roots| transform::op_count(&analysis.graph, roots))
        .sum();

    let d = &analysis.derived;
    let e = |v: &[Entry]| v.iter().map(|e| e.expr).collect::<Vec<_>>();
    let rhs_roots: Vec<ExprId> = [
        e(&d.mass),
        d.forces.clone(),
        e(&d.cq),
        d.gamma_h.clone(),
        e(&d.gm),
        d.gamma_nh.clone(),
    ]
    .concat();
    let rhs = transform::op_count(&analysis.graph, &rhs_roots);

    let cx = ctxt::Ctxt::new();
    let ast = parse::parse(&cx, args, input).expect("parsed once already");
    let model = model::lower(&cx, ast);
    let mut raw = Graph::raw();
    // Deformable bodies given by shape functions need the canonical graph's
    // simplification to recognize `N(ξ) q_f` as linear: their naive tree is not counted.
    let naive = derive::derive(&cx, &model, &mut raw);
    let _ = cx.check();
    let naive_tree = naive.map(|naive| {
        let naive_all: Vec<ExprId> = functions(&naive).into_iter().flatten().collect();
        transform::tree_op_count(&raw, &naive_all)
    });
    Ok(OpCounts {
        naive_tree,
        simplified_tree,
        emitted,
        rhs,
    })
}

/// Largest tree (in operations) that [`Analysis::describe`] prints as a formula.
const TREE_PRINT_LIMIT: u128 = 2000;

impl Analysis {
    /// Every derived quantity as an infix formula, one per line, with the model's names
    /// (`x'` is the velocity of `x`). This is the symbolic layer of the snapshot tests.
    pub fn describe(&self) -> String {
        let m = &self.model;
        let name = |v: Var| match v {
            Var::Time => "t".to_owned(),
            Var::Q(i) => m.coords[i as usize].name.to_string(),
            Var::Qd(i) => format!("{}'", m.coords[i as usize].name),
            Var::Delta(i) => format!("δ{}", m.coords[i as usize].name),
            Var::Param(i) => m.params[i as usize].name.to_string(),
            Var::Input(i) => format!("u{i}"),
            Var::Data(i) => crate::model::data::entry_name(&m.data, i),
        };
        let g = &self.graph;
        let d = &self.derived;
        // A formula whose tree is large (a bicycle's γ) would print as megabytes of
        // text: it is summarized, and the emitted code (linear in the DAG) shows it.
        let all: Vec<ExprId> = functions(d).into_iter().flatten().collect();
        let sizes: std::collections::HashMap<ExprId, u128> = all
            .iter()
            .copied()
            .zip(transform::tree_op_counts(g, &all))
            .collect();
        let f = |e: ExprId| {
            let ops = sizes.get(&e).copied().unwrap_or(0);
            if ops > TREE_PRINT_LIMIT {
                format!("⟨{ops} operations as a tree; see the emitted code⟩")
            } else {
                display::to_infix(g, e, &name)
            }
        };
        let mut s = String::new();
        let coord = |i: u32| m.coords[i as usize].name.to_string();
        let _ = writeln!(s, "T = {}", f(d.kinetic));
        let _ = writeln!(s, "V = {}", f(d.potential));
        for e in &d.mass {
            let _ = writeln!(s, "M[{}, {}] = {}", coord(e.row), coord(e.col), f(e.expr));
        }
        for (i, &q) in d.forces.iter().enumerate() {
            let _ = writeln!(s, "Q[{}] = {}", m.coords[i].name, f(q));
        }
        for (r, item) in m.holonomic.iter().enumerate() {
            let _ = writeln!(s, "C[{}] = {}", item.name, f(d.c[r]));
            for e in d.cq.iter().filter(|e| e.row as usize == r) {
                let _ = writeln!(s, "C_q[{}, {}] = {}", item.name, coord(e.col), f(e.expr));
            }
            if !g.is_zero(d.ct[r]) {
                let _ = writeln!(s, "C_t[{}] = {}", item.name, f(d.ct[r]));
            }
            let _ = writeln!(s, "γ_h[{}] = {}", item.name, f(d.gamma_h[r]));
        }
        for (r, item) in m.nonholonomic.iter().enumerate() {
            for e in d.gm.iter().filter(|e| e.row as usize == r) {
                let _ = writeln!(s, "G[{}, {}] = {}", item.name, coord(e.col), f(e.expr));
            }
            let _ = writeln!(s, "g[{}] = {}", item.name, f(d.gb[r]));
            let _ = writeln!(s, "γ_nh[{}] = {}", item.name, f(d.gamma_nh[r]));
        }
        for (r, k) in d.contacts.list.iter().enumerate() {
            let e = &m.params[k.restitution as usize].name;
            let _ = writeln!(s, "gap[{}] = {} (restitution {e})", k.name, f(k.gap));
            for en in d.contacts.jacobian.iter().filter(|en| en.row as usize == r) {
                let _ = writeln!(s, "D[{}, {}] = {}", k.name, coord(en.col), f(en.expr));
            }
            if !g.is_zero(k.rate) {
                let _ = writeln!(s, "gap_t[{}] = {}", k.name, f(k.rate));
            }
            let _ = writeln!(s, "γ_c[{}] = {}", k.name, f(k.gamma));
        }
        let _ = writeln!(
            s,
            "time dependence: mass {}, forces {}, holonomic {}, nonholonomic {}; conservative {}",
            d.time.mass, d.time.forces, d.time.holonomic, d.time.nonholonomic, d.conservative
        );
        s
    }
}

#[cfg(test)]
mod tests {
    use quote::quote;

    /// The naive derivation runs the body level in a raw graph, where the symmetry of a
    /// full inertia tensor cannot be decided (nothing simplifies `a − a`): it must not
    /// be reported there, or the operation counts of every such model fail.
    #[test]
    fn op_counts_of_a_body_with_a_full_inertia_tensor() {
        let model = quote! {
            mod top {
                static x: Coordinate = Coordinate {};
                static y: Coordinate = Coordinate {};
                static z: Coordinate = Coordinate {};
                static a: Coordinate = Coordinate {};
                static b: Coordinate = Coordinate {};
                static top: Body = Body {
                    origin: [x, y, z],
                    rotation: rot_z(a) * rot_x(b),
                    mass: 1.0,
                    inertia: [[0.3, 0.0, 0.02], [0.0, 0.4, 0.0], [0.02, 0.0, 0.5]],
                };
            }
        };
        let counts = super::op_counts(quote!(), model).expect("the model derives");
        assert!(counts.naive_tree.expect("a rigid body derives raw") >= counts.simplified_tree);
        assert!(counts.simplified_tree >= u128::from(counts.emitted));
    }
}
