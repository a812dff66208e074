//! The frame-output options as a clap group inside a program's own command line.
//!
//! One test per process touches the `TETPBD_*` variables: the test harness runs tests on
//! several threads, so everything that reads or writes them is in one test.

use std::path::Path;

use clap::{CommandFactory, Parser};
use tetpbd_viz::VizOptions;

/// A program with positional arguments of its own around the flattened options.
#[derive(Debug, Parser)]
struct Cli {
    /// A word.
    #[arg(default_value = "mirror")]
    mode: String,
    /// A count.
    #[arg(default_value_t = 120)]
    frames: usize,
    #[command(flatten)]
    viz: VizOptions,
}

const VARIABLES: [&str; 4] = [
    "TETPBD_EXPORT",
    "TETPBD_RENDER",
    "TETPBD_STRIP",
    "TETPBD_ANIMATE",
];

#[test]
fn options_come_from_the_command_line_among_positionals_and_fall_back_on_the_environment() {
    Cli::command().debug_assert();
    for var in VARIABLES {
        std::env::remove_var(var);
    }
    let cli = Cli::try_parse_from(["prog"]).unwrap();
    assert_eq!((cli.mode.as_str(), cli.frames), ("mirror", 120));
    assert_eq!(
        cli.viz,
        VizOptions::default(),
        "every output off by default"
    );
    assert_eq!(cli.viz.strip_frames, 4);

    let cli = Cli::try_parse_from([
        "prog",
        "flatten",
        "--export",
        "out/frames",
        "60",
        "--strip-frames",
        "3",
        "--animate=a.png",
    ])
    .unwrap();
    assert_eq!((cli.mode.as_str(), cli.frames), ("flatten", 60));
    assert_eq!(cli.viz.export.as_deref(), Some(Path::new("out/frames")));
    assert_eq!(cli.viz.animate.as_deref(), Some(Path::new("a.png")));
    assert_eq!(cli.viz.strip_frames, 3);
    assert!(cli.viz.renders());
    assert_eq!((cli.viz.render, cli.viz.strip), (None, None));

    std::env::set_var("TETPBD_STRIP", "env_strip.png");
    std::env::set_var("TETPBD_EXPORT", "env_frames");
    let cli = Cli::try_parse_from(["prog", "--export", "out/frames"]).unwrap();
    assert_eq!(
        cli.viz.export.as_deref(),
        Some(Path::new("out/frames")),
        "the option wins over its variable"
    );
    assert_eq!(cli.viz.strip.as_deref(), Some(Path::new("env_strip.png")));
    assert_eq!(cli.viz.render, None);
    for var in VARIABLES {
        std::env::remove_var(var);
    }
}

#[test]
fn a_bad_option_is_an_error_naming_it() {
    for (args, name) in [
        (&["prog", "--export"][..], "--export"),
        (&["prog", "--strip", ""], "--strip"),
        (&["prog", "--strip-frames", "0"], "--strip-frames"),
        (&["prog", "--strip-frames", "four"], "--strip-frames"),
        (&["prog", "--strip-frames", "-2"], "--strip-frames"),
        (&["prog", "--stirp", "x.png"], "--stirp"),
    ] {
        let error = Cli::try_parse_from(args).unwrap_err();
        let text = error.to_string();
        assert!(text.contains(name), "{args:?}: {text}");
        assert_ne!(
            error.kind(),
            clap::error::ErrorKind::DisplayHelp,
            "{args:?}"
        );
    }
}

#[test]
fn help_lists_every_option_with_its_variable_and_default() {
    let help = Cli::command().render_long_help().to_string();
    for needle in [
        "--export <DIR>",
        "--render <DIR>",
        "--strip <FILE>",
        "--strip-frames <N>",
        "--animate <FILE>",
        "TETPBD_EXPORT",
        "TETPBD_RENDER",
        "TETPBD_STRIP",
        "TETPBD_ANIMATE",
        "[default: 4]",
        "Frame output",
    ] {
        assert!(help.contains(needle), "`{needle}` missing from:\n{help}");
    }
}
