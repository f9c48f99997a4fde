//! An infix printer for expressions, used in snapshots of the symbolic layer and in
//! diagnostics. Variables print through a naming callback so that the model's names
//! appear (`x`, `x'` for velocities, `δx` for variations).

use std::fmt::Write;

use super::graph::{ExprId, Graph, Node, Var};

/// Renders `e` as infix text, fully parenthesised where precedence requires.
pub fn to_infix(g: &Graph, e: ExprId, name: &dyn Fn(Var) -> String) -> String {
    let mut s = String::new();
    write_expr(g, e, name, 0, &mut s);
    s
}

fn write_expr(g: &Graph, e: ExprId, name: &dyn Fn(Var) -> String, prec: u8, s: &mut String) {
    let (own, open) = match g.node(e) {
        Node::Add(_) => (1, prec > 1),
        Node::Mul(_) => (2, prec > 2),
        Node::Const(b) if f64::from_bits(*b) < 0.0 => (2, prec > 2),
        _ => (4, false),
    };
    if open {
        s.push('(');
    }
    match g.node(e) {
        Node::Const(b) => {
            let _ = write!(s, "{:?}", f64::from_bits(*b));
        }
        Node::Var(v) => s.push_str(&name(*v)),
        Node::Add(terms) => {
            for (i, &t) in terms.iter().enumerate() {
                if i > 0 {
                    s.push_str(" + ");
                }
                write_expr(g, t, name, own, s);
            }
        }
        Node::Mul(factors) => {
            for (i, &f) in factors.iter().enumerate() {
                if i > 0 {
                    s.push_str(" * ");
                }
                write_expr(g, f, name, own + 1, s);
            }
        }
        Node::Powi(x, n) => {
            write_expr(g, *x, name, 4, s);
            let _ = write!(s, "^{n}");
        }
        Node::Powf(x, y) => {
            write_expr(g, *x, name, 4, s);
            s.push_str("^(");
            write_expr(g, *y, name, 0, s);
            s.push(')');
        }
        Node::Call(f, x) => {
            let _ = write!(s, "{}(", f.name());
            write_expr(g, *x, name, 0, s);
            s.push(')');
        }
        Node::Atan2(y, x) => {
            s.push_str("atan2(");
            write_expr(g, *y, name, 0, s);
            s.push_str(", ");
            write_expr(g, *x, name, 0, s);
            s.push(')');
        }
    }
    if open {
        s.push(')');
    }
}
