//! Emission of run-time data slots (`model::data`): the `Data` struct the model holds,
//! `Info::data`, the trait's `data`/`set_data`, and `Model::refresh_data`, which fills
//! the beam slots with `pfaff::flex` from the parameters when the model is built or a
//! parameter changes (allocating there is fine: never in a per-step path).

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;

use super::{body, doc_attr, plain, ModelNames};
use crate::derive::Derived;
use crate::model::data::BeamReference;
use crate::model::Model;
use crate::sym::Graph;

/// What a model with data slots adds to its module.
pub struct DataCode {
    /// The value of `Info::data`.
    pub info: TokenStream,
    /// The `Data` struct and `Model::refresh_data`.
    pub items: TokenStream,
    /// The trait methods `data` and `set_data`.
    pub fns: TokenStream,
    /// Whether a parameter change must refresh the data (the model has beam slots).
    pub refresh: bool,
}

/// `None` for a model without data slots (its code stays as it was).
pub fn data(g: &Graph, names: &ModelNames, model: &Model, d: &Derived) -> Option<DataCode> {
    if model.data.is_empty() {
        return None;
    }
    let name_str = model.ident.to_string();
    let flex = quote!(::pfaff::__private::flex);
    let mut slots = Vec::new();
    let mut fields = Vec::new();
    let mut zeros = Vec::new();
    let mut get = Vec::new();
    let mut set = Vec::new();
    let mut refresh = TokenStream::new();
    let mut any_beam = false;
    for (k, (slot, exprs)) in model.data.iter().zip(&d.data).enumerate() {
        let field = &slot.name;
        let (n, doc) = (plain(field), &slot.docs);
        let len = Literal::usize_unsuffixed(slot.len);
        let idx = Literal::usize_unsuffixed(k);
        let len32 = Literal::u32_unsuffixed(u32::try_from(slot.len).expect("slot fits u32"));
        slots.push(quote!(::pfaff::__private::DataSlot { name: #n, doc: #doc, len: #len32 }));
        let fdoc = doc_attr(doc);
        fields.push(quote!(#fdoc pub #field: [f64; #len],));
        zeros.push(quote!(#field: [0.0; #len],));
        get.push(quote!(#idx => &self.data.#field,));
        set.push(quote!(#idx => (&mut self.data.#field, #n),));
        let (Some(beam), Some(exprs)) = (&slot.beam, exprs) else {
            continue;
        };
        any_beam = true;
        let mut roots = vec![exprs.length];
        roots.extend(&exprs.section);
        let count = Literal::usize_unsuffixed(roots.len());
        let values = Ident::new("values", Span::call_site());
        let (code, _) = body(g, names, &roots, |k, ts| {
            let k = Literal::usize_unsuffixed(k);
            quote!(#values[#k] = #ts;)
        });
        let v = |k: usize| {
            let k = Literal::usize_unsuffixed(k);
            quote!(#values[#k])
        };
        let args: Vec<TokenStream> = (1..roots.len()).map(v).collect();
        let (dim, section) = if beam.spatial {
            (quote!(Spatial), quote!(#flex::Section::spatial(#(#args),*)))
        } else {
            (quote!(Planar), quote!(#flex::Section::planar(#(#args),*)))
        };
        let reference = match beam.reference {
            BeamReference::Clamped(a) => {
                let a = Literal::usize_unsuffixed(a);
                quote!(#flex::Reference::Clamped { node: #a })
            }
            BeamReference::SimplySupported(a, b) => {
                let (a, b) = (Literal::usize_unsuffixed(a), Literal::usize_unsuffixed(b));
                quote!(#flex::Reference::SimplySupported { first: #a, last: #b })
            }
        };
        let modes = Literal::usize_unsuffixed(beam.modes);
        let reduction = if let Some(set) = &beam.mode_set {
            let set = set.iter().map(|&x| Literal::usize_unsuffixed(x));
            quote!(#flex::Reduction::ModeSet(::std::vec![#(#set),*]))
        } else if beam.boundary.is_empty() {
            quote!(#flex::Reduction::Modes(#modes))
        } else {
            let b = beam.boundary.iter().map(|&x| Literal::usize_unsuffixed(x));
            quote!(#flex::Reduction::CraigBampton { boundary: ::std::vec![#(#b),*], modes: #modes })
        };
        let elements = Literal::usize_unsuffixed(beam.elements);
        let length = v(0);
        refresh.extend(quote! {
            {
                let mut #values = [0.0_f64; #count];
                #code
                let beam = #flex::Beam {
                    dim: #flex::Dim::#dim,
                    elements: #elements,
                    length: #length,
                    section: #section,
                    reference: #reference,
                    reduction: #reduction,
                };
                if let ::core::result::Result::Err(e) = beam.write_slot(&mut self.data.#field) {
                    self.data.#field.fill(f64::NAN);
                    if result.is_ok() {
                        result = ::core::result::Result::Err(e);
                    }
                }
            }
        });
    }
    let data_doc = format!(" Run-time data of `{name_str}`: one array per `Data` slot.");
    let items = quote! {
        #[doc = #data_doc]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Data {
            #(#fields)*
        }

        impl ::core::default::Default for Data {
            fn default() -> Self {
                Self { #(#zeros)* }
            }
        }

        impl Model {
            /// Recomputes the data slots that follow from the parameters (the invariants
            /// of beam-element bodies, by `pfaff::flex`); slots set by the program are
            /// left alone. Called by `new` and after every parameter change. A failure
            /// (a parameter that makes no beam) fills its slot with NaN, so evaluations
            /// fail with a typed error, and is returned.
            ///
            /// # Errors
            /// The first `pfaff::flex::FlexError` of a beam.
            pub fn refresh_data(&mut self) -> ::core::result::Result<(), #flex::FlexError> {
                #[allow(unused_mut)]
                let mut result = ::core::result::Result::Ok(());
                #refresh
                result
            }
        }
    };
    let fns = quote! {
        fn data(&self, index: usize) -> &[f64] {
            match index {
                #(#get)*
                _ => &[],
            }
        }
        fn set_data(
            &mut self,
            index: usize,
            values: &[f64],
        ) -> ::core::result::Result<(), ::pfaff::__private::DataError> {
            let (slot, name): (&mut [f64], &'static str) = match index {
                #(#set)*
                _ => {
                    return ::core::result::Result::Err(::pfaff::__private::DataError::NoSlot {
                        model: #name_str,
                        index,
                    })
                }
            };
            if values.len() != slot.len() {
                return ::core::result::Result::Err(::pfaff::__private::DataError::Length {
                    slot: name,
                    expected: slot.len(),
                    got: values.len(),
                });
            }
            if let ::core::option::Option::Some((i, &v)) =
                values.iter().enumerate().find(|(_, v)| !v.is_finite())
            {
                return ::core::result::Result::Err(::pfaff::__private::DataError::NotFinite {
                    slot: name,
                    index: i,
                    value: v,
                });
            }
            slot.copy_from_slice(values);
            ::core::result::Result::Ok(())
        }
    };
    Some(DataCode {
        info: quote!(&[#(#slots),*]),
        items,
        fns,
        refresh: any_beam,
    })
}
