//! Run-time data slots: arrays of model data whose length the model fixes and whose
//! values are known only at run time (`pfaff::Info::data`).
//!
//! ```text
//! /// Invariants exported by a finite-element program (set with `set_data`).
//! static fe: Data = Data { len: 127 };
//! /// A beam-element body, computed by `pfaff::flex` from the parameters.
//! static rod: Data = Beam { elements: 8, length: l, rho_a: rho_a, ea: ea, ei: ei,
//!                           modes: 4, reference: Clamped };
//! ```
//!
//! Input: the constructor of a `static name: Data`. Output: a [`DataDecl`] with the
//! slot's length and offset in the model's flat data, and for a beam the integers that
//! fix its layout (elements, reference, modes, boundary nodes) and the parameter
//! expressions of its geometry and section, translated later. A beam slot holds the
//! reduced body's invariants in the flat layout of `pfaff::flex::Invariants::write_flat`
//! (`[m, Ī1, S̄, I_kl, Ī_kl, S̄_kl, M_ff, K_ff]`, `1 + d + dn + d² + d²n + d²n² + 2n²`
//! values for `d` axes and `n` elastic coordinates), then the beam's length and axial
//! stiffness, its reduced basis `T` (`ndof × n`, `ndof` the nodal coordinates) and the
//! geometric stiffness of a unit spin `K_Ω` (`n × n`), the layout of
//! `pfaff::flex::Beam::write_slot`; all sizes are known here. `modes: N` keeps
//! the lowest `N` modes, `modes: [0, 1, 2, 3, 8]` those of the listed indices.
//! Expressions read a slot's entries as `name[i]` (`Var::Data`).

use std::collections::BTreeSet;

use crate::ctxt::{suggest, Ctxt};

/// A data slot.
#[derive(Debug)]
pub struct DataDecl {
    pub name: syn::Ident,
    pub docs: String,
    /// Index of its first value in the model's flat data.
    pub offset: usize,
    /// Its number of values.
    pub len: usize,
    /// The beam-element body whose invariants fill it, if any.
    pub beam: Option<BeamDecl>,
}

/// How a beam's floating frame is fixed (`pfaff::flex::Reference`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BeamReference {
    /// All coordinates of a node.
    Clamped(usize),
    /// Pinned at the first node, on a roller at the second.
    SimplySupported(usize, usize),
}

/// A uniform straight beam along the body's x axis (`pfaff::flex::Beam`).
#[derive(Debug)]
pub struct BeamDecl {
    pub spatial: bool,
    pub elements: usize,
    pub reference: BeamReference,
    /// Fixed-interface modes (Craig–Bampton) or modes kept (no boundary).
    pub modes: usize,
    /// The indices of the modes kept (`modes: [..]`), in ascending order of frequency.
    pub mode_set: Option<Vec<usize>>,
    /// Craig–Bampton boundary nodes (empty: modal reduction).
    pub boundary: Vec<usize>,
    pub length: syn::Expr,
    /// Section properties in the order of [`BeamDecl::section_fields`].
    pub section: Vec<syn::Expr>,
    /// Body-frame axes (2, 3) and elastic coordinates of the reduced body.
    pub d: usize,
    pub n: usize,
}

impl BeamDecl {
    /// Nodal coordinates per node (3 planar, 6 spatial).
    pub fn dofs_per_node(&self) -> usize {
        if self.spatial {
            6
        } else {
            3
        }
    }

    /// The number of nodal coordinates, the rows of the basis `T`.
    pub fn ndof(&self) -> usize {
        (self.elements + 1) * self.dofs_per_node()
    }

    /// Where the length, `EA` and `T` start in the slot.
    pub fn tail(&self) -> usize {
        flat_len(self.d, self.n)
    }
}

const PLANAR_SECTION: &[&str] = &["rho_a", "ea", "ei"];
const SPATIAL_SECTION: &[&str] = &["rho_a", "ea", "ei_y", "ei_z", "gj", "rho_iy", "rho_iz"];

impl BeamDecl {
    /// The names of the section fields, in the order of `pfaff::flex::Section::planar` /
    /// `Section::spatial`'s arguments.
    pub fn section_fields(&self) -> &'static [&'static str] {
        if self.spatial {
            SPATIAL_SECTION
        } else {
            PLANAR_SECTION
        }
    }
}

/// `slot[i]`: the name of entry `i` of the model's flat data.
pub fn entry_name(slots: &[DataDecl], i: u32) -> String {
    let i = i as usize;
    slots
        .iter()
        .find(|d| (d.offset..d.offset + d.len).contains(&i))
        .map_or_else(
            || format!("data[{i}]"),
            |d| format!("{}[{}]", d.name, i - d.offset),
        )
}

/// The length of the flat invariants of `d` axes and `n` coordinates.
pub fn flat_len(d: usize, n: usize) -> usize {
    1 + d + d * n + d * d + d * d * n + d * d * n * n + 2 * n * n
}

/// Lowers the constructor of `static name: Data = ..;`.
pub fn lower(
    cx: &Ctxt,
    name: syn::Ident,
    docs: String,
    e: &syn::Expr,
    offset: usize,
) -> Option<DataDecl> {
    const KINDS: &str = "`Data { len: N }`, `Beam { .. }` or `SpatialBeam { .. }`";
    let syn::Expr::Struct(s) = e else {
        cx.error_spanned_by(e, format!("expected run-time data: {KINDS}"));
        return None;
    };
    let kind = s
        .path
        .get_ident()
        .map(ToString::to_string)
        .unwrap_or_default();
    if let Some(rest) = &s.rest {
        cx.error_spanned_by(rest, "`..` is not needed: optional fields have defaults");
    }
    let (required, optional): (&[&str], &[&str]) = match kind.as_str() {
        "Data" => (&["len"], &[]),
        "Beam" => (
            &["elements", "length", "rho_a", "ea", "ei", "modes"],
            &["reference", "boundary"],
        ),
        "SpatialBeam" => (
            &[
                "elements", "length", "rho_a", "ea", "ei_y", "ei_z", "gj", "rho_iy", "rho_iz",
                "modes",
            ],
            &["reference", "boundary"],
        ),
        _ => {
            let hint = suggest(&kind, ["Data", "Beam", "SpatialBeam"])
                .map(|n| format!("; did you mean `{n}`?"))
                .unwrap_or_default();
            cx.error_spanned_by(
                &s.path,
                format!("unknown run-time data `{kind}`, expected {KINDS}{hint}"),
            );
            return None;
        }
    };
    let mut fields: Vec<(String, &syn::Expr)> = Vec::new();
    let mut ok = true;
    for f in &s.fields {
        let syn::Member::Named(id) = &f.member else {
            cx.error_spanned_by(&f.member, "fields are named");
            ok = false;
            continue;
        };
        let fname = id.to_string();
        if !required.contains(&fname.as_str()) && !optional.contains(&fname.as_str()) {
            let all = required.iter().chain(optional).copied();
            let hint = suggest(&fname, all)
                .map(|n| format!("; did you mean `{n}`?"))
                .unwrap_or_default();
            let list: Vec<String> = required
                .iter()
                .chain(optional)
                .map(|n| format!("`{n}`"))
                .collect();
            cx.error_spanned_by(
                id,
                format!(
                    "`{kind}` has no field `{fname}`, expected {}{hint}",
                    list.join(", ")
                ),
            );
            ok = false;
        } else if fields.iter().any(|(n, _)| *n == fname) {
            cx.error_spanned_by(id, format!("field `{fname}` is given twice"));
            ok = false;
        } else {
            fields.push((fname, &f.expr));
        }
    }
    for r in required {
        if !fields.iter().any(|(n, _)| n == r) {
            cx.error_spanned_by(&s.path, format!("`{kind}` needs the field `{r}`"));
            ok = false;
        }
    }
    if !ok {
        return None;
    }
    let get = |n: &str| fields.iter().find(|(f, _)| f == n).map(|(_, e)| *e);
    if kind == "Data" {
        let len = integer(cx, get("len")?, "the length of a data slot")?;
        if len == 0 {
            cx.error_spanned_by(get("len")?, "a data slot holds at least one value");
            return None;
        }
        if len > MAX_DATA {
            cx.error_spanned_by(
                get("len")?,
                format!("a data slot holds at most {MAX_DATA} values"),
            );
            return None;
        }
        return within_total(
            cx,
            get("len")?,
            DataDecl {
                name,
                docs,
                offset,
                len,
                beam: None,
            },
        );
    }
    let spatial = kind == "SpatialBeam";
    let elements = integer(cx, get("elements")?, "the number of elements")?;
    if elements == 0 {
        cx.error_spanned_by(get("elements")?, "a beam has at least one element");
        return None;
    }
    if elements > MAX_ELEMENTS {
        cx.error_spanned_by(
            get("elements")?,
            format!(
                "a beam has at most {MAX_ELEMENTS} elements: a finer mesh is a finite element \
                 program's job, whose invariants a `Data` slot takes"
            ),
        );
        return None;
    }
    let (modes, mode_set) = match get("modes")? {
        syn::Expr::Array(a) => {
            let mut set = Vec::new();
            for x in &a.elems {
                let k = integer(cx, x, "a mode index")?;
                if set.contains(&k) {
                    cx.error_spanned_by(x, format!("mode {k} is listed twice"));
                    return None;
                }
                set.push(k);
            }
            (set.len(), Some(set))
        }
        e => (integer(cx, e, "the number of modes")?, None),
    };
    if mode_set.is_some() && get("boundary").is_some() {
        cx.error_spanned_by(
            get("modes")?,
            "a list of modes is a modal reduction; with `boundary` (Craig–Bampton) give their number",
        );
        return None;
    }
    let reference = match get("reference") {
        Some(r) => reference(cx, r, elements)?,
        None => BeamReference::Clamped(0),
    };
    let boundary = match get("boundary") {
        Some(b) => nodes(cx, b, elements)?,
        None => Vec::new(),
    };
    let dpn = if spatial { 6 } else { 3 };
    let deleted: BTreeSet<usize> = match reference {
        BeamReference::Clamped(k) => (k * dpn..(k + 1) * dpn).collect(),
        BeamReference::SimplySupported(a, b) if spatial => {
            [6 * a, 6 * a + 1, 6 * a + 2, 6 * a + 3, 6 * b + 1, 6 * b + 2].into()
        }
        BeamReference::SimplySupported(a, b) => [3 * a, 3 * a + 1, 3 * b + 1].into(),
    };
    let mut nb = 0;
    for &node in &boundary {
        let kept = (node * dpn..(node + 1) * dpn)
            .filter(|c| !deleted.contains(c))
            .count();
        if kept == 0 {
            cx.error_spanned_by(
                get("boundary")?,
                format!(
                    "boundary node {node} keeps no coordinate: the reference condition fixes it"
                ),
            );
            return None;
        }
        nb += kept;
    }
    let interior = (elements + 1) * dpn - deleted.len() - nb;
    if let Some(bad) = mode_set.iter().flatten().find(|&&k| k >= interior) {
        cx.error_spanned_by(
            get("modes")?,
            format!("mode {bad} does not exist: the beam has {interior} modes, 0..{interior}"),
        );
        return None;
    }
    if modes > interior || (modes == 0 && boundary.is_empty()) {
        cx.error_spanned_by(
            get("modes")?,
            format!(
                "{modes} modes: the beam has {interior} interior coordinates to reduce (at least one mode without a boundary)"
            ),
        );
        return None;
    }
    let d = if spatial { 3 } else { 2 };
    let n = nb + modes;
    if n > MAX_ELASTIC {
        cx.error_spanned_by(
            get("modes")?,
            format!(
                "{n} elastic coordinates: a body has at most {MAX_ELASTIC} (modes and boundary \
                 coordinates together)"
            ),
        );
        return None;
    }
    let section_names = if spatial {
        SPATIAL_SECTION
    } else {
        PLANAR_SECTION
    };
    let section = section_names
        .iter()
        .map(|f| get(f).cloned())
        .collect::<Option<_>>()?;
    let beam = BeamDecl {
        spatial,
        elements,
        reference,
        modes,
        mode_set,
        boundary,
        length: get("length")?.clone(),
        section,
        d,
        n,
    };
    let len = flat_len(d, n) + 2 + beam.ndof() * n + n * n;
    within_total(
        cx,
        &s.path,
        DataDecl {
            name,
            docs,
            offset,
            len,
            beam: Some(beam),
        },
    )
}

/// The most values one `Data { len }` slot holds.
pub const MAX_DATA: usize = 1 << 24;
/// The most elements one beam assembles.
pub const MAX_ELEMENTS: usize = 10_000;
/// The most elastic coordinates one beam body has.
pub const MAX_ELASTIC: usize = 1_000;

/// Keeps the slot only if every value of the model's run-time data still has a 32-bit
/// index (the generated code addresses data by `u32`).
fn within_total<T: quote::ToTokens>(cx: &Ctxt, at: T, d: DataDecl) -> Option<DataDecl> {
    if d.offset + d.len > u32::MAX as usize {
        cx.error_spanned_by(
            at,
            format!(
                "the model's run-time data would hold {} values: at most {} fit",
                d.offset + d.len,
                u32::MAX
            ),
        );
        return None;
    }
    Some(d)
}

fn integer(cx: &Ctxt, e: &syn::Expr, what: &str) -> Option<usize> {
    // A literal passed through a `macro_rules!` fragment arrives in an invisible group.
    let mut e = e;
    while let syn::Expr::Group(g) = e {
        e = &g.expr;
    }
    if let syn::Expr::Lit(syn::ExprLit {
        lit: syn::Lit::Int(i),
        ..
    }) = e
    {
        if let Ok(v) = i.base10_parse::<usize>() {
            return Some(v);
        }
    }
    cx.error_spanned_by(
        e,
        format!("{what} is an integer literal: it fixes the generated code's sizes"),
    );
    None
}

fn node(cx: &Ctxt, e: &syn::Expr, elements: usize) -> Option<usize> {
    let k = integer(cx, e, "a node index")?;
    if k > elements {
        cx.error_spanned_by(
            e,
            format!("node {k} does not exist: the beam's nodes are 0..={elements}"),
        );
        return None;
    }
    Some(k)
}

fn nodes(cx: &Ctxt, e: &syn::Expr, elements: usize) -> Option<Vec<usize>> {
    let syn::Expr::Array(a) = e else {
        cx.error_spanned_by(e, "the boundary nodes are a list: `boundary: [8]`");
        return None;
    };
    let mut out = Vec::new();
    for x in &a.elems {
        let k = node(cx, x, elements)?;
        if out.contains(&k) {
            cx.error_spanned_by(x, format!("node {k} is listed twice"));
            return None;
        }
        out.push(k);
    }
    out.sort_unstable();
    Some(out)
}

fn reference(cx: &Ctxt, e: &syn::Expr, elements: usize) -> Option<BeamReference> {
    const EXPECTED: &str = "expected `Clamped` (at node 0), `Clamped(k)`, `SimplySupported` \
                            (nodes 0 and the last) or `SimplySupported(a, b)`";
    let (name, args): (String, Vec<&syn::Expr>) = match e {
        syn::Expr::Path(p) if p.path.get_ident().is_some() => {
            (p.path.get_ident()?.to_string(), Vec::new())
        }
        syn::Expr::Call(c) => match &*c.func {
            syn::Expr::Path(p) if p.path.get_ident().is_some() => {
                (p.path.get_ident()?.to_string(), c.args.iter().collect())
            }
            _ => {
                cx.error_spanned_by(e, EXPECTED);
                return None;
            }
        },
        _ => {
            cx.error_spanned_by(e, EXPECTED);
            return None;
        }
    };
    match (name.as_str(), args.as_slice()) {
        ("Clamped", []) => Some(BeamReference::Clamped(0)),
        ("Clamped", [k]) => Some(BeamReference::Clamped(node(cx, k, elements)?)),
        ("SimplySupported", []) => Some(BeamReference::SimplySupported(0, elements)),
        ("SimplySupported", [a, b]) => {
            let (a, b) = (node(cx, a, elements)?, node(cx, b, elements)?);
            if a == b {
                cx.error_spanned_by(e, "a simple support needs two different nodes");
                return None;
            }
            Some(BeamReference::SimplySupported(a, b))
        }
        _ => {
            cx.error_spanned_by(e, EXPECTED);
            None
        }
    }
}
