//! The generator behind `#[pfaff::mechanism]`: a pipeline of stages on `proc_macro2`.
//!
//! ```text
//! parse::parse          syn tokens → surface description (every span kept)
//! model::lower          → model::Model (names resolved, items grouped by role)
//! derive::derive        expressions → sym::Graph (hash-consed, canonical DAG), then
//!                       M, Q, C, C_q, C_t, γ_h, G, g, γ_nh with their sparsity
//! sched::schedule       per generated function → straight-line program
//! emit::mechanism       → the module implementing `pfaff::Mechanism`
//! ```
//! User errors are collected in a [`ctxt::Ctxt`] and reported together with spans; on
//! error a fallback module keeps the rest of the user's crate compiling.
//!
//! [`expand`] is what the proc macro calls; [`analyze`] exposes the intermediate
//! results to tests, snapshots and benchmarks.

// Index loops mirror the mathematics (M_ij, rows r and columns j of C_q).
#![allow(clippy::needless_range_loop)]

#[cfg(test)]
mod bounds;
pub mod ctxt;
pub mod derive;
pub mod emit;
pub mod measure;
pub mod model;
pub mod parse;
#[cfg(test)]
mod repeat_tests;
#[cfg(test)]
mod robustness;
pub mod sched;
#[cfg(test)]
mod sparsity;
pub mod sym;

use proc_macro2::TokenStream;

/// The error reported when the derivation stops without recording why: a defect of
/// the generator, never of the model.
pub const UNEXPLAINED: &str = "pfaff could not derive this model and recorded no cause; \
this is a defect of pfaff's generator, please report it with the model";

/// The results of the front and middle stages for one model.
#[derive(Debug)]
pub struct Analysis {
    pub model: model::Model,
    pub graph: sym::Graph,
    pub derived: derive::Derived,
}

/// Runs parsing, lowering and derivation. Errors come back as one combined
/// `syn::Error` carrying every diagnostic.
pub fn analyze(args: TokenStream, input: TokenStream) -> syn::Result<Analysis> {
    let cx = ctxt::Ctxt::new();
    let Some(ast) = parse::parse(&cx, args, input) else {
        cx.check()?;
        unreachable!("parse failures are recorded in the context");
    };
    let model = model::lower(&cx, ast);
    let mut graph = sym::Graph::new();
    let derived = if cx.has_errors() {
        None
    } else {
        derive::derive(&cx, &model, &mut graph)
    };
    let Some(derived) = derived else {
        // Every stage records why it stops; a stop without a diagnostic is a defect of
        // the generator, reported as one (the fuzz campaign looks for this message).
        if !cx.has_errors() {
            cx.error_at(proc_macro2::Span::call_site(), UNEXPLAINED);
        }
        cx.check()?;
        unreachable!("the context holds an error");
    };
    cx.check()?;
    Ok(Analysis {
        model,
        graph,
        derived,
    })
}

/// Expands `#[mechanism]` on `input`.
pub fn expand(args: TokenStream, input: TokenStream) -> TokenStream {
    // Keep the module's name for the fallback before the input is consumed.
    let head = syn::parse2::<syn::ItemMod>(input.clone())
        .ok()
        .map(|m| (m.vis, m.ident));
    match analyze(args, input) {
        Ok(a) => emit::mechanism(&a.model, &a.derived, &a.graph),
        Err(e) => {
            let mut out = e.to_compile_error();
            if let Some((vis, ident)) = head {
                out.extend(emit::fallback(&vis, &ident));
            }
            out
        }
    }
}

/// Expands the `#[mechanism]` module called `module` of a Rust source file, as the
/// proc macro would: `source` is the text of the file (`include_str!`, or read from
/// disk), the module is found among its top-level items by name, and its attribute
/// (`#[mechanism]`, `#[pfaff::mechanism(linearize)]`, …) gives the arguments. The
/// result is the generated module, ready for `prettyplease` (`syn::parse2::<syn::File>`
/// then `prettyplease::unparse`); `pfaff show --code MODEL` prints it that way.
///
/// # Errors
/// The file does not parse, holds no such module, or the model is rejected (the
/// diagnostics the proc macro would report, with their spans in `source`).
pub fn expand_source(source: &str, module: &str) -> syn::Result<TokenStream> {
    use quote::ToTokens;
    let file: syn::File = syn::parse_str(source)?;
    for item in file.items {
        let syn::Item::Mod(mut m) = item else {
            continue;
        };
        if m.ident != module {
            continue;
        }
        let Some(at) = m.attrs.iter().position(|a| {
            a.path()
                .segments
                .last()
                .is_some_and(|s| s.ident == "mechanism")
        }) else {
            return Err(syn::Error::new_spanned(
                &m.ident,
                format!("module `{module}` has no `#[mechanism]` attribute"),
            ));
        };
        let attr = m.attrs.remove(at);
        let args = match attr.meta {
            syn::Meta::List(list) => list.tokens,
            _ => TokenStream::new(),
        };
        let a = analyze(args, m.into_token_stream())?;
        return Ok(emit::mechanism(&a.model, &a.derived, &a.graph));
    }
    Err(syn::Error::new(
        proc_macro2::Span::call_site(),
        format!("no module `{module}` among the top-level items of the source"),
    ))
}
