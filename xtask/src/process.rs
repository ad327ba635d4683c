//! Running commands with a deadline: nothing xtask starts can hang it.

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Output of a finished command.
pub struct Output {
    /// Exit code (`None`: killed by a signal or by the deadline).
    pub code: Option<i32>,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
    /// The deadline passed and the command was killed.
    pub timed_out: bool,
}

impl Output {
    /// Exit code 0 within the deadline.
    pub fn ok(&self) -> bool {
        self.code == Some(0) && !self.timed_out
    }
}

/// Runs `cmd` capturing its output; kills it after `timeout`. A command that
/// cannot be started gives `code: None` and the reason in `stderr`.
pub fn capture(cmd: &mut Command, timeout: Duration) -> Output {
    cmd.stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped());
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => {
            return Output {
                code: None,
                stdout: String::new(),
                stderr: e.to_string(),
                timed_out: false,
            };
        }
    };
    let mut out = child.stdout.take().expect("piped");
    let mut err = child.stderr.take().expect("piped");
    let t_out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let t_err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });
    let deadline = Instant::now() + timeout;
    let mut timed_out = false;
    let status = loop {
        match child.try_wait() {
            Ok(Some(st)) => break Some(st),
            Ok(None) if Instant::now() >= deadline => {
                timed_out = true;
                kill_tree(&mut child);
                break child.wait().ok();
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(20)),
            Err(_) => break None,
        }
    };
    Output {
        // A command killed at the deadline has no exit code of its own.
        code: if timed_out { None } else { status.and_then(|s| s.code()) },
        stdout: t_out.join().unwrap_or_default(),
        stderr: t_err.join().unwrap_or_default(),
        timed_out,
    }
}

/// Runs `cmd` capturing its standard output only (standard error goes to
/// the terminal: compiler diagnostics stay visible); kills it after
/// `timeout`.
pub fn capture_stdout(cmd: &mut Command, timeout: Duration) -> Output {
    cmd.stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::inherit());
    let mut child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => {
            return Output {
                code: None,
                stdout: String::new(),
                stderr: e.to_string(),
                timed_out: false,
            };
        }
    };
    let mut out = child.stdout.take().expect("piped");
    let t_out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let deadline = Instant::now() + timeout;
    let mut timed_out = false;
    let status = loop {
        match child.try_wait() {
            Ok(Some(st)) => break Some(st),
            Ok(None) if Instant::now() >= deadline => {
                timed_out = true;
                eprintln!(
                    "xtask: {:?} did not finish within {timeout:?}; killed",
                    cmd.get_program()
                );
                kill_tree(&mut child);
                break child.wait().ok();
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(20)),
            Err(_) => break None,
        }
    };
    Output {
        code: if timed_out { None } else { status.and_then(|s| s.code()) },
        stdout: t_out.join().unwrap_or_default(),
        stderr: String::new(),
        timed_out,
    }
}

/// Runs `cmd` with inherited output; kills it after `timeout`. Returns the
/// exit code (`None` on a signal, a start failure, or the deadline).
pub fn run(cmd: &mut Command, timeout: Duration) -> Option<i32> {
    let mut child = cmd.stdin(Stdio::null()).spawn().ok()?;
    let deadline = Instant::now() + timeout;
    loop {
        match child.try_wait() {
            Ok(Some(st)) => return st.code(),
            Ok(None) if Instant::now() >= deadline => {
                eprintln!(
                    "xtask: {:?} did not finish within {timeout:?}; killed",
                    cmd.get_program()
                );
                kill_tree(&mut child);
                let _ = child.wait();
                return None;
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(50)),
            Err(_) => return None,
        }
    }
}

/// Kills `child` and every process descended from it (cargo's rustc,
/// apt-get's dpkg...), so that a deadline leaves nothing running and no
/// pipe held open. The descendants come from `/proc` (Linux); elsewhere
/// only the child is killed. They stay in xtask's process group, so a
/// Ctrl-C at the terminal still reaches all of them.
pub fn kill_tree(child: &mut std::process::Child) {
    let mut tree = vec![child.id()];
    let parents = parent_ids();
    let mut i = 0;
    while i < tree.len() {
        let p = tree[i];
        tree.extend(parents.iter().filter(|(_, pp)| *pp == p).map(|(pid, _)| *pid));
        i += 1;
    }
    // The child first, so that it cannot react to its children's deaths.
    let _ = child.kill();
    if tree.len() > 1 {
        let mut kill = Command::new("kill");
        kill.arg("-KILL").args(tree[1..].iter().map(u32::to_string));
        let _ = kill.stdout(Stdio::null()).stderr(Stdio::null()).status();
    }
}

/// `(pid, parent pid)` of every process in `/proc` (empty elsewhere).
fn parent_ids() -> Vec<(u32, u32)> {
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    dir.filter_map(|e| {
        let pid: u32 = e.ok()?.file_name().to_str()?.parse().ok()?;
        let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
        // "pid (comm) state ppid ...": comm may hold spaces and parentheses.
        let after = &stat[stat.rfind(')')? + 1..];
        let ppid = after.split_whitespace().nth(1)?.parse().ok()?;
        Some((pid, ppid))
    })
    .collect()
}

/// `true` when running as root (may install packages).
pub fn is_root() -> bool {
    capture(Command::new("id").arg("-u"), Duration::from_secs(5))
        .stdout
        .trim()
        == "0"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_deadline_kills_the_grandchildren_too() {
        // The shell's background child holds the output pipe: without the
        // tree kill, reading the output would wait out its 60 s.
        let t0 = Instant::now();
        let out = capture(
            Command::new("sh").args(["-c", "sleep 60 & sleep 60"]),
            Duration::from_millis(300),
        );
        assert!(
            out.timed_out && out.code.is_none(),
            "code {:?}, timed out {}, stderr {:?}",
            out.code,
            out.timed_out,
            out.stderr
        );
        assert!(t0.elapsed() < Duration::from_secs(20), "{:?}", t0.elapsed());
    }
}
