//! Emission: derived quantities → the Rust module that implements `pfaff::Mechanism`.
//!
//! Input: the [`Model`] (names, docs, visibility) and the [`Derived`] expressions.
//! Output: tokens of the replacement module with `Params`, `Model`, `INFO` and the trait
//! impl. A function whose outputs are all identically zero for the model is not emitted
//! (the trait's default fills zeros). Runtime paths go through `::pfaff::__private`.

mod contacts;
mod corrected;
mod data;
pub mod expr;
mod normal_map;
pub mod nullspace;
pub mod solve;

use std::collections::HashSet;

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

use crate::derive::{Derived, Entry};
use crate::model::Model;
use crate::sched::{self, Program};
use crate::sym::{ExprId, Graph, Var};
use expr::{Names, Printer};

/// Most temporaries a generated function binds with `let` (see [`body`]).
const MAX_LETS: usize = 2000;

/// Names of leaves and temporaries in generated code.
struct ModelNames {
    coords: Vec<Ident>,
    velocities: Vec<Ident>,
    params: Vec<Ident>,
    temp_prefix: String,
    /// The argument of `free_motion_residual` holding the applied forces.
    applied: String,
    /// The argument of `linearization_jacobian` holding the accelerations and
    /// multipliers, and the prefix of its entries' names.
    inputs: String,
    input_prefix: String,
    /// The local array of temporaries of long functions.
    temps: String,
    /// The arguments of `holonomic_with_jacobian` receiving `C` and `C_q` (and the
    /// binding of the `C` a caller of the dynamics terms asks for).
    out_c: String,
    out_cq: String,
    /// Per data slot: its field name, the prefix of its entries' names, its offset and
    /// length in the flat data.
    data: Vec<(Ident, String, usize, usize)>,
}

/// `name` without the `r#` of a raw identifier, the text generated names are built on.
fn plain(name: &Ident) -> String {
    syn::ext::IdentExt::unraw(name).to_string()
}

impl ModelNames {
    fn new(model: &Model) -> ModelNames {
        let declared: HashSet<String> = model
            .coords
            .iter()
            .map(|c| plain(&c.name))
            .chain(model.params.iter().map(|p| plain(&p.name)))
            .collect();
        let velocities = model
            .coords
            .iter()
            .map(|c| {
                let mut name = format!("{}_dot", plain(&c.name));
                while declared.contains(&name) {
                    name.push('_');
                }
                Ident::new(&name, Span::call_site())
            })
            .collect();
        // Temporaries are `<prefix><k>`: the prefix must not make any declared name.
        let mut temp_prefix = String::from("t");
        while declared.iter().any(|n| {
            n.strip_prefix(temp_prefix.as_str())
                .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
        }) {
            temp_prefix = if temp_prefix == "t" {
                String::from("tmp_")
            } else {
                format!("{temp_prefix}_")
            };
        }
        let mut applied = String::from("applied");
        while declared.contains(&applied) {
            applied.push('_');
        }
        let mut temps = String::from("temps");
        while declared.contains(&temps) {
            temps.push('_');
        }
        let mut inputs = String::from("inputs");
        while declared.contains(&inputs) {
            inputs.push('_');
        }
        let [out_c, out_cq] = ["c", "cq"].map(|base| {
            let mut name = String::from(base);
            while declared.contains(&name) {
                name.push('_');
            }
            name
        });
        let mut input_prefix = format!("{inputs}_");
        while declared.iter().any(|n| {
            n.strip_prefix(input_prefix.as_str())
                .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
        }) {
            input_prefix.push('_');
        }
        let data = model
            .data
            .iter()
            .map(|d| {
                let mut prefix = format!("{}_", plain(&d.name));
                while declared.iter().any(|n| {
                    n.strip_prefix(prefix.as_str())
                        .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
                }) {
                    prefix.push('_');
                }
                (d.name.clone(), prefix, d.offset, d.len)
            })
            .collect();
        ModelNames {
            data,
            coords: model.coords.iter().map(|c| c.name.clone()).collect(),
            velocities,
            params: model.params.iter().map(|p| p.name.clone()).collect(),
            temp_prefix,
            applied,
            inputs,
            input_prefix,
            temps,
            out_c,
            out_cq,
        }
    }
}

impl ModelNames {
    /// The slot's field, its entries' name prefix and the index in the slot of entry `i`
    /// of the flat data.
    fn data_entry(&self, i: u32) -> (&Ident, &str, usize) {
        let i = i as usize;
        let (field, prefix, offset, _) = self
            .data
            .iter()
            .find(|(_, _, o, len)| (*o..o + len).contains(&i))
            .expect("data entries belong to a slot");
        (field, prefix, i - offset)
    }
}

impl Names for ModelNames {
    fn var(&self, v: Var) -> Ident {
        match v {
            Var::Time => Ident::new("t", Span::call_site()),
            Var::Q(i) => self.coords[i as usize].clone(),
            Var::Qd(i) => self.velocities[i as usize].clone(),
            Var::Param(i) => self.params[i as usize].clone(),
            Var::Delta(i) => format_ident!("delta_{}", plain(&self.coords[i as usize])),
            Var::Input(i) => format_ident!("{}{}", self.input_prefix, i),
            Var::Data(i) => {
                let (_, prefix, k) = self.data_entry(i);
                format_ident!("{}{}", prefix, k)
            }
        }
    }
    fn temp(&self, k: usize) -> Ident {
        format_ident!("{}{}", self.temp_prefix, k)
    }
    fn data_field(&self, i: u32) -> (Ident, usize) {
        let (field, _, k) = self.data_entry(i);
        (field.clone(), k)
    }
}

/// The ranges of `Var::Data` indices of the model's data slots, whose contractions with
/// coordinates the schedule keeps as loops (`sched::runs`). The description bounds the
/// data to 32-bit indices (`model::data`).
fn data_slots(names: &ModelNames) -> Vec<std::ops::Range<u32>> {
    let at = |x: usize| u32::try_from(x).expect("the description bounds data to u32 indices");
    names
        .data
        .iter()
        .map(|&(_, _, offset, len)| at(offset)..at(offset + len))
        .collect()
}

/// Whether a function reads its data entries where it uses them rather than binding
/// each to a `let`: when the bindings and the temporaries together pass [`MAX_LETS`].
fn reads_data_inline(prog: &Program) -> bool {
    let data_reads = prog
        .vars
        .iter()
        .filter(|v| matches!(v, Var::Data(_)))
        .count();
    data_reads + prog.lets.len() > MAX_LETS
}

/// The outputs of `dynamics_terms` in its order, as roots of one schedule and the
/// `(field, index)` of `DynamicsTerms` each root is stored in; `C`, the output the
/// caller may leave out, first.
fn dynamics_roots(d: &Derived) -> (Vec<ExprId>, Vec<(Ident, usize)>) {
    let parts: [(&str, Vec<ExprId>); 7] = [
        ("holonomic", d.c.clone()),
        ("mass", entries(&d.mass)),
        ("forces", d.forces.clone()),
        ("holonomic_jacobian", entries(&d.cq)),
        ("holonomic_gamma", d.gamma_h.clone()),
        ("nonholonomic_matrix", entries(&d.gm)),
        ("nonholonomic_gamma", d.gamma_nh.clone()),
    ];
    let mut roots = Vec::new();
    let mut slots = Vec::new();
    for (field, ids) in &parts {
        for (k, &id) in ids.iter().enumerate() {
            roots.push(id);
            slots.push((Ident::new(field, Span::call_site()), k));
        }
    }
    (roots, slots)
}

/// The body of a generated function: reads of the variables it uses, its temporaries,
/// and a final statement per output produced by `store`.
fn body(
    g: &Graph,
    names: &ModelNames,
    roots: &[ExprId],
    store: impl Fn(usize, TokenStream) -> TokenStream,
) -> (TokenStream, Program) {
    let (code, _, prog) = body_split(g, names, roots, 0, store);
    (code, prog)
}

/// [`body`] with the first `optional` roots split off: the statements the other roots
/// need, then (second) the reads, temporaries and stores that only the optional roots
/// need, for the caller to emit under a guard (an output the caller of the generated
/// function may not ask for).
fn body_split(
    g: &Graph,
    names: &ModelNames,
    roots: &[ExprId],
    optional: usize,
    store: impl Fn(usize, TokenStream) -> TokenStream,
) -> (TokenStream, TokenStream, Program) {
    let prog = sched::schedule_with(g, roots, &data_slots(names));
    let (needed, needed_vars) = prog.needed(g, &roots[optional..]);
    // Every `let` opens a debug-info scope nested in the previous one; LLVM's DWARF
    // writer recurses through that chain, and ten thousand of them (a bicycle's
    // linearization Jacobian) overflow the compiler's stack. Long functions keep their
    // temporaries in one local array instead, and read data entries where they use
    // them (the invariants of a body of 64 modes are 20,000 entries).
    let array = (prog.lets.len() > MAX_LETS).then(|| Ident::new(&names.temps, Span::call_site()));
    let inline_data = reads_data_inline(&prog);
    let printer = Printer {
        g,
        prog: &prog,
        names,
        array: array.clone(),
        inline_data,
    };
    let mut out = TokenStream::new();
    let mut guarded = TokenStream::new();
    for v in &prog.vars {
        if inline_data && matches!(v, Var::Data(_)) {
            continue;
        }
        let read = read_var(names, *v);
        if needed_vars.contains(v) {
            out.extend(read);
        } else {
            guarded.extend(read);
        }
    }
    if let Some(array) = &array {
        let len = Literal::usize_unsuffixed(prog.lets.len());
        out.extend(quote!(let mut #array = [0.0_f64; #len];));
    }
    for (k, &id) in prog.lets.iter().enumerate() {
        let define = printer.define(k, id);
        if needed[id.index()] {
            out.extend(define);
        } else {
            guarded.extend(define);
        }
    }
    for (k, &r) in roots.iter().enumerate() {
        let (ts, _) = printer.expr(r, false);
        if k < optional {
            guarded.extend(store(k, ts));
        } else {
            out.extend(store(k, ts));
        }
    }
    (out, guarded, prog)
}

/// The statement reading variable `v` into its local.
fn read_var(names: &ModelNames, v: Var) -> TokenStream {
    let name = names.var(v);
    match v {
        Var::Time => quote!(),
        Var::Q(i) => {
            let i = Literal::u32_unsuffixed(i);
            quote!(let #name = q[#i];)
        }
        Var::Qd(i) => {
            let i = Literal::u32_unsuffixed(i);
            quote!(let #name = qd[#i];)
        }
        Var::Param(_) => quote!(let #name = self.params.#name;),
        Var::Delta(_) => unreachable!("variations never reach generated code"),
        Var::Input(i) => {
            let inputs = Ident::new(&names.inputs, Span::call_site());
            let i = Literal::u32_unsuffixed(i);
            quote!(let #name = #inputs[#i];)
        }
        Var::Data(i) => {
            let (field, _, k) = names.data_entry(i);
            let k = Literal::usize_unsuffixed(k);
            quote!(let #name = self.data.#field[#k];)
        }
    }
}

/// The argument name for `t`, `q` or `qd`: prefixed with `_` when unused.
fn arg(prog: &Program, name: &str, used: impl Fn(&Var) -> bool) -> Ident {
    if prog.reads(used) {
        Ident::new(name, Span::call_site())
    } else {
        format_ident!("_{}", name)
    }
}

/// A trait method writing a vector of outputs into `out`, with or without `qd`.
fn vector_fn(
    g: &Graph,
    names: &ModelNames,
    fn_name: &str,
    roots: &[ExprId],
    with_qd: bool,
) -> TokenStream {
    let (code, prog) = body(g, names, roots, |k, ts| {
        let k = Literal::usize_unsuffixed(k);
        quote!(out[#k] = #ts;)
    });
    let name = Ident::new(fn_name, Span::call_site());
    let t = arg(&prog, "t", |v| *v == Var::Time);
    let q = arg(&prog, "q", |v| matches!(v, Var::Q(_)));
    if with_qd {
        let qd = arg(&prog, "qd", |v| matches!(v, Var::Qd(_)));
        quote! {
            fn #name(&self, #t: f64, #q: &[f64], #qd: &[f64], out: &mut [f64]) { #code }
        }
    } else {
        quote! {
            fn #name(&self, #t: f64, #q: &[f64], out: &mut [f64]) { #code }
        }
    }
}

fn entries(e: &[Entry]) -> Vec<ExprId> {
    e.iter().map(|e| e.expr).collect()
}

fn pattern(e: &[Entry]) -> TokenStream {
    let items = e.iter().map(|e| {
        let (r, c) = (
            Literal::u32_unsuffixed(e.row),
            Literal::u32_unsuffixed(e.col),
        );
        quote!((#r, #c))
    });
    quote!(&[#(#items),*])
}

fn any_nonzero(g: &Graph, ids: &[ExprId]) -> bool {
    ids.iter().any(|&e| !g.is_zero(e))
}

/// `core::f64::consts::NAME` for a parameter default that is exactly one of them (a
/// literal would trip clippy's `approx_constant` in the user's crate).
fn named_constant(v: f64) -> Option<TokenStream> {
    use std::f64::consts as c;
    let table: [(f64, &str); 8] = [
        (c::PI, "PI"),
        (c::TAU, "TAU"),
        (c::E, "E"),
        (c::FRAC_PI_2, "FRAC_PI_2"),
        (c::FRAC_PI_3, "FRAC_PI_3"),
        (c::FRAC_PI_4, "FRAC_PI_4"),
        (c::FRAC_PI_6, "FRAC_PI_6"),
        (c::SQRT_2, "SQRT_2"),
    ];
    let (sign, a) = if v < 0.0 {
        (quote!(-), -v)
    } else {
        (quote!(), v)
    };
    table.iter().find(|(x, _)| *x == a).map(|(_, name)| {
        let name = Ident::new(name, Span::call_site());
        quote!(#sign ::core::f64::consts::#name)
    })
}

/// `#[doc]` attributes for a doc text, one per line with the leading space that `///`
/// comments have, so formatted output reads `/// text`.
fn doc_attr(docs: &str) -> TokenStream {
    let lines = docs.lines().map(|l| format!(" {l}"));
    quote!(#(#[doc = #lines])*)
}

/// The replacement module for a successfully derived model.
/// The entries of $C_q$ and $G$ at the declared initial state with the parameters'
/// defaults (time 0), where every input is known at compile time: what the null-space
/// solve chooses its partition by ([`nullspace`]).
fn jacobian_at_start(g: &Graph, d: &Derived) -> Option<(Vec<f64>, Vec<f64>)> {
    let (q0, _) = d.initial.as_ref()?;
    let p = &d.param_defaults;
    let param = |v: Var| match v {
        Var::Param(i) => p.get(i as usize).copied().unwrap_or(f64::NAN),
        Var::Time => 0.0,
        _ => f64::NAN,
    };
    let q = crate::sym::transform::eval(g, q0, &param);
    let env = |v: Var| match v {
        Var::Q(i) => q.get(i as usize).copied().unwrap_or(f64::NAN),
        other => param(other),
    };
    let exprs = |entries: &[Entry]| -> Vec<ExprId> { entries.iter().map(|e| e.expr).collect() };
    let cq = crate::sym::transform::eval(g, &exprs(&d.cq), &env);
    let gm = crate::sym::transform::eval(g, &exprs(&d.gm), &env);
    Some((cq, gm))
}

pub fn mechanism(model: &Model, d: &Derived, g: &Graph) -> TokenStream {
    let names = ModelNames::new(model);
    let vis = &model.vis;
    let ident = &model.ident;
    let attrs = &model.attrs;
    let docs = &model.docs;
    let name_str = ident.to_string();

    let pnames = &names.params;
    let pdocs: Vec<TokenStream> = model.params.iter().map(|p| doc_attr(&p.docs)).collect();
    let pdefaults: Vec<TokenStream> = d
        .param_defaults
        .iter()
        .map(|&v| named_constant(v).unwrap_or_else(|| expr::literal(v).0))
        .collect();
    let param_count = model.params.len();
    let param_idx: Vec<Literal> = (0..param_count).map(Literal::usize_unsuffixed).collect();

    let symbols = |items: &mut dyn Iterator<Item = (String, &String)>| {
        let items: Vec<TokenStream> = items
            .map(|(n, doc)| quote!(::pfaff::__private::Symbol { name: #n, doc: #doc }))
            .collect();
        quote!(&[#(#items),*])
    };
    let coordinates = symbols(&mut model.coords.iter().map(|c| (plain(&c.name), &c.docs)));
    let unraw = |n: &String| n.strip_prefix("r#").unwrap_or(n).to_owned();
    let holonomic = symbols(&mut d.holonomic_names.iter().map(|(n, doc)| (unraw(n), doc)));
    let nonholonomic = symbols(&mut d.nonholonomic_names.iter().map(|(n, doc)| (unraw(n), doc)));
    let outputs = symbols(&mut d.outputs.iter().map(|(n, doc, _)| (unraw(n), doc)));
    let structure = body_level(g, &names, d, &mut TokenStream::new());
    let parameters: Vec<TokenStream> = model
        .params
        .iter()
        .zip(&pdefaults)
        .map(|(p, v)| {
            let (n, doc) = (plain(&p.name), &p.docs);
            quote!(::pfaff::__private::Parameter { name: #n, doc: #doc, default: #v })
        })
        .collect();
    let mass_pattern = pattern(&d.mass);
    let cq_pattern = pattern(&d.cq);
    let g_pattern = pattern(&d.gm);
    let (tm, tf, th, tn) = (
        d.time.mass,
        d.time.forces,
        d.time.holonomic,
        d.time.nonholonomic,
    );
    let homogeneous = d.homogeneous;
    let conservative = d.conservative;

    let mut fns = TokenStream::new();
    let _ = body_level(g, &names, d, &mut fns);
    let contact_info = contacts::contacts(g, &names, d, &mut fns);
    if !d.outputs.is_empty() {
        let roots: Vec<ExprId> = d.outputs.iter().map(|o| o.2).collect();
        fns.extend(vector_fn(g, &names, "outputs", &roots, true));
    }
    fns.extend(dynamics_terms(g, &names, d));
    fns.extend(corrected::dynamics_terms_corrected(g, &names, d));
    let at_start = jacobian_at_start(g, d);
    let at_start = at_start.as_ref().map(|(c, n)| (&c[..], &n[..]));
    fns.extend(solve::augmented_solve(
        g,
        model.coords.len(),
        (d.c.len(), d.gb.len()),
        (&d.mass, &d.cq, &d.gm),
        at_start,
    ));
    fns.extend(solve::orthogonal_solve(
        model.coords.len(),
        (d.c.len(), d.gb.len()),
        (&d.cq, &d.gm),
        at_start,
    ));
    fns.extend(solve::velocity_residuals(
        model.coords.len(),
        (d.c.len(), d.gb.len()),
        (&d.cq, &d.gm),
    ));
    fns.extend(solve::holonomic_row_norms(d.c.len(), &d.cq));
    fns.extend(normal_map::holonomic_normal_map(
        model.coords.len(),
        d.c.len(),
        &d.cq,
    ));
    if let Some((q0, qd0)) = &d.initial {
        let mut roots = q0.clone();
        roots.extend(qd0);
        let n = q0.len();
        let (code, _) = body(g, &names, &roots, |k, ts| {
            if k < n {
                let k = Literal::usize_unsuffixed(k);
                quote!(q[#k] = #ts;)
            } else {
                let k = Literal::usize_unsuffixed(k - n);
                quote!(qd[#k] = #ts;)
            }
        });
        fns.extend(quote! {
            fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) { #code }
        });
    }
    fns.extend(vector_fn(
        g,
        &names,
        "mass_matrix",
        &entries(&d.mass),
        false,
    ));
    fns.extend(vector_fn(g, &names, "forces", &d.forces, true));
    if any_nonzero(g, &d.applied) {
        fns.extend(vector_fn(g, &names, "applied_forces", &d.applied, true));
    }
    let free_motion = free_motion(g, &names, model, d, &mut fns);
    let linearization = linearization(g, &names, d, &mut fns);
    if !d.c.is_empty() {
        fns.extend(vector_fn(g, &names, "holonomic", &d.c, false));
        fns.extend(vector_fn(
            g,
            &names,
            "holonomic_jacobian",
            &entries(&d.cq),
            false,
        ));
        fns.extend(holonomic_with_jacobian(g, &names, d));
        if any_nonzero(g, &d.ct) {
            fns.extend(vector_fn(g, &names, "holonomic_rate", &d.ct, false));
        }
        if any_nonzero(g, &d.gamma_h) {
            fns.extend(vector_fn(g, &names, "holonomic_gamma", &d.gamma_h, true));
        }
    }
    if !d.gb.is_empty() {
        fns.extend(vector_fn(
            g,
            &names,
            "nonholonomic_matrix",
            &entries(&d.gm),
            false,
        ));
        if any_nonzero(g, &d.gb) {
            fns.extend(vector_fn(g, &names, "nonholonomic_bias", &d.gb, false));
        }
        if any_nonzero(g, &d.gamma_nh) {
            fns.extend(vector_fn(
                g,
                &names,
                "nonholonomic_gamma",
                &d.gamma_nh,
                true,
            ));
        }
    }
    {
        let (code, prog) = body(g, &names, &[d.kinetic], |_, ts| ts);
        let t = arg(&prog, "t", |v| *v == Var::Time);
        let q = arg(&prog, "q", |v| matches!(v, Var::Q(_)));
        let qd = arg(&prog, "qd", |v| matches!(v, Var::Qd(_)));
        fns.extend(quote! {
            fn kinetic_energy(&self, #t: f64, #q: &[f64], #qd: &[f64]) -> f64 { #code }
        });
    }
    if !g.is_zero(d.potential) {
        let (code, prog) = body(g, &names, &[d.potential], |_, ts| ts);
        let t = arg(&prog, "t", |v| *v == Var::Time);
        let q = arg(&prog, "q", |v| matches!(v, Var::Q(_)));
        fns.extend(quote! {
            fn potential_energy(&self, #t: f64, #q: &[f64]) -> f64 { #code }
        });
    }

    let model_doc = format!(" The `{name_str}` mechanism with its parameters.");
    let params_doc =
        format!(" Parameters of `{name_str}`, with the defaults declared in the model.");
    let info_doc =
        format!(" Names, sizes, sparsity patterns and structural flags of `{name_str}`.");
    let get = if param_count == 0 {
        quote!(::core::panic!("`{}` has no parameters (index {})", #name_str, index))
    } else {
        quote! {
            match index {
                #(#param_idx => self.params.#pnames,)*
                _ => ::core::panic!("parameter index {} out of range for `{}`", index, #name_str),
            }
        }
    };
    let set = if param_count == 0 {
        quote!(
            ::core::panic!("`{}` has no parameters (index {}, value {})", #name_str, index, value)
        )
    } else {
        quote! {
            match index {
                #(#param_idx => self.params.#pnames = value,)*
                _ => ::core::panic!("parameter index {} out of range for `{}`", index, #name_str),
            }
        }
    };

    let data = data::data(g, &names, model, d);
    let (set, model_def, data_info, data_items) = match &data {
        None => (
            set,
            quote! {
                #[doc = #model_doc]
                #[derive(Clone, Copy, Debug, Default, PartialEq)]
                pub struct Model {
                    /// The parameter values.
                    pub params: Params,
                }

                impl Model {
                    /// The mechanism with the given parameters.
                    #[must_use]
                    pub const fn new(params: Params) -> Self {
                        Self { params }
                    }
                }
            },
            quote!(&[]),
            quote!(),
        ),
        Some(dc) => {
            let set = if dc.refresh && param_count > 0 {
                quote! {
                    #set;
                    let _ = self.refresh_data();
                }
            } else {
                set
            };
            fns.extend(dc.fns.clone());
            (
                set,
                quote! {
                    #[doc = #model_doc]
                    #[derive(Clone, Copy, Debug, PartialEq)]
                    pub struct Model {
                        /// The parameter values.
                        pub params: Params,
                        /// The run-time data (`Info::data`).
                        pub data: Data,
                    }

                    impl Model {
                        /// The mechanism with the given parameters, its data computed
                        /// from them where it follows from them (`refresh_data`) and zero
                        /// elsewhere.
                        #[must_use]
                        pub fn new(params: Params) -> Self {
                            let mut model = Self { params, data: Data::default() };
                            let _ = model.refresh_data();
                            model
                        }
                    }

                    impl ::core::default::Default for Model {
                        fn default() -> Self {
                            Self::new(Params::default())
                        }
                    }
                },
                dc.info.clone(),
                dc.items.clone(),
            )
        }
    };
    let mod_doc = doc_attr(docs);
    quote! {
        #(#attrs)*
        #mod_doc
        #vis mod #ident {
            #[doc = #params_doc]
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct Params {
                #(#pdocs pub #pnames: f64,)*
            }

            impl ::core::default::Default for Params {
                fn default() -> Self {
                    Self { #(#pnames: #pdefaults,)* }
                }
            }

            #model_def

            #data_items

            #[doc = #info_doc]
            pub static INFO: ::pfaff::__private::Info = ::pfaff::__private::Info {
                name: #name_str,
                doc: #docs,
                coordinates: #coordinates,
                parameters: &[#(#parameters),*],
                holonomic: #holonomic,
                nonholonomic: #nonholonomic,
                mass_pattern: #mass_pattern,
                holonomic_pattern: #cq_pattern,
                nonholonomic_pattern: #g_pattern,
                time: ::pfaff::__private::TimeDependence {
                    mass: #tm,
                    forces: #tf,
                    holonomic: #th,
                    nonholonomic: #tn,
                },
                nonholonomic_homogeneous: #homogeneous,
                conservative: #conservative,
                outputs: #outputs,
                #contact_info
                data: #data_info,
                linearization: #linearization,
                #structure
            };

            #free_motion

            #[allow(non_snake_case, clippy::all, clippy::pedantic)]
            impl ::pfaff::__private::Mechanism for Model {
                fn info(&self) -> &'static ::pfaff::__private::Info {
                    &INFO
                }
                fn parameter(&self, index: usize) -> f64 {
                    #get
                }
                fn set_parameter(&mut self, index: usize, value: f64) {
                    #set
                }
                #fns
            }
        }
    }
}

/// The linearization Jacobian (`derive::linear`) as the trait method
/// `linearization_jacobian` (added to `fns`); returns the `Info::linearization` value.
fn linearization(g: &Graph, names: &ModelNames, d: &Derived, fns: &mut TokenStream) -> TokenStream {
    let Some(lin) = &d.linear else {
        return quote!(::core::option::Option::None);
    };
    let (code, prog) = body(g, names, &entries(&lin.entries), |k, ts| {
        let k = Literal::usize_unsuffixed(k);
        quote!(out[#k] = #ts;)
    });
    let t = arg(&prog, "t", |v| *v == Var::Time);
    let q = arg(&prog, "q", |v| matches!(v, Var::Q(_)));
    let qd = arg(&prog, "qd", |v| matches!(v, Var::Qd(_)));
    let inputs = arg(&prog, &names.inputs, |v| matches!(v, Var::Input(_)));
    fns.extend(quote! {
        fn linearization_jacobian(
            &self,
            #t: f64,
            #q: &[f64],
            #qd: &[f64],
            #inputs: &[f64],
            out: &mut [f64],
        ) {
            #code
        }
    });
    let pattern = pattern(&lin.entries);
    quote!(::core::option::Option::Some(#pattern))
}

/// The free-motion residual `w = w0 + K Q` (docs/theory.md §free-motion) as the trait methods
/// `free_motion_residual` and `free_motion_conditions` (added to `fns`), and the module
/// item `FREE_MOTION` with the printed conditions (returned). Nothing when the model has
/// no free-motion derivation.
fn free_motion(
    g: &Graph,
    names: &ModelNames,
    model: &Model,
    d: &Derived,
    fns: &mut TokenStream,
) -> TokenStream {
    let Some(fm) = &d.free_motion else {
        return TokenStream::new();
    };
    let m = fm.base.len();
    let mut roots = fm.base.clone();
    roots.extend(fm.coefficients.iter().map(|e| e.expr));
    let applied_arg = Ident::new(&names.applied, Span::call_site());
    let (code, prog) = body(g, names, &roots, |k, ts| {
        if k < m {
            let k = Literal::usize_unsuffixed(k);
            quote!(out[#k] = #ts;)
        } else {
            let e = fm.coefficients[k - m];
            let (r, c) = (
                Literal::u32_unsuffixed(e.row),
                Literal::u32_unsuffixed(e.col),
            );
            quote!(out[#r] += #ts * #applied_arg[#c];)
        }
    });
    let t = arg(&prog, "t", |v| *v == Var::Time);
    let q = arg(&prog, "q", |v| matches!(v, Var::Q(_)));
    let qd = arg(&prog, "qd", |v| matches!(v, Var::Qd(_)));
    let applied = if fm.coefficients.is_empty() {
        format_ident!("_{}", names.applied)
    } else {
        applied_arg
    };
    fns.extend(quote! {
        fn free_motion_residual(
            &self, #t: f64, #q: &[f64], #qd: &[f64], #applied: &[f64], out: &mut [f64],
        ) -> bool {
            #code
            true
        }
        fn free_motion_conditions(&self) -> &'static [&'static str] {
            FREE_MOTION
        }
    });
    let formulas = crate::derive::free_motion::formulas(g, model, fm);
    let doc = doc_attr(
        "The free-motion conditions `w = 0` of docs/theory.md §free-motion, one per constraint \
         (holonomic first),\nwith `x'` the velocity of `x` and `Q_x` the applied force \
         on `x`; the motion is free\n(all multipliers zero) exactly where they hold.",
    );
    quote! {
        #doc
        pub const FREE_MOTION: &[&str] = &[#(#formulas),*];
    }
}

/// The body level's entries of `Info` (returned) and its trait methods `frame_poses` and
/// `point_positions` (added to `fns`).
fn body_level(g: &Graph, names: &ModelNames, d: &Derived, fns: &mut TokenStream) -> TokenStream {
    let Some(b) = &d.bodies else {
        return quote!(frames: &[], points: &[], bodies: &[], joints: &[],);
    };
    let opt = |x: Option<u32>| match x {
        Some(k) => quote!(::core::option::Option::Some(#k)),
        None => quote!(::core::option::Option::None),
    };
    let frames = b.frames.iter().map(|f| {
        let (n, doc, planar) = (&f.name, &f.docs, f.value.dim == 2);
        let (p, r) = (opt(f.parent), opt(f.normalization));
        quote!(::pfaff::__private::Frame { name: #n, doc: #doc, parent: #p, planar: #planar, normalization: #r })
    });
    let points = b.points.iter().map(|p| {
        let (n, doc, f) = (&p.name, &p.docs, p.frame);
        quote!(::pfaff::__private::Point { name: #n, doc: #doc, frame: #f })
    });
    let bodies = b.bodies.iter().map(|p| {
        let (n, doc, f) = (&p.name, &p.docs, p.frame);
        quote!(::pfaff::__private::Body { name: #n, doc: #doc, frame: #f })
    });
    let joints = b.joints.iter().map(|j| {
        let (n, doc) = (&j.name, &j.docs);
        let kind = Ident::new(j.kind, Span::call_site());
        let (fa, fb) = (opt(j.frames[0]), opt(j.frames[1]));
        let (h0, h1, n0, n1) = (
            j.holonomic.0,
            j.holonomic.1,
            j.nonholonomic.0,
            j.nonholonomic.1,
        );
        quote!(::pfaff::__private::Joint {
            name: #n, doc: #doc, kind: ::pfaff::__private::JointKind::#kind,
            frames: [#fa, #fb], holonomic: (#h0, #h1), nonholonomic: (#n0, #n1),
        })
    });
    if !b.frames.is_empty() {
        fns.extend(vector_fn(g, names, "frame_poses", &b.poses, false));
    }
    if !b.points.is_empty() {
        fns.extend(vector_fn(
            g,
            names,
            "point_positions",
            &b.point_roots,
            false,
        ));
    }
    if !b.bodies.is_empty() {
        let masses: Vec<ExprId> = b.bodies.iter().map(|b| b.mass).collect();
        fns.extend(vector_fn(g, names, "body_masses", &masses, false));
    }
    fns.extend(drawing(g, names, &b.drawing));
    quote! {
        frames: &[#(#frames),*],
        points: &[#(#points),*],
        bodies: &[#(#bodies),*],
        joints: &[#(#joints),*],
    }
}

/// The trait methods `drawing` (the static shapes) and `drawing_values` (the points'
/// global coordinates, then the scalars), when the model has shapes.
fn drawing(g: &Graph, names: &ModelNames, d: &crate::derive::drawing::DrawingOut) -> TokenStream {
    if d.shapes.is_empty() && d.up.is_none() {
        return TokenStream::new();
    }
    let opt = |x: Option<u32>| match x {
        Some(k) => quote!(::core::option::Option::Some(#k)),
        None => quote!(::core::option::Option::None),
    };
    let points = d.points.iter().map(|p| {
        let (n, f) = (&p.name, opt(p.frame));
        quote!(::pfaff::__private::DrawPoint { name: #n, frame: #f })
    });
    let shapes = d.shapes.iter().map(|s| {
        let n = &s.name;
        let kind = Ident::new(s.kind, Span::call_site());
        let (f, nrm, r) = (opt(s.frame), opt(s.normal), opt(s.radius));
        let pts = &s.points;
        let color = match &s.color {
            Some(c) => quote!(::core::option::Option::Some(#c)),
            None => quote!(::core::option::Option::None),
        };
        quote!(::pfaff::__private::Shape {
            name: #n, kind: ::pfaff::__private::ShapeKind::#kind, frame: #f,
            points: &[#(#pts),*], normal: #nrm, radius: #r, color: #color,
        })
    });
    let scalars = u32::try_from(d.scalars.len()).expect("drawing size fits u32");
    let up = opt(d.up);
    let mut roots: Vec<ExprId> = d
        .points
        .iter()
        .flat_map(|p| p.value.iter().copied())
        .collect();
    roots.extend(d.scalars.iter().copied());
    let values = vector_fn(g, names, "drawing_values", &roots, false);
    quote! {
        fn drawing(&self) -> &'static ::pfaff::__private::Drawing {
            static DRAWING: ::pfaff::__private::Drawing = ::pfaff::__private::Drawing {
                points: &[#(#points),*],
                scalars: #scalars,
                shapes: &[#(#shapes),*],
                up: #up,
            };
            &DRAWING
        }
        #values
    }
}

/// `dynamics_terms`: `M`, `Q`, `C_q`, `γ_h`, `G`, `γ_nh`, and `C` when the caller asks
/// for it, in one schedule, so that what they share is computed once. The reads,
/// temporaries and stores only `C` needs are emitted under the test of
/// `out.holonomic`: a caller that does not ask pays one branch.
fn dynamics_terms(g: &Graph, names: &ModelNames, d: &Derived) -> TokenStream {
    let (roots, slots) = dynamics_roots(d);
    let c = Ident::new(&names.out_c, Span::call_site());
    let (code, guarded, prog) = body_split(g, names, &roots, d.c.len(), |k, ts| {
        store_term(&slots[k], &c, ts)
    });
    let guarded = guard_constraints(&c, guarded);
    let t = arg(&prog, "t", |v| *v == Var::Time);
    let q = arg(&prog, "q", |v| matches!(v, Var::Q(_)));
    let qd = arg(&prog, "qd", |v| matches!(v, Var::Qd(_)));
    quote! {
        fn dynamics_terms(
            &self, #t: f64, #q: &[f64], #qd: &[f64], out: ::pfaff::__private::DynamicsTerms<'_>,
        ) {
            #code
            #guarded
        }
    }
}

/// The statement storing output `ts` in its `(field, index)` of `DynamicsTerms`; `C`
/// goes to `c`, the slice of the guard of [`guard_constraints`].
fn store_term((field, i): &(Ident, usize), c: &Ident, ts: TokenStream) -> TokenStream {
    let i = Literal::usize_unsuffixed(*i);
    if field == "holonomic" {
        quote!(#c[#i] = #ts;)
    } else {
        quote!(out.#field[#i] = #ts;)
    }
}

/// The statements only `C` needs, run when the caller asked for `C` (nothing when
/// there are none: a model without holonomic constraints).
fn guard_constraints(c: &Ident, guarded: TokenStream) -> TokenStream {
    if guarded.is_empty() {
        return guarded;
    }
    quote! {
        if let ::core::option::Option::Some(#c) = out.holonomic {
            #guarded
        }
    }
}

/// `holonomic_with_jacobian`: `C` and the pattern values of `C_q` in one schedule, so
/// that the sines and cosines of the angles and the lengths they share are computed
/// once (the position projections and the monitors need both at one point).
fn holonomic_with_jacobian(g: &Graph, names: &ModelNames, d: &Derived) -> TokenStream {
    let nc = d.c.len();
    let mut roots = d.c.clone();
    roots.extend(entries(&d.cq));
    let c = Ident::new(&names.out_c, Span::call_site());
    let cq = Ident::new(&names.out_cq, Span::call_site());
    let (code, prog) = body(g, names, &roots, |k, ts| {
        if k < nc {
            let k = Literal::usize_unsuffixed(k);
            quote!(#c[#k] = #ts;)
        } else {
            let k = Literal::usize_unsuffixed(k - nc);
            quote!(#cq[#k] = #ts;)
        }
    });
    let t = arg(&prog, "t", |v| *v == Var::Time);
    let q = arg(&prog, "q", |v| matches!(v, Var::Q(_)));
    let cq = if d.cq.is_empty() {
        format_ident!("_{}", cq)
    } else {
        cq
    };
    quote! {
        fn holonomic_with_jacobian(&self, #t: f64, #q: &[f64], #c: &mut [f64], #cq: &mut [f64]) {
            #code
        }
    }
}

/// The module emitted after user errors: the same public items with bodies that are
/// never run, so that uses of the model elsewhere do not add errors of their own.
pub fn fallback(vis: &syn::Visibility, ident: &Ident) -> TokenStream {
    quote! {
        #vis mod #ident {
            #[derive(Clone, Copy, Debug, Default, PartialEq)]
            pub struct Params {}
            #[derive(Clone, Copy, Debug, Default, PartialEq)]
            pub struct Model {
                pub params: Params,
            }
            impl Model {
                pub const fn new(params: Params) -> Self {
                    Self { params }
                }
            }
            impl ::pfaff::__private::Mechanism for Model {
                fn info(&self) -> &'static ::pfaff::__private::Info {
                    ::core::unreachable!()
                }
                fn parameter(&self, _: usize) -> f64 {
                    ::core::unreachable!()
                }
                fn set_parameter(&mut self, _: usize, _: f64) {
                    ::core::unreachable!()
                }
                fn mass_matrix(&self, _: f64, _: &[f64], _: &mut [f64]) {
                    ::core::unreachable!()
                }
                fn forces(&self, _: f64, _: &[f64], _: &[f64], _: &mut [f64]) {
                    ::core::unreachable!()
                }
                fn kinetic_energy(&self, _: f64, _: &[f64], _: &[f64]) -> f64 {
                    ::core::unreachable!()
                }
            }
        }
    }
}
