//! Repetition: arrays with a compile-time length, loops that declare items and sums,
//! expanded into ordinary items before the rest of parsing sees them.
//!
//! ```text
//! const N: usize = 10;                                  // a structural constant
//! static th: [Coordinate; N] = [Coordinate { q0: 0.1 }; N];   // th_0 … th_9
//! static x: [Coordinate; N] = from_fn(|i| Coordinate { q0: (i as f64 + 0.5) * l });
//! const _: () = for i in 1..N {                         // items named name_i
//!     #[holonomic]
//!     fn link() -> f64 { (x[i] - x[i - 1]).powi(2) - l * l }
//! };
//! fn potential_energy() -> f64 { (0..N).map(|i| m * g * x[i]).sum() }
//! ```
//!
//! Element `k` of the array `th` is the item `th_k` (`th_1_2` for `th[1][2]` declared
//! by nested loops): that is its name for the run time (`INFO`, `--q0 th_3=0.2`, error
//! messages). Indices are integer expressions of loop variables and `usize` constants
//! (`+ - * / %`, parentheses), evaluated here; `i as f64` becomes the number; an `if`
//! whose condition is such an expression is resolved. The expansion is purely
//! syntactic, so a model written with arrays derives and emits exactly as its
//! unrolled source. Misuse (an index out of range or negative, a length that is not a
//! constant, a loop variable outside its loop) is reported at the offending tokens.

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

use proc_macro2::Span;
use quote::ToTokens;
use syn::spanned::Spanned;

use crate::ctxt::Ctxt;

/// What an array name stands for: the index tuples that exist.
#[derive(Debug, Clone)]
struct Array {
    rank: usize,
    indices: BTreeSet<Vec<i64>>,
    /// How the indices were declared, for messages (`0..10`, `1..10`).
    shape: String,
}

struct Expander<'a> {
    cx: &'a Ctxt,
    /// `const N: usize = ..;`
    consts: HashMap<String, i64>,
    arrays: HashMap<String, Array>,
    /// Every loop variable of the module, to tell a variable used outside its loop from
    /// an unknown name.
    loop_vars: HashSet<String>,
    /// Names declared by plain items (never flagged as loop variables).
    plain: HashSet<String>,
}

/// The loop variables in scope, innermost last, and names shadowing them.
#[derive(Clone, Default)]
struct Env {
    vars: Vec<(String, i64)>,
    shadow: HashSet<String>,
}

impl Env {
    fn get(&self, name: &str) -> Option<i64> {
        if self.shadow.contains(name) {
            return None;
        }
        self.vars.iter().rev().find(|(n, _)| n == name).map(|v| v.1)
    }
    fn with(&self, name: &str, value: i64) -> Env {
        let mut e = self.clone();
        e.shadow.remove(name);
        e.vars.push((name.to_owned(), value));
        e
    }
}

fn unraw(id: &syn::Ident) -> String {
    syn::ext::IdentExt::unraw(id).to_string()
}

fn single_ident(e: &syn::Expr) -> Option<&syn::Ident> {
    match e {
        syn::Expr::Path(p) if p.qself.is_none() => p.path.get_ident(),
        _ => None,
    }
}

fn element_name(base: &str, index: &[i64]) -> String {
    let mut s = base.to_owned();
    for k in index {
        s.push('_');
        s.push_str(&k.to_string());
    }
    s
}

fn int_lit(v: i64, span: Span) -> syn::Expr {
    syn::Expr::Lit(syn::ExprLit {
        attrs: Vec::new(),
        lit: syn::Lit::Int(syn::LitInt::new(&v.to_string(), span)),
    })
}

fn float_lit(v: i64, span: Span) -> syn::Expr {
    syn::Expr::Lit(syn::ExprLit {
        attrs: Vec::new(),
        lit: syn::Lit::Float(syn::LitFloat::new(&format!("{v}.0"), span)),
    })
}

fn path_expr(ident: syn::Ident) -> syn::Expr {
    syn::Expr::Path(syn::ExprPath {
        attrs: Vec::new(),
        qself: None,
        path: ident.into(),
    })
}

/// `[T; LEN]` of a `static`.
fn array_type(ty: &syn::Type) -> Option<(&syn::Type, &syn::Expr)> {
    match ty {
        syn::Type::Array(a) => Some((&a.elem, &a.len)),
        _ => None,
    }
}

fn is_usize(ty: &syn::Type) -> bool {
    matches!(ty, syn::Type::Path(p) if p.qself.is_none() && p.path.is_ident("usize"))
}

/// `const _: () = <loops>;`
fn is_loop_block(c: &syn::ItemConst) -> bool {
    c.ident == "_"
        && matches!(&*c.ty, syn::Type::Tuple(t) if t.elems.is_empty())
        && matches!(&*c.expr, syn::Expr::ForLoop(_) | syn::Expr::Block(_))
}

const INDEX_HELP: &str = "an index or a length is an integer expression of loop variables, \
     `usize` constants (`const N: usize = 10;`) and integers, with `+ - * / %`";

/// The result of a structural evaluation.
enum Eval {
    Value(i64),
    /// Not structural (a parameter, a coordinate, a float): the expression is left alone.
    NotStructural,
    /// Structural but wrong; the error is recorded.
    Failed,
}

impl Expander<'_> {
    /// Evaluates an integer expression of loop variables and constants.
    fn eval(&self, e: &syn::Expr, env: &Env) -> Eval {
        use syn::BinOp as B;
        match e {
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Int(i),
                ..
            }) => match i.base10_parse::<i64>() {
                Ok(v) => Eval::Value(v),
                Err(_) => {
                    self.cx.error_spanned_by(i, "this integer is too large");
                    Eval::Failed
                }
            },
            syn::Expr::Paren(p) => self.eval(&p.expr, env),
            syn::Expr::Group(g) => self.eval(&g.expr, env),
            syn::Expr::Path(_) => {
                let Some(id) = single_ident(e) else {
                    return Eval::NotStructural;
                };
                let name = unraw(id);
                if let Some(v) = env.get(&name) {
                    Eval::Value(v)
                } else if let Some(v) = self.consts.get(&name) {
                    Eval::Value(*v)
                } else if self.loop_vars.contains(&name) && !self.plain.contains(&name) {
                    self.outside_loop(id);
                    Eval::Failed
                } else {
                    Eval::NotStructural
                }
            }
            syn::Expr::Unary(syn::ExprUnary {
                op: syn::UnOp::Neg(_),
                expr,
                ..
            }) => match self.eval(expr, env) {
                Eval::Value(v) => Eval::Value(-v),
                other => other,
            },
            syn::Expr::Binary(b) => {
                let (l, r) = (self.eval(&b.left, env), self.eval(&b.right, env));
                let (l, r) = match (l, r) {
                    (Eval::Value(l), Eval::Value(r)) => (l, r),
                    (Eval::Failed, _) | (_, Eval::Failed) => return Eval::Failed,
                    _ => return Eval::NotStructural,
                };
                let v = match b.op {
                    B::Add(_) => l.checked_add(r),
                    B::Sub(_) => l.checked_sub(r),
                    B::Mul(_) => l.checked_mul(r),
                    B::Div(_) | B::Rem(_) if r == 0 => {
                        self.cx.error_spanned_by(e, "division by zero in an index");
                        return Eval::Failed;
                    }
                    B::Div(_) => l.checked_div(r),
                    B::Rem(_) => l.checked_rem(r),
                    _ => return Eval::NotStructural,
                };
                match v {
                    Some(v) => Eval::Value(v),
                    None => {
                        self.cx.error_spanned_by(e, "this index overflows");
                        Eval::Failed
                    }
                }
            }
            _ => Eval::NotStructural,
        }
    }

    /// Evaluates an expression that must be structural (an index, a length, a range).
    fn eval_required(&self, e: &syn::Expr, env: &Env, what: &str) -> Option<i64> {
        match self.eval(e, env) {
            Eval::Value(v) => Some(v),
            Eval::Failed => None,
            Eval::NotStructural => {
                let msg = match single_ident(e) {
                    Some(id) => format!(
                        "`{id}` is not a `usize` constant or a loop variable: {what} is a \
                         compile-time integer; {INDEX_HELP}"
                    ),
                    None => format!("{what} is a compile-time integer; {INDEX_HELP}"),
                };
                self.cx.error_spanned_by(e, msg);
                None
            }
        }
    }

    /// A condition of loop variables and constants (`i == 0`, `i + 1 < N && j > 0`).
    fn eval_cond(&self, e: &syn::Expr, env: &Env) -> Option<bool> {
        use syn::BinOp as B;
        match e {
            syn::Expr::Paren(p) => self.eval_cond(&p.expr, env),
            syn::Expr::Unary(syn::ExprUnary {
                op: syn::UnOp::Not(_),
                expr,
                ..
            }) => self.eval_cond(expr, env).map(|b| !b),
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Bool(b),
                ..
            }) => Some(b.value),
            syn::Expr::Binary(b) if matches!(b.op, B::And(_) | B::Or(_)) => {
                let l = self.eval_cond(&b.left, env)?;
                let r = self.eval_cond(&b.right, env)?;
                Some(if matches!(b.op, B::And(_)) {
                    l && r
                } else {
                    l || r
                })
            }
            syn::Expr::Binary(b) => {
                let cmp: fn(i64, i64) -> bool = match b.op {
                    B::Eq(_) => |l, r| l == r,
                    B::Ne(_) => |l, r| l != r,
                    B::Lt(_) => |l, r| l < r,
                    B::Le(_) => |l, r| l <= r,
                    B::Gt(_) => |l, r| l > r,
                    B::Ge(_) => |l, r| l >= r,
                    _ => return None,
                };
                let l = self.eval_required(&b.left, env, "a condition's operand")?;
                let r = self.eval_required(&b.right, env, "a condition's operand")?;
                Some(cmp(l, r))
            }
            _ => {
                self.cx.error_spanned_by(
                    e,
                    "a condition compares loop variables and `usize` constants \
                     (`i == 0`, `i + 1 < N`, `&&`, `||`, `!`)",
                );
                None
            }
        }
    }

    fn outside_loop(&self, id: &syn::Ident) {
        self.cx.error_spanned_by(
            id,
            format!(
                "the loop variable `{id}` is used outside its loop: it is in scope only in \
                 the loop (`for {id} in ..`) or closure (`|{id}| ..`) that declares it"
            ),
        );
    }

    /// `a..b` or `a..=b` as the list of its values.
    fn range(&self, e: &syn::Expr, env: &Env) -> Option<Vec<i64>> {
        let e = match e {
            syn::Expr::Paren(p) => &*p.expr,
            e => e,
        };
        let syn::Expr::Range(r) = e else {
            self.cx.error_spanned_by(
                e,
                "expected a range of indices, `a..b` or `a..=b` (`0..N`, `1..=N - 1`)",
            );
            return None;
        };
        let (Some(start), Some(end)) = (&r.start, &r.end) else {
            self.cx
                .error_spanned_by(e, "a range of indices has both ends: `a..b`");
            return None;
        };
        let a = self.eval_required(start, env, "a range's start")?;
        let b = self.eval_required(end, env, "a range's end")?;
        if a < 0 {
            self.cx
                .error_spanned_by(start, format!("negative index {a}: indices start at 0"));
            return None;
        }
        let b = match r.limits {
            syn::RangeLimits::HalfOpen(_) => b,
            syn::RangeLimits::Closed(_) => b + 1,
        };
        Some((a..b).collect())
    }

    /// The element name `base_k` for `base[idx]…`, checked against the array.
    fn element(
        &self,
        base: &syn::Ident,
        indices: &[&syn::Expr],
        whole: &syn::Expr,
        env: &Env,
    ) -> Option<syn::Ident> {
        let name = unraw(base);
        let array = &self.arrays[&name];
        if indices.len() != array.rank {
            self.cx.error_spanned_by(
                whole,
                format!(
                    "`{name}` has {} {}: write `{name}{}`",
                    array.rank,
                    if array.rank == 1 { "index" } else { "indices" },
                    "[i]".repeat(array.rank)
                ),
            );
            return None;
        }
        let mut values = Vec::new();
        for ix in indices {
            let v = self.eval_required(ix, env, "an array index")?;
            if v < 0 {
                self.cx.error_spanned_by(
                    ix,
                    format!("negative index {v} into `{name}`: indices start at 0"),
                );
                return None;
            }
            values.push(v);
        }
        if !array.indices.contains(&values) {
            let shown = values.iter().map(|v| format!("[{v}]")).collect::<String>();
            self.cx.error_spanned_by(
                whole,
                format!(
                    "index out of range: `{name}{shown}` is not declared (`{name}` has the \
                     indices {})",
                    array.shape
                ),
            );
            return None;
        }
        Some(syn::Ident::new(&element_name(&name, &values), base.span()))
    }

    /// Rewrites an expression: array elements to their names, loop variables and
    /// constants to numbers, sums unrolled, structural `if`s resolved.
    fn expr(&self, e: &mut syn::Expr, env: &Env) {
        use syn::Expr as E;
        match e {
            E::Index(_) => {
                // Collect `base[i][j]…`.
                let mut indices = Vec::new();
                let mut cur: &syn::Expr = e;
                while let E::Index(ix) = cur {
                    indices.push(&*ix.index);
                    cur = &ix.expr;
                }
                indices.reverse();
                if let Some(base) = single_ident(cur) {
                    let name = unraw(base);
                    if self.arrays.contains_key(&name) && env.get(&name).is_none() {
                        // After an error, a number stands in for the element so that
                        // later stages add no error of their own.
                        *e = match self.element(base, &indices, e, env) {
                            Some(id) => path_expr(id),
                            None => float_lit(0, e.span()),
                        };
                        return;
                    }
                }
                // Not an array of this module (a data slot, `d[k]`): evaluate a
                // structural index, keep the rest.
                let E::Index(ix) = e else { unreachable!() };
                self.expr(&mut ix.expr, env);
                match self.eval(&ix.index, env) {
                    Eval::Value(v) if v >= 0 => *ix.index = int_lit(v, ix.index.span()),
                    Eval::Value(v) => self.cx.error_spanned_by(
                        &ix.index,
                        format!("negative index {v}: indices start at 0"),
                    ),
                    Eval::Failed => {}
                    Eval::NotStructural => self.expr(&mut ix.index, env),
                }
            }
            E::Path(_) => {
                let Some(id) = single_ident(e) else { return };
                let name = unraw(id);
                let span = id.span();
                if let Some(v) = env.get(&name) {
                    *e = int_lit(v, span);
                } else if env.shadow.contains(&name) {
                    // A `let` or a closure's parameter: not ours.
                } else if let Some(v) = self.consts.get(&name) {
                    *e = int_lit(*v, span);
                } else if let Some(a) = self.arrays.get(&name) {
                    self.cx.error_spanned_by(
                        id,
                        format!(
                            "`{name}` is an array (indices {}): write one element, `{name}{}`",
                            a.shape,
                            "[i]".repeat(a.rank)
                        ),
                    );
                    *e = float_lit(0, span);
                } else if self.loop_vars.contains(&name) && !self.plain.contains(&name) {
                    self.outside_loop(id);
                    *e = float_lit(0, span);
                }
            }
            E::Cast(c) => match self.eval(&c.expr, env) {
                Eval::Value(v) => *e = float_lit(v, c.expr.span()),
                Eval::Failed => {}
                Eval::NotStructural => self.expr(&mut c.expr, env),
            },
            E::If(i) => {
                let Some(cond) = self.eval_cond(&i.cond, env) else {
                    return;
                };
                let chosen = if cond {
                    Some(syn::Expr::Block(syn::ExprBlock {
                        attrs: Vec::new(),
                        label: None,
                        block: i.then_branch.clone(),
                    }))
                } else {
                    i.else_branch.as_ref().map(|(_, b)| (**b).clone())
                };
                let Some(mut chosen) = chosen else {
                    self.cx.error_spanned_by(
                        &*e,
                        "an `if` in a description has an `else`: both branches give a value",
                    );
                    return;
                };
                // `{ expr }` is the expression itself.
                if let E::Block(b) = &chosen {
                    if let [syn::Stmt::Expr(inner, None)] = b.block.stmts.as_slice() {
                        chosen = inner.clone();
                    }
                }
                self.expr(&mut chosen, env);
                *e = chosen;
            }
            E::MethodCall(m) if m.method == "sum" && m.args.is_empty() => {
                if let Some(sum) = self.sum(m, env) {
                    *e = sum;
                } else {
                    self.expr(&mut m.receiver, env);
                }
            }
            E::MethodCall(m) => {
                self.expr(&mut m.receiver, env);
                for a in &mut m.args {
                    self.expr(a, env);
                }
            }
            E::Binary(b) => {
                self.expr(&mut b.left, env);
                self.expr(&mut b.right, env);
            }
            E::Unary(u) => self.expr(&mut u.expr, env),
            E::Paren(p) => self.expr(&mut p.expr, env),
            E::Group(g) => self.expr(&mut g.expr, env),
            E::Call(c) => {
                self.expr(&mut c.func, env);
                for a in &mut c.args {
                    self.expr(a, env);
                }
            }
            E::Array(a) => {
                for x in &mut a.elems {
                    self.expr(x, env);
                }
            }
            E::Tuple(t) => {
                for x in &mut t.elems {
                    self.expr(x, env);
                }
            }
            E::Struct(s) => {
                for f in &mut s.fields {
                    self.expr(&mut f.expr, env);
                }
            }
            E::Field(f) => self.expr(&mut f.base, env),
            E::Range(r) => {
                if let Some(x) = &mut r.start {
                    self.expr(x, env);
                }
                if let Some(x) = &mut r.end {
                    self.expr(x, env);
                }
            }
            E::Reference(r) => self.expr(&mut r.expr, env),
            E::Repeat(r) => {
                self.expr(&mut r.expr, env);
                self.expr(&mut r.len, env);
            }
            E::Closure(c) => {
                let mut inner = env.clone();
                for p in &c.inputs {
                    if let syn::Pat::Ident(pi) = p {
                        inner.shadow.insert(unraw(&pi.ident));
                    }
                }
                self.expr(&mut c.body, &inner);
            }
            E::Block(b) => self.block(&mut b.block, env),
            _ => {}
        }
    }

    fn block(&self, b: &mut syn::Block, env: &Env) {
        let mut env = env.clone();
        for s in &mut b.stmts {
            match s {
                syn::Stmt::Local(l) => {
                    if let Some(init) = &mut l.init {
                        self.expr(&mut init.expr, &env);
                    }
                    if let syn::Pat::Ident(pi) = &l.pat {
                        env.shadow.insert(unraw(&pi.ident));
                    } else if let syn::Pat::Type(pt) = &l.pat {
                        if let syn::Pat::Ident(pi) = &*pt.pat {
                            env.shadow.insert(unraw(&pi.ident));
                        }
                    }
                }
                syn::Stmt::Expr(x, _) => self.expr(x, &env),
                _ => {}
            }
        }
    }

    /// `(a..b).map(|i| body).sum()` as `body_a + … + body_{b-1}` (`0.0` if empty).
    fn sum(&self, m: &syn::ExprMethodCall, env: &Env) -> Option<syn::Expr> {
        let syn::Expr::MethodCall(map) = &*m.receiver else {
            return None;
        };
        if map.method != "map" || map.args.len() != 1 {
            return None;
        }
        let range = match &*map.receiver {
            syn::Expr::Paren(p) => &*p.expr,
            r => r,
        };
        if !matches!(range, syn::Expr::Range(_)) {
            return None;
        }
        let syn::Expr::Closure(c) = &map.args[0] else {
            return None;
        };
        let [syn::Pat::Ident(var)] = c.inputs.iter().collect::<Vec<_>>().as_slice() else {
            self.cx.error_spanned_by(
                &c.inputs,
                "a sum's closure takes one index: `(0..N).map(|i| ..).sum()`",
            );
            return Some(float_lit(0, m.span()));
        };
        let Some(values) = self.range(range, env) else {
            return Some(float_lit(0, m.span()));
        };
        let var = unraw(&var.ident);
        let mut acc: Option<syn::Expr> = None;
        for v in values {
            let mut term = (*c.body).clone();
            self.expr(&mut term, &env.with(&var, v));
            let term = syn::Expr::Paren(syn::ExprParen {
                attrs: Vec::new(),
                paren_token: Default::default(),
                expr: Box::new(term),
            });
            acc = Some(match acc {
                None => term,
                Some(a) => syn::Expr::Binary(syn::ExprBinary {
                    attrs: Vec::new(),
                    left: Box::new(a),
                    op: syn::BinOp::Add(Default::default()),
                    right: Box::new(term),
                }),
            });
        }
        Some(acc.unwrap_or_else(|| float_lit(0, m.span())))
    }

    /// Rewrites a `#[force(x[i])]`/`#[contact(e)]` argument.
    fn attrs(&self, attrs: &mut [syn::Attribute], env: &Env) {
        for a in attrs {
            if !(a.path().is_ident(super::kw::FORCE) || a.path().is_ident(super::kw::CONTACT)) {
                continue;
            }
            let syn::Meta::List(list) = &mut a.meta else {
                continue;
            };
            let Ok(mut arg) = syn::parse2::<syn::Expr>(list.tokens.clone()) else {
                continue;
            };
            self.expr(&mut arg, env);
            list.tokens = arg.into_token_stream();
        }
    }

    /// Expands one item declared with the index `suffix` (empty at the top level).
    fn item(&self, item: syn::Item, env: &Env, suffix: &[i64], out: &mut Vec<syn::Item>) {
        // Outside a loop the name is kept as written (a raw `r#type` stays raw).
        let rename = |id: &syn::Ident| -> syn::Ident {
            if suffix.is_empty() {
                id.clone()
            } else {
                syn::Ident::new(&element_name(&unraw(id), suffix), id.span())
            }
        };
        match item {
            syn::Item::Const(c) if is_usize(&c.ty) => {
                if !suffix.is_empty() {
                    self.cx.error_spanned_by(
                        &c.ident,
                        "`usize` constants are declared at the module's level, not in a loop",
                    );
                }
                // Evaluated in `collect`.
            }
            syn::Item::Const(c) if is_loop_block(&c) => self.loops(&c.expr, env, suffix, out),
            syn::Item::Const(mut c) => {
                if !suffix.is_empty() {
                    self.cx.error_spanned_by(
                        &c.ident,
                        "parameters are declared at the module's level, not in a loop",
                    );
                    return;
                }
                self.expr(&mut c.expr, env);
                out.push(syn::Item::Const(c));
            }
            syn::Item::Static(s) => {
                if let Some((elem, len)) = array_type(&s.ty) {
                    let Some(n) = self.eval_required(len, env, "an array's length") else {
                        return;
                    };
                    let (elem, len) = (elem.clone(), len.clone());
                    if n < 0 {
                        self.cx
                            .error_spanned_by(&len, format!("negative length {n}"));
                        return;
                    }
                    let inits = self.array_init(&s.expr, n, env);
                    let Some(inits) = inits else { return };
                    for (k, (mut init, ienv)) in inits.into_iter().enumerate() {
                        self.expr(&mut init, &ienv);
                        let mut idx = suffix.to_vec();
                        idx.push(k as i64);
                        let mut el = s.clone();
                        el.ident =
                            syn::Ident::new(&element_name(&unraw(&s.ident), &idx), s.ident.span());
                        el.ty = Box::new(elem.clone());
                        el.expr = Box::new(init);
                        out.push(syn::Item::Static(el));
                    }
                } else {
                    let mut s = s;
                    self.expr(&mut s.expr, env);
                    s.ident = rename(&s.ident);
                    out.push(syn::Item::Static(s));
                }
            }
            syn::Item::Fn(mut f) => {
                self.attrs(&mut f.attrs, env);
                self.block(&mut f.block, env);
                f.sig.ident = rename(&f.sig.ident);
                out.push(syn::Item::Fn(f));
            }
            other if suffix.is_empty() => out.push(other),
            other => self.cx.error_spanned_by(
                &other,
                "a loop declares `static` items, functions and nested loops",
            ),
        }
    }

    /// The initializers of `static a: [T; n] = <init>;`, each with its environment.
    fn array_init(&self, init: &syn::Expr, n: i64, env: &Env) -> Option<Vec<(syn::Expr, Env)>> {
        match init {
            syn::Expr::Repeat(r) => {
                let m = self.eval_required(&r.len, env, "an array's length")?;
                if m != n {
                    self.cx.error_spanned_by(
                        &r.len,
                        format!("the initializer has {m} elements, the array {n}"),
                    );
                    return None;
                }
                Some((0..n).map(|_| ((*r.expr).clone(), env.clone())).collect())
            }
            syn::Expr::Array(a) => {
                if a.elems.len() as i64 != n {
                    self.cx.error_spanned_by(
                        init,
                        format!(
                            "the initializer has {} elements, the array {n}",
                            a.elems.len()
                        ),
                    );
                    return None;
                }
                Some(a.elems.iter().map(|x| (x.clone(), env.clone())).collect())
            }
            syn::Expr::Call(c)
                if matches!(&*c.func, syn::Expr::Path(p)
                    if p.path.segments.last().is_some_and(|s| s.ident == "from_fn"))
                    && c.args.len() == 1 =>
            {
                let syn::Expr::Closure(cl) = &c.args[0] else {
                    self.cx
                        .error_spanned_by(&c.args[0], "expected a closure `|i| ..`");
                    return None;
                };
                let [syn::Pat::Ident(var)] = cl.inputs.iter().collect::<Vec<_>>().as_slice() else {
                    self.cx
                        .error_spanned_by(&cl.inputs, "the closure takes one index: `|i| ..`");
                    return None;
                };
                let var = unraw(&var.ident);
                Some(
                    (0..n)
                        .map(|k| ((*cl.body).clone(), env.with(&var, k)))
                        .collect(),
                )
            }
            other => {
                self.cx.error_spanned_by(
                    other,
                    "an array is initialized by `[<item>; N]`, `[<item 0>, <item 1>, ..]` or \
                     `from_fn(|i| <item i>)`",
                );
                None
            }
        }
    }

    /// `for i in a..b { items }`, a block of such loops, nested loops.
    fn loops(&self, e: &syn::Expr, env: &Env, suffix: &[i64], out: &mut Vec<syn::Item>) {
        match e {
            syn::Expr::Block(b) => {
                for s in &b.block.stmts {
                    self.stmt(s, env, suffix, out);
                }
            }
            syn::Expr::ForLoop(f) => {
                let syn::Pat::Ident(var) = &*f.pat else {
                    self.cx
                        .error_spanned_by(&f.pat, "a loop's variable is one name: `for i in ..`");
                    return;
                };
                let Some(values) = self.range(&f.expr, env) else {
                    return;
                };
                let var = unraw(&var.ident);
                for v in values {
                    let inner = env.with(&var, v);
                    let mut idx = suffix.to_vec();
                    idx.push(v);
                    for s in &f.body.stmts {
                        self.stmt(s, &inner, &idx, out);
                    }
                }
            }
            other => self.cx.error_spanned_by(
                other,
                "expected a loop that declares items: `const _: () = for i in 0..N { .. };`",
            ),
        }
    }

    fn stmt(&self, s: &syn::Stmt, env: &Env, suffix: &[i64], out: &mut Vec<syn::Item>) {
        match s {
            syn::Stmt::Item(item) => self.item(item.clone(), env, suffix, out),
            syn::Stmt::Expr(e @ syn::Expr::ForLoop(_), _) => self.loops(e, env, suffix, out),
            other => self.cx.error_spanned_by(
                other,
                "a loop declares `static` items, functions and nested loops \
                 (`for j in 0..M { .. }`)",
            ),
        }
    }

    /// First pass: constants, arrays and the names that loops declare.
    fn collect(&mut self, items: &[syn::Item]) {
        for item in items {
            match item {
                syn::Item::Const(c) if is_usize(&c.ty) => {
                    if let Some(v) =
                        self.eval_required(&c.expr, &Env::default(), "a `usize` constant")
                    {
                        if v < 0 {
                            self.cx.error_spanned_by(
                                &c.expr,
                                format!("a `usize` constant is not negative ({v})"),
                            );
                        } else {
                            self.consts.insert(unraw(&c.ident), v);
                        }
                    }
                }
                syn::Item::Const(c) if is_loop_block(c) => {
                    let mut names = BTreeMap::new();
                    self.collect_loops(&c.expr, &Env::default(), &[], &mut names);
                    for (name, indices) in names {
                        let rank = indices.iter().next().map_or(1, Vec::len);
                        let shape = shape_of(&indices);
                        self.arrays.insert(
                            name,
                            Array {
                                rank,
                                indices,
                                shape,
                            },
                        );
                    }
                }
                syn::Item::Static(s) => {
                    let name = unraw(&s.ident);
                    if let Some((_, len)) = array_type(&s.ty) {
                        if let Eval::Value(n) = self.eval(len, &Env::default()) {
                            let indices = (0..n.max(0)).map(|k| vec![k]).collect();
                            self.arrays.insert(
                                name,
                                Array {
                                    rank: 1,
                                    indices,
                                    shape: format!("0..{n}"),
                                },
                            );
                        }
                        if let Some(v) = closure_var(&s.expr) {
                            self.loop_vars.insert(v);
                        }
                    } else {
                        self.plain.insert(name);
                    }
                }
                syn::Item::Const(c) => {
                    self.plain.insert(unraw(&c.ident));
                }
                syn::Item::Fn(f) => {
                    self.plain.insert(unraw(&f.sig.ident));
                }
                _ => {}
            }
        }
    }

    /// The names loops declare with their index tuples (errors reported in `item`).
    fn collect_loops(
        &mut self,
        e: &syn::Expr,
        env: &Env,
        suffix: &[i64],
        names: &mut BTreeMap<String, BTreeSet<Vec<i64>>>,
    ) {
        let quiet = Ctxt::new();
        let probe = Expander {
            cx: &quiet,
            consts: self.consts.clone(),
            arrays: HashMap::new(),
            loop_vars: HashSet::new(),
            plain: HashSet::new(),
        };
        let mut visit = |s: &syn::Stmt, env: &Env, idx: &[i64], this: &mut Self| match s {
            syn::Stmt::Item(syn::Item::Static(st)) => {
                let mut idx = idx.to_vec();
                if let Some((_, len)) = array_type(&st.ty) {
                    if let Eval::Value(n) = probe.eval(len, env) {
                        for k in 0..n.max(0) {
                            idx.push(k);
                            names
                                .entry(unraw(&st.ident))
                                .or_default()
                                .insert(idx.clone());
                            idx.pop();
                        }
                    }
                } else {
                    names.entry(unraw(&st.ident)).or_default().insert(idx);
                }
            }
            syn::Stmt::Item(syn::Item::Fn(f)) => {
                names
                    .entry(unraw(&f.sig.ident))
                    .or_default()
                    .insert(idx.to_vec());
            }
            syn::Stmt::Expr(inner @ syn::Expr::ForLoop(_), _) => {
                this.collect_loops(inner, env, idx, names);
            }
            _ => {}
        };
        match e {
            syn::Expr::Block(b) => {
                for s in &b.block.stmts {
                    visit(s, env, suffix, self);
                }
            }
            syn::Expr::ForLoop(f) => {
                if let syn::Pat::Ident(var) = &*f.pat {
                    let var = unraw(&var.ident);
                    self.loop_vars.insert(var.clone());
                    if let Some(values) = probe.range(&f.expr, env) {
                        for v in values {
                            let inner = env.with(&var, v);
                            let mut idx = suffix.to_vec();
                            idx.push(v);
                            for s in &f.body.stmts {
                                visit(s, &inner, &idx, self);
                            }
                        }
                    }
                }
            }
            _ => {}
        }
        drop(quiet.check());
    }
}

fn closure_var(init: &syn::Expr) -> Option<String> {
    let syn::Expr::Call(c) = init else {
        return None;
    };
    let syn::Expr::Closure(cl) = c.args.first()? else {
        return None;
    };
    match cl.inputs.first()? {
        syn::Pat::Ident(p) => Some(unraw(&p.ident)),
        _ => None,
    }
}

/// `0..10`, `1..10`, or the list for irregular sets.
fn shape_of(indices: &BTreeSet<Vec<i64>>) -> String {
    let rank = indices.iter().next().map_or(1, Vec::len);
    if rank == 1 {
        let v: Vec<i64> = indices.iter().map(|x| x[0]).collect();
        if let (Some(a), Some(b)) = (v.first(), v.last()) {
            if (b - a + 1) as usize == v.len() {
                return format!("{a}..{}", b + 1);
            }
        }
    }
    indices
        .iter()
        .map(|x| x.iter().map(|k| format!("[{k}]")).collect::<String>())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Collects the sum-expression loop variables (`.map(|i| ..)`) of every item, so that
/// one used outside its closure is reported as such.
fn sum_vars(items: &[syn::Item], vars: &mut HashSet<String>) {
    fn walk(ts: proc_macro2::TokenStream, vars: &mut HashSet<String>) {
        // `map ( | i |`: the closure's first parameter.
        let tts: Vec<proc_macro2::TokenTree> = ts.into_iter().collect();
        for (k, tt) in tts.iter().enumerate() {
            let proc_macro2::TokenTree::Group(g) = tt else {
                continue;
            };
            if k > 0 {
                if let proc_macro2::TokenTree::Ident(m) = &tts[k - 1] {
                    if m == "map" || m == "from_fn" {
                        let inner: Vec<_> = g.stream().into_iter().collect();
                        if let [proc_macro2::TokenTree::Punct(p), proc_macro2::TokenTree::Ident(v), ..] =
                            inner.as_slice()
                        {
                            if p.as_char() == '|' {
                                vars.insert(v.to_string());
                            }
                        }
                    }
                }
            }
            walk(g.stream(), vars);
        }
    }
    for item in items {
        walk(item.to_token_stream(), vars);
    }
}

/// Expands the repetition in a module's items (see the module's documentation).
pub fn expand(cx: &Ctxt, items: Vec<syn::Item>) -> Vec<syn::Item> {
    let mut x = Expander {
        cx,
        consts: HashMap::new(),
        arrays: HashMap::new(),
        loop_vars: HashSet::new(),
        plain: HashSet::new(),
    };
    x.collect(&items);
    sum_vars(&items, &mut x.loop_vars);
    let mut out = Vec::with_capacity(items.len());
    for item in items {
        x.item(item, &Env::default(), &[], &mut out);
    }
    out
}
