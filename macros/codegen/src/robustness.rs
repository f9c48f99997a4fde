//! Expansion of unusual but valid input: it must never panic, and what it emits must
//! mean what the user wrote.

use proc_macro2::TokenStream;
use quote::quote;

/// The expansion as a string, or the panic message.
fn expand(src: TokenStream) -> Result<String, String> {
    std::panic::catch_unwind(|| crate::expand(quote!(), src).to_string()).map_err(|e| {
        e.downcast_ref::<String>()
            .cloned()
            .or_else(|| e.downcast_ref::<&str>().map(|s| (*s).to_owned()))
            .unwrap_or_default()
    })
}

/// The generated function `name` (its tokens up to the next `fn`).
fn function<'a>(out: &'a str, name: &str) -> &'a str {
    let start = out
        .find(&format!("fn {name} "))
        .unwrap_or_else(|| panic!("no `{name}` in {out}"));
    let end = out[start + 3..]
        .find("fn ")
        .map_or(out.len(), |e| start + 3 + e);
    &out[start..end]
}

#[test]
fn raw_identifiers_name_coordinates_and_parameters() {
    let out = expand(quote!(
        mod m {
            const r#fn: f64 = 2.0;
            static r#type: Coordinate = Coordinate {};
            fn kinetic_energy() -> f64 {
                0.5 * r#fn * r#type.dot().powi(2)
            }
        }
    ))
    .expect("expansion does not panic");
    assert!(!out.contains("compile_error"), "{out}");
    assert!(out.contains("let type_dot = qd [0]"), "{out}");
    assert!(out.contains("name : \"type\""), "{out}");
    assert!(out.contains("name : \"fn\""), "{out}");
}

#[test]
fn exponents_at_the_ends_of_i32() {
    // d/dx x^(−MAX) = −MAX x^MIN: the reciprocal of x^MIN has no `i32` exponent, so
    // it is printed as `x.powi(-2147483648)`, never `1.0 / x.powi(...)`.
    let out = expand(quote!(
        mod m {
            static x: Coordinate = Coordinate {};
            fn kinetic_energy() -> f64 {
                x.dot().powi(2)
            }
            fn potential_energy() -> f64 {
                x.powi(2147483647) * x.powi(2147483647) * x
            }
            #[holonomic]
            fn c() -> f64 {
                x.powi(-2147483647)
            }
        }
    ))
    .expect("expansion does not panic");
    assert!(!out.contains("compile_error"), "{out}");
    let jac = function(&out, "holonomic_jacobian");
    assert!(jac.contains("x . powi (- 2147483648)"), "{jac}");
    assert!(!jac.contains("/"), "{jac}");
    // V = x^(2^32 − 1), not the wrapped x^(−1).
    let v = function(&out, "potential_energy");
    assert!(!v.contains("/"), "{v}");
    assert!(v.contains("2147483647"), "{v}");
}

#[test]
fn user_errors_are_diagnostics() {
    let cases = [
        (
            quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    fn kinetic_energy() -> f64 {
                        1e400 * x.dot().powi(2)
                    }
                }
            ),
            "number out of range for `f64`",
        ),
        (
            quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    fn kinetic_energy() -> f64 {
                        x.dot().powi(2)
                    }
                    fn potential_energy() -> f64 {
                        x / (x - x)
                    }
                }
            ),
            "division by zero",
        ),
        (
            quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    fn kinetic_energy() -> f64 {
                        x.dot().powi(2)
                    }
                    fn potential_energy() -> f64 {
                        x * (1.0 - 1.0).ln()
                    }
                }
            ),
            "this expression is constant and evaluates to -inf",
        ),
        (
            quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    fn kinetic_energy() -> f64 {
                        x.dot().powi(2)
                    }
                    fn potential_energy() -> f64 {
                        (-1.0).sqrt() * x
                    }
                }
            ),
            "this expression is constant and evaluates to NaN",
        ),
        (
            quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    fn a() -> f64 {
                        a()
                    }
                    fn kinetic_energy() -> f64 {
                        x.dot().powi(2) * a()
                    }
                }
            ),
            "definition `a` uses itself; definitions are not recursive",
        ),
        (
            quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    fn kinetic_energy() -> f64 {
                        x.dot().powi(2)
                    }
                    fn potential_energy() -> f64 {
                        x.powi(-2147483648)
                    }
                }
            ),
            "`powi` takes an integer literal exponent",
        ),
        (
            quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    static y: Coordinate = Coordinate {};
                    fn mass_matrix() -> [[f64; 2]; 2] {
                        [[1.0], [0.0, 1.0]]
                    }
                }
            ),
            "it must be 2×2",
        ),
        (
            quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    fn mass_matrix() -> [[f64; 1]; 1] {
                        []
                    }
                }
            ),
            "it must be 1×1",
        ),
        (
            quote!(
                mod m {
                    const r#t: f64 = 1.0;
                    static x: Coordinate = Coordinate {};
                    fn kinetic_energy() -> f64 {
                        x.dot().powi(2)
                    }
                    fn potential_energy() -> f64 {
                        t * x
                    }
                }
            ),
            "`t` is reserved and cannot be declared",
        ),
        (
            quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    static r#x: Coordinate = Coordinate {};
                    fn kinetic_energy() -> f64 {
                        x.dot().powi(2)
                    }
                }
            ),
            "duplicate name `x`",
        ),
        (
            quote!(
                mod m {}
            ),
            "at least one coordinate",
        ),
        (
            quote!(
                mod m {
                    fn a() -> f64 {
                        1.0
                    }
                }
            ),
            "at least one coordinate",
        ),
    ];
    for (src, msg) in cases {
        let out = expand(src.clone()).unwrap_or_else(|p| panic!("panic {p} on {src}"));
        assert!(
            out.contains("compile_error") && out.contains(msg),
            "{msg}: {out}"
        );
    }
}

/// A spatial revolute joint without `axis_a` (optional only for a planar one) is a
/// compile error, not a panic (found by the fuzz campaign, seed 1795831916, case 20483).
#[test]
fn a_spatial_revolute_joint_without_its_axis_is_an_error() {
    let out = expand(quote!(
        mod hinge {
            static x: Coordinate = Coordinate {};
            static y: Coordinate = Coordinate {};
            static z: Coordinate = Coordinate {};
            static psi: Coordinate = Coordinate {};
            static door: Body = Body {
                origin: [x, y, z],
                rotation: rot_z(psi),
                mass: 1.0,
                inertia: diag(1.0, 1.0, 1.0),
            };
            static pivot: Joint = Revolute {
                a: door,
                at_b: [0.0, 0.0, 0.0],
                axis_b: [0.0, 0.0, 1.0],
            };
        }
    ))
    .expect("expansion does not panic");
    assert!(out.contains("compile_error"), "{out}");
    assert!(out.contains("needs `axis_a`"), "{out}");
}

/// A deformable body whose material closure reads its own `material(..)` is a compile
/// error at the call (it recursed until the stack overflowed, which no `catch_unwind`
/// catches), in the position closure and in the displacement closure alike.
#[test]
fn a_material_closure_that_reads_its_own_material_is_an_error() {
    let rod = |position: TokenStream, displacement: TokenStream| {
        quote!(
            mod m {
                static x: Coordinate = Coordinate {};
                static y: Coordinate = Coordinate {};
                static rod: Body = Deformable {
                    origin: [x, 0.0],
                    angle: 0.0,
                    elastic: [y],
                    position: #position,
                    displacement: #displacement,
                    density: 1.0,
                    span: 0.0..1.0,
                };
            }
        )
    };
    let own = quote!(|xi| rod.material(xi));
    for src in [
        rod(own.clone(), quote!(|xi| [0.0, xi * y])),
        rod(quote!(|xi| [xi, 0.0]), own),
    ] {
        let out = expand(src).expect("expansion does not panic");
        assert!(out.contains("cannot use its own `material(..)`"), "{out}");
        assert_eq!(out.matches("compile_error").count(), 1, "one error: {out}");
    }
}

/// A mass matrix written by the user in a model with frames but no body is the
/// model's mass matrix (it was dropped for the bodies' kinetic energy, zero).
#[test]
fn a_mass_matrix_beside_frames_without_bodies_is_kept() {
    let out = expand(quote!(
        mod m {
            static x: Coordinate = Coordinate {};
            static f: Frame = Frame {
                origin: [x, 0.0],
                angle: 0.0,
            };
            fn mass_matrix() -> [[f64; 1]; 1] {
                [[7.0]]
            }
        }
    ))
    .expect("expansion does not panic");
    assert!(!out.contains("compile_error"), "{out}");
    let mass = function(&out, "mass_matrix");
    assert!(mass.contains("7f64") || mass.contains("7.0"), "{mass}");
}
