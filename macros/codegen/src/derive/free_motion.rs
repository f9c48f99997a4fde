//! Free-motion conditions (docs/theory.md §free-motion, \[S2\] eq. 18), derived symbolically.
//!
//! Input: the derived mass matrix $A$, forces $h$ (the generated `forces`, which already
//! hold $Q + \partial T/\partial q - T_{\dot q q}\dot q - T_{\dot q t}$), the declared
//! applied forces $Q$ (the `#[force]` items and the coefficients of the virtual work),
//! the constraint rows $J = [C_q; G]$ and $\gamma = [\gamma_h; \gamma_{nh}]$.
//!
//! Output, when $A^{-1}$ has a closed form worth printing (diagonal $A$ with no zero on
//! the diagonal, or a constant numeric $A$ that is regular): for every constraint $\beta$
//! the residual, affine in the applied forces,
//! $$w_\beta = w^0_\beta + K_{\beta s} Q_s,\qquad w^0 = -\gamma + J A^{-1} h^0,\quad
//!   K = J A^{-1},\quad h^0 = h - Q,$$
//! which is (S2-18) with $c = -\gamma_h$. The motion is free ($\lambda = 0$) iff $w = 0$.
//! Otherwise nothing is derived and nothing is emitted.
//!
//! Invariant: the applied-force symbols $Q_s$ appear only in the printed formulas, where
//! they are carried by the variation leaves `Var::Delta(s)` (the virtual work
//! $\delta W = Q_s\,\delta q_s$ is linear in $\delta q$ exactly as $w$ is in $Q$); they never
//! reach generated code, which receives $Q$ as a slice.

use std::cell::RefCell;
use std::collections::HashMap;

use super::Entry;
use crate::model::Model;
use crate::sym::{transform, Deps, ExprId, Graph, Node, Var};

/// The free-motion residual of every constraint, split as $w = w^0 + K Q$.
#[derive(Debug)]
pub struct FreeMotion {
    /// $w^0_\beta$ (the residual with no applied force), holonomic rows first.
    pub base: Vec<ExprId>,
    /// Structurally non-zero entries of $K = J A^{-1}$ (row: constraint, column:
    /// coordinate), sorted by row then column.
    pub coefficients: Vec<Entry>,
    /// $w_\beta$ with the applied forces as the symbols `Var::Delta(s)`.
    pub symbolic: Vec<ExprId>,
}

/// The inputs of the derivation, all from [`super::derive`].
#[derive(Debug)]
pub struct Inputs<'a> {
    pub n: usize,
    pub mass: &'a [Entry],
    pub forces: &'a [ExprId],
    pub applied: &'a [ExprId],
    /// Constraint rows: `(entries of the row of J, γ)`, holonomic first.
    pub rows: Vec<(Vec<Entry>, ExprId)>,
}

/// $A^{-1}$ as sparse rows of expressions, when it has a printable closed form.
fn inverse(g: &mut Graph, n: usize, mass: &[Entry]) -> Option<Vec<Vec<(usize, ExprId)>>> {
    if mass.iter().all(|e| e.row == e.col) {
        if mass.len() != n {
            return None; // a zero on the diagonal: A is singular
        }
        return Some(
            mass.iter()
                .map(|e| vec![(e.row as usize, g.powi(e.expr, -1))])
                .collect(),
        );
    }
    // A constant numeric matrix: Gauss–Jordan with partial pivoting at expansion time.
    let mut a = vec![vec![0.0; 2 * n]; n];
    for e in mass {
        a[e.row as usize][e.col as usize] = g.as_const(e.expr)?;
    }
    let scale = a.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
    for (i, row) in a.iter_mut().enumerate() {
        row[n + i] = 1.0;
    }
    for k in 0..n {
        let p = (k..n).max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))?;
        if a[p][k].abs() <= 1e-12 * scale {
            return None;
        }
        a.swap(k, p);
        let pivot = a[k][k];
        for v in &mut a[k] {
            *v /= pivot;
        }
        for i in (0..n).filter(|&i| i != k) {
            let f = a[i][k];
            if f != 0.0 {
                for j in 0..2 * n {
                    a[i][j] -= f * a[k][j];
                }
            }
        }
    }
    Some(
        a.iter()
            .map(|row| {
                (0..n)
                    .filter(|&j| row[n + j] != 0.0)
                    .map(|j| (j, g.constant(row[n + j])))
                    .collect()
            })
            .collect(),
    )
}

/// Derives the free-motion residuals, or `None` when they do not apply (no constraint,
/// or no closed-form inverse of the mass matrix).
pub fn derive(g: &mut Graph, inputs: &Inputs<'_>) -> Option<FreeMotion> {
    let n = inputs.n;
    if inputs.rows.is_empty() || !g.is_canonical() {
        return None;
    }
    let inv = inverse(g, n, inputs.mass)?;
    // K_βs = Σ_k J_βk (A⁻¹)_ks, over the non-zero entries of row k of A⁻¹.
    let h0: Vec<ExprId> = (0..n)
        .map(|s| g.sub(inputs.forces[s], inputs.applied[s]))
        .collect();
    let mut base = Vec::new();
    let mut coefficients = Vec::new();
    let mut symbolic = Vec::new();
    for (beta, (row, gamma)) in inputs.rows.iter().enumerate() {
        let mut k_row = vec![Vec::new(); n];
        for e in row {
            for &(s, a_inv) in &inv[e.col as usize] {
                k_row[s].push(g.mul(vec![e.expr, a_inv]));
            }
        }
        let mut terms = vec![g.neg(*gamma)];
        let mut sym_terms = Vec::new();
        for (s, parts) in k_row.into_iter().enumerate() {
            let k = g.add(parts);
            if g.is_zero(k) {
                continue;
            }
            terms.push(g.mul(vec![k, h0[s]]));
            let q = g.var(Var::Delta(u32::try_from(s).expect("model size fits u32")));
            sym_terms.push(g.mul(vec![k, q]));
            coefficients.push(Entry {
                row: u32::try_from(beta).expect("model size fits u32"),
                col: u32::try_from(s).expect("model size fits u32"),
                expr: k,
            });
        }
        let w0 = g.add(terms);
        sym_terms.push(w0);
        base.push(w0);
        symbolic.push(g.add(sym_terms));
    }
    debug_assert!(base.iter().all(|&w| !g.deps(w).has(Deps::DELTA)));
    Some(FreeMotion {
        base,
        coefficients,
        symbolic,
    })
}

/// The conditions $w_\beta = 0$ as infix text: coordinates by name, velocities primed
/// (`q1'`), the applied force on coordinate `x` as `Q_x`, parameters by name, e.g.
/// `2*q1' + t*Q_q1 + 2*Q_q2 - 3*Q_q3` for Example 1 of \[S2\].
///
/// A subexpression of at least a dozen operations (`SHARED_SIZE`) that occurs more than once
/// (in one formula or across them) is printed once, as a temporary `#k` defined in a
/// `where` clause of the first formula that uses it (`… + #1*x', where #1 = …`), so
/// that the text is linear in the size of the shared graph: printed as a tree, a
/// constraint nesting `sin` 400 deep gave formulas of 164 MB.
pub fn formulas(g: &Graph, model: &Model, fm: &FreeMotion) -> Vec<String> {
    let name = |v: Var| match v {
        Var::Time => "t".to_owned(),
        Var::Q(i) => model.coords[i as usize].name.to_string(),
        Var::Qd(i) => format!("{}'", model.coords[i as usize].name),
        Var::Delta(i) => format!("Q_{}", model.coords[i as usize].name),
        Var::Param(i) => model.params[i as usize].name.to_string(),
        Var::Input(i) => format!("u{i}"),
        Var::Data(i) => crate::model::data::entry_name(&model.data, i),
    };
    let (temps, order) = shared(g, &fm.symbolic);
    let p = Printer {
        g,
        name: &name,
        temps: &temps,
        used: RefCell::new(Vec::new()),
    };
    let mut defined = vec![false; order.len()];
    fm.symbolic
        .iter()
        .map(|&w| {
            let mut text = p.expr(w, SUM);
            // The temporaries this formula needs and no earlier one defined, with those
            // their definitions need in turn.
            let mut defs: Vec<(usize, String)> = Vec::new();
            loop {
                // (The borrow ends here: printing a definition records more uses.)
                let next = p.used.borrow_mut().pop();
                let Some(k) = next else { break };
                if !defined[k] {
                    defined[k] = true;
                    defs.push((k, p.body(order[k], SUM)));
                }
            }
            defs.sort_unstable_by_key(|d| d.0);
            for (i, (k, def)) in defs.iter().enumerate() {
                text.push_str(if i == 0 { ", where " } else { ", " });
                text.push_str(&format!("#{} = {def}", k + 1));
            }
            text
        })
        .collect()
}

/// Subexpressions of at least this many operations (a shared operand counted once)
/// that occur more than once in the formulas are printed as temporaries.
const SHARED_SIZE: usize = 12;

/// The temporaries of [`formulas`]: for each node its temporary number, and the nodes
/// in temporary order (a post-order, so definitions only use earlier temporaries).
fn shared(g: &Graph, roots: &[ExprId]) -> (HashMap<ExprId, usize>, Vec<ExprId>) {
    let order = transform::post_order(g, roots);
    let mut uses: HashMap<ExprId, u32> = HashMap::new();
    for &id in &order {
        for a in g.node(id).args() {
            *uses.entry(a).or_insert(0) += 1;
        }
    }
    for &r in roots {
        *uses.entry(r).or_insert(0) += 1;
    }
    let mut size: HashMap<ExprId, usize> = HashMap::new();
    let mut temps = HashMap::new();
    let mut list = Vec::new();
    for &id in &order {
        let node = g.node(id);
        let own = 1 + node
            .args()
            .iter()
            .map(|a| if temps.contains_key(a) { 1 } else { size[a] })
            .sum::<usize>();
        size.insert(id, own);
        let leaf = matches!(node, Node::Const(_) | Node::Var(_));
        if !leaf && own >= SHARED_SIZE && uses.get(&id).copied().unwrap_or(0) >= 2 {
            temps.insert(id, list.len());
            list.push(id);
        }
    }
    (temps, list)
}

/// Binding strengths of the formula printer.
const SUM: u8 = 0;
const PRODUCT: u8 = 1;
const POWER: u8 = 2;

/// A printer for formulas meant to be read: `a - b` rather than `a + (-1)*b`, `a/b`
/// rather than `a*b^-1`, integral constants without a fraction, and shared
/// subexpressions as temporaries `#k` (recorded in `used` when printed).
struct Printer<'a> {
    g: &'a Graph,
    name: &'a dyn Fn(Var) -> String,
    temps: &'a HashMap<ExprId, usize>,
    used: RefCell<Vec<usize>>,
}

impl Printer<'_> {
    fn number(v: f64) -> String {
        if v.fract() == 0.0 && v.abs() < 1e15 {
            format!("{v:.0}")
        } else {
            format!("{v:?}")
        }
    }

    /// The temporary's name when `e` is one (and records its use).
    fn temp(&self, e: ExprId) -> Option<String> {
        let k = *self.temps.get(&e)?;
        self.used.borrow_mut().push(k);
        Some(format!("#{}", k + 1))
    }

    /// `e` printed where an operand of binding strength `need` is expected: its
    /// temporary, or its body.
    fn expr(&self, e: ExprId, need: u8) -> String {
        self.temp(e).unwrap_or_else(|| self.body(e, need))
    }

    /// `e` itself (not its temporary) where an operand of binding strength `need` is
    /// expected.
    fn body(&self, e: ExprId, need: u8) -> String {
        let wrap = |s: String, own: u8| if own < need { format!("({s})") } else { s };
        match self.g.node(e) {
            Node::Const(b) => {
                let v = f64::from_bits(*b);
                wrap(Self::number(v), if v < 0.0 { SUM } else { POWER })
            }
            Node::Var(v) => (self.name)(*v),
            Node::Add(terms) => {
                let mut s = String::new();
                for (i, &t) in terms.iter().enumerate() {
                    let (neg, body) = self.signed(t);
                    s.push_str(match (i, neg) {
                        (0, false) => "",
                        (0, true) => "-",
                        (_, false) => " + ",
                        (_, true) => " - ",
                    });
                    s.push_str(&body);
                }
                wrap(s, SUM)
            }
            Node::Powi(x, n) if *n > 0 => wrap(format!("{}^{n}", self.expr(*x, POWER + 1)), POWER),
            Node::Mul(_) | Node::Powi(_, _) => {
                let (neg, body) = self.signed_body(e);
                if neg {
                    wrap(format!("-{body}"), SUM)
                } else {
                    body
                }
            }
            Node::Powf(x, y) => wrap(
                format!("{}^({})", self.expr(*x, POWER + 1), self.expr(*y, SUM)),
                POWER,
            ),
            Node::Call(f, x) => format!("{}({})", f.name(), self.expr(*x, SUM)),
            Node::Atan2(y, x) => {
                format!("atan2({}, {})", self.expr(*y, SUM), self.expr(*x, SUM))
            }
        }
    }

    /// A term of a sum as (is negative, its magnitude printed as a product).
    fn signed(&self, e: ExprId) -> (bool, String) {
        match self.temp(e) {
            Some(t) => (false, t),
            None => self.signed_body(e),
        }
    }

    /// [`Printer::signed`] of `e` itself, not of its temporary.
    fn signed_body(&self, e: ExprId) -> (bool, String) {
        let factors: Vec<ExprId> = match self.g.node(e) {
            Node::Mul(f) => f.to_vec(),
            Node::Powi(_, n) if *n < 0 => vec![e],
            Node::Const(b) if f64::from_bits(*b) < 0.0 => {
                return (true, Self::number(-f64::from_bits(*b)));
            }
            _ => return (false, self.expr(e, PRODUCT)),
        };
        let mut coefficient = 1.0;
        let (mut num, mut den) = (Vec::new(), Vec::new());
        for f in factors {
            match self.g.node(f) {
                Node::Const(b) => coefficient *= f64::from_bits(*b),
                Node::Powi(x, n) if *n < 0 => den.push(if *n == -1 {
                    self.expr(*x, POWER)
                } else {
                    format!("{}^{}", self.expr(*x, POWER + 1), -i64::from(*n))
                }),
                Node::Powi(x, n) => num.push(format!("{}^{n}", self.expr(*x, POWER + 1))),
                _ => num.push(self.expr(f, PRODUCT + 1)),
            }
        }
        if coefficient.abs() != 1.0 || num.is_empty() {
            num.insert(0, Self::number(coefficient.abs()));
        }
        let mut s = num.join("*");
        match den.len() {
            0 => {}
            1 => s = format!("{s}/{}", den[0]),
            _ => s = format!("{s}/({})", den.join("*")),
        }
        (coefficient < 0.0, s)
    }
}
