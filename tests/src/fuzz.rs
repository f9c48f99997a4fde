//! A mutation fuzzer over the description language (issue 9).
//!
//! The corpus is every `#[pfaff::mechanism]` module of the built-in models
//! (`models/src/`) and of the compile-fail cases (`tests/ui/`). A case is a corpus
//! module with a few token-level mutations, drawn from a seeded generator: a number
//! replaced by an extreme one (`0`, `1e308`, `1e-320`, a huge integer), a name by
//! another of the corpus, an operator by another, a token tree deleted, duplicated or
//! swapped with its neighbour, a call such as `.sin()` or `.powi(n)` appended. Each case
//! is expanded by the generator, and
//!
//! - the expansion does not panic;
//! - what it emits parses as a Rust file (a model, or `compile_error!`s and the
//!   fallback module);
//! - it takes at most [`BUDGET`].
//!
//! [`smoke`] runs a few hundred cases with every test run; [`campaign`] runs for
//! `PFAFF_FUZZ_SECONDS` seconds (default 60) with a seed from `PFAFF_FUZZ_SEED`, and is
//! the separate step of `.ci/run`: `cargo test --release -p pfaff-tests fuzz::campaign
//! -- --ignored`. A failure prints the seed, the case number and the mutated source.

use std::path::Path;
use std::time::{Duration, Instant};

use proc_macro2::{Group, Literal, Punct, Spacing, TokenStream, TokenTree};
use quote::{quote, ToTokens};

use crate::accuracy::util::Rng;

/// The longest an expansion may take. The largest built-in model expands in a few
/// milliseconds; a mutation can multiply the work (a nested call, a large power) but
/// the generator's work is near-linear in the size of its graph, so a case beyond this
/// is a bug (a quadratic or exponential path).
const BUDGET: Duration = Duration::from_secs(2);

/// Mutations per case, at most.
const MAX_MUTATIONS: u64 = 4;

/// The corpus: mechanism modules of the model files and of the compile-fail cases.
fn corpus() -> Vec<(String, TokenStream)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut out = crate::sources::model_sources();
    let mut files: Vec<_> = std::fs::read_dir(root.join("tests/ui"))
        .expect("tests/ui exists")
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .collect();
    files.sort();
    for path in files {
        let src = std::fs::read_to_string(&path).expect("readable case");
        // A compile-fail case may not be valid Rust at all: those are skipped.
        let Ok(file) = syn::parse_file(&src) else {
            continue;
        };
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
                m.attrs.remove(at);
                let name = path.file_stem().unwrap().to_string_lossy().into_owned();
                out.push((name, m.into_token_stream()));
            }
        }
    }
    out
}

/// Every identifier of the corpus (names, methods, keywords), deduplicated.
fn identifiers(corpus: &[(String, TokenStream)]) -> Vec<String> {
    fn walk(ts: &TokenStream, out: &mut Vec<String>) {
        for tt in ts.clone() {
            match tt {
                TokenTree::Ident(i) => out.push(i.to_string()),
                TokenTree::Group(g) => walk(&g.stream(), out),
                _ => {}
            }
        }
    }
    let mut out = Vec::new();
    for (_, ts) in corpus {
        walk(ts, &mut out);
    }
    out.sort();
    out.dedup();
    out
}

/// Number of token trees in `ts`, groups and their contents included.
fn count(ts: &TokenStream) -> usize {
    ts.clone()
        .into_iter()
        .map(|tt| match tt {
            TokenTree::Group(g) => 1 + count(&g.stream()),
            _ => 1,
        })
        .sum()
}

const NUMBERS: [&str; 9] = [
    "0",
    "0.0",
    "1e308",
    "1e-320",
    "2147483647",
    "4294967296",
    "1e-300",
    "3",
    "0.5",
];
const OPERATORS: [char; 5] = ['+', '-', '*', '/', '%'];
const CALLS: [&str; 8] = ["sin", "cos", "sqrt", "ln", "exp", "abs", "signum", "atan"];

/// One mutation of the token list `list` at position `k` (of its own level).
fn mutate_at(list: &mut Vec<TokenTree>, k: usize, rng: &mut Rng, names: &[String]) {
    let pick = |rng: &mut Rng, n: usize| (rng.next_u64() % n as u64) as usize;
    match rng.next_u64() % 8 {
        0 => {
            let lit: TokenStream = NUMBERS[pick(rng, NUMBERS.len())].parse().unwrap();
            list[k] = lit.into_iter().next().unwrap();
        }
        1 => {
            let name = &names[pick(rng, names.len())];
            if let Ok(ts) = name.parse::<TokenStream>() {
                if let Some(tt) = ts.into_iter().next() {
                    list[k] = tt;
                }
            }
        }
        2 => {
            let op = OPERATORS[pick(rng, OPERATORS.len())];
            list[k] = TokenTree::Punct(Punct::new(op, Spacing::Alone));
        }
        3 => {
            list.remove(k);
        }
        4 => {
            let tt = list[k].clone();
            list.insert(k, tt);
        }
        5 if k + 1 < list.len() => list.swap(k, k + 1),
        6 => {
            // `.f()` after the tree: `x.sin()`.
            let f = proc_macro2::Ident::new(CALLS[pick(rng, CALLS.len())], list[k].span());
            let call = quote!(. #f ());
            for (i, tt) in call.into_iter().enumerate() {
                list.insert(k + 1 + i, tt);
            }
        }
        _ => {
            // `.powi(n)` after the tree, with n from the extremes.
            let n = [0_i64, 2, 7, 400, -3, 2_147_483_647][pick(rng, 6)];
            let lit = Literal::i64_unsuffixed(n);
            let call = quote!(.powi(#lit));
            for (i, tt) in call.into_iter().enumerate() {
                list.insert(k + 1 + i, tt);
            }
        }
    }
}

/// Applies one mutation at the `target`-th token tree (depth first) of `ts`; returns
/// the new stream and how many trees were visited.
fn mutate(ts: &TokenStream, target: &mut usize, rng: &mut Rng, names: &[String]) -> TokenStream {
    let mut list: Vec<TokenTree> = ts.clone().into_iter().collect();
    let mut k = 0;
    while k < list.len() {
        if *target == 0 {
            mutate_at(&mut list, k, rng, names);
            *target = usize::MAX;
            break;
        }
        *target -= 1;
        if let TokenTree::Group(g) = &list[k] {
            let inner = mutate(&g.stream(), target, rng, names);
            let mut group = Group::new(g.delimiter(), inner);
            group.set_span(g.span());
            list[k] = TokenTree::Group(group);
            if *target == usize::MAX {
                break;
            }
        }
        k += 1;
    }
    list.into_iter().collect()
}

/// The expansion of `input` and how long it took, or the panic message.
fn expand(input: &TokenStream) -> (Result<TokenStream, String>, Duration) {
    let start = Instant::now();
    let input = input.clone();
    let out =
        std::panic::catch_unwind(move || pfaff_codegen::expand(quote!(), input)).map_err(|e| {
            e.downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| (*s).to_owned()))
                .unwrap_or_default()
        });
    (out, start.elapsed())
}

/// Checks one case; the error says what failed.
fn check(input: &TokenStream) -> Result<(), String> {
    let (out, took) = expand(input);
    let out = out.map_err(|panic| format!("the generator panicked: {panic}"))?;
    if took > BUDGET {
        return Err(format!("expansion took {took:?}, more than {BUDGET:?}"));
    }
    syn::parse2::<syn::File>(out.clone())
        .map_err(|e| format!("the expansion does not parse ({e}): {out}"))?;
    Ok(())
}

/// Runs cases from `seed` until `cases` are done or `time` has passed; returns the
/// number run.
fn run(seed: u64, cases: u64, time: Duration) -> u64 {
    let corpus = corpus();
    assert!(corpus.len() > 10, "corpus of {} modules", corpus.len());
    let names = identifiers(&corpus);
    let mut rng = Rng::new(seed);
    let start = Instant::now();
    let mut done = 0;
    while done < cases && start.elapsed() < time {
        let (origin, base) = &corpus[(rng.next_u64() % corpus.len() as u64) as usize];
        let mut ts = base.clone();
        for _ in 0..=rng.next_u64() % MAX_MUTATIONS {
            let n = count(&ts);
            if n == 0 || n > 4 * count(base) + 64 {
                break;
            }
            let mut target = (rng.next_u64() % n as u64) as usize;
            ts = mutate(&ts, &mut target, &mut rng, &names);
        }
        if let Err(e) = check(&ts) {
            panic!("seed {seed}, case {done} (from `{origin}`): {e}\ninput: {ts}");
        }
        done += 1;
    }
    done
}

/// The unmutated corpus expands within the budget and parses.
#[test]
fn corpus_expands() {
    let corpus = corpus();
    for (name, ts) in &corpus {
        check(ts).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    // Both sources are represented.
    assert!(corpus.iter().any(|(n, _)| n == "andrews"));
    assert!(corpus.iter().any(|(n, _)| n == "kinetic_not_quadratic"));
}

/// A few hundred mutated cases with a fixed seed, with every test run.
#[test]
fn smoke() {
    let done = run(0x5EED, 300, Duration::from_secs(60));
    assert_eq!(done, 300);
}

/// The CI campaign (see the module docs).
#[test]
#[ignore = "a long fuzzing run: `.ci/run` runs it as its own step"]
fn campaign() {
    let seconds: u64 = std::env::var("PFAFF_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60);
    let seed: u64 = std::env::var("PFAFF_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(1, |d| d.as_secs())
        });
    let done = run(seed, u64::MAX, Duration::from_secs(seconds));
    println!("fuzz: {done} cases in {seconds} s from seed {seed}, no failure");
    assert!(done > 0);
}
