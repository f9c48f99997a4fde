//! Emission of the contacts: `Info::contacts`, `Info::contact_pattern`, and the trait
//! methods `contact_gaps`, `contact_jacobian`, `contact_rate` and `contact_gamma` (the
//! last two only when not identically zero).

use proc_macro2::TokenStream;
use quote::quote;

use super::{any_nonzero, entries, pattern, vector_fn, ModelNames};
use crate::derive::Derived;
use crate::sym::{ExprId, Graph};

/// The contacts' entries of `Info` (returned) and their trait methods (added to `fns`).
pub(super) fn contacts(
    g: &Graph,
    names: &ModelNames,
    d: &Derived,
    fns: &mut TokenStream,
) -> TokenStream {
    let c = &d.contacts;
    let items = c.list.iter().map(|k| {
        let name = k.name.strip_prefix("r#").unwrap_or(&k.name);
        let (doc, e) = (&k.docs, k.restitution);
        quote!(::pfaff::__private::Contact { name: #name, doc: #doc, restitution: #e })
    });
    let pat = pattern(&c.jacobian);
    if !c.list.is_empty() {
        let gaps: Vec<ExprId> = c.list.iter().map(|k| k.gap).collect();
        let rates: Vec<ExprId> = c.list.iter().map(|k| k.rate).collect();
        let gammas: Vec<ExprId> = c.list.iter().map(|k| k.gamma).collect();
        fns.extend(vector_fn(g, names, "contact_gaps", &gaps, false));
        fns.extend(vector_fn(
            g,
            names,
            "contact_jacobian",
            &entries(&c.jacobian),
            false,
        ));
        if any_nonzero(g, &rates) {
            fns.extend(vector_fn(g, names, "contact_rate", &rates, false));
        }
        if any_nonzero(g, &gammas) {
            fns.extend(vector_fn(g, names, "contact_gamma", &gammas, true));
        }
    }
    quote! {
        contacts: &[#(#items),*],
        contact_pattern: #pat,
    }
}
