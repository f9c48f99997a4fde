//! Keywords of the description language.

pub const HOLONOMIC: &str = "holonomic";
pub const NONHOLONOMIC: &str = "nonholonomic";
pub const FORCE: &str = "force";
pub const VIRTUAL_WORK: &str = "virtual_work";
pub const KINETIC_ENERGY: &str = "kinetic_energy";
pub const POTENTIAL_ENERGY: &str = "potential_energy";
pub const MASS_MATRIX: &str = "mass_matrix";
pub const COORDINATE: &str = "Coordinate";
pub const OUTPUT: &str = "output";
pub const CONTACT: &str = "contact";
pub const GROUND: &str = "ground";
/// The types of `static` declarations of the body level.
pub const FRAME: &str = "Frame";
pub const POINT: &str = "Point";
pub const BODY: &str = "Body";
pub const JOINT: &str = "Joint";
pub const FORCE_ELEMENT: &str = "Force";
pub const DRAWING: &str = "Drawing";
pub const CONTACT_ITEM: &str = "Contact";
/// The type of a run-time data slot (`static name: Data = ..;`).
pub const DATA: &str = "Data";
pub const Q0: &str = "q0";
pub const QD0: &str = "qd0";
pub const DOT: &str = "dot";
pub const DELTA: &str = "delta";
pub const TIME: &str = "t";

/// Names users may not declare: they mean something already. (`delta` stays free for
/// coordinates — `delta(..)` is a call, so the two never meet — but not for functions.)
pub const RESERVED: &[&str] = &[TIME, "self", "q", "qd", "out", GROUND];

/// Mathematical constants usable in expressions.
pub fn constant(name: &str) -> Option<f64> {
    use std::f64::consts as c;
    Some(match name {
        "PI" => c::PI,
        "TAU" => c::TAU,
        "E" => c::E,
        "FRAC_PI_2" => c::FRAC_PI_2,
        "FRAC_PI_3" => c::FRAC_PI_3,
        "FRAC_PI_4" => c::FRAC_PI_4,
        "FRAC_PI_6" => c::FRAC_PI_6,
        "SQRT_2" => c::SQRT_2,
        _ => return None,
    })
}
