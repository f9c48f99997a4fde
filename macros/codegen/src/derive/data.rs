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

/// The invariants held by a data slot, as `Var::Data` leaves in the flat layout of
/// `pfaff::flex::Invariants::write_flat` (each field row-major as documented there).
#[derive(Debug)]
pub struct SlotLeaves {
    pub m: ExprId,
    /// `Ī₁` (d).
    pub i1: Vec<ExprId>,
    /// `S̄` (d × n).
    pub s_bar: Vec<ExprId>,
    /// `I_kl` (d × d).
    pub i_kl: Vec<ExprId>,
    /// `Ī_kl` (d × d × n).
    pub i_bar: Vec<ExprId>,
    /// `S̄_kl` (d × d × n × n).
    pub s_kl: Vec<ExprId>,
    /// `M_ff` (n × n).
    pub m_ff: Vec<ExprId>,
    /// `K_ff` (n × n).
    pub k_ff: Vec<ExprId>,
    /// What a beam slot holds besides the invariants; `None` for a slot set by the
    /// program.
    pub beam: Option<BeamLeaves>,
}

/// The nodes and elements of a beam slot: its length, axial stiffness and reduced basis.
#[derive(Clone, Debug)]
pub struct BeamLeaves {
    pub elements: usize,
    /// Nodal coordinates per node (3: `u v θ`, 6: `u_x u_y u_z θ_x θ_y θ_z`).
    pub dofs_per_node: usize,
    pub length: ExprId,
    pub ea: ExprId,
    /// `T` (ndof × n): nodal coordinates in the body frame from the elastic ones.
    pub basis: Vec<ExprId>,
    /// `K_Ω` (n × n): the geometric stiffness of a unit spin about an axis through the
    /// root perpendicular to the beam (`pfaff::flex::Beam::spin_stiffness`).
    pub k_spin: Vec<ExprId>,
}

/// The invariants of a deformable body of `d` axes and `n` elastic coordinates read from
/// the data slot named by `e` (`data: rod` in its declaration).
///
/// Errors (recorded in `cx`, spanned at `e`): `e` is not the name of a data slot; a
/// beam slot's axes or coordinates differ from the body's; a slot set by the program
/// has another length than the layout's.
pub fn slot_leaves(
    cx: &Ctxt,
    model: &Model,
    g: &mut crate::sym::Graph,
    e: &syn::Expr,
    d: usize,
    n: usize,
) -> Option<SlotLeaves> {
    let slot = match e {
        syn::Expr::Path(p) => p
            .path
            .get_ident()
            .and_then(|id| model.data_slot(&id.to_string())),
        _ => None,
    };
    let Some(slot) = slot else {
        let names: Vec<String> = model.data.iter().map(|s| format!("`{}`", s.name)).collect();
        cx.error_spanned_by(
            e,
            if names.is_empty() {
                "expected the name of a data slot (`static rod: Data = Beam { .. };`); the model declares none".to_owned()
            } else {
                format!("expected the name of a data slot: {}", names.join(", "))
            },
        );
        return None;
    };
    let len = crate::model::data::flat_len(d, n);
    if let Some(b) = &slot.beam {
        if (b.d, b.n) != (d, n) {
            cx.error_spanned_by(
                e,
                format!(
                    "beam `{}` is {} with {} elastic coordinates; this body is {} with {n}",
                    slot.name,
                    if b.d == 2 { "planar" } else { "spatial" },
                    b.n,
                    if d == 2 { "planar" } else { "spatial" },
                ),
            );
            return None;
        }
    } else if slot.len != len {
        cx.error_spanned_by(
            e,
            format!(
                "data slot `{}` holds {} values; the invariants of a {} body with {n} elastic coordinates take {len}",
                slot.name,
                slot.len,
                if d == 2 { "planar" } else { "spatial" },
            ),
        );
        return None;
    }
    let mut at = slot.offset;
    let mut take = |g: &mut crate::sym::Graph, k: usize| -> Vec<ExprId> {
        let out = (at..at + k)
            .map(|i| g.var(Var::Data(u32::try_from(i).expect("data size fits u32"))))
            .collect();
        at += k;
        out
    };
    let m = take(g, 1)[0];
    let i1 = take(g, d);
    let s_bar = take(g, d * n);
    let i_kl = take(g, d * d);
    let i_bar = take(g, d * d * n);
    let s_kl = take(g, d * d * n * n);
    let m_ff = take(g, n * n);
    let k_ff = take(g, n * n);
    let beam = slot.beam.as_ref().map(|b| {
        let length = take(g, 1)[0];
        let ea = take(g, 1)[0];
        BeamLeaves {
            elements: b.elements,
            dofs_per_node: b.dofs_per_node(),
            length,
            ea,
            basis: take(g, b.ndof() * n),
            k_spin: take(g, n * n),
        }
    });
    Some(SlotLeaves {
        beam,
        m,
        i1,
        s_bar,
        i_kl,
        i_bar,
        s_kl,
        m_ff,
        k_ff,
    })
}
