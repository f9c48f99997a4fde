//! The parameter expressions of beam data slots (`model::data`).
//!
//! Input: the model's data slots. Output: per slot, for a beam, its length and section
//! properties as expressions of the parameters (context of an initial value: parameters
//! and constants only), checked finite and positive at the parameters' defaults
//! (`rho_iy`, `rho_iz` may be zero). The emitted `refresh_data` evaluates them and calls
//! `pfaff::flex`; derivations read the slots through `Var::Data` leaves like parameters.

use crate::ctxt::Ctxt;
use crate::model::expr::{Context, Translator};
use crate::model::Model;
use crate::sym::{transform, ExprId, Var};

/// A beam slot's parameter expressions.
#[derive(Debug)]
pub struct BeamExprs {
    pub length: ExprId,
    /// In the order of `model::data::BeamDecl::section_fields`.
    pub section: Vec<ExprId>,
}

/// One entry per data slot: the beam's expressions, `None` for a slot set by the program.
pub fn translate(
    cx: &Ctxt,
    model: &Model,
    tr: &mut Translator<'_>,
    defaults: &[f64],
) -> Vec<Option<BeamExprs>> {
    let mut out = Vec::new();
    for slot in &model.data {
        let Some(beam) = &slot.beam else {
            out.push(None);
            continue;
        };
        let fields = std::iter::once(("length", &beam.length)).chain(
            beam.section_fields()
                .iter()
                .copied()
                .zip(beam.section.iter()),
        );
        let mut ids = Vec::new();
        for (name, e) in fields {
            let Some(id) = tr.standalone(e, Context::Initial) else {
                continue;
            };
            let v = transform::eval(tr.g, &[id], &|v| match v {
                Var::Param(i) => defaults.get(i as usize).copied().unwrap_or(f64::NAN),
                _ => f64::NAN,
            })[0];
            let may_be_zero = name.starts_with("rho_i");
            if !v.is_finite() || v < 0.0 || (v == 0.0 && !may_be_zero) {
                cx.error_spanned_by(
                    e,
                    format!(
                        "`{name}` of beam `{}` is {v} at the parameters' defaults; it must be {}",
                        slot.name,
                        if may_be_zero {
                            "finite and not negative"
                        } else {
                            "finite and positive"
                        }
                    ),
                );
            }
            ids.push(id);
        }
        if ids.len() == 1 + beam.section.len() {
            out.push(Some(BeamExprs {
                length: ids[0],
                section: ids[1..].to_vec(),
            }));
        } else {
            out.push(None);
        }
    }
    out
}
