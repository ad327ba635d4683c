//! Writes the documented probe log, `data/logs/probe-warm-up.csv`
//! (`host_tests::board::warm_up_log`: a simulated board with the paper
//! preset over a warm-up), which `compensator estimate` replays in the
//! docs; `cargo test -p host-tests --test cli_estimate` checks that the
//! committed file is what this writes.
//!
//!     cargo run -p host-tests --example probe_log

fn main() {
    let root = host_tests::repo_root();
    let raw = compensator_cli::load(&root.join("presets/paper.toml")).expect("paper preset");
    let text = host_tests::board::warm_up_log(&raw).expect("the run");
    let path = root.join(host_tests::board::WARM_UP_LOG);
    std::fs::create_dir_all(path.parent().expect("a folder")).expect("data/logs");
    std::fs::write(&path, text).expect("written");
    println!("wrote {}", path.display());
}
