//! The generator behind `#[pfaff::mechanism]`.
pub fn expand(
    args: proc_macro2::TokenStream,
    input: proc_macro2::TokenStream,
) -> proc_macro2::TokenStream {
    let _ = args;
    input
}
