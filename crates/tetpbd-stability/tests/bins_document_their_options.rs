//! The suite's binaries take `--help`, describing each option, and reject an unknown option or
//! an option missing its value with a message naming it instead of running.

use std::process::{Command, Output};

fn run(bin: &str, args: &[&str]) -> Output {
    Command::new(bin).args(args).output().expect("runs")
}

#[test]
fn every_suite_binary_documents_its_options_and_rejects_bad_ones() {
    let bins = [
        (env!("CARGO_BIN_EXE_stability"), "--out"),
        (env!("CARGO_BIN_EXE_random_scenes"), "--scenes"),
    ];
    for (bin, valued) in bins {
        let help = run(bin, &["--help"]);
        let text = String::from_utf8_lossy(&help.stdout);
        assert!(help.status.success(), "{bin} --help failed");
        assert!(
            text.contains("Usage:") && text.contains(valued),
            "{bin}: {text}"
        );
        for bad in [&["--no-such-option"][..], &[valued][..]] {
            let out = run(bin, bad);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{bin} {bad:?}: {err}");
            assert!(err.contains(bad[0]), "{bin} {bad:?}: message {err}");
        }
    }
}
