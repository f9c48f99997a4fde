//! Differentiation that skips absent variables (`sym::diff`) derives every built-in
//! model and a spatial chain into exactly the graph of the full walk, node for node.

use proc_macro2::TokenStream;
use quote::ToTokens;

use crate::sym::{ExprId, Graph, Node};
use crate::{ctxt, derive, model, parse};

#[path = "chain_unrolled.rs"]
pub(crate) mod chain;

/// The `#[mechanism]` modules of a source file, the attribute removed (its arguments,
/// e.g. `linearize`, kept with the module).
fn modules(src: &str) -> Vec<(String, TokenStream, TokenStream)> {
    let file = syn::parse_file(src).expect("model files parse");
    file.items
        .into_iter()
        .filter_map(|item| match item {
            syn::Item::Mod(mut m) => {
                let at = m.attrs.iter().position(|a| {
                    a.path()
                        .segments
                        .last()
                        .is_some_and(|s| s.ident == "mechanism")
                })?;
                let args = match &m.attrs[at].meta {
                    syn::Meta::List(l) => l.tokens.clone(),
                    _ => TokenStream::new(),
                };
                m.attrs.remove(at);
                Some((m.ident.to_string(), args, m.into_token_stream()))
            }
            _ => None,
        })
        .collect()
}

/// The graph's nodes and a dump of the derived quantities.
fn derive_in(mut g: Graph, args: &TokenStream, src: &TokenStream) -> (Vec<Node>, String) {
    let cx = ctxt::Ctxt::new();
    let ast = parse::parse(&cx, args.clone(), src.clone()).expect("the model parses");
    let m = model::lower(&cx, ast);
    let d = derive::derive(&cx, &m, &mut g).expect("the model derives");
    cx.check().expect("no diagnostics");
    let dump = format!(
        "{:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?}",
        d.mass,
        d.forces,
        d.c,
        d.cq,
        d.ct,
        d.gamma_h,
        d.gm,
        d.gb,
        d.gamma_nh,
        d.applied,
        d.linear.as_ref().map(|l| &l.entries)
    );
    let nodes = (0..g.len())
        .map(|i| g.node(ExprId::from_index(i)).clone())
        .collect();
    (nodes, dump)
}

#[test]
fn every_built_in_model_and_a_chain_derive_as_with_the_full_walk() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/src");
    let mut sources = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("models/src exists") {
        let path = entry.expect("directory entry").path();
        if path.extension().is_some_and(|e| e == "rs") {
            sources.extend(modules(&std::fs::read_to_string(&path).expect("readable")));
        }
    }
    assert!(sources.len() > 10, "the built-in models were found");
    sources.extend(modules(&chain::chain_source("chain4", 4)));
    assert!(
        sources.iter().any(|(_, args, _)| !args.is_empty()),
        "a model with a generated linearization is among them"
    );
    for (name, args, src) in &sources {
        let (skip_nodes, skip) = derive_in(Graph::new(), args, src);
        let (full_nodes, full) = derive_in(Graph::full_walk(), args, src);
        assert_eq!(skip, full, "{name}: derived quantities");
        assert_eq!(skip_nodes.len(), full_nodes.len(), "{name}: graph size");
        assert!(skip_nodes == full_nodes, "{name}: graph nodes");
    }
}

#[test]
fn a_chain_has_a_sparse_mass_matrix_and_jacobian() {
    // Seven coordinates per link; a link's kinetic energy involves only its own, so M is
    // block diagonal (7×7 blocks, those of the Euler parameters full 4×4, the masses
    // on the diagonal) and each joint row involves at most two links.
    let (_, _, src) = modules(&chain::chain_source("chain5", 5)).remove(0);
    let cx = ctxt::Ctxt::new();
    let ast = parse::parse(&cx, TokenStream::new(), src).expect("the model parses");
    let m = model::lower(&cx, ast);
    let mut g = Graph::new();
    let d = derive::derive(&cx, &m, &mut g).expect("the model derives");
    assert_eq!(m.nq(), 35);
    assert!(
        d.mass.iter().all(|e| e.row / 7 == e.col / 7),
        "block diagonal"
    );
    assert_eq!(d.mass.len(), 5 * (3 + 16));
    assert_eq!(d.c.len(), 5 + 15, "5 normalizations, 5 ball joints");
    for r in 0..d.c.len() {
        let links: std::collections::BTreeSet<u32> =
            d.cq.iter()
                .filter(|e| e.row as usize == r)
                .map(|e| e.col / 7)
                .collect();
        assert!(!links.is_empty() && links.len() <= 2, "row {r}: {links:?}");
    }
}
