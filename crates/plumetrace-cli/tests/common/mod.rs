//! Helpers shared by the binary's integration tests.

use std::process::{Command, Output};

/// The built `plumetrace` binary.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_plumetrace"))
}

/// Runs it and fails the test with its standard error unless it succeeds.
pub fn run_ok(args: &[&str]) -> Output {
    let out = bin().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "plumetrace {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}
