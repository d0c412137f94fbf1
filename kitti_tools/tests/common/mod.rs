//! Running the `kitti-tools` binary from the command-line tests.

#![allow(dead_code)] // each test binary uses a subset

use std::process::{Command, Output};

/// Runs `kitti-tools ARGS` and returns its whole output.
pub fn output(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kitti-tools"))
        .args(args)
        .output()
        .expect("run kitti-tools")
}

/// The standard output of a successful run; fails the test with both streams otherwise.
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "stdout: {}\nstderr: {}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs `kitti-tools ARGS`: (success, stdout, stderr).
pub fn run(args: &[&str]) -> (bool, String, String) {
    let out = output(args);
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}
