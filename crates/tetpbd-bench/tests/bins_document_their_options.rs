//! Every benchmark binary takes `--help`, describing itself and each option, and rejects an
//! unknown option or an option missing its value with a message naming it instead of running.

use std::process::{Command, Output};

/// The binaries and one option of each that takes a value.
const BINS: [(&str, &str); 11] = [
    (env!("CARGO_BIN_EXE_error_vs_time"), "--out"),
    (env!("CARGO_BIN_EXE_plastic_cost"), "--frames"),
    (env!("CARGO_BIN_EXE_projections"), "--cells"),
    (env!("CARGO_BIN_EXE_queries"), "--queries"),
    (env!("CARGO_BIN_EXE_rest_vs_rapier"), "--substeps"),
    (env!("CARGO_BIN_EXE_scaling"), "--frames"),
    (env!("CARGO_BIN_EXE_spin_cost"), "--frames"),
    (env!("CARGO_BIN_EXE_stack_rest"), "--cubes"),
    (env!("CARGO_BIN_EXE_stacking"), "--frames"),
    (env!("CARGO_BIN_EXE_tearing_cost"), "--frames"),
    (env!("CARGO_BIN_EXE_vs_rapier"), "--frames"),
];

fn run(bin: &str, args: &[&str]) -> Output {
    Command::new(bin).args(args).output().expect("runs")
}

#[test]
fn every_bench_binary_documents_its_options_and_rejects_bad_ones() {
    for (bin, numeric) in BINS {
        let help = run(bin, &["--help"]);
        let text = String::from_utf8_lossy(&help.stdout);
        assert!(help.status.success(), "{bin} --help failed");
        assert!(text.contains("Usage:"), "{bin}: {text}");
        assert!(text.contains(numeric), "{bin}: {numeric} not in {text}");
        for bad in [&["--no-such-option"][..], &[numeric][..]] {
            let out = run(bin, bad);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{bin} {bad:?}: {err}");
            assert!(err.contains(bad[0]), "{bin} {bad:?}: message {err}");
        }
    }
}
