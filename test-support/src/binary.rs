//! The `kapitza` binary run as a user runs it. Cargo names the binary only to the tests of its
//! own package (`CARGO_BIN_EXE_kapitza`), so each test file passes the path in:
//! `const KAPITZA: Binary = Binary(env!("CARGO_BIN_EXE_kapitza"));`.

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Command, Output, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serde_json::Value;

/// The binary at this path. `KAPITZA_PORT` is removed from every run, so a developer's own
/// setting never picks the port of a test.
#[derive(Debug, Clone, Copy)]
pub struct Binary(pub &'static str);

impl Binary {
    fn command(&self, args: &[&str]) -> Command {
        let mut c = Command::new(self.0);
        c.args(args).env_remove("KAPITZA_PORT");
        c
    }

    /// Runs it to the end.
    pub fn run(&self, args: &[&str]) -> Output {
        self.command(args).output().unwrap()
    }

    /// Runs it with `env` set and `dir` as its working folder (`None`: this one), stdin empty;
    /// `None` when it has not ended by `deadline` (it is then killed): a hang, which the
    /// caller fails on.
    pub fn run_within(
        &self,
        args: &[&str],
        env: &[(&str, &str)],
        dir: Option<&std::path::Path>,
        deadline: Duration,
    ) -> Option<Output> {
        let mut c = self.command(args);
        c.envs(env.iter().copied())
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        if let Some(d) = dir {
            c.current_dir(d);
        }
        let mut child = c.spawn().unwrap();
        let drain = |r: Option<Box<dyn Read + Send>>| {
            std::thread::spawn(move || {
                let mut v = Vec::new();
                if let Some(mut r) = r {
                    let _ = r.read_to_end(&mut v);
                }
                v
            })
        };
        let out = drain(
            child
                .stdout
                .take()
                .map(|s| Box::new(s) as Box<dyn Read + Send>),
        );
        let err = drain(
            child
                .stderr
                .take()
                .map(|s| Box::new(s) as Box<dyn Read + Send>),
        );
        let end = Instant::now() + deadline;
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            if Instant::now() >= end {
                let _ = child.kill();
                let _ = child.wait();
                return None;
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        Some(Output {
            status,
            stdout: out.join().unwrap(),
            stderr: err.join().unwrap(),
        })
    }

    /// Starts it and reads its first line of stdout (a served rig's device path, an owner's
    /// "attached …"); the rest is collected until it ends.
    pub fn start(&self, args: &[&str]) -> Running {
        let mut child = self
            .command(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let mut out = BufReader::new(child.stdout.take().unwrap());
        let mut first_line = String::new();
        out.read_line(&mut first_line).unwrap();
        let rest = std::thread::spawn(move || {
            let mut s = String::new();
            let _ = out.read_to_string(&mut s);
            s
        });
        Running {
            child,
            first_line: first_line.trim().to_string(),
            rest,
        }
    }

    /// `kapitza rig serve --speed SPEED EXTRA…`: a simulated rig on a pseudo-terminal, whose
    /// device path is `first_line`.
    pub fn serve(&self, speed: &str, extra: &[&str]) -> Running {
        let mut args = vec!["rig", "serve", "--speed", speed];
        args.extend_from_slice(extra);
        let r = self.start(&args);
        assert!(
            r.first_line.starts_with('/'),
            "device path: {:?}",
            r.first_line
        );
        r
    }
}

/// A running `kapitza` whose first stdout line has been read; Ctrl-C'd, then killed, when
/// dropped.
pub struct Running {
    child: Child,
    pub first_line: String,
    rest: JoinHandle<String>,
}

impl Running {
    fn sigint(&self) {
        // SAFETY: kill(2) on our own child's pid.
        unsafe { libc::kill(self.child.id() as i32, libc::SIGINT) };
    }

    /// Stops it (SIGINT, as Ctrl-C) and returns what it printed after the first line.
    pub fn interrupt(mut self) -> String {
        self.sigint();
        let _ = self.child.wait();
        std::mem::replace(&mut self.rest, std::thread::spawn(String::new))
            .join()
            .unwrap()
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        interrupt_then_kill(&mut self.child);
    }
}

/// Ends a child that may still run: Ctrl-C first, so a server removes its symlink and an owner
/// its socket; a kill after 2 s.
pub fn interrupt_then_kill(child: &mut Child) {
    if let Ok(Some(_)) = child.try_wait() {
        return;
    }
    // SAFETY: kill(2) on our own child's pid.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let deadline = Instant::now() + Duration::from_secs(2);
    while Instant::now() < deadline {
        if let Ok(Some(_)) = child.try_wait() {
            return;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let _ = child.kill();
    let _ = child.wait();
}

/// Its stdout as JSON, or a panic showing both streams.
pub fn json(o: &Output) -> Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}\n{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        )
    })
}
