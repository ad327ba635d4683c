//! `compensator`: the host command-line tool (`compensator_cli::app`).
//!
//! Reads the parameter file of `docs/model.md` section 8, writes CSV with a header
//! row in SI units (`--units eng`: mm, bar, L/min). Bad input exits with status 2
//! and one or two lines on stderr naming the field or argument; nothing is written
//! to stdout then. A table some of whose rows could not be computed is written
//! with its `error` column filled, then the status is 1.

fn main() -> std::process::ExitCode {
    compensator_cli::app::main()
}
