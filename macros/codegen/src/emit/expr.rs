//! Printing one expression as Rust tokens: one `match` arm per node kind, precedence-
//! aware, turning `(−1)·x`, `a + (−1)·b` and `a · b⁻¹` back into `-x`, `a - b`, `a / b`.

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;

use crate::sched::Program;
use crate::sched::Run;
use crate::sym::{ExprId, Func, Graph, Node, Var};

/// Binding strength of an emitted expression.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Prec {
    Sum,
    Product,
    Unary,
    Atom,
}

/// Names of the leaves and temporaries.
pub trait Names {
    fn var(&self, v: crate::sym::Var) -> Ident;
    fn temp(&self, k: usize) -> Ident;
    /// The field of the data slot holding `Var::Data(i)` and the entry's index in it.
    fn data_field(&self, i: u32) -> (Ident, usize);
}

/// Prints expressions of one program.
#[allow(missing_debug_implementations)] // holds a `dyn Names`
pub struct Printer<'a> {
    pub g: &'a Graph,
    pub prog: &'a Program,
    pub names: &'a dyn Names,
    /// When set, temporary `k` is element `k` of this local array instead of a `let`.
    pub array: Option<Ident>,
    /// Data entries are read where they are used (`self.data.slot[k]`) instead of
    /// bound by `let`s (see `emit::body`).
    pub inline_data: bool,
}

fn wrap(ts: TokenStream, prec: Prec, need: Prec) -> TokenStream {
    if prec < need {
        quote!((#ts))
    } else {
        ts
    }
}

/// A non-negative finite `f64` literal, or the named constant for other values.
pub fn literal(v: f64) -> (TokenStream, Prec) {
    if v.is_nan() {
        return (quote!(f64::NAN), Prec::Atom);
    }
    if v.is_infinite() {
        return if v > 0.0 {
            (quote!(f64::INFINITY), Prec::Atom)
        } else {
            (quote!(f64::NEG_INFINITY), Prec::Atom)
        };
    }
    let lit = Literal::f64_unsuffixed(v.abs());
    if v < 0.0 {
        (quote!(-#lit), Prec::Unary)
    } else {
        (quote!(#lit), Prec::Atom)
    }
}

impl Printer<'_> {
    /// Tokens of `id`, using its temporary when it has one (unless `define` is set, to
    /// print the definition of that temporary itself).
    pub fn expr(&self, id: ExprId, define: bool) -> (TokenStream, Prec) {
        if !define {
            if let Some(k) = self.prog.temp(id) {
                if let Some(array) = &self.array {
                    let k = proc_macro2::Literal::usize_unsuffixed(k);
                    return (quote!(#array[#k]), Prec::Atom);
                }
                let name = self.names.temp(k);
                return (quote!(#name), Prec::Atom);
            }
        }
        match self.g.node(id) {
            Node::Const(b) => literal(f64::from_bits(*b)),
            Node::Var(Var::Data(i)) if self.inline_data => {
                let (field, k) = self.names.data_field(*i);
                let k = Literal::usize_unsuffixed(k);
                (quote!(self.data.#field[#k]), Prec::Atom)
            }
            Node::Var(v) => {
                let name = self.names.var(*v);
                (quote!(#name), Prec::Atom)
            }
            Node::Add(terms) => self.sum(id, terms),
            Node::Mul(factors) => {
                let (neg, ts, prec) = self.product(factors);
                if neg {
                    let ts = wrap(ts, prec, Prec::Unary);
                    (quote!(-#ts), Prec::Unary)
                } else {
                    (ts, prec)
                }
            }
            Node::Powi(x, n) if *n < 0 && *n != i32::MIN => {
                let d = self.power(*x, -n);
                (quote!(1.0 / #d), Prec::Product)
            }
            Node::Powi(x, n) => (self.power(*x, *n), Prec::Atom),
            Node::Powf(x, y) => {
                let x = self.atom(*x);
                let (y, _) = self.expr(*y, false);
                (quote!(#x.powf(#y)), Prec::Atom)
            }
            // The runtime's sine and cosine (`pfaff::math`): inlined, without the C
            // library's call and rounding-mode save.
            Node::Call(f @ (Func::Sin | Func::Cos), x) => {
                let (x, _) = self.expr(*x, false);
                let m = Ident::new(f.name(), Span::call_site());
                (quote!(::pfaff::math::#m(#x)), Prec::Atom)
            }
            Node::Call(f, x) => {
                let x = self.atom(*x);
                let m = Ident::new(f.name(), Span::call_site());
                (quote!(#x.#m()), Prec::Atom)
            }
            Node::Atan2(y, x) => {
                let y = self.atom(*y);
                let (x, _) = self.expr(*x, false);
                (quote!(#y.atan2(#x)), Prec::Atom)
            }
        }
    }

    /// The statement defining temporary `k`, node `id`: a `let` (or an element of
    /// [`Printer::array`]). Of a [`Program::partner`] pair `sin u`, `cos u`, the first
    /// defines both with one `sin_cos` call and the second nothing; of two
    /// [`Program::twins`], the first defines both pairs with one `sin_cos2` call.
    pub fn define(&self, k: usize, id: ExprId) -> TokenStream {
        let place = |k: usize| match &self.array {
            Some(array) => {
                let k = Literal::usize_unsuffixed(k);
                quote!(#array[#k])
            }
            None => {
                let name = self.names.temp(k);
                quote!(#name)
            }
        };
        let let_ = if self.array.is_some() {
            quote!()
        } else {
            quote!(let)
        };
        if let Some(&other) = self.prog.partner.get(&id) {
            let j = self
                .prog
                .temp(other)
                .expect("both of a pair are temporaries");
            if j < k {
                return TokenStream::new();
            }
            let (sin, cos, u) = self.pair(id);
            let (sin, cos) = (place(sin), place(cos));
            if let Some(sum) = self.prog.angle_sums.get(&id) {
                let [sa, ca, sb, cb] = sum.pairs.map(|p| {
                    let (ts, p) = self.expr(p, false);
                    wrap(ts, p, Prec::Atom)
                });
                // sin(a ± b) = sin a cos b ± cos a sin b, cos(a ± b) = cos a cos b ∓ sin a sin b.
                return if sum.minus {
                    quote!(#let_ #sin = #sa * #cb - #ca * #sb; #let_ #cos = #ca * #cb + #sa * #sb;)
                } else {
                    quote!(#let_ #sin = #sa * #cb + #ca * #sb; #let_ #cos = #ca * #cb - #sa * #sb;)
                };
            }
            if let Some(&twin) = self.prog.twins.get(&id) {
                let m = self.prog.temp(twin).expect("twins are temporaries");
                if m < k {
                    // Defined with the earlier pair.
                    return TokenStream::new();
                }
                let (sin2, cos2, u2) = self.pair(twin);
                let (sin2, cos2) = (place(sin2), place(cos2));
                let (u, _) = self.expr(u, false);
                let (u2, _) = self.expr(u2, false);
                return quote!(
                    #let_ ((#sin, #cos), (#sin2, #cos2)) = ::pfaff::math::sin_cos2(#u, #u2);
                );
            }
            let (u, _) = self.expr(u, false);
            return quote!(#let_ (#sin, #cos) = ::pfaff::math::sin_cos(#u););
        }
        let (ts, _) = self.expr(id, true);
        let place = place(k);
        quote!(#let_ #place = #ts;)
    }

    /// The temporaries `(sin u, cos u)` of the [`Program::partner`] pair of `id`, and
    /// `u`.
    fn pair(&self, id: ExprId) -> (usize, usize, ExprId) {
        let other = self.prog.partner[&id];
        let temp = |e| self.prog.temp(e).expect("both of a pair are temporaries");
        match self.g.node(id) {
            Node::Call(Func::Sin, u) => (temp(id), temp(other), *u),
            Node::Call(Func::Cos, u) => (temp(other), temp(id), *u),
            _ => unreachable!("pairs are a sine and a cosine"),
        }
    }

    /// An operand in receiver position (`x` in `x.sin()`).
    fn atom(&self, id: ExprId) -> TokenStream {
        let (ts, p) = self.expr(id, false);
        wrap(ts, p, Prec::Atom)
    }

    /// `x^n`, `n > 0`.
    fn power(&self, x: ExprId, n: i32) -> TokenStream {
        let b = self.atom(x);
        if n == 1 {
            b
        } else {
            let n = Literal::i32_unsuffixed(n);
            quote!(#b.powi(#n))
        }
    }

    /// The sign of a term and its magnitude's tokens.
    fn signed_term(&self, id: ExprId) -> (bool, TokenStream, Prec) {
        if self.prog.temp(id).is_none() {
            match self.g.node(id) {
                Node::Const(b) if f64::from_bits(*b) < 0.0 => {
                    let (ts, p) = literal(-f64::from_bits(*b));
                    return (true, ts, p);
                }
                Node::Mul(f) => return self.product(f),
                _ => {}
            }
        }
        let (ts, p) = self.expr(id, false);
        (false, ts, p)
    }

    /// A contraction as a signed term: `c · dot_strided(&data[..], stride, &x[..])`.
    fn run(&self, r: &Run) -> (bool, TokenStream, Prec) {
        let (field, k0) = self.names.data_field(r.data);
        let len = r.len as usize;
        let stride = r.stride as usize;
        let end = Literal::usize_unsuffixed(k0 + (len - 1) * stride + 1);
        let (x, i0) = match r.first {
            Var::Q(i) => (quote!(q), i as usize),
            Var::Qd(i) => (quote!(qd), i as usize),
            _ => unreachable!("runs read coordinates or velocities"),
        };
        let (k0, i0, i1) = (
            Literal::usize_unsuffixed(k0),
            Literal::usize_unsuffixed(i0),
            Literal::usize_unsuffixed(i0 + len),
        );
        let stride = Literal::usize_unsuffixed(stride);
        let call = quote!(::pfaff::__private::dot_strided(
            &self.data.#field[#k0..#end], #stride, &#x[#i0..#i1]
        ));
        let mag = r.coef.abs();
        if mag == 1.0 {
            (r.coef < 0.0, call, Prec::Atom)
        } else {
            let (c, _) = literal(mag);
            (r.coef < 0.0, quote!(#c * #call), Prec::Product)
        }
    }

    fn sum(&self, id: ExprId, terms: &[ExprId]) -> (TokenStream, Prec) {
        let (runs, terms): (&[Run], &[ExprId]) = match self.prog.runs.get(&id) {
            Some((r, rest)) => (r, rest),
            None => (&[], terms),
        };
        let mut parts: Vec<(bool, TokenStream, Prec)> =
            terms.iter().map(|&t| self.signed_term(t)).collect();
        parts.extend(runs.iter().map(|r| self.run(r)));
        if parts.len() == 1 && !parts[0].0 {
            let (_, ts, p) = parts.pop().expect("one part");
            return (ts, p);
        }
        // Positive terms first reads better: `a - b` rather than `-b + a`.
        parts.sort_by_key(|p| p.0);
        let mut out = TokenStream::new();
        for (i, (neg, ts, prec)) in parts.into_iter().enumerate() {
            let ts = wrap(ts, prec, Prec::Product);
            match (i, neg) {
                (0, false) => out.extend(ts),
                (0, true) => out.extend(quote!(-#ts)),
                (_, false) => out.extend(quote!(+ #ts)),
                (_, true) => out.extend(quote!(- #ts)),
            }
        }
        (out, Prec::Sum)
    }

    /// A product as `(negative, |product| tokens, precedence)`: the coefficient and the
    /// positive powers form the numerator, the negative powers the denominator.
    fn product(&self, factors: &[ExprId]) -> (bool, TokenStream, Prec) {
        let mut coef = 1.0;
        let mut num: Vec<(TokenStream, Prec)> = Vec::new();
        let mut den = Vec::new();
        for &f in factors {
            if self.prog.temp(f).is_none() {
                match self.g.node(f) {
                    Node::Const(b) => {
                        coef *= f64::from_bits(*b);
                        continue;
                    }
                    Node::Powi(x, n) if *n < 0 && *n != i32::MIN => {
                        den.push(self.power(*x, -n));
                        continue;
                    }
                    _ => {}
                }
            }
            num.push(self.expr(f, false));
        }
        let neg = coef < 0.0;
        let mag = coef.abs();
        if mag != 1.0 || num.is_empty() {
            num.insert(0, literal(mag));
        }
        let (mut out, mut prec) = if num.len() == 1 {
            num.pop().expect("one factor")
        } else {
            (
                join(
                    num.into_iter().map(|(ts, p)| wrap(ts, p, Prec::Unary)),
                    &quote!(*),
                ),
                Prec::Product,
            )
        };
        if !den.is_empty() {
            out = wrap(out, prec, Prec::Product);
            let d = if den.len() == 1 {
                den.pop().expect("one factor")
            } else {
                let d = join(den.into_iter(), &quote!(*));
                quote!((#d))
            };
            out.extend(quote!(/ #d));
            prec = Prec::Product;
        }
        (neg, out, prec)
    }
}

fn join(parts: impl Iterator<Item = TokenStream>, sep: &TokenStream) -> TokenStream {
    let mut out = TokenStream::new();
    for (i, ts) in parts.enumerate() {
        if i > 0 {
            out.extend(sep.clone());
        }
        out.extend(ts);
    }
    out
}
