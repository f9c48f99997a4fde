use quote::ToTokens;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let src = std::fs::read_to_string(path).unwrap();
    let file = syn::parse_file(&src).unwrap();
    for item in file.items {
        if let syn::Item::Mod(mut m) = item {
            let Some(at) = m.attrs.iter().position(|a| {
                a.path()
                    .segments
                    .last()
                    .is_some_and(|s| s.ident == "mechanism")
            }) else {
                continue;
            };
            let attr = m.attrs.remove(at);
            let args = match attr.meta {
                syn::Meta::List(l) => l.tokens,
                _ => Default::default(),
            };
            let ts = pfaff_codegen::expand(args, m.into_token_stream());
            println!(
                "{}",
                prettyplease::unparse(&syn::parse2::<syn::File>(ts).unwrap())
            );
        }
    }
}
