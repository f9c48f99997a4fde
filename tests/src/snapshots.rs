//! Snapshots of the generator's output for every built-in model (`models/src/*.rs`):
//! the derived quantities as formulas (`<model>__symbolic`) and the emitted Rust,
//! formatted by prettyplease (`<model>__emit`). A change to the generator shows up
//! here as a readable diff; review it with `cargo insta review`.

use proc_macro2::TokenStream;

use crate::sources::model_sources;

fn pretty(ts: TokenStream) -> String {
    prettyplease::unparse(&syn::parse2::<syn::File>(ts).expect("generated code parses"))
}

#[test]
fn every_model_expands_to_the_reviewed_code() {
    let models = model_sources();
    assert!(
        models.len() >= 7,
        "the built-in models are found: {}",
        models.len()
    );
    for (name, tokens) in models {
        let analysis = pfaff_codegen::analyze(TokenStream::new(), tokens.clone())
            .unwrap_or_else(|e| panic!("{name} has errors: {e}"));
        insta::assert_snapshot!(format!("{name}__symbolic"), analysis.describe());
        insta::assert_snapshot!(
            format!("{name}__emit"),
            pretty(pfaff_codegen::expand(TokenStream::new(), tokens))
        );
    }
}

#[test]
fn expansion_is_deterministic() {
    for (name, tokens) in model_sources() {
        let a = pfaff_codegen::expand(TokenStream::new(), tokens.clone()).to_string();
        let b = pfaff_codegen::expand(TokenStream::new(), tokens).to_string();
        assert_eq!(a, b, "{name}: two expansions differ");
    }
}
