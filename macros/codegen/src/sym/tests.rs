//! Unit and property tests of the symbolic engine: identities of the canonical
//! constructors, and random expressions whose simplified and unsimplified forms (and
//! derivatives) must evaluate equal.

use super::transform::{self, eval, rebuild};
use super::*;

/// splitmix64, seeded: reproducible random numbers without a dependency.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        #[allow(clippy::cast_precision_loss)]
        let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

const VARS: [Var; 4] = [Var::Q(0), Var::Q(1), Var::Qd(0), Var::Time];

fn env(vals: &[f64; 4]) -> impl Fn(Var) -> f64 + '_ {
    move |v| match v {
        Var::Q(0) => vals[0],
        Var::Q(1) => vals[1],
        Var::Qd(0) => vals[2],
        Var::Time => vals[3],
        _ => f64::NAN,
    }
}

/// A random expression of bounded depth, built in `g` (raw or canonical alike).
fn random_expr(g: &mut Graph, rng: &mut Rng, depth: u32) -> ExprId {
    if depth == 0 || rng.below(4) == 0 {
        return if rng.below(3) == 0 {
            let c = [0.0, 1.0, -1.0, 2.0, 0.5, 3.0][rng.below(6) as usize];
            g.constant(c)
        } else {
            g.var(VARS[rng.below(4) as usize])
        };
    }
    match rng.below(12) {
        0..=2 => {
            let a = random_expr(g, rng, depth - 1);
            let b = random_expr(g, rng, depth - 1);
            g.add(vec![a, b])
        }
        3 => {
            let a = random_expr(g, rng, depth - 1);
            let b = random_expr(g, rng, depth - 1);
            g.sub(a, b)
        }
        4..=5 => {
            let a = random_expr(g, rng, depth - 1);
            let b = random_expr(g, rng, depth - 1);
            g.mul(vec![a, b])
        }
        6 => {
            // Keep denominators away from zero: a / (1 + b²).
            let a = random_expr(g, rng, depth - 1);
            let b = random_expr(g, rng, depth - 1);
            let one = g.constant(1.0);
            let b2 = g.powi(b, 2);
            let den = g.add(vec![one, b2]);
            g.div(a, den)
        }
        7 => {
            let a = random_expr(g, rng, depth - 1);
            let n = [2, 3, -1, -2][rng.below(4) as usize];
            if n < 0 {
                let one = g.constant(1.0);
                let a2 = g.powi(a, 2);
                let s = g.add(vec![one, a2]);
                g.powi(s, n)
            } else {
                g.powi(a, n)
            }
        }
        8 => {
            let a = random_expr(g, rng, depth - 1);
            let f =
                [Func::Sin, Func::Cos, Func::Atan, Func::Tanh, Func::Sinh][rng.below(5) as usize];
            g.call(f, a)
        }
        9 => {
            // Functions with restricted domains get arguments inside it.
            let a = random_expr(g, rng, depth - 1);
            let one = g.constant(1.0);
            let a2 = g.powi(a, 2);
            let pos = g.add(vec![one, a2]);
            let f = [Func::Sqrt, Func::Ln][rng.below(2) as usize];
            g.call(f, pos)
        }
        10 => {
            // atan2(a, 1 + b²): away from the branch cut, where the sign of a zero
            // (not preserved by constant folding) would decide between ±π.
            let a = random_expr(g, rng, depth - 1);
            let b = random_expr(g, rng, depth - 1);
            let one = g.constant(1.0);
            let b2 = g.powi(b, 2);
            let x = g.add(vec![one, b2]);
            g.atan2(a, x)
        }
        _ => {
            let a = random_expr(g, rng, depth - 1);
            g.neg(a)
        }
    }
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + scale)
}

fn x(g: &mut Graph) -> ExprId {
    g.var(Var::Q(0))
}

#[test]
fn identities_of_the_canonical_constructors() {
    let mut g = Graph::new();
    let x = x(&mut g);
    let y = g.var(Var::Q(1));
    let d = g.sub(x, x);
    assert!(g.is_zero(d), "x - x = 0");
    let q = g.div(x, x);
    assert_eq!(g.as_const(q), Some(1.0), "x / x = 1");
    let two = g.constant(2.0);
    let three = g.constant(3.0);
    let a = g.mul(vec![two, x]);
    let b = g.mul(vec![three, x]);
    let s = g.add(vec![a, b]);
    let five = g.constant(5.0);
    assert_eq!(s, g.mul(vec![five, x]), "2x + 3x = 5x");
    let xy = g.mul(vec![x, y]);
    assert_eq!(xy, g.mul(vec![y, x]), "commutative operands are ordered");
    let xx = g.mul(vec![x, x]);
    assert_eq!(xx, g.powi(x, 2), "x x = x²");
    let s2 = g.call(Func::Sin, y);
    let c2 = g.call(Func::Cos, y);
    let s2 = g.powi(s2, 2);
    let c2 = g.powi(c2, 2);
    let lhs = g.mul(vec![three, x, s2]);
    let rhs = g.mul(vec![three, x, c2]);
    let pyth = g.add(vec![lhs, rhs]);
    assert_eq!(pyth, g.mul(vec![three, x]), "3x sin²y + 3x cos²y = 3x");
    let sq = g.call(Func::Sqrt, x);
    assert_eq!(g.powi(sq, 2), x, "(√x)² = x");
    let neg = g.neg(x);
    let sn = g.call(Func::Sin, neg);
    let sx = g.call(Func::Sin, x);
    assert_eq!(sn, g.neg(sx), "sin(−x) = −sin x");
    let cn = g.call(Func::Cos, neg);
    assert_eq!(cn, g.call(Func::Cos, x), "cos(−x) = cos x");
    let half = g.constant(0.5);
    let sum = g.add(vec![a, b]);
    let hs = g.mul(vec![half, sum]);
    let e = g.sub(hs, x);
    let c = g.constant(1.5);
    let expect = g.mul(vec![c, x]);
    assert_eq!(e, expect, "½(2x + 3x) − x = 1.5x");
}

#[test]
fn hash_consing_shares_equal_subexpressions() {
    let mut g = Graph::new();
    let x = x(&mut g);
    let a = g.call(Func::Sin, x);
    let n = g.len();
    let b = g.call(Func::Sin, x);
    assert_eq!(a, b);
    assert_eq!(g.len(), n, "no new node for an equal expression");
}

#[test]
fn simplified_and_unsimplified_expressions_evaluate_equal() {
    let mut rng = Rng(0x51_4D_B1);
    let mut checked = 0;
    for _ in 0..400 {
        let mut raw = Graph::raw();
        let e = random_expr(&mut raw, &mut rng, 5);
        let mut canon = Graph::new();
        let s = rebuild(&raw, &mut canon, &[e], &mut |g, v| g.var(v))[0];
        for _ in 0..5 {
            let vals = [
                rng.uniform(-2.0, 2.0),
                rng.uniform(-2.0, 2.0),
                rng.uniform(-2.0, 2.0),
                rng.uniform(-2.0, 2.0),
            ];
            let a = eval(&raw, &[e], &env(&vals))[0];
            let b = eval(&canon, &[s], &env(&vals))[0];
            if !a.is_finite() || a.abs() > 1e6 {
                continue;
            }
            let name = |v: Var| format!("{v:?}");
            assert!(
                close(a, b, a.abs()),
                "raw {a} vs simplified {b} at {vals:?}\n{}\n{}",
                display::to_infix(&raw, e, &name),
                display::to_infix(&canon, s, &name)
            );
            checked += 1;
        }
        assert!(
            canon.len() <= raw.len() + 8,
            "simplification does not blow up the graph"
        );
    }
    assert!(
        checked > 1000,
        "enough finite samples were compared: {checked}"
    );
}

#[test]
fn derivatives_match_central_differences() {
    let mut rng = Rng(0xD1FF);
    let mut checked = 0;
    for _ in 0..300 {
        let mut g = Graph::new();
        let e = random_expr(&mut g, &mut rng, 4);
        for (k, &v) in VARS.iter().enumerate() {
            let d = diff::differentiate(&mut g, e, v);
            let vals = [
                rng.uniform(-1.5, 1.5),
                rng.uniform(-1.5, 1.5),
                rng.uniform(-1.5, 1.5),
                rng.uniform(-1.5, 1.5),
            ];
            let h = 1e-5;
            let (mut p, mut m) = (vals, vals);
            p[k] += h;
            m[k] -= h;
            let fp = eval(&g, &[e], &env(&p))[0];
            let fm = eval(&g, &[e], &env(&m))[0];
            let fd = (fp - fm) / (2.0 * h);
            let an = eval(&g, &[d], &env(&vals))[0];
            if !fd.is_finite() || !an.is_finite() || fd.abs() > 1e4 {
                continue;
            }
            // Central differences: truncation O(h²·f''') plus rounding O(ε|f|/h).
            let scale = fp.abs().max(fm.abs());
            assert!(
                (fd - an).abs() <= 1e-5 * (1.0 + an.abs()) + 1e-9 * scale / h,
                "d/d{v:?}: symbolic {an} vs central difference {fd}"
            );
            checked += 1;
        }
    }
    assert!(checked > 500, "enough derivatives were compared: {checked}");
}

#[test]
fn canonical_and_raw_derivatives_agree() {
    let mut rng = Rng(0xCA0);
    for _ in 0..200 {
        let mut raw = Graph::raw();
        let e = random_expr(&mut raw, &mut rng, 4);
        let dr = diff::differentiate(&mut raw, e, Var::Q(0));
        let mut canon = Graph::new();
        let s = rebuild(&raw, &mut canon, &[e], &mut |g, v| g.var(v))[0];
        let ds = diff::differentiate(&mut canon, s, Var::Q(0));
        let vals = [0.3, -0.7, 1.1, 0.4];
        let a = eval(&raw, &[dr], &env(&vals))[0];
        let b = eval(&canon, &[ds], &env(&vals))[0];
        if a.is_finite() && a.abs() < 1e6 {
            assert!(close(a, b, a.abs()), "raw derivative {a} vs canonical {b}");
        }
    }
}

#[test]
fn building_is_deterministic() {
    let build = || {
        let mut rng = Rng(7);
        let mut g = Graph::new();
        let roots: Vec<ExprId> = (0..20).map(|_| random_expr(&mut g, &mut rng, 5)).collect();
        let d: Vec<ExprId> = roots
            .iter()
            .map(|&r| diff::differentiate(&mut g, r, Var::Q(1)))
            .collect();
        let name = |v: Var| format!("{v:?}");
        d.iter()
            .map(|&e| display::to_infix(&g, e, &name))
            .collect::<Vec<_>>()
    };
    assert_eq!(build(), build());
}

#[test]
fn integer_exponents_never_wrap() {
    let mut g = Graph::new();
    let x = g.var(Var::Q(0));
    let at = |g: &Graph, e: ExprId, v: f64| eval(g, &[e], &|_| v)[0];
    // x^MAX · x^MAX · x = x^(2³² − 1): 0 below 1, infinite above, −1 at −1.
    let big = g.powi(x, i32::MAX);
    let p = g.mul(vec![big, big, x]);
    assert_eq!(at(&g, p, 0.5), 0.0);
    assert_eq!(at(&g, p, 2.0), f64::INFINITY);
    assert_eq!(at(&g, p, -1.0), -1.0);
    // d²/dx² x^(−MAX) = MAX (MAX + 1) x^(−MAX − 2): through x^MIN, whose exponent has no
    // `n − 1` in `i32`.
    let e = g.powi(x, -i32::MAX);
    let d1 = diff::differentiate(&mut g, e, Var::Q(0));
    let d2 = diff::differentiate(&mut g, d1, Var::Q(0));
    assert_eq!(at(&g, d1, 2.0), 0.0);
    assert_eq!(at(&g, d2, 2.0), 0.0);
    assert_eq!(at(&g, d2, 0.5), f64::INFINITY);
    assert_eq!(
        at(&g, d2, 1.0),
        f64::from(i32::MAX) * (f64::from(i32::MAX) + 1.0)
    );
}

/// The variables among the leaves of `e`, by a plain walk.
fn leaves(g: &Graph, e: ExprId) -> Vec<Var> {
    let mut vs: Vec<Var> = transform::post_order(g, &[e])
        .into_iter()
        .filter_map(|id| match g.node(id) {
            Node::Var(v) => Some(*v),
            _ => None,
        })
        .collect();
    vs.sort();
    vs.dedup();
    vs
}

/// A random expression over a wide pool of coordinates and velocities, so that most
/// variables are absent from most nodes (as in a long chain of bodies).
fn sparse_expr(g: &mut Graph, rng: &mut Rng) -> ExprId {
    let e = random_expr(g, rng, 4);
    let base = 2 * rng.below(6) as u32;
    transform::substitute(g, e, &mut |g, v| match v {
        Var::Q(i) => Some(g.var(Var::Q(base + i))),
        Var::Qd(i) => Some(g.var(Var::Qd(base + i + 1))),
        _ => None,
    })
}

#[test]
fn variable_sets_hold_exactly_the_leaves() {
    let mut rng = Rng(0x5E7);
    let mut g = Graph::new();
    let roots: Vec<ExprId> = (0..200).map(|_| sparse_expr(&mut g, &mut rng)).collect();
    let sum = g.add(roots.clone());
    for id in (0..g.len()).map(ExprId::from_index) {
        let set = g.var_set(id);
        assert_eq!(&*set, leaves(&g, id).as_slice(), "node {id:?}");
        for v in [Var::Time, Var::Q(3), Var::Qd(4), Var::Param(0)] {
            assert_eq!(g.depends_on(id, v), set.contains(&v), "{v:?} in {id:?}");
        }
    }
    assert!(g.var_set(sum).len() > 10, "the sum spans the pool");
    // `2 + x` and `x²` share the set of `x` instead of copying it.
    let x = g.var(Var::Q(7));
    let two = g.constant(2.0);
    let s = g.add(vec![two, x]);
    let p = g.powi(x, 2);
    let (sx, ss, sp) = (g.var_set(x), g.var_set(s), g.var_set(p));
    assert!(std::sync::Arc::ptr_eq(&sx, &ss) && std::sync::Arc::ptr_eq(&sx, &sp));
    assert!(g.var_set(two).is_empty());
}

#[test]
fn skipping_absent_variables_builds_the_graph_of_the_full_walk() {
    // The same random derivation in a graph that skips absent variables and in one that
    // walks every node of the variable's kind: node for node the same graph, and the
    // same results, whatever the order of the variables.
    let run = |mut g: Graph| {
        let mut rng = Rng(0xF011);
        let mut out = Vec::new();
        let roots: Vec<ExprId> = (0..60).map(|_| sparse_expr(&mut g, &mut rng)).collect();
        let pairs: Vec<(Var, ExprId)> = (0..14).map(|i| (Var::Q(i), g.var(Var::Qd(i)))).collect();
        for (k, &r) in roots.iter().enumerate() {
            for _ in 0..6 {
                let v = match rng.below(3) {
                    0 => Var::Q(rng.below(14) as u32),
                    1 => Var::Qd(rng.below(14) as u32),
                    _ => Var::Time,
                };
                let d = diff::differentiate(&mut g, r, v);
                out.push(diff::differentiate(&mut g, d, Var::Q(rng.below(14) as u32)));
            }
            let kind = if k % 2 == 0 { Var::Q } else { Var::Qd };
            let mut rates = Vec::new();
            diff::for_each_partial(&mut g, r, 14, kind, &mut |g, j, d| {
                rates.push(g.mul(vec![d, pairs[j as usize].1]));
                out.push(d);
            });
            out.extend(rates);
            out.push(diff::directional(&mut g, r, &pairs));
        }
        let nodes: Vec<Node> = (0..g.len())
            .map(|i| g.node(ExprId::from_index(i)).clone())
            .collect();
        (nodes, out)
    };
    let (skip_nodes, skip_out) = run(Graph::new());
    let (full_nodes, full_out) = run(Graph::full_walk());
    assert_eq!(skip_out, full_out);
    assert_eq!(skip_nodes.len(), full_nodes.len());
    assert!(skip_nodes == full_nodes, "the graphs differ");
    assert!(skip_out
        .iter()
        .any(|&e| !matches!(skip_nodes[e.index()], Node::Const(_))));
}

#[test]
fn rates_match_central_differences_along_the_motion() {
    // `rate(e)` is de/ds along q(s) = q + s·q̇, t(s) = t + s with q̇ held (q̈ = 0).
    let mut rng = Rng(0x4A7E);
    let mut checked = 0;
    for _ in 0..300 {
        let mut g = Graph::new();
        let e = random_expr(&mut g, &mut rng, 4);
        let r = diff::rate(&mut g, e);
        let (q, qd, t) = (
            [rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5)],
            [rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5)],
            rng.uniform(-1.5, 1.5),
        );
        let at = |s: f64| {
            move |v: Var| match v {
                Var::Q(i) => q[i as usize] + s * qd[i as usize],
                Var::Qd(i) => qd[i as usize],
                Var::Time => t + s,
                _ => f64::NAN,
            }
        };
        let h = 1e-5;
        let (fp, fm) = (eval(&g, &[e], &at(h))[0], eval(&g, &[e], &at(-h))[0]);
        let fd = (fp - fm) / (2.0 * h);
        let an = eval(&g, &[r], &at(0.0))[0];
        if !fd.is_finite() || !an.is_finite() || fd.abs() > 1e4 {
            continue;
        }
        let scale = fp.abs().max(fm.abs());
        assert!(
            (fd - an).abs() <= 1e-5 * (1.0 + an.abs()) + 1e-9 * scale / h,
            "rate: symbolic {an} vs central difference {fd}"
        );
        checked += 1;
    }
    assert!(checked > 200, "enough rates were compared: {checked}");
}

/// `share::share_products` regroups products only: on random expressions the rebuilt
/// roots evaluate to the originals (to rounding) and never count more operations; on
/// products that share a pair of factors it counts fewer.
#[test]
fn shared_products_keep_values_and_save_operations() {
    let mut rng = Rng(0x5EED_5A4E);
    let mut g = Graph::new();
    let roots: Vec<ExprId> = (0..60).map(|_| random_expr(&mut g, &mut rng, 5)).collect();
    let mut shared = roots.clone();
    super::share::share_products(&mut g, &mut shared);
    assert!(transform::op_count(&g, &shared) <= transform::op_count(&g, &roots));
    for _ in 0..20 {
        let vals = [
            rng.uniform(-1.5, 1.5),
            rng.uniform(-1.5, 1.5),
            rng.uniform(-1.5, 1.5),
            rng.uniform(-1.5, 1.5),
        ];
        let a = eval(&g, &roots, &env(&vals));
        let b = eval(&g, &shared, &env(&vals));
        for (x, y) in a.iter().zip(&b) {
            if x.is_finite() {
                assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()), "{x} vs {y}");
            }
        }
    }
    // a·b·c·x and a·b·c·y: `a·b·c` is computed once (6 → 4 multiplications).
    let mut g = Graph::new();
    let [a, b, c, x, y] = [0, 1, 2, 3, 4].map(|i| g.var(Var::Q(i)));
    let p1 = g.mul(vec![a, b, c, x]);
    let p2 = g.mul(vec![a, b, c, y]);
    let mut r = vec![p1, p2];
    assert_eq!(transform::op_count(&g, &r), 6);
    super::share::share_products(&mut g, &mut r);
    assert_eq!(transform::op_count(&g, &r), 4);
}
