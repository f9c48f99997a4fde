//! Writes the spatial N-link chains `chain10` and `chain100` into `OUT_DIR`, from the
//! one template `src/chain/source.rs` with `N` substituted; `src/lib.rs` includes them.

use std::path::PathBuf;

#[path = "src/chain/source.rs"]
mod source;

fn main() {
    println!("cargo:rerun-if-changed=src/chain/source.rs");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    for (name, n) in [("chain10", 10), ("chain100", 100)] {
        std::fs::write(
            out.join(format!("{name}.rs")),
            source::chain_source(name, n),
        )
        .expect("OUT_DIR is writable");
    }
}
