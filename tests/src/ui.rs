//! Compile-fail cases of `#[mechanism]`: each file under `tests/ui/` is a model with a
//! user error, and its `.stderr` is the diagnostic the user sees (message and span).

#[test]
fn diagnostics() {
    let t = trybuild::TestCases::new();
    t.compile_fail("ui/*.rs");
}
