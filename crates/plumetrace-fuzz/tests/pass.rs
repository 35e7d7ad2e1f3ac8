//! The parent of a pass survives children that abort or hang: it records the input that killed
//! each child (`abort`, `hang`), writes it out as a finding, restarts after it and finishes the
//! range. The children are made to abort and hang by the harness's self-test variable.

use std::process::Command;

#[test]
fn a_pass_survives_an_abort_and_a_hang() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let run = Command::new(env!("CARGO_BIN_EXE_plumetrace-fuzz"))
        .args(["pass", "--inputs", "12", "--jobs", "2", "--chunk", "6"])
        .args(["--timeout-s", "1", "--memory-mb", "2048", "--out"])
        .arg(out.path())
        .env("PLUMETRACE_FUZZ_SELFTEST", "abort:3,hang:8")
        .output()
        .expect("running plumetrace-fuzz");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert_eq!(
        run.status.code(),
        Some(1),
        "findings give exit status 1\n{stdout}"
    );
    let report: serde_json::Value = serde_json::from_str(&stdout).expect("a JSON report");
    assert_eq!(report["inputs"], 12, "{report}");
    assert_eq!(report["counts"]["abort"], 1, "{report}");
    assert_eq!(report["counts"]["hang"], 1, "{report}");
    assert_eq!(report["examples"]["abort"][0]["index"], 3, "{report}");
    assert_eq!(report["examples"]["hang"][0]["index"], 8, "{report}");
    let findings = out.path().join("findings");
    assert!(findings.join("abort/3.txt").exists());
    assert!(findings.join("hang/8.txt").exists());
    let message = std::fs::read_to_string(findings.join("abort/3.txt")).unwrap_or_default();
    assert!(message.contains("signal 6"), "{message}");
}

#[test]
fn one_replays_an_input() {
    let run = Command::new(env!("CARGO_BIN_EXE_plumetrace-fuzz"))
        .args(["one", "--index", "0", "--seed", "1"])
        .output()
        .expect("running plumetrace-fuzz");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.starts_with("input 0 of seed 1:"), "{stdout}");
    assert!(stdout.contains("\nresult: "), "{stdout}");
}
