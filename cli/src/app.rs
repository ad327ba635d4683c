//! The binary's frame around the commands: parsing the command line, the
//! one error path (clap's own message with its suggestions, or a
//! command's [`CliError`], one or two lines on standard error, exit status
//! 2 for bad input and 1 for a failed computation), and writing the
//! output (rendered tables, `-o FILE`, a closed pipe).

use crate::args::Output;
use crate::commands::{Cli, Command};
use crate::error::CliError;
use clap::Parser;
use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

/// What the command writes and its rows that could not be computed
/// (failed, total).
fn run(command: Command, path: Option<&Path>) -> Result<(usize, usize), CliError> {
    let (out, failed) = match command.run()? {
        Output::Table { csv, format, units } => {
            let failed = crate::csv::failed_rows(&csv);
            (crate::csv::render(&units.convert_csv(&csv), format), failed)
        }
        Output::Text(text) => (text, (0, 0)),
        Output::Rows(rows) => return write_rows(&rows, path),
    };
    write_output(&out, path).map(|()| failed)
}

/// Streams a sweep's rows ([`crate::sweep::stream::write`]) to standard
/// output or, through `FILE.partial` renamed once complete, to `path`.
/// A closed pipe ends quietly. Returns the failed and total rows.
fn write_rows(rows: &crate::sweep::stream::Rows, path: Option<&Path>) -> Result<(usize, usize), CliError> {
    use crate::sweep::stream::write;
    let written = match path {
        Some(path) => {
            let partial = std::path::PathBuf::from(format!("{}.partial", path.display()));
            let file = std::fs::File::create(&partial)
                .map_err(|e| CliError::Input(format!("--output: {}: {e}", partial.display())))?;
            let mut w = std::io::BufWriter::new(file);
            let written = write(&rows.sweep, rows.shard, rows.units, &mut w).inspect_err(|_| {
                let _ = std::fs::remove_file(&partial);
            })?;
            drop(w);
            std::fs::rename(&partial, path)
                .map_err(|e| CliError::Input(format!("--output: {}: {e}", path.display())))?;
            written
        }
        None => {
            let mut w = std::io::BufWriter::new(std::io::stdout().lock());
            write(&rows.sweep, rows.shard, rows.units, &mut w)?
        }
    };
    Ok(if written.closed {
        (0, 0)
    } else {
        (written.failed, written.rows)
    })
}

/// Writes the output to `path` or standard output. A closed pipe on
/// standard output (`| head`) ends quietly: `Ok(())`.
fn write_output(out: &str, path: Option<&Path>) -> Result<(), CliError> {
    match path {
        Some(path) => {
            std::fs::write(path, out).map_err(|e| CliError::Input(format!("--output: {}: {e}", path.display())))
        }
        None => {
            let mut stdout = std::io::stdout().lock();
            match stdout.write_all(out.as_bytes()).and_then(|()| stdout.flush()) {
                Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                    Err(CliError::Failed(format!("standard output: {e}")))
                }
                _ => Ok(()),
            }
        }
    }
}

/// The message of a command-line error in at most two lines, from clap's
/// own rendering: the problem with what it lists (the missing arguments,
/// the values allowed) on the first line, then clap's tips (the nearest
/// subcommand, flag or value: "a similar argument exists") or, without a
/// tip, the usage line that shows what the command takes.
pub fn clap_message(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let mut problem = String::new();
    let mut tips: Vec<String> = Vec::new();
    let mut usage = None;
    for line in text.lines().map(str::trim_end).filter(|l| !l.trim().is_empty()) {
        let t = line.trim_start();
        if t.starts_with("For more information, try") {
            continue;
        } else if let Some(u) = t.strip_prefix("Usage: ") {
            usage.get_or_insert(u);
        } else if t.starts_with("tip: ") {
            tips.push(t.to_string());
        } else if usage.is_none() {
            if !problem.is_empty() {
                problem.push(' ');
            }
            problem.push_str(t);
        }
    }
    if let Some(tip) = taken_elsewhere(e) {
        tips.insert(0, tip);
    }
    match (tips.is_empty(), usage) {
        (false, _) => format!("{problem}\n  {}", tips.join("; ")),
        (true, Some(u)) => format!("{problem}\n  usage: {u}"),
        (true, None) => problem,
    }
}

/// For an option a command does not take but others do (`paper
/// --format`), which commands take it, from their definitions.
fn taken_elsewhere(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() != ErrorKind::UnknownArgument {
        return None;
    }
    let Some(ContextValue::String(arg)) = e.get(ContextKind::InvalidArg) else {
        return None;
    };
    let long = arg.strip_prefix("--")?.split('=').next()?;
    let takers: Vec<String> = crate::commands::command()
        .get_subcommands()
        .filter(|c| c.get_arguments().any(|a| a.get_long() == Some(long)))
        .map(|c| c.get_name().to_string())
        .collect();
    (!takers.is_empty()).then(|| format!("tip: --{long} is taken by {}", takers.join(", ")))
}

/// The program: parses the arguments, runs the command, writes its output.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                return if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                    ExitCode::from(2)
                } else {
                    ExitCode::SUCCESS
                };
            }
            let _ = writeln!(std::io::stderr(), "{}", clap_message(&e));
            return ExitCode::from(2);
        }
    };
    let output = cli.output.clone();
    match run(cli.command, output.as_deref()) {
        Ok((0, _)) => ExitCode::SUCCESS,
        Ok((failed, total)) => {
            let _ = writeln!(
                std::io::stderr(),
                "error: {failed} of {total} rows could not be computed (their error column says why)"
            );
            ExitCode::from(1)
        }
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
