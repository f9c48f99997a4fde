//! Snapshots of the generator's output for every built-in model (`models/src/*.rs`):
//! the derived quantities as formulas (`<model>__symbolic`) and the emitted Rust,
//! formatted by prettyplease (`<model>__emit`). A change to the generator shows up
//! here as a readable diff; review it with `cargo insta review`.

use proc_macro2::TokenStream;

use crate::sources::model_sources_with_args;

fn pretty(ts: TokenStream) -> String {
    prettyplease::unparse(&syn::parse2::<syn::File>(ts).expect("generated code parses"))
}

/// Largest emitted module (bytes) kept whole in a snapshot. Larger ones (the bicycle
/// with its linearization Jacobian, 2 MB) are recorded as a digest: each function's
/// signature with its line count and a hash of its text, so a change still fails the
/// test and names the function, without megabytes of unreviewable text in the
/// repository.
const MAX_SNAPSHOT: usize = 300_000;

/// 64-bit FNV-1a.
fn fnv(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// One line per item of the emitted code that starts a function or a static: the line,
/// the number of lines up to the next such item, and the hash of that text.
fn digest(code: &str) -> String {
    let lines: Vec<&str> = code.lines().collect();
    let starts: Vec<usize> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| {
            let t = l.trim_start();
            t.starts_with("fn ") || t.starts_with("pub fn ") || t.starts_with("pub static ")
        })
        .map(|(i, _)| i)
        .collect();
    let mut out = format!("{} lines, fnv {:016x}\n", lines.len(), fnv(code));
    for (k, &start) in starts.iter().enumerate() {
        let end = starts.get(k + 1).copied().unwrap_or(lines.len());
        let text = lines[start..end].join("\n");
        out.push_str(&format!(
            "{}  [{} lines, fnv {:016x}]\n",
            lines[start].trim(),
            end - start,
            fnv(&text)
        ));
    }
    out
}

#[test]
fn every_model_expands_to_the_reviewed_code() {
    let models = model_sources_with_args();
    assert!(
        models.len() >= 7,
        "the built-in models are found: {}",
        models.len()
    );
    for (name, args, tokens) in models {
        let analysis = pfaff_codegen::analyze(args.clone(), tokens.clone())
            .unwrap_or_else(|e| panic!("{name} has errors: {e}"));
        insta::assert_snapshot!(format!("{name}__symbolic"), analysis.describe());
        let code = pretty(pfaff_codegen::expand(args, tokens));
        if code.len() <= MAX_SNAPSHOT {
            insta::assert_snapshot!(format!("{name}__emit"), code);
        } else {
            insta::assert_snapshot!(format!("{name}__emit_digest"), digest(&code));
        }
    }
}

#[test]
fn expansion_is_deterministic() {
    for (name, args, tokens) in model_sources_with_args() {
        let a = pfaff_codegen::expand(args.clone(), tokens.clone()).to_string();
        let b = pfaff_codegen::expand(args, tokens).to_string();
        assert_eq!(a, b, "{name}: two expansions differ");
    }
}
