//! The table of operations: every function the description language knows, with its
//! name, its numeric evaluation and its derivative rule.
//!
//! Adding a function touches this file only: a variant of [`Func`], its name (the
//! `f64` method it is written as and emitted as), `eval`, and `derivative`. The
//! structural nodes (sums, products, powers, `atan2`) have their partial-derivative
//! rules in [`partials`] below, so the chain rule in `diff` is generic.
//!
//! Derivative conventions at non-smooth points: `d|x|/dx` is emitted as `x.signum()`,
//! so at `x = 0.0` it is Rust's `0.0_f64.signum() = 1.0` (a one-sided derivative; `-1.0`
//! at `-0.0`), and `d signum(x)/dx = 0` everywhere (the jump at 0 is not represented).
//! Models that need a smooth force through 0 should use a smooth surrogate such as
//! `x / (x * x + eps).sqrt()`.

use super::graph::{ExprId, Graph, Node};

/// A unary function of the description language.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func {
    Sqrt,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Exp,
    Ln,
    Sinh,
    Cosh,
    Tanh,
    Abs,
    Signum,
}

impl Func {
    /// Every unary function, in a fixed order (used for diagnostics).
    pub const ALL: [Func; 14] = [
        Func::Sqrt,
        Func::Sin,
        Func::Cos,
        Func::Tan,
        Func::Asin,
        Func::Acos,
        Func::Atan,
        Func::Exp,
        Func::Ln,
        Func::Sinh,
        Func::Cosh,
        Func::Tanh,
        Func::Abs,
        Func::Signum,
    ];

    /// The `f64` method name, as written by users and emitted.
    pub fn name(self) -> &'static str {
        match self {
            Func::Sqrt => "sqrt",
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Asin => "asin",
            Func::Acos => "acos",
            Func::Atan => "atan",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Tanh => "tanh",
            Func::Abs => "abs",
            Func::Signum => "signum",
        }
    }

    /// Looks a function up by its method name.
    pub fn from_name(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Numeric value.
    pub fn eval(self, x: f64) -> f64 {
        match self {
            Func::Sqrt => x.sqrt(),
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Asin => x.asin(),
            Func::Acos => x.acos(),
            Func::Atan => x.atan(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Sinh => x.sinh(),
            Func::Cosh => x.cosh(),
            Func::Tanh => x.tanh(),
            Func::Abs => x.abs(),
            Func::Signum => x.signum(),
        }
    }

    /// Odd functions satisfy `f(−x) = −f(x)`; the simplifier pulls signs out of them.
    pub fn is_odd(self) -> bool {
        matches!(
            self,
            Func::Sin | Func::Tan | Func::Asin | Func::Atan | Func::Sinh | Func::Tanh
        )
    }

    /// Even functions satisfy `f(−x) = f(x)`.
    pub fn is_even(self) -> bool {
        matches!(self, Func::Cos | Func::Cosh | Func::Abs)
    }

    /// `f'(x)` as an expression, given the argument `x` and the node `y = f(x)` itself
    /// (rules may reuse the result, as in `exp' = exp`).
    pub fn derivative(self, g: &mut Graph, x: ExprId, y: ExprId) -> ExprId {
        match self {
            // 1 / (2 sqrt x)
            Func::Sqrt => {
                let inv = g.powi(y, -1);
                let half = g.constant(0.5);
                g.mul(vec![half, inv])
            }
            Func::Sin => g.call(Func::Cos, x),
            Func::Cos => {
                let s = g.call(Func::Sin, x);
                g.neg(s)
            }
            // 1 + tan²x
            Func::Tan => {
                let one = g.constant(1.0);
                let y2 = g.powi(y, 2);
                g.add(vec![one, y2])
            }
            // ±1 / sqrt(1 − x²)
            Func::Asin | Func::Acos => {
                let one = g.constant(1.0);
                let x2 = g.powi(x, 2);
                let mx2 = g.neg(x2);
                let d = g.add(vec![one, mx2]);
                let s = g.call(Func::Sqrt, d);
                let r = g.powi(s, -1);
                if self == Func::Asin {
                    r
                } else {
                    g.neg(r)
                }
            }
            // 1 / (1 + x²)
            Func::Atan => {
                let one = g.constant(1.0);
                let x2 = g.powi(x, 2);
                let d = g.add(vec![one, x2]);
                g.powi(d, -1)
            }
            Func::Exp => y,
            Func::Ln => g.powi(x, -1),
            Func::Sinh => g.call(Func::Cosh, x),
            Func::Cosh => g.call(Func::Sinh, x),
            // 1 − tanh²x
            Func::Tanh => {
                let one = g.constant(1.0);
                let y2 = g.powi(y, 2);
                let m = g.neg(y2);
                g.add(vec![one, m])
            }
            Func::Abs => g.call(Func::Signum, x),
            Func::Signum => g.constant(0.0),
        }
    }
}

/// The partial derivatives of node `id` with respect to each of its operands, in operand
/// order: `∂node/∂arg_k`. Leaves have no operands.
pub fn partials(g: &mut Graph, id: ExprId) -> Vec<(ExprId, ExprId)> {
    partials_where(g, id, &|_| true)
}

/// The partials of [`partials`] for the operands `k` with `keep(k)` only, in order.
/// Sums and products build only those; other operations (at most two operands) build
/// all of them.
pub fn partials_where(
    g: &mut Graph,
    id: ExprId,
    keep: &dyn Fn(usize) -> bool,
) -> Vec<(ExprId, ExprId)> {
    let node = g.node(id).clone();
    match node {
        Node::Const(_) | Node::Var(_) => Vec::new(),
        Node::Add(terms) => {
            let one = g.constant(1.0);
            (0..terms.len())
                .filter(|&k| keep(k))
                .map(|k| (terms[k], one))
                .collect()
        }
        // ∂(Π a_j)/∂a_k = Π_{j≠k} a_j
        Node::Mul(factors) => (0..factors.len())
            .filter(|&k| keep(k))
            .map(|k| {
                let others: Vec<ExprId> = factors
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != k)
                    .map(|(_, &f)| f)
                    .collect();
                (factors[k], g.mul(others))
            })
            .collect(),
        // d xⁿ = n xⁿ⁻¹
        Node::Powi(x, n) => {
            let c = g.constant(f64::from(n));
            let p = match n.checked_sub(1) {
                Some(m) => g.powi(x, m),
                // `n = i32::MIN`: `x^(n−1) = xⁿ · x⁻¹`.
                None => {
                    let inv = g.powi(x, -1);
                    g.mul(vec![id, inv])
                }
            };
            vec![(x, g.mul(vec![c, p]))]
        }
        // d xʸ = y xʸ⁻¹ dx + xʸ ln x dy
        Node::Powf(x, y) => {
            let one = g.constant(-1.0);
            let ym1 = g.add(vec![y, one]);
            let p = g.powf(x, ym1);
            let dx = g.mul(vec![y, p]);
            let lx = g.call(Func::Ln, x);
            let dy = g.mul(vec![id, lx]);
            vec![(x, dx), (y, dy)]
        }
        Node::Call(f, x) => vec![(x, f.derivative(g, x, id))],
        // atan2(y, x): ∂/∂y = x / (x² + y²), ∂/∂x = −y / (x² + y²)
        Node::Atan2(y, x) => {
            let x2 = g.powi(x, 2);
            let y2 = g.powi(y, 2);
            let r2 = g.add(vec![x2, y2]);
            let inv = g.powi(r2, -1);
            let dy = g.mul(vec![x, inv]);
            let my = g.neg(y);
            let dx = g.mul(vec![my, inv]);
            vec![(y, dy), (x, dx)]
        }
    }
}
