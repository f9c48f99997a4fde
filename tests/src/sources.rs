//! The `#[pfaff::mechanism]` modules of the built-in model files, as token streams, for
//! snapshot tests and benchmarks that call the generator directly.

use std::path::PathBuf;

use proc_macro2::TokenStream;
use quote::ToTokens;

/// The mechanism modules of one source file, with the attribute removed, by name.
///
/// # Panics
/// If `src` is not valid Rust.
#[must_use]
pub fn mechanisms(src: &str) -> Vec<(String, TokenStream)> {
    mechanisms_with_args(src)
        .into_iter()
        .map(|(name, _, tokens)| (name, tokens))
        .collect()
}

/// The mechanism modules of one source file by name, with the arguments of their
/// `#[mechanism(..)]` attribute (empty without) and the module without the attribute.
///
/// # Panics
/// If `src` is not valid Rust.
#[must_use]
pub fn mechanisms_with_args(src: &str) -> Vec<(String, TokenStream, TokenStream)> {
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
                let attr = m.attrs.remove(at);
                let args = match attr.meta {
                    syn::Meta::List(list) => list.tokens,
                    _ => TokenStream::new(),
                };
                Some((m.ident.to_string(), args, m.into_token_stream()))
            }
            _ => None,
        })
        .collect()
}

/// Every built-in model (`models/src/*.rs`), sorted by file name.
///
/// # Panics
/// If the model directory cannot be read.
#[must_use]
pub fn model_sources() -> Vec<(String, TokenStream)> {
    model_sources_with_args()
        .into_iter()
        .map(|(name, _, tokens)| (name, tokens))
        .collect()
}

/// Every built-in model as [`mechanisms_with_args`] gives it, sorted by file name.
///
/// # Panics
/// If the model directory cannot be read.
#[must_use]
pub fn model_sources_with_args() -> Vec<(String, TokenStream, TokenStream)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models/src");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("models/src exists")
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .collect();
    files.sort();
    files
        .iter()
        .flat_map(|p| {
            mechanisms_with_args(&std::fs::read_to_string(p).expect("readable model file"))
        })
        .collect()
}
