//! Writes the spatial N-link chain `chain10` into `OUT_DIR`, from the one template
//! `src/chain/source.rs` with `N` substituted; `src/lib.rs` includes it. (`chain100`
//! expands in under a second, but rustc needs minutes for its 2 MB of straight-line
//! code, so it is not built with the crate yet.)

use std::path::PathBuf;

#[path = "src/chain/source.rs"]
mod source;

fn main() {
    println!("cargo:rerun-if-changed=src/chain/source.rs");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let (name, n) = ("chain10", 10);
    std::fs::write(
        out.join(format!("{name}.rs")),
        source::chain_source(name, n),
    )
    .expect("OUT_DIR is writable");
}
