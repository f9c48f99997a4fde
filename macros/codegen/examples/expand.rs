//! Prints the expansion of a mechanism read from a file (or stdin), formatted.
//!
//! `cargo run --release -p pfaff-codegen --example expand -- models/src/pendulum.rs`
use std::io::Read;

fn main() {
    let path = std::env::args().nth(1);
    let mut src = String::new();
    match &path {
        Some(p) => src = std::fs::read_to_string(p).expect("readable file"),
        None => {
            std::io::stdin().read_to_string(&mut src).expect("stdin");
        }
    }
    let file: syn::File = syn::parse_str(&src).expect("a Rust file");
    for item in file.items {
        let syn::Item::Mod(mut m) = item else { continue };
        let Some(pos) = m.attrs.iter().position(|a| a.path().segments.last().is_some_and(|s| s.ident == "mechanism")) else {
            continue;
        };
        m.attrs.remove(pos);
        let out = pfaff_codegen::expand(proc_macro2::TokenStream::new(), quote::quote!(#m));
        match syn::parse2::<syn::File>(out.clone()) {
            Ok(f) => println!("{}", prettyplease::unparse(&f)),
            Err(_) => println!("{out}"),
        }
    }
}
