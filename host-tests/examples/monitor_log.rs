//! A log for `compensator estimate` and `compensator monitor`
//! (`host_tests::monitor_log`): a seeded device of a parameter file with
//! its second sensor, a fault injected.
//!
//!     cargo run --release -p host-tests --example monitor_log -- [PARAMS.toml LOG.csv [fault] [seed]]
//!
//! Without arguments it writes `data/logs/monitor-capillary.csv`, the log
//! `docs/monitoring.md` runs, and its first second in bar,
//! `data/logs/monitor-capillary-bar.csv`. Otherwise: `PARAMS.toml` a device file with a
//! `[monitor]` section, whose sensor's quantity names the column; `fault`
//! as `campaign_data` takes it (default `capillary:0.8`); `seed` (default
//! 11). The history and the onset are the documented log's
//! (`Spec::DOCUMENTED`: 60 C, cooling at 0.1 C/s from the onset at 20 s,
//! 60 s, the second sensor at 100 Hz).

use host_tests::campaign::Fault;
use host_tests::monitor_log::{DOCUMENTED_BAR_LOG, DOCUMENTED_LOG, Spec, documented, in_bar, log};

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (text, out) = match (args.first(), args.get(1)) {
        (None, _) => {
            let text = documented()?;
            let bar = host_tests::repo_root().join(DOCUMENTED_BAR_LOG);
            std::fs::write(&bar, in_bar(&text, 1.0)).map_err(|e| format!("{}: {e}", bar.display()))?;
            (text, host_tests::repo_root().join(DOCUMENTED_LOG))
        }
        (Some(params), Some(out)) => {
            let raw = compensator_cli::load(std::path::Path::new(params)).map_err(|e| format!("{params}: {e}"))?;
            let spec = Spec {
                fault: Fault::parse(args.get(2).map_or("capillary:0.8", String::as_str))?,
                seed: args
                    .get(3)
                    .map_or(Ok(11), |s| s.parse())
                    .map_err(|_| "seed: a whole number")?,
                ..Spec::DOCUMENTED
            };
            (log(&raw, &spec)?.0, std::path::PathBuf::from(out))
        }
        _ => return Err("usage: monitor_log [PARAMS.toml LOG.csv [fault] [seed]]".into()),
    };
    std::fs::write(&out, &text).map_err(|e| format!("{}: {e}", out.display()))?;
    eprintln!("monitor_log: {} rows to {}", text.lines().count() - 1, out.display());
    Ok(())
}
