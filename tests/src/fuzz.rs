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

use proc_macro2::{Delimiter, Group, Literal, Punct, Spacing, TokenStream, TokenTree};
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
    // `chain100` (700 coordinates, a scaling model) expands in about a second: a mutated
    // copy can pass the budget by its size alone; `chain10` has the same structure.
    let mut out: Vec<_> = crate::sources::model_sources()
        .into_iter()
        .filter(|(name, _)| name != "chain100")
        .collect();
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

/// The brace groups directly inside the module's body: function bodies and
/// `Coordinate { .. }` literals, where the expressions are.
fn bodies(module: &TokenStream) -> Vec<Group> {
    let Some(TokenTree::Group(body)) = module
        .clone()
        .into_iter()
        .filter(|tt| matches!(tt, TokenTree::Group(g) if g.delimiter() == Delimiter::Brace))
        .last()
    else {
        return Vec::new();
    };
    body.stream()
        .into_iter()
        .filter_map(|tt| match tt {
            TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => Some(g),
            _ => None,
        })
        .collect()
}

/// Every identifier of the corpus's expressions (names, methods), deduplicated.
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
        for g in bodies(ts) {
            walk(&g.stream(), &mut out);
        }
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
    // Weighted towards mutations that keep the expression well-formed, so that a good
    // share of the cases reaches the derivation and the emitter.
    match rng.next_u64() % 20 {
        0..=4 => {
            // A number where there was one: an extreme value.
            if let TokenTree::Literal(_) = &list[k] {
                let lit: TokenStream = NUMBERS[pick(rng, NUMBERS.len())].parse().unwrap();
                list[k] = lit.into_iter().next().unwrap();
            }
        }
        5..=7 => {
            if let TokenTree::Ident(_) = &list[k] {
                let name = &names[pick(rng, names.len())];
                if let Ok(ts) = name.parse::<TokenStream>() {
                    if let Some(tt) = ts.into_iter().next() {
                        list[k] = tt;
                    }
                }
            }
        }
        8..=10 => {
            if let TokenTree::Punct(p) = &list[k] {
                if OPERATORS.contains(&p.as_char()) && p.spacing() == Spacing::Alone {
                    let op = OPERATORS[pick(rng, OPERATORS.len())];
                    list[k] = TokenTree::Punct(Punct::new(op, Spacing::Alone));
                }
            }
        }
        11 => {
            list.remove(k);
        }
        12 => {
            let tt = list[k].clone();
            list.insert(k, tt);
        }
        13 if k + 1 < list.len() => list.swap(k, k + 1),
        14..=16 => {
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

/// The depth-first index (as counted by [`mutate`]) of a random token tree inside a
/// random expression group of `ts` (see [`bodies`]).
fn expression_tree(ts: &TokenStream, rng: &mut Rng) -> Option<usize> {
    let groups = bodies(ts);
    if groups.is_empty() {
        return None;
    }
    let chosen = &groups[(rng.next_u64() % groups.len() as u64) as usize];
    let inside = count(&chosen.stream());
    if inside == 0 {
        return None;
    }
    // Find the chosen group's own index by walking the stream like `mutate` does.
    fn find(ts: &TokenStream, target: &Group, index: &mut usize) -> Option<usize> {
        for tt in ts.clone() {
            let here = *index;
            *index += 1;
            if let TokenTree::Group(g) = &tt {
                if g.delimiter() == target.delimiter()
                    && g.span().start() == target.span().start()
                    && g.stream().to_string() == target.stream().to_string()
                {
                    return Some(here);
                }
                if let Some(k) = find(&g.stream(), target, index) {
                    return Some(k);
                }
            }
        }
        None
    }
    let start = find(ts, chosen, &mut 0)?;
    Some(start + 1 + (rng.next_u64() % inside as u64) as usize)
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

/// Checks one case; the error says what failed. `Ok(true)` when the case expanded to a
/// model (no `compile_error!`).
fn check(input: &TokenStream) -> Result<bool, String> {
    let (out, took) = expand(input);
    let out = out.map_err(|panic| format!("the generator panicked: {panic}"))?;
    if took > BUDGET {
        return Err(format!("expansion took {took:?}, more than {BUDGET:?}"));
    }
    let file = syn::parse2::<syn::File>(out.clone())
        .map_err(|e| format!("the expansion does not parse ({e}): {out}"))?;
    if unexplained(&out) {
        return Err("the generator stopped without a diagnostic".to_owned());
    }
    let error = file.items.iter().any(|item| {
        matches!(item, syn::Item::Macro(m) if m.mac.path.segments.last().is_some_and(|s| s.ident == "compile_error"))
    });
    Ok(!error)
}

/// Whether an expansion reports a derivation that stopped without recording why
/// ([`pfaff_codegen::UNEXPLAINED`]): a defect of the generator, as a panic is.
fn unexplained(out: &TokenStream) -> bool {
    out.to_string().contains(pfaff_codegen::UNEXPLAINED)
}

/// Runs cases from `seed` until `cases` are done or `time` has passed; returns the
/// number run and how many of them expanded to a model.
fn run(seed: u64, cases: u64, time: Duration) -> (u64, u64) {
    let corpus = corpus();
    assert!(corpus.len() > 10, "corpus of {} modules", corpus.len());
    let names = identifiers(&corpus);
    let mut rng = Rng::new(seed);
    let start = Instant::now();
    let (mut done, mut models) = (0, 0);
    while done < cases && start.elapsed() < time {
        let (origin, base) = &corpus[(rng.next_u64() % corpus.len() as u64) as usize];
        let mut ts = base.clone();
        for _ in 0..=rng.next_u64() % MAX_MUTATIONS {
            let n = count(&ts);
            if n == 0 || n > 4 * count(base) + 64 {
                break;
            }
            // Mostly inside the expressions; sometimes anywhere (the item structure).
            let mut target = if rng.next_u64() % 8 == 0 {
                (rng.next_u64() % n as u64) as usize
            } else {
                match expression_tree(&ts, &mut rng) {
                    Some(k) => k,
                    None => continue,
                }
            };
            ts = mutate(&ts, &mut target, &mut rng, &names);
        }
        match check(&ts) {
            Ok(model) => models += u64::from(model),
            Err(e) => panic!("seed {seed}, case {done} (from `{origin}`): {e}\ninput: {ts}"),
        }
        done += 1;
    }
    (done, models)
}

/// The unmutated corpus expands within the budget and parses.
#[test]
fn corpus_expands() {
    let corpus = corpus();
    for (name, ts) in &corpus {
        check(ts).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    // The built-in models expand to models.
    for (name, ts) in crate::sources::model_sources() {
        assert_eq!(check(&ts), Ok(true), "{name}");
    }
    // Both sources are represented.
    assert!(corpus.iter().any(|(n, _)| n == "andrews"));
    assert!(corpus.iter().any(|(n, _)| n == "kinetic_not_quadratic"));
}

/// The generator's report of a stop without a diagnostic is recognized in its
/// expansion (the message survives the literal's escaping), and an ordinary error is
/// not taken for it.
#[test]
fn a_stop_without_a_diagnostic_is_recognized() {
    let span = proc_macro2::Span::call_site();
    let defect = syn::Error::new(span, pfaff_codegen::UNEXPLAINED).to_compile_error();
    assert!(unexplained(&defect));
    let ordinary = syn::Error::new(span, "unknown coordinate `x`").to_compile_error();
    assert!(!unexplained(&ordinary));
}

/// A few hundred mutated cases with a fixed seed, with every test run.
#[test]
fn smoke() {
    let (done, models) = run(0x5EED, 300, Duration::from_secs(60));
    assert_eq!(done, 300);
    // The mutations keep a share of the cases valid, which reach every stage (half
    // the corpus are compile-fail cases, invalid by design).
    assert!(models > 15, "{models} of {done} cases expanded to a model");
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
    let (done, models) = run(seed, u64::MAX, Duration::from_secs(seconds));
    println!(
        "fuzz: {done} cases ({models} expanded to a model) in {seconds} s from seed {seed}, no failure"
    );
    assert!(done > 0);
}
