//! The generator's bounds (issue 9): derived constants that leave `f64` are spanned
//! errors, the printed formulas are linear in the shared graph, a long sum expands (its
//! time is a benchmark), and messages always name what they blame.

use proc_macro2::TokenStream;
use quote::quote;

fn expand(src: TokenStream) -> String {
    crate::expand(quote!(), src).to_string()
}

/// `1e308 * x.dot().powi(2)` in T folds to M = 2e308 = inf: an error at the kinetic
/// energy, not `f64::INFINITY` in the emitted mass matrix.
#[test]
fn an_overflowing_derived_constant_is_an_error() {
    let out = expand(quote!(
        mod m {
            static x: Coordinate = Coordinate {};
            fn kinetic_energy() -> f64 {
                1e308 * x.dot().powi(2)
            }
        }
    ));
    assert!(out.contains("compile_error"), "{out}");
    assert!(
        out.contains("the mass matrix holds a constant that evaluates to inf"),
        "{out}"
    );
    assert!(!out.contains("INFINITY"), "{out}");
}

/// A mass of 1e-320 (subnormal) is finite, its inverse in the free-motion residual is
/// not: an error, not `f64::NAN` in `FREE_MOTION`.
#[test]
fn an_underflowing_derived_constant_is_an_error() {
    let out = expand(quote!(
        mod m {
            static x: Coordinate = Coordinate {};
            static y: Coordinate = Coordinate {};
            fn kinetic_energy() -> f64 {
                1e-320 * (x.dot().powi(2) + y.dot().powi(2))
            }
            #[holonomic]
            fn rod() -> f64 {
                x.powi(2) + y.powi(2) - 1.0
            }
        }
    ));
    assert!(out.contains("free-motion residual"), "{out}");
    assert!(!out.contains("NAN") && !out.contains("INFINITY"), "{out}");
}

/// A constraint nesting `sin` `depth` deep.
fn nested(depth: usize) -> TokenStream {
    let mut e = quote!(x);
    for _ in 0..depth {
        e = quote!((#e).sin());
    }
    quote!(
        mod m {
            static x: Coordinate = Coordinate {};
            static y: Coordinate = Coordinate {};
            fn kinetic_energy() -> f64 {
                0.5 * (x.dot().powi(2) + y.dot().powi(2))
            }
            #[holonomic]
            fn c() -> f64 {
                y - #e
            }
        }
    )
}

/// The printed free-motion formulas of `src` (total length) and the size of the graph
/// they print (nodes plus operands, each shared node counted once).
fn formulas_and_graph(src: TokenStream) -> (usize, usize) {
    let a = crate::analyze(quote!(), src).expect("a valid model");
    let fm = a
        .derived
        .free_motion
        .as_ref()
        .expect("free-motion conditions");
    let text: usize = crate::derive::free_motion::formulas(&a.graph, &a.model, fm)
        .iter()
        .map(String::len)
        .sum();
    let graph = crate::sym::transform::post_order(&a.graph, &fm.symbolic)
        .iter()
        .map(|&id| 1 + a.graph.node(id).args().len())
        .sum();
    (text, graph)
}

/// The printed formulas of a constraint nesting `sin` 100 and 400 deep: a bounded
/// number of characters per node and operand of the shared graph (printed as a tree,
/// depth 400 gave 164 MB). The graph itself grows as the square of the depth: the
/// derivative of the nest is a product of the cosines of all its levels.
#[test]
fn printed_formulas_are_linear_in_the_shared_graph() {
    let per: Vec<f64> = [100, 400]
        .into_iter()
        .map(|depth| {
            let (text, graph) = formulas_and_graph(nested(depth));
            println!("depth {depth}: {text} characters for a graph of {graph}");
            text as f64 / graph as f64
        })
        .collect();
    // Characters per element: a constant (subexpressions below `SHARED_SIZE` are
    // repeated inline), the same at both depths.
    assert!(per[0] < 64.0 && per[1] < 1.2 * per[0], "{per:?}");
}

/// A sum of 6,000 terms expands without a compile error (it took 5.1 s when the
/// expansion was quadratic; its time against a sum of 1,500 terms is measured by
/// `cargo bench -p pfaff-tests --bench codegen`, group `long_sum`).
#[test]
fn a_long_sum_expands() {
    // The 6,000-deep left-nested sum is parsed and dropped recursively: on a thread
    // with a stack like the compiler's own (8 MiB and more), not a test thread's 2 MiB.
    let out = std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(|| {
            let mut e = quote!(x);
            for i in 2..=6000 {
                let c = proc_macro2::Literal::i32_unsuffixed(i);
                e = quote!(#e + #c * x.powi(#c));
            }
            expand(quote!(
                mod m {
                    static x: Coordinate = Coordinate {};
                    fn kinetic_energy() -> f64 {
                        0.5 * x.dot().powi(2)
                    }
                    fn potential_energy() -> f64 {
                        #e
                    }
                }
            ))
        })
        .expect("thread spawns")
        .join()
        .expect("expansion does not panic");
    assert!(
        !out.contains("compile_error"),
        "{}",
        &out[..out.len().min(400)]
    );
    assert!(out.contains("impl"), "no implementation emitted");
}

/// A kinetic energy whose Hessian depends on a velocity only through `abs` (whose
/// second derivative is taken as zero) still names the velocity.
#[test]
fn messages_name_the_velocity_through_abs() {
    let out = expand(quote!(
        mod m {
            static x: Coordinate = Coordinate {};
            fn kinetic_energy() -> f64 {
                x.dot().abs() * x.dot()
            }
        }
    ));
    assert!(out.contains("still depends on `x.dot()`"), "{out}");
    let out = expand(quote!(
        mod m {
            static x: Coordinate = Coordinate {};
            static y: Coordinate = Coordinate {};
            fn kinetic_energy() -> f64 {
                0.5 * (x.dot().powi(2) + y.dot().powi(2))
            }
            #[nonholonomic]
            fn c() -> f64 {
                x.dot().abs() - y.dot()
            }
        }
    ));
    assert!(out.contains("`x.dot()` enters non-linearly"), "{out}");
    assert!(!out.contains("``"), "{out}");
}
