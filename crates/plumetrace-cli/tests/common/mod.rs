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

/// The `demo` preset's scenario text.
#[allow(dead_code)] // not every test file that shares these helpers needs it
pub fn demo() -> String {
    plumetrace_scenario::find_preset("demo")
        .unwrap()
        .toml
        .to_string()
}
