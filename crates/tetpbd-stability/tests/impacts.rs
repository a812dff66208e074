//! A soft body thrown at immovable ground ends intact (no inverted tetrahedron, the volume of
//! the same body set down at rest within 1 %) and never leaves faster than it came, at any
//! speed, grid split and substep count, under every configuration at default settings.
//! Compliant bodies at many substeps were the hard part: their constraints carry a push
//! through them slower than a substep's reach (`tetpbd::impact_speed`).

use tetpbd::generators::CellSplit;
use tetpbd_stability::{impact, run_scene, verdict, Config, ConstraintSet, Verdict};

const SPLITS: [CellSplit; 2] = [CellSplit::Five, CellSplit::Six];

/// Runs the impact scene at every `speeds` × split × `substeps` under `configs`; returns the
/// failing cells, described.
fn failures(configs: &[Config], speeds: &[f32], substeps: &[u32]) -> Vec<String> {
    let mut failed = Vec::new();
    for config in configs {
        for &speed in speeds {
            for split in SPLITS {
                for &n in substeps {
                    let o = run_scene(&impact(split, speed, n), config);
                    let (came, rose) = o.rebound.expect("a thrown body measures its rebound");
                    if verdict(config, &o) == Verdict::Fail || rose >= came {
                        failed.push(format!(
                            "{} at {speed} m/s, {split:?}, {n} substeps: {o:?}",
                            config.label()
                        ));
                    }
                }
            }
        }
    }
    failed
}

fn compliant() -> [Config; 2] {
    [
        Config {
            set: ConstraintSet::EdgesVolume,
            soft: true,
        },
        Config {
            set: ConstraintSet::Material,
            soft: true,
        },
    ]
}

#[test]
fn compliant_bodies_thrown_at_the_ground_end_intact_however_many_substeps() {
    let failed = failures(&compliant(), &[100.0, 300.0], &[1, 20, 80]);
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
#[ignore = "long: every configuration at 50–300 m/s, both splits, 1–80 substeps (CI runs it in release)"]
fn every_body_thrown_at_the_ground_ends_intact_and_leaves_slower_than_it_came() {
    let failed = failures(
        &Config::all(),
        &[50.0, 100.0, 200.0, 300.0],
        &tetpbd_stability::SWEEP_SUBSTEPS,
    );
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
