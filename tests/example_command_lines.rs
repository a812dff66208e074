//! Every example's command line: a consistent clap definition, `--help` naming each option
//! with its default, the positional forms the README, the guides and CI run, and a bad value
//! rejected with a message naming the argument.
//!
//! The command lines live in `examples/cli/`, one file per example, included here as they are
//! included by the examples.

use std::path::Path;

use clap::error::ErrorKind;
use clap::{CommandFactory, Parser};

#[path = "../examples/cli/asset_drop.rs"]
mod asset_drop;
#[path = "../examples/cli/integrating.rs"]
mod integrating;
#[path = "../examples/cli/kinematic_platform.rs"]
mod kinematic_platform;
#[path = "../examples/cli/recover.rs"]
mod recover;
#[path = "../examples/cli/rigid_ball_on_soft.rs"]
mod rigid_ball_on_soft;
#[path = "../examples/cli/sleeping_pile.rs"]
mod sleeping_pile;
#[path = "../examples/cli/soft_on_rigid_stack.rs"]
mod soft_on_rigid_stack;
#[path = "../examples/cli/soft_pile.rs"]
mod soft_pile;
#[path = "../examples/cli/tearing.rs"]
mod tearing;

/// Each example's command, by name.
fn commands() -> Vec<clap::Command> {
    vec![
        asset_drop::Cli::command(),
        integrating::Cli::command(),
        kinematic_platform::Cli::command(),
        recover::Cli::command(),
        rigid_ball_on_soft::Cli::command(),
        soft_on_rigid_stack::Cli::command(),
        soft_pile::Cli::command(),
        sleeping_pile::Cli::command(),
        tearing::Cli::command(),
    ]
}

/// The error of parsing `args` with `command`; panics if they parse.
fn error(command: clap::Command, args: &[&str]) -> clap::Error {
    command
        .try_get_matches_from(args)
        .expect_err(&format!("{args:?} should be rejected"))
}

#[test]
fn every_example_command_line_is_consistent_and_documents_its_options() {
    for mut command in commands() {
        command.clone().debug_assert();
        let name = command.get_name().to_owned();
        let help = command.render_long_help().to_string();
        let about = command.get_about().map(ToString::to_string);
        assert!(
            about.is_some_and(|a| a.len() > 20),
            "{name}: no description"
        );
        for needle in ["--export <DIR>", "--strip <FILE>", "Frame output"] {
            assert!(help.contains(needle), "{name}: `{needle}` missing:\n{help}");
        }
        for arg in command.get_arguments() {
            let id = arg.get_id().as_str();
            if id == "help" {
                continue;
            }
            assert!(
                arg.get_long_help().or(arg.get_help()).is_some(),
                "{name}: `{id}` has no help"
            );
            let help = arg.get_long_help().or(arg.get_help()).unwrap().to_string();
            assert!(!arg.is_required_set(), "{name}: `{id}` is required");
            assert!(
                !arg.get_default_values().is_empty()
                    || arg.get_env().is_some()
                    || help.contains("default"),
                "{name}: `{id}` names no default"
            );
        }
        let e = error(command.clone(), &[name.as_str(), "--help"]);
        assert_eq!(e.kind(), ErrorKind::DisplayHelp, "{name}");
    }
}

#[test]
fn the_documented_invocations_parse() {
    // .ci/run and docs/guide/stability-and-limits.md.
    let cli = recover::Cli::try_parse_from(["recover", "mirror", "vfe", "60", "10", "3"]).unwrap();
    assert_eq!(
        (cli.mode, cli.families, cli.frames, cli.substeps, cli.cells),
        (
            recover::Mode::Mirror,
            recover::Families::VertexFaceEdges,
            60,
            10,
            3
        )
    );
    assert_eq!((cli.alpha, cli.max_correction_speed), (0.0, None));
    let cli = recover::Cli::try_parse_from([
        "recover",
        "mirror",
        "vf",
        "120",
        "10",
        "4",
        "--max-correction-speed",
        "10",
    ])
    .unwrap();
    assert_eq!(cli.families, recover::Families::VertexFace);
    assert_eq!(cli.max_correction_speed, Some(10.0));
    let cli =
        recover::Cli::try_parse_from(["recover", "scramble", "ev", "--alpha", "1e-6"]).unwrap();
    assert_eq!((cli.mode, cli.alpha), (recover::Mode::Scramble, 1e-6));
    assert_eq!(
        (cli.frames, cli.substeps, cli.cells),
        (120, 10, 4),
        "defaults"
    );
    assert!(!cli.viz.renders());

    // .ci/run and docs/guide/integrating.md.
    let cli = integrating::Cli::try_parse_from(["integrating", "--frames", "60"]).unwrap();
    assert_eq!(cli.frames, 60);
    assert_eq!(
        (cli.render_hz, cli.physics_hz, cli.substeps),
        (144.0, 60.0, 10)
    );

    // .ci/run and the README's gallery section.
    let cli = rigid_ball_on_soft::Cli::try_parse_from([
        "rigid_ball_on_soft",
        "30",
        "--export",
        "frames/obj",
        "--strip",
        "frames/strip.png",
    ])
    .unwrap();
    assert_eq!(cli.frames, 30);
    assert_eq!(cli.viz.export.as_deref(), Some(Path::new("frames/obj")));
    assert_eq!(
        cli.viz.strip.as_deref(),
        Some(Path::new("frames/strip.png"))
    );
    let cli = rigid_ball_on_soft::Cli::try_parse_from(["rigid_ball_on_soft"]).unwrap();
    assert_eq!(cli.frames, 180);

    let cli = soft_on_rigid_stack::Cli::try_parse_from(["soft_on_rigid_stack", "90"]).unwrap();
    assert_eq!((cli.frames, cli.viz.strip_frames), (90, 4));
    let cli = kinematic_platform::Cli::try_parse_from(["kinematic_platform", "--strip", "k.png"])
        .unwrap();
    assert_eq!(cli.frames, 240);
    assert!(cli.viz.renders());

    let cli = soft_pile::Cli::try_parse_from(["soft_pile"]).unwrap();
    assert_eq!((cli.ground, cli.seconds), (soft_pile::Ground::Rigid, 5));
    let cli = soft_pile::Cli::try_parse_from(["soft_pile", "soft", "2"]).unwrap();
    assert_eq!((cli.ground, cli.seconds), (soft_pile::Ground::Soft, 2));
    assert!(cli.viz.export.is_none());

    // .ci/run and docs/performance.md.
    let cli = sleeping_pile::Cli::try_parse_from(["sleeping_pile"]).unwrap();
    assert_eq!((cli.scene, cli.cubes), (sleeping_pile::Scene::Pile, 20));
    let cli =
        sleeping_pile::Cli::try_parse_from(["sleeping_pile", "pile", "6", "--frames-after", "30"])
            .unwrap();
    assert_eq!((cli.cubes, cli.frames_after), (6, 30));
    let cli = sleeping_pile::Cli::try_parse_from(["sleeping_pile", "field", "200"]).unwrap();
    assert_eq!((cli.scene, cli.cubes), (sleeping_pile::Scene::Field, 200));

    // .ci/run, the README and docs/decisions/tearing.md.
    let cli = tearing::Cli::try_parse_from([
        "tearing",
        "--speed",
        "5",
        "--settle-frames",
        "30",
        "--export",
        "frames/tear",
    ])
    .unwrap();
    assert_eq!(
        (cli.speed, cli.settle_frames, cli.no_rapier),
        (5.0, 30, false)
    );
    assert_eq!(cli.viz.export.as_deref(), Some(Path::new("frames/tear")));
    let cli = tearing::Cli::try_parse_from(["tearing"]).unwrap();
    assert_eq!((cli.speed, cli.settle_frames), (3.0, 60));

    // docs/guide/building-bodies.md.
    let cli = asset_drop::Cli::try_parse_from(["asset_drop"]).unwrap();
    assert!(cli.obj.ends_with("examples/assets/bunny_blob.obj"));
    assert!(cli.obj.is_file(), "the default asset exists");
    assert_eq!((cli.frames, cli.cell), (180, 0.07));
    let cli = asset_drop::Cli::try_parse_from([
        "asset_drop",
        "blob.obj",
        "60",
        "0.05",
        "--animate",
        "a.png",
    ])
    .unwrap();
    assert_eq!(cli.obj, Path::new("blob.obj"));
    assert_eq!((cli.frames, cli.cell), (60, 0.05));
    assert_eq!(cli.viz.animate.as_deref(), Some(Path::new("a.png")));
}

#[test]
fn a_bad_argument_is_rejected_with_a_message_naming_it() {
    let cases: [(clap::Command, &[&str], &str); 19] = [
        (rigid_ball_on_soft::Cli::command(), &["x", "ten"], "FRAMES"),
        (rigid_ball_on_soft::Cli::command(), &["x", "-3"], "FRAMES"),
        (soft_on_rigid_stack::Cli::command(), &["x", "1.5"], "FRAMES"),
        (
            kinematic_platform::Cli::command(),
            &["x", "--strip-frames", "0"],
            "--strip-frames",
        ),
        (recover::Cli::command(), &["x", "mirorr"], "MODE"),
        (recover::Cli::command(), &["x", "mirror", "vef"], "FAMILIES"),
        (
            recover::Cli::command(),
            &["x", "mirror", "vf", "60", "0"],
            "SUBSTEPS",
        ),
        (
            recover::Cli::command(),
            &["x", "mirror", "vf", "60", "10", "0"],
            "CELLS",
        ),
        (recover::Cli::command(), &["x", "--alpha", "-1"], "--alpha"),
        (
            recover::Cli::command(),
            &["x", "--max-correction-speed", "0"],
            "--max-correction-speed",
        ),
        (
            recover::Cli::command(),
            &["x", "--max-correction-speed", "inf"],
            "--max-correction-speed",
        ),
        (soft_pile::Cli::command(), &["x", "jelly"], "GROUND"),
        (soft_pile::Cli::command(), &["x", "soft", "0"], "SECONDS"),
        (soft_pile::Cli::command(), &["x", "soft", "-1"], "SECONDS"),
        (
            asset_drop::Cli::command(),
            &["x", "a.obj", "60", "-0.1"],
            "CELL_M",
        ),
        (
            integrating::Cli::command(),
            &["x", "--render-hz", "fast"],
            "--render-hz",
        ),
        (
            integrating::Cli::command(),
            &["x", "--frames", "-3"],
            "--frames",
        ),
        (tearing::Cli::command(), &["x", "--speed", "-1"], "--speed"),
        (
            tearing::Cli::command(),
            &["x", "--settle-frames", "-5"],
            "--settle-frames",
        ),
    ];
    for (command, args, name) in cases {
        let e = error(command, args);
        let text = e.to_string();
        assert!(
            text.contains(name),
            "{args:?}: `{name}` missing from: {text}"
        );
        assert!(!text.contains("ParseIntError"), "{args:?}: {text}");
        assert_ne!(e.kind(), ErrorKind::DisplayHelp, "{args:?}");
    }
}
