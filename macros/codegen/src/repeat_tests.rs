//! Arrays, loops and sums (`parse::repeat`): a model written with them emits the code
//! of its unrolled source, and misuse is a diagnostic, never a panic.

use proc_macro2::TokenStream;
use quote::ToTokens;

use crate::sparsity::chain;

/// The `#[mechanism]` module `name` of a source file, its attribute and docs removed.
fn module(src: &str, name: &str) -> TokenStream {
    let file = syn::parse_file(src).expect("the source parses");
    for item in file.items {
        if let syn::Item::Mod(mut m) = item {
            if m.ident == name {
                m.attrs.clear();
                return m.into_token_stream();
            }
        }
    }
    panic!("no module `{name}`");
}

fn emitted(tokens: TokenStream) -> String {
    crate::expand(TokenStream::new(), tokens).to_string()
}

/// The diagnostics of a model that should not compile.
fn errors(src: &str) -> Vec<String> {
    let tokens: TokenStream = src.parse().expect("the source lexes");
    match crate::analyze(TokenStream::new(), tokens) {
        Ok(_) => Vec::new(),
        Err(e) => e.into_iter().map(|e| e.to_string()).collect(),
    }
}

fn chain_file() -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/src/chain.rs");
    std::fs::read_to_string(path).expect("models/src/chain.rs is readable")
}

#[test]
fn chain10_with_loops_emits_the_code_of_the_unrolled_chain() {
    for (name, n) in [("chain10", 10), ("chain100", 100)] {
        let looped = emitted(module(&chain_file(), name));
        let unrolled = emitted(module(&chain::chain_source(name, n), name));
        assert!(!looped.contains("compile_error"), "{name}: {looped:.400}");
        eprintln!(
            "{name}: emitted code {} bytes from loops, {} bytes unrolled",
            looped.len(),
            unrolled.len()
        );
        assert!(looped == unrolled, "{name}: the emitted code differs");
    }
}

#[test]
fn sums_and_index_arithmetic_unroll_to_the_written_out_model() {
    let looped = r"mod m {
        const N: usize = 3;
        const k: f64 = 2.0;
        static x: [Coordinate; N] = from_fn(|i| Coordinate { q0: i as f64 });
        fn kinetic_energy() -> f64 { (0..N).map(|i| 0.5 * x[i].dot().powi(2)).sum() }
        fn potential_energy() -> f64 {
            (1..N).map(|i| 0.5 * k * (x[i] - x[i - 1]).powi(2)).sum::<f64>()
                + (0..N).map(|i| (i as f64 + 1.0) * x[N - 1 - i]).sum()
        }
        const _: () = for i in 0..N - 1 {
            #[output]
            fn gap() -> f64 { x[i + 1] - x[2 * i / 2] }
        };
    }";
    let unrolled = r"mod m {
        const k: f64 = 2.0;
        static x_0: Coordinate = Coordinate { q0: 0.0 };
        static x_1: Coordinate = Coordinate { q0: 1.0 };
        static x_2: Coordinate = Coordinate { q0: 2.0 };
        fn kinetic_energy() -> f64 {
            (0.5 * x_0.dot().powi(2)) + (0.5 * x_1.dot().powi(2)) + (0.5 * x_2.dot().powi(2))
        }
        fn potential_energy() -> f64 {
            (0.5 * k * (x_1 - x_0).powi(2)) + (0.5 * k * (x_2 - x_1).powi(2))
                + ((0.0 + 1.0) * x_2) + ((1.0 + 1.0) * x_1) + ((2.0 + 1.0) * x_0)
        }
        #[output]
        fn gap_0() -> f64 { x_1 - x_0 }
        #[output]
        fn gap_1() -> f64 { x_2 - x_1 }
    }";
    let a = emitted(looped.parse().unwrap());
    let b = emitted(unrolled.parse().unwrap());
    assert!(!a.contains("compile_error"), "{a:.600}");
    assert!(a == b, "the emitted code differs");
}

#[test]
fn nested_loops_name_elements_by_both_indices_and_resolve_conditions() {
    let src = r"mod m {
        const N: usize = 2;
        const _: () = for i in 0..N {
            for j in 0..=1 {
                static p: Coordinate = Coordinate { q0: if i == j { 1.0 } else { 0.0 } };
            }
        };
        fn kinetic_energy() -> f64 { p[1][0].dot().powi(2) + p[0][1].dot().powi(2) + p[0][0].dot().powi(2) + p[1][1].dot().powi(2) }
        #[holonomic]
        fn c() -> f64 { p[0][0] + p[1][1] - 2.0 }
    }";
    let tokens: TokenStream = src.parse().unwrap();
    let a = crate::analyze(TokenStream::new(), tokens).expect("the model derives");
    let names: Vec<String> = a.model.coords.iter().map(|c| c.name.to_string()).collect();
    assert_eq!(names, ["p_0_0", "p_0_1", "p_1_0", "p_1_1"]);
    let q0: Vec<String> = a
        .model
        .coords
        .iter()
        .map(|c| c.q0.to_token_stream().to_string())
        .collect();
    assert_eq!(q0, ["1.0", "0.0", "0.0", "1.0"]);
}

fn one_error(src: &str, expected: &str) {
    let e = errors(src);
    assert!(
        e.iter().any(|m| m.contains(expected)),
        "expected an error containing {expected:?}, got {e:?}"
    );
}

#[test]
fn misuse_is_a_diagnostic() {
    let head = "const N: usize = 3; static x: [Coordinate; N] = [Coordinate {}; N]; \
                fn kinetic_energy() -> f64 { x[0].dot().powi(2) + x[1].dot().powi(2) + x[2].dot().powi(2) }";
    let cases = [
        ("fn potential_energy() -> f64 { x[3] }", "index out of range: `x[3]` is not declared (`x` has the indices 0..3)"),
        ("fn potential_energy() -> f64 { x[0 - 1] }", "negative index -1 into `x`"),
        ("const _: () = for i in 1..N { #[output] fn d() -> f64 { x[i - 2] } };", "negative index -1 into `x`"),
        ("fn potential_energy() -> f64 { x[N] }", "`x[3]` is not declared"),
        ("const m: f64 = 1.0; static y: [Coordinate; m] = [Coordinate {}; 2];", "`m` is not a `usize` constant or a loop variable: an array's length"),
        ("const _: () = for i in 0..N { #[output] fn d() -> f64 { x[i] } }; fn potential_energy() -> f64 { x[i] }", "the loop variable `i` is used outside its loop"),
        ("fn potential_energy() -> f64 { (0..N).map(|j| x[j]).sum::<f64>() + j as f64 }", "the loop variable `j` is used outside its loop"),
        ("fn potential_energy() -> f64 { x }", "`x` is an array (indices 0..3): write one element, `x[i]`"),
        ("fn potential_energy() -> f64 { x[0][1] }", "`x` has 1 index"),
        ("const _: () = for i in -1..N { #[output] fn d() -> f64 { x[0] } };", "negative index -1: indices start at 0"),
        ("static y: [Coordinate; 2] = [Coordinate {}; 3];", "the initializer has 3 elements, the array 2"),
        ("static y: [Coordinate; 2] = from_fn(|i| Coordinate { q0: if x == 0 { 1.0 } else { 0.0 } });", "`x` is not a `usize` constant or a loop variable"),
        ("const _: () = for i in 0..N { let a = 1.0; };", "a loop declares `static` items"),
        ("const M: usize = N - 4;", "a `usize` constant is not negative (-1)"),
    ];
    for (item, expected) in cases {
        one_error(&format!("mod m {{ {head} {item} }}"), expected);
    }
}
