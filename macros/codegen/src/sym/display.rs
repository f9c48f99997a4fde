//! An infix printer for expressions, used in snapshots of the symbolic layer and in
//! diagnostics. Variables print through a naming callback so that the model's names
//! appear (`x`, `x'` for velocities, `δx` for variations). Like the emitter, it turns
//! `(−1)·x`, `a + (−1)·b` and `a · b⁻¹` back into `-x`, `a - b` and `a / b`.

use super::graph::{ExprId, Graph, Node, Var};

/// Binding strength: sums < products < unary minus < atoms.
const SUM: u8 = 1;
const PRODUCT: u8 = 2;
const UNARY: u8 = 3;
const ATOM: u8 = 4;

/// Renders `e` as infix text, parenthesised where precedence requires.
pub fn to_infix(g: &Graph, e: ExprId, name: &dyn Fn(Var) -> String) -> String {
    Printer { g, name }.expr(e).0
}

struct Printer<'a> {
    g: &'a Graph,
    name: &'a dyn Fn(Var) -> String,
}

fn wrap((s, p): (String, u8), need: u8) -> String {
    if p < need {
        format!("({s})")
    } else {
        s
    }
}

fn number(v: f64) -> String {
    format!("{v:?}")
}

impl Printer<'_> {
    fn expr(&self, e: ExprId) -> (String, u8) {
        match self.g.node(e) {
            Node::Const(b) => {
                let v = f64::from_bits(*b);
                (number(v), if v < 0.0 { UNARY } else { ATOM })
            }
            Node::Var(v) => ((self.name)(*v), ATOM),
            Node::Add(terms) => {
                let mut s = String::new();
                for (i, &t) in terms.iter().enumerate() {
                    let (neg, mag) = self.signed(t);
                    let mag = wrap(mag, PRODUCT);
                    match (i, neg) {
                        (0, false) => s.push_str(&mag),
                        (0, true) => s = format!("-{mag}"),
                        (_, false) => s = format!("{s} + {mag}"),
                        (_, true) => s = format!("{s} - {mag}"),
                    }
                }
                (s, SUM)
            }
            Node::Mul(f) => {
                let (neg, mag) = self.product(f);
                if neg {
                    (format!("-{}", wrap(mag, UNARY)), UNARY)
                } else {
                    mag
                }
            }
            Node::Powi(x, n) if *n < 0 => {
                (format!("1 / {}", self.power(*x, -i64::from(*n))), PRODUCT)
            }
            Node::Powi(x, n) => (self.power(*x, i64::from(*n)), ATOM),
            Node::Powf(x, y) => (
                format!("{}^({})", wrap(self.expr(*x), ATOM), self.expr(*y).0),
                ATOM,
            ),
            Node::Call(f, x) => (format!("{}({})", f.name(), self.expr(*x).0), ATOM),
            Node::Atan2(y, x) => (
                format!("atan2({}, {})", self.expr(*y).0, self.expr(*x).0),
                ATOM,
            ),
        }
    }

    fn power(&self, x: ExprId, n: i64) -> String {
        let b = wrap(self.expr(x), ATOM);
        if n == 1 {
            b
        } else {
            format!("{b}^{n}")
        }
    }

    /// A term of a sum as (negative, magnitude).
    fn signed(&self, t: ExprId) -> (bool, (String, u8)) {
        match self.g.node(t) {
            Node::Const(b) if f64::from_bits(*b) < 0.0 => {
                (true, (number(-f64::from_bits(*b)), ATOM))
            }
            Node::Mul(f) => self.product(f),
            _ => (false, self.expr(t)),
        }
    }

    /// A product as (negative, magnitude): coefficient and positive powers over the
    /// negative powers.
    fn product(&self, factors: &[ExprId]) -> (bool, (String, u8)) {
        let mut coef = 1.0;
        let mut num = Vec::new();
        let mut den = Vec::new();
        for &f in factors {
            match self.g.node(f) {
                Node::Const(b) => coef *= f64::from_bits(*b),
                Node::Powi(x, n) if *n < 0 => den.push(self.power(*x, -i64::from(*n))),
                _ => num.push(self.expr(f)),
            }
        }
        if coef.abs() != 1.0 || num.is_empty() {
            num.insert(0, (number(coef.abs()), ATOM));
        }
        let (mut s, mut p) = if num.len() == 1 {
            num.pop().expect("one factor")
        } else {
            let parts: Vec<String> = num.into_iter().map(|x| wrap(x, UNARY)).collect();
            (parts.join(" * "), PRODUCT)
        };
        if !den.is_empty() {
            let d = if den.len() == 1 {
                den.pop().expect("one factor")
            } else {
                format!("({})", den.join(" * "))
            };
            s = format!("{} / {d}", wrap((s, p), PRODUCT));
            p = PRODUCT;
        }
        (coef < 0.0, (s, p))
    }
}
