//! Writes the seed corpus, `fuzz/corpus/<target>/seed-<name>`
//! (`compensator_fuzz::seeds`), replacing the seeds of the same names.
//!
//! `cargo run --manifest-path fuzz/Cargo.toml --example write_seeds`

use std::path::Path;

fn main() -> std::io::Result<()> {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus");
    for (target, name, bytes) in compensator_fuzz::seeds::all() {
        let dir = corpus.join(target);
        std::fs::create_dir_all(&dir)?;
        std::fs::write(dir.join(format!("seed-{name}")), bytes)?;
    }
    println!("wrote the seeds under {}", corpus.display());
    Ok(())
}
