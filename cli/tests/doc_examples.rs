//! Every `compensator` example of README.md and docs/*.md runs, as written,
//! against the binary: a doc that drifts from the binary fails.
//!
//! * Each command line in a fenced code block (`compensator ...`, or
//!   `$ compensator ...` in a `console` block, `\` continuing a line) runs
//!   in a scratch folder per document, in the document's order (so an
//!   example may read what an earlier one wrote: `step -o step.csv`, then
//!   `identify --data step.csv`), with the repository's `presets/` and
//!   `data/` beside it and `my-device.toml` (the reader's own file; a copy
//!   of `presets/paper.toml`). It must exit 0, unless a `? N` line after it says
//!   which status it must exit with.
//! * In a `console` block the lines after a command, up to the next `$`
//!   line or the end of the block, are its output (standard output, then
//!   standard error), compared by snapbox: `...` on a line of its own
//!   stands for any lines, `[..]` for the rest of a line.
//! * [`FIGURES`]: the figures the prose quotes from a command's output,
//!   each of which must appear in that output.
//! * Each inline `` `compensator ...` `` that is a complete command (no
//!   placeholder such as `F`, `DIR`, `...`) runs too and must exit 0.
//!
//! `cargo test -p compensator-cli --test doc_examples -- --nocapture`
//! prints the counts.

mod common;
use common::{cli, root};
use std::path::{Path, PathBuf};
use std::process::Stdio;

/// Figures quoted in prose, each with the command whose output holds it.
const FIGURES: &[(&str, &[&str])] = &[
    // README.md's figure table and docs/paper.md.
    (
        "compensator paper",
        &[
            "1.3 %",
            "11.1 %",
            "RMS 0.0527 bar, max 0.1262 bar",
            "RMS 0.0051 mm, max 0.0087 mm",
            "t0 =  34.7 C, RMS 0.0064 mm",
            "35.24 C",
            "2.36 kPa/C (max 3.79)",
            "3.85 kPa/C",
        ],
    ),
    (
        "compensator indicators --params presets/paper.toml --format table",
        &["0.042700", "0.005100", "-91.77", "-329.61", "0.000"],
    ),
    // docs/paper.md and docs/plots.md: the plunger's damping ratio.
    (
        "compensator eigen --params presets/paper.toml --temps 30,80 --format table",
        &["8.306", "1.859"],
    ),
    (
        "compensator twin-config --params presets/paper.toml",
        &["sdirk3,1,0.001,26,78,"],
    ),
];

/// One example: the document, its line, the command line, the status it
/// must exit with, its expected output (a `console` block).
#[derive(Debug, Clone)]
struct Example {
    doc: String,
    line: usize,
    command: String,
    status: i32,
    output: Option<String>,
}

/// The documents whose examples are tested.
fn documents() -> Vec<PathBuf> {
    let root = root();
    let mut docs = vec![root.join("README.md")];
    let mut more: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    more.sort();
    docs.extend(more);
    docs
}

/// The examples in the fenced code blocks of `text`.
fn block_examples(doc: &str, text: &str) -> Vec<Example> {
    let mut out: Vec<Example> = Vec::new();
    let mut fence: Option<String> = None;
    let mut block_start = 0;
    let mut lines = text.lines().enumerate();
    while let Some((i, line)) = lines.next() {
        let trimmed = line.trim_start();
        if let Some(info) = trimmed.strip_prefix("```") {
            fence = match fence {
                Some(_) => None,
                None => Some(info.trim().to_string()),
            };
            block_start = out.len();
            continue;
        }
        let Some(info) = &fence else { continue };
        let console = info == "console";
        let command = if console {
            trimmed.strip_prefix("$ ")
        } else {
            Some(trimmed)
        };
        let Some(command) = command.filter(|c| c.starts_with("compensator ")) else {
            let in_block = out.len() > block_start;
            if console
                && in_block
                && let Some(status) = trimmed.strip_prefix("? ")
                && let Some(last) = out.last_mut()
            {
                last.status = status.trim().parse().unwrap();
            } else if console
                && in_block
                && let Some(last) = out.last_mut()
            {
                let o = last.output.as_mut().unwrap();
                o.push_str(line);
                o.push('\n');
            }
            continue;
        };
        let mut command = command.to_string();
        while command.ends_with('\\') {
            command.pop();
            match lines.next() {
                Some((_, next)) => command.push_str(next.trim_start().trim_start_matches("> ")),
                None => break,
            }
        }
        out.push(Example {
            doc: doc.to_string(),
            line: i + 1,
            command: command.split_whitespace().collect::<Vec<_>>().join(" "),
            status: 0,
            output: console.then(String::new),
        });
    }
    out
}

/// Words that mark an inline command as a pattern, not an example.
const PLACEHOLDERS: &[&str] = &[
    "F", "DIR", "C", "S", "N", "...", "FILE", "F.toml", "it.toml", "P.csv", "X.csv",
];

/// Inline `` `compensator ...` `` spans of `text` that are complete commands.
fn inline_examples(doc: &str, text: &str) -> (Vec<Example>, usize) {
    let mut out = Vec::new();
    let mut patterns = 0;
    let mut fenced = false;
    // Spans may wrap onto the next line: join the prose outside fences.
    let mut prose = String::new();
    let mut starts = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            prose.push('\n');
            continue;
        }
        if !fenced {
            starts.push((prose.len(), i + 1));
            prose.push_str(line);
            prose.push(' ');
        }
    }
    let mut rest = prose.as_str();
    let mut offset = 0;
    while let Some(at) = rest.find("`compensator ") {
        let Some(len) = rest[at + 1..].find('`') else { break };
        let span = &rest[at + 1..at + 1 + len];
        let line = starts
            .iter()
            .rev()
            .find(|(o, _)| *o <= offset + at)
            .map_or(0, |(_, l)| *l);
        let words: Vec<&str> = span.split_whitespace().collect();
        let subcommand = words.get(1).copied().unwrap_or("");
        if words.len() < 2
            || !subcommand.chars().all(|c| c.is_ascii_lowercase() || c == '-')
            || words
                .iter()
                .any(|w| PLACEHOLDERS.contains(w) || w.contains('|') || w.contains('['))
            || span.contains("...")
        {
            patterns += 1;
        } else {
            out.push(Example {
                doc: doc.to_string(),
                line,
                command: words.join(" "),
                status: 0,
                output: None,
            });
        }
        offset += at + 2 + len;
        rest = &rest[at + 2 + len..];
    }
    (out, patterns)
}

/// A scratch folder with the repository's presets and data beside it.
fn sandbox(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("compensator-doc-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for d in ["presets", "data"] {
        std::os::unix::fs::symlink(root().join(d), dir.join(d)).unwrap();
    }
    // The reader's own device file of the examples.
    std::fs::copy(root().join("presets/paper.toml"), dir.join("my-device.toml")).unwrap();
    dir
}

/// Runs one example's command line (split like a shell: quotes, `>`,
/// `|` are not used by the examples; a `2>`/`>` redirection becomes `-o`).
fn run(example: &Example, dir: &Path) -> (i32, String) {
    let words: Vec<String> = shlex(&example.command);
    let mut args: Vec<String> = words[1..].to_vec();
    let mut stdout_to = None;
    if let Some(i) = args.iter().position(|a| a == ">") {
        stdout_to = args.get(i + 1).cloned();
        args.truncate(i);
    }
    if let Some(i) = args.iter().position(|a| a == "|" || a == "&&") {
        args.truncate(i);
    }
    let out = cli()
        .current_dir(dir)
        .args(&args)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    if let Some(file) = stdout_to {
        std::fs::write(dir.join(file), &stdout).unwrap();
    }
    let text = format!("{stdout}{}", String::from_utf8_lossy(&out.stderr));
    (out.status.code().unwrap_or(-1), text)
}

/// Splits on white space, keeping quoted words whole.
fn shlex(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut word = String::new();
    let mut quote = None;
    for c in line.chars() {
        match (quote, c) {
            (None, '\'' | '"') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, c) if c.is_whitespace() => {
                if !word.is_empty() {
                    out.push(std::mem::take(&mut word));
                }
            }
            (_, c) => word.push(c),
        }
    }
    if !word.is_empty() {
        out.push(word);
    }
    out
}

#[test]
fn every_documented_command_runs_and_prints_what_the_doc_shows() {
    let mut failures = Vec::new();
    let (mut blocks, mut inline, mut with_output, mut patterns) = (0, 0, 0, 0);
    for path in documents() {
        let text = std::fs::read_to_string(&path).unwrap();
        let doc = path.strip_prefix(root()).unwrap().display().to_string();
        let dir = sandbox(&doc.replace('/', "-"));
        let block = block_examples(&doc, &text);
        let (spans, n) = inline_examples(&doc, &text);
        patterns += n;
        blocks += block.len();
        inline += spans.len();
        for (i, e) in block.iter().chain(&spans).enumerate() {
            let (code, text) = run(e, &dir);
            let at = format!("{}:{}: {}", e.doc, e.line, e.command);
            // An inline mention of a command without its required
            // arguments (`compensator eigen`) names it; it is no example.
            if i >= block.len() && code == 2 && text.contains("required arguments were not provided") {
                inline -= 1;
                patterns += 1;
                continue;
            }
            if code != e.status {
                failures.push(format!("{at}: exit {code}, the doc says {}\n{text}", e.status));
                continue;
            }
            if let Some(expected) = e.output.as_deref().filter(|o| !o.trim().is_empty()) {
                with_output += 1;
                let assert = snapbox::Assert::new().action_env("SNAPSHOTS");
                if let Err(diff) = assert.try_eq(Some(&at), text.into(), expected.to_string().into()) {
                    failures.push(format!("{at}: output differs from the doc\n{diff}"));
                }
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    println!(
        "doc examples: {blocks} in code blocks ({with_output} with their output checked), {inline} inline, \
         {patterns} inline patterns with placeholders not run"
    );
    assert!(
        failures.is_empty(),
        "{} failing:\n{}",
        failures.len(),
        failures.join("\n\n")
    );
    assert!(
        blocks >= 15,
        "{blocks} examples in code blocks: the extractor lost them"
    );
}

#[test]
fn the_figures_the_prose_quotes_are_in_the_output() {
    let dir = sandbox("figures");
    for (command, figures) in FIGURES {
        let e = Example {
            doc: "FIGURES".into(),
            line: 0,
            command: command.to_string(),
            status: 0,
            output: None,
        };
        let (code, text) = run(&e, &dir);
        assert_eq!(code, 0, "{command}: {text}");
        for f in *figures {
            assert!(text.contains(f), "{command}: no '{f}' in\n{text}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
