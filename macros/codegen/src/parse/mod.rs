//! Parsing: `syn` tokens → the surface description ([`Mechanism`]).
//!
//! Input: the attribute arguments and the annotated item. Output: the declarations of
//! the module, classified by kind, with every user token kept for spans. This stage
//! checks only the *shape* of each item; names are resolved in `model`.

pub mod kw;
pub mod repeat;

use proc_macro2::TokenStream;
use quote::ToTokens;
use syn::spanned::Spanned;

use crate::ctxt::Ctxt;

/// The annotated module.
#[derive(Debug)]
pub struct Mechanism {
    pub vis: syn::Visibility,
    pub ident: syn::Ident,
    pub docs: String,
    /// Non-doc attributes of the module, forwarded to the output.
    pub attrs: Vec<syn::Attribute>,
    pub items: Vec<Item>,
    /// `#[mechanism(linearize)]`.
    pub linearize: bool,
}

/// A declaration inside the module.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)] // built once per expansion, never stored in bulk
pub enum Item {
    /// `const m: f64 = 1.0;`
    Param {
        name: syn::Ident,
        docs: String,
        default: syn::Expr,
    },
    /// `static x: Coordinate = Coordinate { q0: .., qd0: .. };`
    Coord {
        name: syn::Ident,
        docs: String,
        q0: Option<syn::Expr>,
        qd0: Option<syn::Expr>,
    },
    /// A function item with its role.
    Fn(FnItem),
    /// `static name: Data = Data { len: N } | Beam { .. };`, an array of run-time data
    /// (`model::data`).
    Data {
        name: syn::Ident,
        docs: String,
        expr: syn::Expr,
    },
    /// `static name: Frame|Point|Body|Joint|Force|Drawing|Contact = <constructor>;`, a declaration of
    /// the body level.
    Decl(Decl),
}

/// What a body-level declaration declares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeclKind {
    Frame,
    Point,
    Body,
    Joint,
    Force,
    /// A shape to draw (`pfaff::Drawing`).
    Drawing,
    /// A contact between a point and a surface (`PointPlane`, `PointSphere`), compiled to
    /// a gap function like `#[contact(e)] fn`.
    Contact,
}

/// A body-level declaration: its kind, name and constructor expression.
#[derive(Debug)]
pub struct Decl {
    pub kind: DeclKind,
    pub name: syn::Ident,
    pub docs: String,
    pub expr: syn::Expr,
}

/// A function item: an energy, a constraint, a force or a definition.
#[derive(Debug)]
pub struct FnItem {
    pub name: syn::Ident,
    pub docs: String,
    pub role: Role,
    pub block: syn::Block,
}

/// What a function item declares.
#[derive(Debug, Clone)]
pub enum Role {
    KineticEnergy,
    PotentialEnergy,
    /// `fn mass_matrix() -> [[f64; N]; N]`, with the declared `N` if readable.
    MassMatrix,
    Holonomic,
    Nonholonomic,
    /// `#[force(coordinate)]`
    Force(syn::Ident),
    VirtualWork,
    /// An intermediate definition, used as `name()`.
    Definition,
    /// `#[output]`: a named scalar output.
    Output,
    /// `#[contact(e)]`: a gap function of `q` and `t` with the parameter `e` as its
    /// coefficient of restitution.
    Contact(syn::Ident),
}

/// Parses the attribute arguments and the module.
pub fn parse(cx: &Ctxt, args: TokenStream, input: TokenStream) -> Option<Mechanism> {
    let mut linearize = false;
    if !args.is_empty() {
        match syn::parse2::<syn::Ident>(args.clone()) {
            Ok(id) if id == "linearize" => linearize = true,
            _ => cx.error_spanned_by(
                &args,
                "`#[mechanism]` takes no arguments or `linearize` (emit the derivatives of the linearized equations)",
            ),
        }
    }
    let module: syn::ItemMod = match syn::parse2(input) {
        Ok(m) => m,
        Err(e) => {
            cx.syn_error(syn::Error::new(
                e.span(),
                "`#[mechanism]` applies to an inline module: `#[mechanism] mod name { ... }`",
            ));
            return None;
        }
    };
    let Some((_, content)) = module.content else {
        cx.error_spanned_by(
            &module.ident,
            "`#[mechanism]` needs an inline module with a body: `mod name { ... }`",
        );
        return None;
    };
    let (docs, attrs) = split_docs(module.attrs);
    let items = repeat::expand(cx, content)
        .into_iter()
        .filter_map(|item| parse_item(cx, item))
        .collect();
    Some(Mechanism {
        vis: module.vis,
        ident: module.ident,
        docs,
        attrs,
        items,
        linearize,
    })
}

/// Separates doc comments (joined, trimmed) from the other attributes.
fn split_docs(attrs: Vec<syn::Attribute>) -> (String, Vec<syn::Attribute>) {
    let mut lines = Vec::new();
    let mut rest = Vec::new();
    for attr in attrs {
        if attr.path().is_ident("doc") {
            if let syn::Meta::NameValue(nv) = &attr.meta {
                if let syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Str(s),
                    ..
                }) = &nv.value
                {
                    let v = s.value();
                    lines.push(v.strip_prefix(' ').unwrap_or(&v).to_owned());
                    continue;
                }
            }
        }
        rest.push(attr);
    }
    (lines.join("\n").trim().to_owned(), rest)
}

fn is_type(ty: &syn::Type, name: &str) -> bool {
    matches!(ty, syn::Type::Path(p) if p.qself.is_none() && p.path.is_ident(name))
}

fn parse_item(cx: &Ctxt, item: syn::Item) -> Option<Item> {
    match item {
        syn::Item::Const(c) => {
            let (docs, attrs) = split_docs(c.attrs);
            reject_attrs(cx, &attrs);
            if !is_type(&c.ty, "f64") {
                cx.error_spanned_by(
                    &c.ty,
                    "parameters have type `f64` (`usize` constants give lengths and indices)",
                );
            }
            Some(Item::Param {
                name: c.ident,
                docs,
                default: *c.expr,
            })
        }
        syn::Item::Static(s) => {
            let (docs, attrs) = split_docs(s.attrs);
            reject_attrs(cx, &attrs);
            if let syn::StaticMutability::Mut(m) = &s.mutability {
                cx.error_spanned_by(m, "declarations of a mechanism are not `mut`");
            }
            let kind = [
                (kw::FRAME, DeclKind::Frame),
                (kw::POINT, DeclKind::Point),
                (kw::BODY, DeclKind::Body),
                (kw::JOINT, DeclKind::Joint),
                (kw::FORCE_ELEMENT, DeclKind::Force),
                (kw::DRAWING, DeclKind::Drawing),
                (kw::CONTACT_ITEM, DeclKind::Contact),
            ]
            .into_iter()
            .find(|(n, _)| is_type(&s.ty, n))
            .map(|(_, k)| k);
            if is_type(&s.ty, kw::DATA) {
                return Some(Item::Data {
                    name: s.ident,
                    docs,
                    expr: *s.expr,
                });
            }
            if let Some(kind) = kind {
                return Some(Item::Decl(Decl {
                    kind,
                    name: s.ident,
                    docs,
                    expr: *s.expr,
                }));
            }
            if !is_type(&s.ty, kw::COORDINATE) {
                cx.error_spanned_by(
                    &s.ty,
                    "a `static` declares a generalized coordinate (`Coordinate`), a `Frame`, \
                     a `Point`, a `Body`, a `Joint`, a `Force`, a `Drawing`, a `Contact` or \
                     run-time `Data`",
                );
                return None;
            }
            let (q0, qd0) = parse_coordinate_init(cx, *s.expr);
            Some(Item::Coord {
                name: s.ident,
                docs,
                q0,
                qd0,
            })
        }
        syn::Item::Fn(f) => parse_fn(cx, f).map(Item::Fn),
        syn::Item::Use(_) => None,
        syn::Item::Verbatim(ts) => {
            if let Ok(p) = syn::parse2::<ConstWithoutValue>(ts.clone()) {
                cx.error_spanned_by(
                    &p.ident,
                    format!(
                        "parameter `{}` has no default value; write `const {}: f64 = <value>;`",
                        p.ident, p.ident
                    ),
                );
            } else {
                cx.error_spanned_by(&ts, UNSUPPORTED_ITEM);
            }
            None
        }
        other => {
            cx.error_spanned_by(&other, UNSUPPORTED_ITEM);
            None
        }
    }
}

const UNSUPPORTED_ITEM: &str = "unsupported item in a mechanism, expected a parameter \
     (`const m: f64 = 1.0;`), a coordinate (`static x: Coordinate = Coordinate {};`) or a \
     function (`fn kinetic_energy() -> f64 { .. }`)";

/// `const NAME: TYPE;` (accepted by Rust's parser, but a parameter needs a value).
struct ConstWithoutValue {
    ident: syn::Ident,
}

impl syn::parse::Parse for ConstWithoutValue {
    fn parse(input: syn::parse::ParseStream<'_>) -> syn::Result<Self> {
        let _: Vec<syn::Attribute> = input.call(syn::Attribute::parse_outer)?;
        let _: syn::Visibility = input.parse()?;
        let _: syn::Token![const] = input.parse()?;
        let ident: syn::Ident = input.parse()?;
        let _: syn::Token![:] = input.parse()?;
        let _: syn::Type = input.parse()?;
        let _: syn::Token![;] = input.parse()?;
        Ok(ConstWithoutValue { ident })
    }
}

fn reject_attrs(cx: &Ctxt, attrs: &[syn::Attribute]) {
    for a in attrs {
        cx.error_spanned_by(a, "unexpected attribute here");
    }
}

/// `Coordinate { q0: <expr>, qd0: <expr> }`, both fields optional.
fn parse_coordinate_init(cx: &Ctxt, expr: syn::Expr) -> (Option<syn::Expr>, Option<syn::Expr>) {
    let syn::Expr::Struct(s) = expr else {
        cx.error_spanned_by(
            &expr,
            "expected `Coordinate { q0: <initial value>, qd0: <initial velocity> }` \
             (both fields optional)",
        );
        return (None, None);
    };
    if !s.path.is_ident(kw::COORDINATE) {
        cx.error_spanned_by(&s.path, "expected `Coordinate { .. }`");
    }
    if let Some(rest) = &s.rest {
        cx.error_spanned_by(rest, "`..` is not needed: omitted fields default to 0");
    }
    let (mut q0, mut qd0) = (None, None);
    for field in s.fields {
        let name = match &field.member {
            syn::Member::Named(i) => i.to_string(),
            syn::Member::Unnamed(_) => String::new(),
        };
        let slot = match name.as_str() {
            kw::Q0 => &mut q0,
            kw::QD0 => &mut qd0,
            _ => {
                cx.error_spanned_by(
                    &field.member,
                    format!("unknown field `{name}`, expected `q0` or `qd0`"),
                );
                continue;
            }
        };
        if slot.is_some() {
            cx.error_spanned_by(&field.member, format!("duplicate field `{name}`"));
        }
        *slot = Some(field.expr);
    }
    (q0, qd0)
}

fn parse_fn(cx: &Ctxt, f: syn::ItemFn) -> Option<FnItem> {
    let (docs, attrs) = split_docs(f.attrs);
    let name = f.sig.ident.clone();
    if !f.sig.inputs.is_empty() {
        cx.error_spanned_by(
            &f.sig.inputs,
            "functions of a mechanism take no arguments: coordinates, velocities, parameters \
             and `t` are in scope",
        );
    }
    if !f.sig.generics.params.is_empty() {
        cx.error_spanned_by(&f.sig.generics, "functions of a mechanism are not generic");
    }
    let mut role = None;
    for attr in &attrs {
        let path = attr.path();
        let r = if path.is_ident(kw::HOLONOMIC) {
            Role::Holonomic
        } else if path.is_ident(kw::NONHOLONOMIC) {
            Role::Nonholonomic
        } else if path.is_ident(kw::VIRTUAL_WORK) {
            Role::VirtualWork
        } else if path.is_ident(kw::OUTPUT) {
            Role::Output
        } else if path.is_ident(kw::FORCE) {
            match attr.parse_args::<syn::Ident>() {
                Ok(c) => Role::Force(c),
                Err(_) => {
                    cx.error_spanned_by(attr, "expected `#[force(coordinate)]`");
                    continue;
                }
            }
        } else if path.is_ident(kw::CONTACT) {
            match attr.parse_args::<syn::Ident>() {
                Ok(e) => Role::Contact(e),
                Err(_) => {
                    cx.error_spanned_by(
                        attr,
                        "expected `#[contact(e)]`, with `e` the parameter holding the \
                         coefficient of restitution",
                    );
                    continue;
                }
            }
        } else {
            cx.error_spanned_by(
                attr,
                format!(
                    "unknown attribute `#[{}]`, expected `#[holonomic]`, `#[nonholonomic]`, \
                     `#[force(coordinate)]`, `#[virtual_work]`, `#[output]` or \
                     `#[contact(restitution)]`",
                    path.to_token_stream()
                ),
            );
            continue;
        };
        if !matches!(attr.meta, syn::Meta::Path(_))
            && !matches!(r, Role::Force(_) | Role::Contact(_))
        {
            cx.error_spanned_by(
                attr,
                format!("`#[{}]` takes no arguments", path.to_token_stream()),
            );
        }
        if role.is_some() {
            cx.error_spanned_by(attr, "a function has at most one role attribute");
        }
        role = Some(r);
    }
    let special = match name.to_string().as_str() {
        kw::KINETIC_ENERGY => Some(Role::KineticEnergy),
        kw::POTENTIAL_ENERGY => Some(Role::PotentialEnergy),
        kw::MASS_MATRIX => Some(Role::MassMatrix),
        _ => None,
    };
    let role = match (role, special) {
        (Some(_), Some(_)) => {
            cx.error_spanned_by(
                &name,
                format!("`{name}` has a fixed meaning and takes no role attribute"),
            );
            return None;
        }
        (Some(r), None) => r,
        (None, Some(r)) => r,
        (None, None) => Role::Definition,
    };
    match (&role, &f.sig.output) {
        (Role::MassMatrix, syn::ReturnType::Type(_, ty)) if matches!(**ty, syn::Type::Array(_)) => {
        }
        (Role::MassMatrix, out) => cx.error_at(
            sig_span(&f.sig, out),
            "`mass_matrix` returns a square array: `fn mass_matrix() -> [[f64; N]; N]`",
        ),
        (_, syn::ReturnType::Type(_, ty)) if is_type(ty, "f64") => {}
        (_, out) => cx.error_at(
            sig_span(&f.sig, out),
            format!("`{name}` returns a scalar: `fn {name}() -> f64`"),
        ),
    }
    Some(FnItem {
        name,
        docs,
        role,
        block: *f.block,
    })
}

fn sig_span(sig: &syn::Signature, out: &syn::ReturnType) -> proc_macro2::Span {
    match out {
        syn::ReturnType::Default => sig.span(),
        syn::ReturnType::Type(_, ty) => ty.span(),
    }
}
