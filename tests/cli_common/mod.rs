//! Shared helpers of the command-line tests: run the `parvo` binary this
//! test build made, with or without standard input, and read what it
//! printed.
#![allow(dead_code)]

use std::io::Write;
use std::process::{Command, Output, Stdio};

/// `parvo ARGS`, its output captured.
pub fn parvo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(args)
        .output()
        .expect("run parvo")
}

/// `parvo ARGS` with `stdin` as its standard input.
pub fn parvo_with_input(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_parvo"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run parvo");
    let written = child
        .stdin
        .take()
        .expect("piped stdin")
        .write_all(stdin.as_bytes());
    // A run that refuses its arguments exits before it reads its input;
    // the write then meets a closed pipe, which is not the test's failure
    // (its exit status and messages are).
    if let Err(e) = written {
        assert_eq!(e.kind(), std::io::ErrorKind::BrokenPipe, "write stdin: {e}");
    }
    child.wait_with_output().expect("wait for parvo")
}

/// The standard output of a run that must have succeeded (both streams
/// shown when it did not).
pub fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}
