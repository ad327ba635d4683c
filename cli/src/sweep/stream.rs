//! Running a sweep as a stream of rows, whole or one shard of it.
//!
//! Variants are taken in blocks of [`BLOCK`]: a block's variants are drawn
//! in variant order, evaluated on all cores (rayon), and its rows written
//! in variant order before the next block starts. Memory is one block's
//! rows whatever the number of variants, and each row is the same bytes
//! for any thread count (a variant's values are fixed before the parallel
//! part, its metrics depend on nothing else).
//!
//! `--shard K/N` (K in 1..=N) runs variants `floor((K-1) n / N)` up to
//! `floor(K n / N)` of the `n`: contiguous ranges that cover every variant
//! once, in order. The generator's draws of the variants before the
//! shard's start are replayed ([`super::Sweep::variants_in`]), so a
//! shard's rows are the single run's, and only shard 1 writes the header:
//! the shards' outputs concatenated in K order are the single run's output
//! byte for byte.
//!
//! Every row has an `error` cell (empty when the variant was evaluated):
//! a stream cannot add the column when the first failure comes.

use super::{Progress, Sweep, cache::Shared, evaluate_with, metric_columns, with_value};
use crate::csv::error_cell;
use crate::error::CliError;
use crate::units::Units;
use rayon::prelude::*;
use std::io::Write;

/// Variants evaluated (and rows held) at a time.
pub const BLOCK: usize = 4096;

/// One shard of a sweep: `index` of `count`, 1-based.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// Which shard, `1..=count`.
    pub index: usize,
    /// How many.
    pub count: usize,
}

impl Shard {
    /// Parses `K/N` (whole numbers, `1 <= K <= N`).
    ///
    /// # Errors
    ///
    /// Bad input naming `--shard` and what is wrong.
    pub fn parse(s: &str) -> Result<Shard, CliError> {
        let bad = |why: &str| CliError::Input(format!("--shard: '{s}' {why}"));
        let (k, n) = s.split_once('/').ok_or_else(|| bad("is not of the form K/N"))?;
        let k: usize = k
            .trim()
            .parse()
            .map_err(|_| bad("is not of the form K/N (whole numbers)"))?;
        let n: usize = n
            .trim()
            .parse()
            .map_err(|_| bad("is not of the form K/N (whole numbers)"))?;
        if n == 0 || k == 0 || k > n {
            return Err(bad("needs 1 <= K <= N"));
        }
        Ok(Shard { index: k, count: n })
    }

    /// The variants `start..end` of this shard of `total`.
    pub fn range(self, total: usize) -> std::ops::Range<usize> {
        let at = |k: usize| (k as u128 * total as u128 / self.count as u128) as usize;
        at(self.index - 1)..at(self.index)
    }
}

/// A sweep to stream: what `compensator sweep` in CSV hands the binary's
/// frame to write ([`crate::args::Output::Rows`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Rows {
    /// The sweep.
    pub sweep: Sweep,
    /// Its shard, or all of it.
    pub shard: Option<Shard>,
    /// Units of the metric columns.
    pub units: Units,
}

/// The header line of `sweep`'s output (with its newline).
pub fn header(sweep: &Sweep) -> String {
    let mut header: Vec<String> = vec!["variant".into()];
    header.extend(sweep.parameter_names().iter().map(|s| s.to_string()));
    header.extend(metric_columns(&sweep.metrics, sweep.base.machine.is_some()));
    header.push("error".into());
    header.join(",") + "\n"
}

/// What a stream wrote.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Written {
    /// Rows (variants).
    pub rows: usize,
    /// Of which could not be evaluated.
    pub failed: usize,
    /// The output was closed before the end (a reader such as `head` that
    /// had enough): the rest was not computed.
    pub closed: bool,
}

/// Writes `sweep`'s rows (of `shard`, or all) to `out` as CSV in `units`,
/// one block at a time (module docs).
///
/// # Errors
///
/// Too many variants (bad input); a failed write as [`CliError::Failed`]
/// with the I/O error (a closed pipe is not an error: [`Written::closed`]).
pub fn write(sweep: &Sweep, shard: Option<Shard>, units: Units, out: &mut dyn Write) -> Result<Written, CliError> {
    let total = sweep.variant_count()?;
    let range = shard.map_or(0..total, |s| s.range(total));
    let names = sweep.parameter_names();
    let head = header(sweep);
    let shared = Shared::new(
        &sweep.base,
        sweep.base.estimator.valid_min,
        sweep.base.estimator.valid_max,
        super::monotonicity_samples(&sweep.base),
    );
    let convert = |rows: &str| -> String {
        match units {
            Units::Si => rows.to_string(),
            // Converted with the header naming each column's unit, which
            // is then dropped.
            _ => {
                let text = units.convert_csv(&(head.clone() + rows));
                text.split_once('\n').map_or(String::new(), |(_, r)| r.to_string())
            }
        }
    };
    let mut written = Written::default();
    let put = |out: &mut dyn Write, text: &str, written: &mut Written| match out.write_all(text.as_bytes()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            written.closed = true;
            Ok(())
        }
        r => r.map_err(|e| CliError::Failed(format!("writing the sweep: {e}"))),
    };
    if shard.is_none_or(|s| s.index == 1) {
        put(out, &units.convert_csv(&head), &mut written)?;
    }
    let progress = Progress::new(range.len());
    let mut variants = sweep.variants_in(range.start, range.end)?;
    while !written.closed {
        let block: Vec<(usize, Vec<f64>)> = variants.by_ref().take(BLOCK).collect();
        if block.is_empty() {
            break;
        }
        let rows: Vec<(String, bool)> = block
            .par_iter()
            .map(|(i, values)| {
                let r = row(sweep, &names, &shared, *i, values);
                progress.inc();
                r
            })
            .collect();
        let mut text = String::with_capacity(rows.iter().map(|r| r.0.len()).sum());
        for (line, failed) in &rows {
            text.push_str(line);
            written.rows += 1;
            written.failed += usize::from(*failed);
        }
        put(out, &convert(&text), &mut written)?;
    }
    if !written.closed {
        put(out, "", &mut written)?;
        match out.flush() {
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => written.closed = true,
            r => r.map_err(|e| CliError::Failed(format!("writing the sweep: {e}")))?,
        }
    }
    progress.finish();
    Ok(written)
}

/// Variant `i`'s row (with its newline) and whether it failed.
fn row(sweep: &Sweep, names: &[&'static str], shared: &Shared, i: usize, values: &[f64]) -> (String, bool) {
    let mut raw = sweep.base;
    let mut r = Ok(());
    for (name, &v) in names.iter().zip(values) {
        match with_value(&raw, name, v) {
            Ok(next) => raw = next,
            Err(e) => r = Err(e.to_string()),
        }
    }
    let result = r.and_then(|()| evaluate_with(&raw, &sweep.metrics, shared));
    let mut cells: Vec<String> = vec![i.to_string()];
    cells.extend(values.iter().map(|v| format!("{v}")));
    let failed = match result {
        Ok(metrics) => {
            cells.extend(metrics);
            cells.push(String::new());
            false
        }
        Err(e) => {
            let width = 1 + names.len() + metric_columns(&sweep.metrics, sweep.base.machine.is_some()).len();
            cells.resize(width, String::new());
            cells.push(error_cell(&e));
            true
        }
    };
    (cells.join(",") + "\n", failed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_cover_every_variant_once_in_order() {
        for total in [1usize, 2, 7, 100, 4097, 1_000_003] {
            for count in [1usize, 2, 3, 7, 64, 1000] {
                let mut next = 0;
                for k in 1..=count {
                    let r = Shard { index: k, count }.range(total);
                    assert_eq!(r.start, next, "{total} in {count}: shard {k}");
                    assert!(r.end >= r.start);
                    next = r.end;
                }
                assert_eq!(next, total);
            }
        }
        assert_eq!(Shard::parse("2/5").unwrap(), Shard { index: 2, count: 5 });
        for bad in ["0/5", "6/5", "1/0", "a/2", "3", "1/2/3", "-1/2"] {
            let e = Shard::parse(bad).unwrap_err();
            assert_eq!(e.exit_code(), 2);
            assert!(e.to_string().contains("--shard"), "{e}");
        }
    }
}
