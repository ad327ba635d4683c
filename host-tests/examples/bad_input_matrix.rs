//! The parameter file's field table and bad-input matrix, as markdown.
//!
//! `cargo run -p host-tests --example bad_input_matrix` prints both tables;
//! with `-- --write` it rewrites their blocks in `docs/parameters.md`
//! (which `host-tests/tests/bad_input_matrix.rs` checks are current).

use clap::Parser;
use host_tests::matrix::{generated_blocks, with_blocks};

/// The parameter file's field table and bad-input matrix, as markdown.
#[derive(Parser)]
struct Args {
    /// Rewrite the tables' blocks in docs/parameters.md instead of printing
    /// them.
    #[arg(long)]
    write: bool,
}

fn main() {
    let args = Args::parse();
    let blocks = generated_blocks();
    if args.write {
        let path = host_tests::repo_root().join("docs/parameters.md");
        let doc = std::fs::read_to_string(&path).expect("docs/parameters.md");
        let new = with_blocks(&doc, &blocks).expect("docs/parameters.md has the GENERATED markers");
        std::fs::write(&path, new).expect("docs/parameters.md written");
        eprintln!("{} updated", path.display());
    } else {
        for (name, content) in &blocks {
            println!("<!-- {name} -->\n{content}");
        }
    }
}
