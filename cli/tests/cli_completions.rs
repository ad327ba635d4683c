//! `completions SHELL` and `man`: non-empty scripts and a man page that
//! name every subcommand.

mod common;
use common::run;

/// Every subcommand, from the binary's own help (so that a new command is
/// checked without editing this list).
fn subcommands() -> Vec<String> {
    let (code, help, _) = run(&["--help"]);
    assert_eq!(code, 0);
    let names: Vec<String> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(String::from))
        .filter(|n| n != "help")
        .collect();
    for expected in ["equilibrium", "step", "report", "sweep", "completions", "man"] {
        assert!(names.iter().any(|n| n == expected), "{names:?}");
    }
    names
}

#[test]
fn every_shell_completes_every_subcommand() {
    let names = subcommands();
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let (code, out, err) = run(&["completions", shell]);
        assert_eq!(code, 0, "{shell}: {err}");
        assert!(out.len() > 1000, "{shell}: {} bytes", out.len());
        for name in &names {
            assert!(out.contains(name.as_str()), "{shell}: no {name}");
        }
    }
    // Options are completed too.
    let (_, bash, _) = run(&["completions", "bash"]);
    assert!(bash.contains("--overlay-reference") && bash.contains("--units"));
    let (code, _, err) = run(&["completions", "tcsh"]);
    assert_eq!(code, 2);
    assert!(err.contains("tcsh"), "{err}");
}

#[test]
fn the_man_page_names_every_subcommand() {
    let (code, out, err) = run(&["man"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.starts_with(".ie") || out.starts_with(".TH") || out.contains("\n.TH "),
        "{}",
        &out[..80]
    );
    assert!(out.contains("compensator"));
    // roff escapes hyphens: compensator\-twin\-config(1).
    let plain = out.replace("\\-", "-");
    let names = subcommands();
    for name in &names {
        assert!(plain.contains(&format!("compensator-{name}(1)")), "no {name}");
    }
    // --dir: one page per subcommand, each with its own options.
    let dir = common::temp_dir("man");
    let (code, _, err) = run(&["man", "--dir", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("compensator.1").exists());
    for name in &names {
        let page = std::fs::read_to_string(dir.join(format!("compensator-{name}.1"))).unwrap();
        assert!(
            page.contains(".SH OPTIONS") || name == "man" || name == "calibrate",
            "{name}"
        );
    }
    let sweep = std::fs::read_to_string(dir.join("compensator-sweep.1")).unwrap();
    assert!(sweep.replace("\\-", "-").contains("--vary"), "{sweep}");
    let _ = std::fs::remove_dir_all(&dir);
}
