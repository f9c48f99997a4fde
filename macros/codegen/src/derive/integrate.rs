//! Exact integration over a material coordinate, at compile time.
//!
//! Input: an expression of the graph in which the material coordinate `ξ` appears as the
//! placeholder variable [`XI`], and numeric bounds. Output: the definite integral as an
//! expression free of `ξ` (its coefficients may be any expressions of parameters,
//! coordinates and velocities), or a description of the first sub-expression outside the
//! class.
//!
//! The class is the sums of `c · ξⁿ · e^{aξ} · cos(bξ)` and `c · ξⁿ · e^{aξ} · sin(bξ)`
//! with numeric `a`, `b` and coefficients `c` free of `ξ`: it is closed under products,
//! and holds polynomials, `sin`, `cos`, `exp`, `sinh`, `cosh` of affine arguments
//! `αξ + β` (numeric `α`, any `β`), so polynomial, trigonometric and hyperbolic shape
//! functions (the clamped-free beam's modes) and their products integrate exactly. An
//! expression is expanded into that normal form with like terms collected (so the
//! `e^{βξ}` parts of `cosh βξ − σ sinh βξ` cancel in their coefficient before anything is
//! integrated), and each term is integrated by its closed form
//! `∫ ξⁿ e^{zξ} dξ = e^{zξ} Σₖ (−1)ᵏ n!/(n−k)! ξ^{n−k} / z^{k+1}`, `z = a + ib`
//! (the power series of `e^{zξ}` when `|z ξ| ≤ 1`, where that sum cancels).

use std::collections::BTreeMap;

use crate::sym::{ExprId, Func, Graph, Node, Var};

/// The placeholder of the material coordinate while integrating (never emitted).
pub const XI: Var = Var::Input(u32::MAX);

/// `ξⁿ e^{aξ} cos(bξ)` (`sin: false`) or `… sin(bξ)`, with `b ≥ 0` and no `sin` at `b = 0`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Key {
    n: u32,
    a: u64,
    b: u64,
    sin: bool,
}

impl Key {
    fn new(n: u32, a: f64, b: f64, sin: bool) -> Option<(Key, f64)> {
        // sin(−bξ) = −sin(bξ), cos(−bξ) = cos(bξ); sin(0) = 0.
        let (b, sign) = if b < 0.0 {
            (-b, if sin { -1.0 } else { 1.0 })
        } else {
            (b, 1.0)
        };
        if sin && b == 0.0 {
            return None;
        }
        let a = if a == 0.0 { 0.0 } else { a };
        let b = if b == 0.0 { 0.0 } else { b };
        Some((
            Key {
                n,
                a: a.to_bits(),
                b: b.to_bits(),
                sin,
            },
            sign,
        ))
    }
    fn a(self) -> f64 {
        f64::from_bits(self.a)
    }
    fn b(self) -> f64 {
        f64::from_bits(self.b)
    }
}

/// An expression in normal form: coefficient (summands) per basis function.
type Series = BTreeMap<Key, Vec<ExprId>>;

fn push(s: &mut Series, g: &mut Graph, key: Option<(Key, f64)>, c: ExprId, factor: f64) {
    let Some((k, sign)) = key else { return };
    let f = sign * factor;
    let c = if f == 1.0 {
        c
    } else {
        let f = g.constant(f);
        g.mul(vec![f, c])
    };
    s.entry(k).or_default().push(c);
}

fn collect(g: &mut Graph, s: Series) -> BTreeMap<Key, ExprId> {
    let mut out = BTreeMap::new();
    for (k, v) in s {
        let c = g.add(v);
        if !g.is_zero(c) {
            out.insert(k, c);
        }
    }
    out
}

fn product(
    g: &mut Graph,
    x: &BTreeMap<Key, ExprId>,
    y: &BTreeMap<Key, ExprId>,
) -> BTreeMap<Key, ExprId> {
    let mut s = Series::new();
    for (&k1, &c1) in x {
        for (&k2, &c2) in y {
            let c = g.mul(vec![c1, c2]);
            let (n, a) = (k1.n + k2.n, k1.a() + k2.a());
            let (b1, b2) = (k1.b(), k2.b());
            if b1 == 0.0 && !k1.sin {
                push(&mut s, g, Key::new(n, a, b2, k2.sin), c, 1.0);
                continue;
            }
            if b2 == 0.0 && !k2.sin {
                push(&mut s, g, Key::new(n, a, b1, k1.sin), c, 1.0);
                continue;
            }
            let (sum, dif) = (b1 + b2, b1 - b2);
            match (k1.sin, k2.sin) {
                (false, false) => {
                    push(&mut s, g, Key::new(n, a, dif, false), c, 0.5);
                    push(&mut s, g, Key::new(n, a, sum, false), c, 0.5);
                }
                (true, true) => {
                    push(&mut s, g, Key::new(n, a, dif, false), c, 0.5);
                    push(&mut s, g, Key::new(n, a, sum, false), c, -0.5);
                }
                (true, false) => {
                    push(&mut s, g, Key::new(n, a, sum, true), c, 0.5);
                    push(&mut s, g, Key::new(n, a, dif, true), c, 0.5);
                }
                (false, true) => {
                    push(&mut s, g, Key::new(n, a, sum, true), c, 0.5);
                    push(&mut s, g, Key::new(n, a, -dif, true), c, 0.5);
                }
            }
        }
    }
    collect(g, s)
}

/// Most pairs of terms one product of two expansions may form. The invariants of a
/// beam's few shape functions need hundreds; a description that needs more (a shape
/// raised to a large power) is refused with an error instead of expanding for minutes.
const MAX_PAIRS: usize = 1 << 16;

/// Largest power of an expression of ξ that is expanded.
const MAX_POWER: i32 = 64;

/// [`product`] within [`MAX_PAIRS`].
fn product_within(
    g: &mut Graph,
    x: &BTreeMap<Key, ExprId>,
    y: &BTreeMap<Key, ExprId>,
) -> Result<BTreeMap<Key, ExprId>, String> {
    if x.len().saturating_mul(y.len()) > MAX_PAIRS {
        return Err(format!(
            "the integrand expands to a product of {} by {} terms, more than the {MAX_PAIRS} an exact integration forms",
            x.len(),
            y.len()
        ));
    }
    Ok(product(g, x, y))
}

/// Expands `e` into the normal form, or says which part is outside the class.
fn expand(g: &mut Graph, e: ExprId) -> Result<BTreeMap<Key, ExprId>, String> {
    let mut out = BTreeMap::new();
    if !g.depends_on(e, XI) {
        if !g.is_zero(e) {
            out.insert(Key::new(0, 0.0, 0.0, false).expect("cos 0").0, e);
        }
        return Ok(out);
    }
    match g.node(e).clone() {
        Node::Var(_) => {
            let one = g.constant(1.0);
            out.insert(Key::new(1, 0.0, 0.0, false).expect("cos 0").0, one);
            Ok(out)
        }
        Node::Add(terms) => {
            let mut s = Series::new();
            for &t in terms.iter() {
                for (k, c) in expand(g, t)? {
                    s.entry(k).or_default().push(c);
                }
            }
            Ok(collect(g, s))
        }
        Node::Mul(factors) => {
            let mut acc = expand(g, factors[0])?;
            for &f in &factors[1..] {
                let x = expand(g, f)?;
                acc = product_within(g, &acc, &x)?;
            }
            Ok(acc)
        }
        Node::Powi(x, n) if n >= 0 => {
            if n > MAX_POWER {
                return Err(format!(
                    "a power {n} of an expression of the material coordinate: at most {MAX_POWER} is integrated exactly"
                ));
            }
            let base = expand(g, x)?;
            let one = g.constant(1.0);
            let mut acc = BTreeMap::from([(Key::new(0, 0.0, 0.0, false).expect("cos 0").0, one)]);
            for _ in 0..n {
                acc = product_within(g, &acc, &base)?;
            }
            Ok(acc)
        }
        Node::Call(f @ (Func::Sin | Func::Cos | Func::Exp | Func::Sinh | Func::Cosh), x) => {
            let (alpha, beta) = affine(g, x)?;
            let mut s = Series::new();
            match f {
                Func::Sin | Func::Cos => {
                    // sin(αξ+β) = cos β sin αξ + sin β cos αξ; cos(αξ+β) = cos β cos αξ − sin β sin αξ.
                    let (sb, cb) = (g.call(Func::Sin, beta), g.call(Func::Cos, beta));
                    if f == Func::Sin {
                        push(&mut s, g, Key::new(0, 0.0, alpha, true), cb, 1.0);
                        push(&mut s, g, Key::new(0, 0.0, alpha, false), sb, 1.0);
                    } else {
                        push(&mut s, g, Key::new(0, 0.0, alpha, false), cb, 1.0);
                        push(&mut s, g, Key::new(0, 0.0, alpha, true), sb, -1.0);
                    }
                }
                _ => {
                    let ep = g.call(Func::Exp, beta);
                    if f == Func::Exp {
                        push(&mut s, g, Key::new(0, alpha, 0.0, false), ep, 1.0);
                    } else {
                        let mb = g.neg(beta);
                        let em = g.call(Func::Exp, mb);
                        let sign = if f == Func::Sinh { -0.5 } else { 0.5 };
                        push(&mut s, g, Key::new(0, alpha, 0.0, false), ep, 0.5);
                        push(&mut s, g, Key::new(0, -alpha, 0.0, false), em, sign);
                    }
                }
            }
            Ok(collect(g, s))
        }
        Node::Powi(..) => Err("a negative power of the material coordinate".into()),
        Node::Call(f, _) => Err(format!(
            "`{}` of the material coordinate (the class is polynomials, sin, cos, exp, sinh, cosh of affine arguments, and their products)",
            f.name()
        )),
        Node::Powf(..) => Err("a real power of the material coordinate".into()),
        Node::Atan2(..) => Err("`atan2` of the material coordinate".into()),
        Node::Const(_) => unreachable!("constants do not depend on ξ"),
    }
}

/// `x = α ξ + β` with numeric `α`.
fn affine(g: &mut Graph, x: ExprId) -> Result<(f64, ExprId), String> {
    let s = expand(g, x)?;
    let mut alpha = 0.0;
    let mut beta = g.constant(0.0);
    for (k, c) in s {
        match (k.n, k.a(), k.b(), k.sin) {
            (0, 0.0, 0.0, false) => beta = c,
            (1, 0.0, 0.0, false) => match g.as_const(c) {
                Some(v) => alpha = v,
                None => {
                    return Err("a function whose argument has a non-numeric factor of the material coordinate (write `sin(b * xi)` with a numeric `b`)".into())
                }
            },
            _ => return Err("a function of a non-affine argument of the material coordinate".into()),
        }
    }
    Ok((alpha, beta))
}

#[derive(Clone, Copy, Debug)]
struct C(f64, f64);

impl C {
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn scale(self, s: f64) -> C {
        C(self.0 * s, self.1 * s)
    }
    fn inv(self) -> C {
        let d = self.0 * self.0 + self.1 * self.1;
        C(self.0 / d, -self.1 / d)
    }
    fn exp(self) -> C {
        let r = self.0.exp();
        C(r * self.1.cos(), r * self.1.sin())
    }
}

/// An antiderivative of `ξⁿ e^{zξ}` at `x`, and the size of the terms it sums (the
/// scale of its rounding error).
fn antiderivative(n: u32, z: C, x: f64, series: bool) -> (C, f64) {
    let size = |c: C| c.0.abs() + c.1.abs();
    if series {
        // Σ_j z^j/j! x^{n+j+1}/(n+j+1)
        let mut term = C(1.0, 0.0); // z^j / j!
        let mut sum = C(0.0, 0.0);
        let mut scale = 0.0;
        for j in 0..400_u32 {
            let p = n + j + 1;
            let add = term.scale(x.powi(p as i32) / f64::from(p));
            sum = sum.add(add);
            scale += size(add);
            if size(add) <= 1e-18 * size(sum) && j > n {
                break;
            }
            term = term.mul(z).scale(1.0 / f64::from(j + 1));
        }
        return (sum, scale);
    }
    let zi = z.inv();
    let mut sum = C(0.0, 0.0);
    let mut scale = 0.0;
    // k-th term: (−1)^k n!/(n−k)! x^{n−k} / z^{k+1}
    let mut coef = 1.0_f64;
    let mut zk = zi;
    for k in 0..=n {
        let t = zk.scale(coef * x.powi((n - k) as i32));
        sum = sum.add(t);
        scale += size(t);
        coef *= -f64::from(n - k);
        zk = zk.mul(zi);
    }
    let e = z.scale(x).exp();
    (e.mul(sum), size(e) * scale)
}

/// `∫_{x0}^{x1} ξⁿ e^{aξ} cos|sin(bξ) dξ`; a result within the rounding of the terms it
/// is computed from is exactly 0 (`∫₀¹ sin πξ sin 2πξ`, which `sin π ≠ 0` in floating
/// point would otherwise leave at 1e-33 and make a structural non-zero).
fn basis_integral(k: Key, x0: f64, x1: f64) -> f64 {
    let z = C(k.a(), k.b());
    let big = (z.0.hypot(z.1)) * x0.abs().max(x1.abs());
    let series = big <= 1.0;
    let (f1, s1) = antiderivative(k.n, z, x1, series);
    let (f0, s0) = antiderivative(k.n, z, x0, series);
    let v = f1.add(f0.scale(-1.0));
    let v = if k.sin { v.1 } else { v.0 };
    if v.abs() <= 16.0 * f64::EPSILON * (s0 + s1) {
        0.0
    } else {
        v
    }
}

/// `∫_{x0}^{x1} e dξ` for `e` in the class, as an expression free of `ξ`.
///
/// # Errors
/// A description of the part of `e` outside the class.
pub fn integrate(g: &mut Graph, e: ExprId, x0: f64, x1: f64) -> Result<ExprId, String> {
    let s = expand(g, e)?;
    let mut terms = Vec::new();
    for (k, c) in s {
        let v = basis_integral(k, x0, x1);
        if v != 0.0 {
            let v = g.constant(v);
            terms.push(g.mul(vec![v, c]));
        }
    }
    Ok(g.add(terms))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sym::transform;

    fn value(g: &Graph, e: ExprId) -> f64 {
        transform::eval(g, &[e], &|_| f64::NAN)[0]
    }

    /// Closed forms of the integrals (by hand): ∫₀¹ ξ² = 1/3, ∫₀¹ sin²(πξ) = 1/2,
    /// ∫₀¹ ξ sin(πξ) = 1/π, ∫₀¹ 4ξ(1−ξ) sin(πξ) = 16/π³, ∫₀² e^{3ξ} cos(2ξ) =
    /// [e^{3ξ}(3 cos 2ξ + 2 sin 2ξ)/13]₀², ∫₀¹ cosh²(ξ) = (sinh 2 / 2 + 1)/2.
    #[test]
    fn closed_forms() {
        let mut g = Graph::new();
        let xi = g.var(XI);
        let pi = g.constant(std::f64::consts::PI);
        let px = g.mul(vec![pi, xi]);
        let s = g.call(Func::Sin, px);
        let cases: Vec<(ExprId, f64, f64, f64)> = {
            let x2 = g.powi(xi, 2);
            let s2 = g.powi(s, 2);
            let xs = g.mul(vec![xi, s]);
            let one = g.constant(1.0);
            let omx = g.sub(one, xi);
            let four = g.constant(4.0);
            let bub = g.mul(vec![four, xi, omx, s]);
            let three = g.constant(3.0);
            let two = g.constant(2.0);
            let e3 = g.mul(vec![three, xi]);
            let e3 = g.call(Func::Exp, e3);
            let c2 = g.mul(vec![two, xi]);
            let c2 = g.call(Func::Cos, c2);
            let ec = g.mul(vec![e3, c2]);
            let ch = g.call(Func::Cosh, xi);
            let ch2 = g.powi(ch, 2);
            let pi3 = std::f64::consts::PI.powi(3);
            let f =
                |x: f64| (3.0 * x).exp() * (3.0 * (2.0 * x).cos() + 2.0 * (2.0 * x).sin()) / 13.0;
            vec![
                (x2, 0.0, 1.0, 1.0 / 3.0),
                (s2, 0.0, 1.0, 0.5),
                (xs, 0.0, 1.0, 1.0 / std::f64::consts::PI),
                (bub, 0.0, 1.0, 16.0 / pi3),
                (ec, 0.0, 2.0, f(2.0) - f(0.0)),
                (ch2, 0.0, 1.0, (2.0_f64.sinh() / 2.0 + 1.0) / 2.0),
            ]
        };
        for (e, a, b, want) in cases {
            let i = integrate(&mut g, e, a, b).unwrap();
            let got = value(&g, i);
            assert!(
                (got - want).abs() <= 1e-14 * want.abs().max(1.0),
                "{got} vs {want}"
            );
        }
    }

    /// Integrals that vanish exactly come out exactly 0: ∫₀¹ sin πξ sin 2πξ = 0,
    /// ∫₀² cos(πξ) = 0 (closed forms).
    #[test]
    fn exact_zeros() {
        let mut g = Graph::new();
        let xi = g.var(XI);
        let pi = g.constant(std::f64::consts::PI);
        let two = g.constant(2.0);
        let px = g.mul(vec![pi, xi]);
        let p2x = g.mul(vec![two, pi, xi]);
        let (s1, s2) = (g.call(Func::Sin, px), g.call(Func::Sin, p2x));
        let e = g.mul(vec![s1, s2]);
        let i = integrate(&mut g, e, 0.0, 1.0).unwrap();
        assert!(g.is_zero(i));
        let c = g.call(Func::Cos, px);
        let i = integrate(&mut g, c, 0.0, 2.0).unwrap();
        assert!(g.is_zero(i));
    }

    /// Symbolic coefficients stay symbolic: ∫₀¹ p ξ = p/2.
    #[test]
    fn symbolic_coefficients() {
        let mut g = Graph::new();
        let xi = g.var(XI);
        let p = g.var(Var::Param(0));
        let e = g.mul(vec![p, xi]);
        let i = integrate(&mut g, e, 0.0, 1.0).unwrap();
        let half = g.constant(0.5);
        let want = g.mul(vec![half, p]);
        assert_eq!(i, want);
    }

    /// A shape raised to a large power (what the fuzzer appends: `.powi(1000)`) is an
    /// error at once, not an expansion of minutes; a moderate power still integrates:
    /// ∫₀¹ ξ¹⁰ = 1/11, and the largest allowed power of a three-term shape expands.
    #[test]
    fn large_expansions_are_refused() {
        let mut g = Graph::new();
        let xi = g.var(XI);
        let one = g.constant(1.0);
        let pi = g.constant(std::f64::consts::PI);
        let px = g.mul(vec![pi, xi]);
        let s = g.call(Func::Sin, px);
        let shape = g.add(vec![one, xi, s]);
        let big = g.powi(shape, 1000);
        let err = integrate(&mut g, big, 0.0, 1.0).unwrap_err();
        assert!(err.contains("power 1000"), "{err}");
        let wide = g.powi(shape, MAX_POWER);
        assert!(integrate(&mut g, wide, 0.0, 1.0).is_ok());
        let x10 = g.powi(xi, 10);
        let i = integrate(&mut g, x10, 0.0, 1.0).unwrap();
        assert!((value(&g, i) - 1.0 / 11.0).abs() < 1e-15);
    }

    #[test]
    fn outside_the_class() {
        let mut g = Graph::new();
        let xi = g.var(XI);
        let e = g.call(Func::Sqrt, xi);
        assert!(integrate(&mut g, e, 0.0, 1.0).is_err());
        let p = g.var(Var::Param(0));
        let px = g.mul(vec![p, xi]);
        let e = g.call(Func::Sin, px);
        assert!(integrate(&mut g, e, 0.0, 1.0).is_err());
    }
}
