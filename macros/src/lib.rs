//! The `#[mechanism]` attribute of pfaff.
//!
//! This crate is a shim: a proc-macro crate can export only macros, so the whole
//! generator lives in the ordinary library `pfaff-codegen`, where tests, benchmarks
//! and tools can call it as a function. Use the macro through `pfaff::mechanism`.

use proc_macro::TokenStream;

/// Derives a multibody mechanism from a declarative inline module.
///
/// See the crate-level documentation of `pfaff` for the description language.
#[proc_macro_attribute]
pub fn mechanism(args: TokenStream, input: TokenStream) -> TokenStream {
    pfaff_codegen::expand(args.into(), input.into()).into()
}
