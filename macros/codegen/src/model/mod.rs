//! Lowering: the surface description → a [`Model`] with resolved names.
//!
//! Input: [`parse::Mechanism`]. Output: declarations grouped by role, each coordinate,
//! parameter and constraint with a stable index. Checks: duplicate and reserved names,
//! exactly one kinetic-energy description, forces on existing coordinates. Expressions
//! stay as `syn` trees here; [`expr`] translates them into the symbolic graph.

pub mod data;
pub mod expr;
pub mod value;

use std::collections::HashMap;

use crate::ctxt::{suggest, Ctxt};
use crate::parse::{self, kw, Decl, DeclKind, FnItem, Role};

/// A parameter declaration.
#[derive(Debug)]
pub struct Param {
    pub name: syn::Ident,
    pub docs: String,
    pub default: syn::Expr,
}

/// A coordinate declaration.
#[derive(Debug)]
pub struct Coord {
    pub name: syn::Ident,
    pub docs: String,
    pub q0: Option<syn::Expr>,
    pub qd0: Option<syn::Expr>,
}

/// The lowered model.
#[derive(Debug)]
pub struct Model {
    pub vis: syn::Visibility,
    pub ident: syn::Ident,
    pub docs: String,
    pub attrs: Vec<syn::Attribute>,
    pub params: Vec<Param>,
    pub coords: Vec<Coord>,
    pub kinetic: Option<FnItem>,
    pub mass_matrix: Option<FnItem>,
    pub potential: Option<FnItem>,
    /// `#[force(c)]` items with the index of `c`.
    pub forces: Vec<(u32, FnItem)>,
    pub virtual_work: Vec<FnItem>,
    pub holonomic: Vec<FnItem>,
    pub nonholonomic: Vec<FnItem>,
    /// Intermediate definitions, in declaration order.
    pub definitions: Vec<FnItem>,
    /// `#[output]` functions, in declaration order.
    pub outputs: Vec<FnItem>,
    /// `#[contact(e)]` gap functions with the index of the restitution parameter `e`,
    /// in declaration order.
    pub contacts: Vec<(u32, FnItem)>,
    /// Body-level declarations (frames, points, bodies, joints, force elements), in
    /// declaration order.
    pub decls: Vec<Decl>,
    /// `#[mechanism(linearize)]`: emit the linearization Jacobian.
    pub linearize: bool,
    /// Run-time data slots, in declaration order, with their offsets in the model's
    /// flat data (`Var::Data`).
    pub data: Vec<data::DataDecl>,
}

impl Model {
    /// Names of the frames: every `Frame` and every `Body` (a body is its frame).
    pub fn frame_names(&self) -> Vec<String> {
        self.decls
            .iter()
            .filter(|d| matches!(d.kind, DeclKind::Frame | DeclKind::Body))
            .map(|d| d.name.to_string())
            .collect()
    }
    /// Names of the named points.
    pub fn point_names(&self) -> Vec<String> {
        self.decls
            .iter()
            .filter(|d| d.kind == DeclKind::Point)
            .map(|d| d.name.to_string())
            .collect()
    }
    /// Whether the model declares bodies.
    pub fn has_bodies(&self) -> bool {
        self.decls.iter().any(|d| d.kind == DeclKind::Body)
    }
    /// Number of coordinates.
    pub fn nq(&self) -> usize {
        self.coords.len()
    }
    /// Index of the coordinate called `name`.
    pub fn coord_index(&self, name: &str) -> Option<u32> {
        self.coords
            .iter()
            .position(|c| c.name == name)
            .map(|i| u32::try_from(i).expect("coordinate count fits u32"))
    }
    /// The data slot called `name`.
    pub fn data_slot(&self, name: &str) -> Option<&data::DataDecl> {
        self.data.iter().find(|d| d.name == name)
    }
    /// Index of the parameter called `name`.
    pub fn param_index(&self, name: &str) -> Option<u32> {
        self.params
            .iter()
            .position(|c| c.name == name)
            .map(|i| u32::try_from(i).expect("parameter count fits u32"))
    }
}

/// Groups the items by role and checks names.
pub fn lower(cx: &Ctxt, ast: parse::Mechanism) -> Model {
    let mut model = Model {
        vis: ast.vis,
        ident: ast.ident,
        docs: ast.docs,
        attrs: ast.attrs,
        params: Vec::new(),
        coords: Vec::new(),
        kinetic: None,
        mass_matrix: None,
        potential: None,
        forces: Vec::new(),
        virtual_work: Vec::new(),
        holonomic: Vec::new(),
        nonholonomic: Vec::new(),
        definitions: Vec::new(),
        outputs: Vec::new(),
        contacts: Vec::new(),
        decls: Vec::new(),
        linearize: ast.linearize,
        data: Vec::new(),
    };
    let mut seen: HashMap<String, syn::Ident> = HashMap::new();
    let mut declare = |name: &syn::Ident| {
        // `r#t` is the identifier `t`: compare names without the raw prefix.
        let s = syn::ext::IdentExt::unraw(name).to_string();
        if kw::RESERVED.contains(&s.as_str()) {
            cx.error_spanned_by(name, format!("`{s}` is reserved and cannot be declared"));
        } else if let std::collections::hash_map::Entry::Vacant(slot) = seen.entry(s.clone()) {
            slot.insert(name.clone());
        } else {
            cx.error_spanned_by(name, format!("duplicate name `{s}`: it is declared above"));
        }
    };
    let mut pending_forces = Vec::new();
    for item in ast.items {
        match item {
            parse::Item::Param {
                name,
                docs,
                default,
            } => {
                declare(&name);
                model.params.push(Param {
                    name,
                    docs,
                    default,
                });
            }
            parse::Item::Coord {
                name,
                docs,
                q0,
                qd0,
            } => {
                declare(&name);
                model.coords.push(Coord {
                    name,
                    docs,
                    q0,
                    qd0,
                });
            }
            parse::Item::Decl(d) => {
                declare(&d.name);
                model.decls.push(d);
            }
            parse::Item::Data { name, docs, expr } => {
                declare(&name);
                let offset = model.data.last().map_or(0, |d| d.offset + d.len);
                if let Some(d) = data::lower(cx, name, docs, &expr, offset) {
                    model.data.push(d);
                }
            }
            parse::Item::Fn(f) => {
                if f.name == kw::DELTA {
                    cx.error_spanned_by(
                        &f.name,
                        "`delta` is reserved for variations and cannot name a function",
                    );
                }
                declare(&f.name);
                let slot = match &f.role {
                    Role::KineticEnergy => &mut model.kinetic,
                    Role::PotentialEnergy => &mut model.potential,
                    Role::MassMatrix => &mut model.mass_matrix,
                    Role::Holonomic => {
                        model.holonomic.push(f);
                        continue;
                    }
                    Role::Nonholonomic => {
                        model.nonholonomic.push(f);
                        continue;
                    }
                    Role::VirtualWork => {
                        model.virtual_work.push(f);
                        continue;
                    }
                    Role::Definition => {
                        model.definitions.push(f);
                        continue;
                    }
                    Role::Output => {
                        model.outputs.push(f);
                        continue;
                    }
                    Role::Force(_) | Role::Contact(_) => {
                        pending_forces.push(f);
                        continue;
                    }
                };
                *slot = Some(f);
            }
        }
    }
    for f in pending_forces {
        if let Role::Contact(e) = &f.role {
            match model.param_index(&e.to_string()) {
                Some(i) => model.contacts.push((i, f)),
                None => {
                    let names = model
                        .params
                        .iter()
                        .map(|p| p.name.to_string())
                        .collect::<Vec<_>>();
                    let hint = suggest(&e.to_string(), names.iter().map(String::as_str))
                        .map(|s| format!("; did you mean `{s}`?"))
                        .unwrap_or_default();
                    cx.error_spanned_by(
                        e,
                        format!(
                            "`#[contact({e})]` names no parameter: the coefficient of \
                             restitution is a parameter (`const {e}: f64 = 0.5;`){hint}"
                        ),
                    );
                }
            }
            continue;
        }
        let Role::Force(target) = &f.role else {
            unreachable!("only forces and contacts are pending")
        };
        match model.coord_index(&target.to_string()) {
            Some(i) => model.forces.push((i, f)),
            None => {
                let names = model
                    .coords
                    .iter()
                    .map(|c| c.name.to_string())
                    .collect::<Vec<_>>();
                let hint = suggest(&target.to_string(), names.iter().map(String::as_str))
                    .map(|s| format!("; did you mean `{s}`?"))
                    .unwrap_or_default();
                cx.error_spanned_by(
                    target,
                    format!("`#[force({target})]` names no coordinate{hint}"),
                );
            }
        }
    }
    if model.coords.is_empty() {
        cx.error_spanned_by(
            &model.ident,
            "a mechanism declares at least one coordinate: `static x: Coordinate = Coordinate {};`",
        );
    }
    match (&model.kinetic, &model.mass_matrix) {
        (_, Some(m)) if model.has_bodies() => cx.error_spanned_by(
            &m.name,
            "a model with bodies derives its mass matrix from them; add further kinetic \
             energy with `fn kinetic_energy`",
        ),
        (None, None) if model.has_bodies() => {}
        (None, None) => cx.error_spanned_by(
            &model.ident,
            "a mechanism needs its kinetic energy: `fn kinetic_energy() -> f64 { .. }`, \
             `fn mass_matrix() -> [[f64; N]; N] { .. }` or bodies (`static b: Body = ..;`)",
        ),
        (Some(_), Some(m)) => cx.error_spanned_by(
            &m.name,
            "give either `kinetic_energy` or `mass_matrix`, not both",
        ),
        _ => {}
    }
    model
}
