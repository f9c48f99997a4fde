//! Translation of user expressions (`syn::Expr`) into the symbolic graph.
//!
//! Input: a function body or an initialiser, and the [`Context`] it appears in. Output:
//! an [`ExprId`] in a canonical graph, or `None` after recording errors with the span of
//! the offending tokens. Each context says what may appear: velocities (`x.dot()`),
//! coordinates, time, variations (`delta(..)`). Translation carries on after an error so
//! that every error of a body is reported at once.

use quote::ToTokens;
use syn::spanned::Spanned;

use super::value::{FrameValue, Value};
use super::Model;
use crate::ctxt::{suggest, Ctxt};
use crate::parse::kw;
use crate::sym::{diff, Deps, ExprId, Func, Graph, Var};

/// Where an expression appears; decides what it may use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Context {
    /// The default of parameter `i` (only parameters above it and constants).
    ParamDefault(u32),
    /// A coordinate's initial value or velocity (parameters and constants).
    Initial,
    Kinetic,
    MassMatrix,
    Potential,
    Holonomic,
    Nonholonomic,
    Force,
    VirtualWork,
    Definition,
    /// A frame, point, body or holonomic joint of the body level (no velocities).
    Kinematics,
    /// A named output (velocities allowed).
    Output,
    /// A contact's gap function (coordinates and time, no velocities).
    Contact,
}

impl Context {
    fn describe(self) -> &'static str {
        match self {
            Context::ParamDefault(_) => "a parameter default",
            Context::Initial => "an initial value",
            Context::Kinetic => "the kinetic energy",
            Context::MassMatrix => "the mass matrix",
            Context::Potential => "the potential energy",
            Context::Holonomic => "a holonomic constraint",
            Context::Nonholonomic => "a non-holonomic constraint",
            Context::Force => "a generalized force",
            Context::VirtualWork => "a virtual work",
            Context::Definition => "a definition",
            Context::Kinematics => "a frame, point, body or holonomic joint",
            Context::Output => "an output",
            Context::Contact => "a contact gap",
        }
    }
    fn allows_velocity(self) -> bool {
        matches!(
            self,
            Context::Kinetic
                | Context::Nonholonomic
                | Context::Force
                | Context::VirtualWork
                | Context::Definition
                | Context::Output
        )
    }
    fn allows_state(self) -> bool {
        !matches!(self, Context::ParamDefault(_) | Context::Initial)
    }
}

/// Translates the expressions of one model into one graph.
#[derive(Debug)]
pub struct Translator<'a> {
    pub(super) cx: &'a Ctxt,
    model: &'a Model,
    pub g: &'a mut Graph,
    /// Translated definitions, by index; `None` until translated (or on error).
    defs: Vec<Option<ExprId>>,
    locals: Vec<(String, Value)>,
    ctx: Context,
    /// The definition being translated, if any.
    current_def: Option<usize>,
    /// Names of the model's frames (frames and bodies), in declaration order.
    pub frame_names: Vec<String>,
    /// The frames translated so far (a declaration may use the ones above it).
    pub frames: Vec<FrameValue>,
    /// Names of the model's named points, in declaration order.
    pub point_names: Vec<String>,
    /// Global positions of the points translated so far.
    pub points: Vec<Vec<ExprId>>,
    /// The material description of deformable bodies, by frame index (for
    /// `body.material(ξ)`).
    pub materials: Vec<(usize, super::value::Material)>,
    /// The frames whose material description is being expanded (a description that
    /// reads its own body's `material` would never end).
    pub expanding_materials: Vec<usize>,
}

const METHODS: &[&str] = &[
    "dot", "powi", "powf", "atan2", "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "exp",
    "ln", "sinh", "cosh", "tanh", "abs", "signum",
];

impl<'a> Translator<'a> {
    /// A translator over `model` writing into `g`.
    pub fn new(cx: &'a Ctxt, model: &'a Model, g: &'a mut Graph) -> Translator<'a> {
        let n = model.definitions.len();
        Translator {
            cx,
            model,
            g,
            defs: vec![None; n],
            locals: Vec::new(),
            ctx: Context::Definition,
            current_def: None,
            frame_names: model.frame_names(),
            frames: Vec::new(),
            point_names: model.point_names(),
            points: Vec::new(),
            materials: Vec::new(),
            expanding_materials: Vec::new(),
        }
    }

    /// The local binding `name`, if any (the innermost).
    pub(super) fn local(&self, name: &str) -> Option<Value> {
        self.locals
            .iter()
            .rev()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.clone())
    }

    /// Whether the current context allows velocities.
    pub(super) fn allows_velocity(&self) -> bool {
        self.ctx.allows_velocity()
    }

    /// The current context, for messages.
    pub(super) fn context_name(&self) -> &'static str {
        self.ctx.describe()
    }

    /// The number of coordinates.
    /// The model being translated.
    pub fn model(&self) -> &'a Model {
        self.model
    }

    pub fn nq(&self) -> usize {
        self.model.nq()
    }

    /// The index of the parameter called `name`.
    pub fn param_index(&self, name: &str) -> Option<u32> {
        self.model.param_index(name)
    }

    /// The names of the parameters.
    pub fn param_names(&self) -> Vec<String> {
        self.model
            .params
            .iter()
            .map(|p| p.name.to_string())
            .collect()
    }

    /// Translates a value in context `ctx` with no local bindings (a declaration's field).
    pub fn field_value(&mut self, e: &syn::Expr, ctx: Context) -> Option<Value> {
        self.with_locals(ctx, &[], |t| t.value(e))
    }

    /// Translates a scalar field of a declaration in context `ctx`.
    pub fn field_scalar(&mut self, e: &syn::Expr, ctx: Context) -> Option<ExprId> {
        self.with_locals(ctx, &[], |t| t.expr(e))
    }

    /// Translates the definitions in order; each may use the ones above it.
    pub fn definitions(&mut self) {
        for i in 0..self.model.definitions.len() {
            let block = &self.model.definitions[i].block;
            self.current_def = Some(i);
            self.defs[i] = self.block(block, Context::Definition);
        }
        self.current_def = None;
    }

    /// Translates a function body (`let` bindings and a final expression).
    pub fn block(&mut self, block: &syn::Block, ctx: Context) -> Option<ExprId> {
        let (stmts, tail) = self.split_block(block)?;
        self.with_locals(ctx, stmts, |t| t.expr(tail))
    }

    /// Translates a mass-matrix body: `let`s and an `N × N` array of arrays.
    pub fn matrix_block(&mut self, block: &syn::Block) -> Option<Vec<Vec<(ExprId, syn::Expr)>>> {
        let (stmts, tail) = self.split_block(block)?;
        let syn::Expr::Array(rows) = tail else {
            self.cx.error_spanned_by(
                tail,
                "`mass_matrix` ends with an array of rows: `[[..], [..]]`",
            );
            return None;
        };
        self.with_locals(Context::MassMatrix, stmts, |t| {
            let mut out = Vec::new();
            let mut ok = true;
            for row in &rows.elems {
                let syn::Expr::Array(cols) = row else {
                    t.cx.error_spanned_by(row, "each row of `mass_matrix` is an array `[..]`");
                    ok = false;
                    continue;
                };
                let mut r = Vec::new();
                for e in &cols.elems {
                    match t.expr(e) {
                        Some(id) => r.push((id, e.clone())),
                        None => ok = false,
                    }
                }
                out.push(r);
            }
            ok.then_some(out)
        })
    }

    /// Translates a standalone expression (a default or an initial value).
    pub fn standalone(&mut self, e: &syn::Expr, ctx: Context) -> Option<ExprId> {
        self.with_locals(ctx, &[], |t| t.expr(e))
    }

    fn split_block<'b>(&self, block: &'b syn::Block) -> Option<(&'b [syn::Stmt], &'b syn::Expr)> {
        match block.stmts.split_last() {
            Some((syn::Stmt::Expr(e, None), rest)) => Some((rest, e)),
            _ => {
                self.cx.error_spanned_by(
                    block,
                    "the body ends with the value, an expression without `;`",
                );
                None
            }
        }
    }

    /// Translates `e` with the extra local `name = value` on top of the current
    /// bindings and context (a closure's argument).
    pub fn with_binding<T>(
        &mut self,
        name: &str,
        value: Value,
        body: impl FnOnce(&mut Self) -> Option<T>,
    ) -> Option<T> {
        self.locals.push((name.to_owned(), value));
        let out = body(self);
        self.locals.pop();
        out
    }

    /// Runs `body` in context `ctx` with no local bindings.
    pub fn in_context<T>(
        &mut self,
        ctx: Context,
        body: impl FnOnce(&mut Self) -> Option<T>,
    ) -> Option<T> {
        self.with_locals(ctx, &[], body)
    }

    fn with_locals<T>(
        &mut self,
        ctx: Context,
        stmts: &[syn::Stmt],
        body: impl FnOnce(&mut Self) -> Option<T>,
    ) -> Option<T> {
        self.ctx = ctx;
        self.locals.clear();
        let mut ok = true;
        for stmt in stmts {
            ok &= self.stmt(stmt);
        }
        let out = body(self);
        self.locals.clear();
        if ok {
            out
        } else {
            None
        }
    }

    fn stmt(&mut self, stmt: &syn::Stmt) -> bool {
        let syn::Stmt::Local(local) = stmt else {
            self.cx.error_spanned_by(
                stmt,
                "only `let name = <expression>;` bindings may precede the value",
            );
            return false;
        };
        let ident = match &local.pat {
            syn::Pat::Ident(p)
                if p.by_ref.is_none() && p.mutability.is_none() && p.subpat.is_none() =>
            {
                &p.ident
            }
            syn::Pat::Type(pt) => match &*pt.pat {
                syn::Pat::Ident(p) if p.subpat.is_none() => &p.ident,
                other => {
                    self.cx
                        .error_spanned_by(other, "expected a name: `let name = ..;`");
                    return false;
                }
            },
            other => {
                self.cx
                    .error_spanned_by(other, "expected a name: `let name = ..;`");
                return false;
            }
        };
        let Some(init) = &local.init else {
            self.cx
                .error_spanned_by(local, "a `let` binding needs a value");
            return false;
        };
        if let Some((_, diverge)) = &init.diverge {
            self.cx
                .error_spanned_by(diverge, "`let .. else` is not supported here");
            return false;
        }
        match self.value(&init.expr) {
            Some(Value::Frame(_)) => {
                self.cx.error_spanned_by(
                    &init.expr,
                    "a `let` binds a number, a vector or a matrix, not a frame",
                );
                false
            }
            Some(v) => {
                self.locals.push((ident.to_string(), v));
                true
            }
            None => false,
        }
    }

    /// Translates `e`, which must be a scalar.
    pub fn expr(&mut self, e: &syn::Expr) -> Option<ExprId> {
        let id = match self.value(e)? {
            Value::Scalar(id) => id,
            other => {
                self.cx.error_spanned_by(
                    e,
                    format!("expected a scalar here; this is {}", other.describe()),
                );
                return None;
            }
        };
        Some(id)
    }

    /// `slot[i]` of a run-time data slot: `None` when `e` does not index a data slot,
    /// `Some(None)` after an error.
    pub(super) fn data_entry(&mut self, e: &syn::ExprIndex) -> Option<Option<ExprId>> {
        let syn::Expr::Path(p) = &*e.expr else {
            return None;
        };
        let name = p.path.get_ident()?.to_string();
        if self.local(&name).is_some() {
            return None;
        }
        let slot = self.model.data_slot(&name)?;
        let (offset, len) = (slot.offset, slot.len);
        if let Context::ParamDefault(_) = self.ctx {
            self.cx.error_spanned_by(
                e,
                format!("run-time data `{name}` in a parameter default: only parameters and constants are allowed here"),
            );
            return Some(None);
        }
        if let syn::Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(i),
            ..
        }) = &*e.index
        {
            if let Ok(k) = i.base10_parse::<usize>() {
                if k < len {
                    let v = u32::try_from(offset + k).expect("data size fits u32");
                    return Some(Some(self.g.var(Var::Data(v))));
                }
            }
        }
        self.cx.error_spanned_by(
            &e.index,
            format!("the index into `{name}` is an integer literal below its length {len}"),
        );
        Some(None)
    }

    /// A scalar expression that is not a sum, product or negation (those go through
    /// [`Translator::value`]): a literal, a name, a function call or method.
    pub(super) fn scalar_leaf(&mut self, e: &syn::Expr) -> Option<ExprId> {
        match e {
            syn::Expr::Lit(l) => self.literal(&l.lit),
            syn::Expr::Path(p) => self.path(p),
            syn::Expr::Unary(u) => {
                self.cx.error_spanned_by(
                    u.op,
                    format!(
                        "unsupported operator `{}`, expected `-`",
                        u.op.to_token_stream()
                    ),
                );
                None
            }
            syn::Expr::MethodCall(m) => self.method(m),
            syn::Expr::Call(c) => self.call(c),
            other => {
                self.cx.error_spanned_by(
                    other,
                    "unsupported expression: mechanism expressions use numbers, names, \
                     `+ - * /`, vectors `[x, y, z]`, and the `f64` methods of the function table",
                );
                None
            }
        }
    }

    /// `lhs op rhs` for scalars.
    pub(super) fn scalar_binary(
        &mut self,
        b: &syn::ExprBinary,
        lhs: ExprId,
        rhs: ExprId,
    ) -> Option<ExprId> {
        Some(match b.op {
            syn::BinOp::Add(_) => self.g.add(vec![lhs, rhs]),
            syn::BinOp::Sub(_) => self.g.sub(lhs, rhs),
            syn::BinOp::Mul(_) => self.g.mul(vec![lhs, rhs]),
            syn::BinOp::Div(_) if self.g.is_zero(rhs) => {
                self.cx.error_spanned_by(&b.right, "division by zero");
                return None;
            }
            syn::BinOp::Div(_) => self.g.div(lhs, rhs),
            op => {
                self.cx.error_spanned_by(
                    op,
                    format!(
                        "unsupported operator `{}`, expected `+`, `-`, `*` or `/`",
                        op.to_token_stream()
                    ),
                );
                return None;
            }
        })
    }

    fn literal(&mut self, lit: &syn::Lit) -> Option<ExprId> {
        let v = match lit {
            syn::Lit::Int(i) => i.base10_parse::<f64>(),
            syn::Lit::Float(f) => f.base10_parse::<f64>(),
            other => {
                self.cx.error_spanned_by(other, "expected a number");
                return None;
            }
        };
        match v {
            Ok(v) if !v.is_finite() => {
                self.cx
                    .error_spanned_by(lit, "number out of range for `f64`");
                None
            }
            Ok(v) => Some(self.g.constant(v)),
            Err(e) => {
                self.cx.syn_error(e);
                None
            }
        }
    }

    pub(super) fn path(&mut self, p: &syn::ExprPath) -> Option<ExprId> {
        if let Some(ident) = p.path.get_ident() {
            return self.expr_ident(ident);
        }
        // `std::f64::consts::PI` and friends.
        let segs: Vec<String> = p
            .path
            .segments
            .iter()
            .map(|s| s.ident.to_string())
            .collect();
        if segs.len() >= 2 && segs[segs.len() - 2] == "consts" {
            if let Some(v) = kw::constant(&segs[segs.len() - 1]) {
                return Some(self.g.constant(v));
            }
        }
        self.cx
            .error_spanned_by(p, "unknown path; use the names declared in the mechanism");
        None
    }

    /// A scalar named `ident`: a local, coordinate, parameter, `t` or constant.
    pub(super) fn expr_ident(&mut self, ident: &syn::Ident) -> Option<ExprId> {
        let s = ident.to_string();
        if let Some(v) = self.local(&s) {
            return match v {
                Value::Scalar(id) => Some(id),
                other => {
                    self.cx.error_spanned_by(
                        ident,
                        format!("`{s}` is {}; a scalar is expected here", other.describe()),
                    );
                    None
                }
            };
        }
        if let Some(i) = self.model.coord_index(&s) {
            if !self.ctx.allows_state() {
                self.cx.error_spanned_by(
                    ident,
                    format!(
                        "coordinate `{s}` in {}: only parameters and constants are allowed here",
                        self.ctx.describe()
                    ),
                );
                return None;
            }
            return Some(self.g.var(Var::Q(i)));
        }
        if self.model.data_slot(&s).is_some() {
            self.cx.error_spanned_by(
                ident,
                format!("`{s}` is an array of run-time data: read one value, e.g. `{s}[0]`"),
            );
            return None;
        }
        if let Some(i) = self.model.param_index(&s) {
            if let Context::ParamDefault(me) = self.ctx {
                if i >= me {
                    self.cx.error_spanned_by(
                        ident,
                        format!("parameter `{s}` is declared below; a default may use only the parameters above it"),
                    );
                    return None;
                }
            }
            return Some(self.g.var(Var::Param(i)));
        }
        if s == kw::TIME {
            if !self.ctx.allows_state() {
                self.cx.error_spanned_by(
                    ident,
                    format!(
                        "time `t` in {}: only parameters and constants are allowed here",
                        self.ctx.describe()
                    ),
                );
                return None;
            }
            return Some(self.g.var(Var::Time));
        }
        if let Some(v) = kw::constant(&s) {
            return Some(self.g.constant(v));
        }
        if self.model.definitions.iter().any(|d| d.name == s) {
            self.cx
                .error_spanned_by(ident, format!("`{s}` is a definition: write `{s}()`"));
            return None;
        }
        let mut names: Vec<String> = self.locals.iter().map(|(n, _)| n.clone()).collect();
        names.extend(self.model.coords.iter().map(|c| c.name.to_string()));
        names.extend(self.frame_names.iter().cloned());
        names.extend(self.point_names.iter().cloned());
        names.extend(self.model.params.iter().map(|c| c.name.to_string()));
        names.push(kw::TIME.to_owned());
        names.extend(["PI", "TAU", "E"].map(String::from));
        let hint = suggest(&s, names.iter().map(String::as_str))
            .map(|n| format!("; did you mean `{n}`?"))
            .unwrap_or_default();
        self.cx
            .error_spanned_by(ident, format!("unknown name `{s}`{hint}"));
        None
    }

    pub(super) fn method(&mut self, m: &syn::ExprMethodCall) -> Option<ExprId> {
        let name = m.method.to_string();
        if name == kw::DOT {
            return self.velocity(m);
        }
        let recv = self.expr(&m.receiver);
        let args: Vec<&syn::Expr> = m.args.iter().collect();
        let want = match name.as_str() {
            "powi" | "powf" | "atan2" => 1,
            _ => 0,
        };
        if Func::from_name(&name).is_none() && !matches!(name.as_str(), "powi" | "powf" | "atan2") {
            let hint = match name.as_str() {
                "log" | "log10" | "log2" => Some("ln"),
                "pow" => Some("powi"),
                _ => suggest(&name, METHODS.iter().copied()),
            }
            .map(|n| format!("; did you mean `{n}`?"))
            .unwrap_or_default();
            self.cx.error_spanned_by(
                &m.method,
                format!(
                    "unsupported function `{name}`, expected one of {}{hint}",
                    METHODS[1..]
                        .iter()
                        .map(|s| format!("`{s}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            );
            return None;
        }
        if args.len() != want {
            self.cx.error_spanned_by(
                &m.args,
                format!(
                    "`{name}` takes {want} argument{}",
                    if want == 1 { "" } else { "s" }
                ),
            );
            return None;
        }
        if name == "powi" {
            let n = self.integer(args[0]);
            return Some(self.g.powi(recv?, n?));
        }
        let arg = if want == 1 {
            Some(self.expr(args[0]))
        } else {
            None
        };
        let recv = recv?;
        Some(match name.as_str() {
            "powf" => {
                let y = arg.flatten()?;
                self.g.powf(recv, y)
            }
            "atan2" => {
                let x = arg.flatten()?;
                self.g.atan2(recv, x)
            }
            _ => {
                let f = Func::from_name(&name).expect("checked above");
                self.g.call(f, recv)
            }
        })
    }

    /// The integer exponent of `powi`: a literal, possibly negated.
    fn integer(&mut self, e: &syn::Expr) -> Option<i32> {
        let (neg, inner) = match e {
            syn::Expr::Unary(syn::ExprUnary {
                op: syn::UnOp::Neg(_),
                expr,
                ..
            }) => (true, &**expr),
            other => (false, other),
        };
        if let syn::Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(i),
            ..
        }) = inner
        {
            if let Ok(v) = i.base10_parse::<i32>() {
                return Some(if neg { -v } else { v });
            }
        }
        self.cx.error_spanned_by(
            e,
            "`powi` takes an integer literal exponent; use `powf` for a general exponent",
        );
        None
    }

    /// `x.dot()`: the velocity of coordinate `x`.
    fn velocity(&mut self, m: &syn::ExprMethodCall) -> Option<ExprId> {
        if !m.args.is_empty() {
            self.cx
                .error_spanned_by(&m.args, "`.dot()` takes no arguments");
            return None;
        }
        let coord = match &*m.receiver {
            syn::Expr::Path(p) => p
                .path
                .get_ident()
                .filter(|i| !self.locals.iter().any(|(n, _)| *i == n))
                .and_then(|i| self.model.coord_index(&i.to_string())),
            _ => None,
        };
        let Some(i) = coord else {
            if let syn::Expr::Path(p) = &*m.receiver {
                if let Some(id) = p.path.get_ident() {
                    let known = self.locals.iter().any(|(n, _)| id == n)
                        || self.model.param_index(&id.to_string()).is_some();
                    if !known {
                        let names: Vec<String> = self
                            .model
                            .coords
                            .iter()
                            .map(|c| c.name.to_string())
                            .collect();
                        let hint = suggest(&id.to_string(), names.iter().map(String::as_str))
                            .map(|n| format!("; did you mean `{n}`?"))
                            .unwrap_or_default();
                        self.cx
                            .error_spanned_by(id, format!("unknown coordinate `{id}`{hint}"));
                        return None;
                    }
                }
            }
            self.cx.error_spanned_by(
                &m.receiver,
                "`.dot()` applies to a coordinate, as in `x.dot()`",
            );
            return None;
        };
        if !self.ctx.allows_velocity() {
            self.cx.error_spanned_by(
                m,
                format!(
                    "velocity `{}` in {}: velocities are not allowed here",
                    m.to_token_stream().to_string().replace(' ', ""),
                    self.ctx.describe()
                ),
            );
            return None;
        }
        Some(self.g.var(Var::Qd(i)))
    }

    pub(super) fn call(&mut self, c: &syn::ExprCall) -> Option<ExprId> {
        let syn::Expr::Path(p) = &*c.func else {
            self.cx.error_spanned_by(&c.func, "unsupported call");
            return None;
        };
        let Some(ident) = p.path.get_ident() else {
            self.cx.error_spanned_by(
                p,
                "unsupported call; write functions as methods, as in `x.sin()`",
            );
            return None;
        };
        let s = ident.to_string();
        if s == kw::DELTA {
            return self.delta(c);
        }
        let Some(k) = self.model.definitions.iter().position(|d| d.name == s) else {
            let hint = if Func::from_name(&s).is_some() || s == "atan2" || s.starts_with("pow") {
                format!("; write functions as methods, as in `x.{s}()`")
            } else {
                let defs: Vec<String> = self
                    .model
                    .definitions
                    .iter()
                    .map(|d| d.name.to_string())
                    .collect();
                suggest(&s, defs.iter().map(String::as_str))
                    .map(|n| format!("; did you mean `{n}()`?"))
                    .unwrap_or_default()
            };
            self.cx
                .error_spanned_by(ident, format!("unknown function `{s}`{hint}"));
            return None;
        };
        if !c.args.is_empty() {
            self.cx
                .error_spanned_by(&c.args, format!("definition `{s}` takes no arguments"));
        }
        if !self.ctx.allows_state() {
            self.cx.error_spanned_by(
                ident,
                format!(
                    "definition `{s}()` in {}: only parameters and constants are allowed here",
                    self.ctx.describe()
                ),
            );
            return None;
        }
        let Some(id) = self.defs[k] else {
            if self.ctx == Context::Definition && self.current_def == Some(k) {
                self.cx.error_spanned_by(
                    ident,
                    format!("definition `{s}` uses itself; definitions are not recursive"),
                );
            } else if self.ctx == Context::Definition {
                self.cx.error_spanned_by(
                    ident,
                    format!("definition `{s}` is declared below; a definition may use only the definitions above it"),
                );
            }
            return None;
        };
        if !self.ctx.allows_velocity() && self.g.deps(id).has(Deps::QD) {
            self.cx.error_spanned_by(
                c,
                format!(
                    "`{s}()` depends on velocities, which are not allowed in {}",
                    self.ctx.describe()
                ),
            );
            return None;
        }
        Some(id)
    }

    /// `delta(e)`: the variation `Σ ∂e/∂q_i δq_i`.
    fn delta(&mut self, c: &syn::ExprCall) -> Option<ExprId> {
        if self.ctx != Context::VirtualWork {
            self.cx.error_spanned_by(
                c,
                format!(
                    "`delta(..)` in {}: variations belong in `#[virtual_work]` functions",
                    self.ctx.describe()
                ),
            );
            return None;
        }
        if c.args.len() != 1 {
            self.cx
                .error_spanned_by(c, "`delta` takes one argument, as in `delta(x)`");
            return None;
        }
        let e = self.expr(&c.args[0])?;
        let pairs: Vec<(Var, ExprId)> = (0..self.model.nq())
            .map(|i| {
                let i = u32::try_from(i).expect("coordinate count fits u32");
                (Var::Q(i), self.g.var(Var::Delta(i)))
            })
            .collect();
        let d = diff::directional(self.g, e, &pairs);
        if self.g.is_zero(d) {
            self.cx.error_spanned_by(&c.args[0], "this variation is identically zero: the expression does not depend on the coordinates");
        }
        Some(d)
    }
}

/// A span for a whole function item (its name), used for model-level diagnostics.
pub fn item_span(f: &crate::parse::FnItem) -> proc_macro2::Span {
    f.name.span()
}

/// Keeps `Spanned` in use for callers that want the span of a body.
pub fn body_span(f: &crate::parse::FnItem) -> proc_macro2::Span {
    f.block.span()
}
