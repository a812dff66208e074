//! The stability suite's bounds, asserted at default settings: the seed's families on every
//! fast case, the material on the stiff and large-step cases, and (long, in release) every
//! cell of the uncoupled matrix — recovery and impact sweeps and the material's columns
//! included — but the known limits listed here. `docs/stability.md` shows the whole matrix,
//! the vertex–face-alone shape cells included.

use tetpbd_stability::{
    all_cases, run_scene, verdict, CaseKind, Config, ConstraintSet, Outcome, Verdict,
};

fn fast_cases(net: Option<f32>) -> Vec<tetpbd_stability::Case> {
    all_cases(net)
        .into_iter()
        .filter(|c| c.kind == CaseKind::Fast)
        .collect()
}

fn describe(case: &tetpbd_stability::Case, config: &Config, o: &Outcome) -> String {
    format!(
        "{} / {} under {}: {o:?}",
        case.group,
        case.name,
        config.label()
    )
}

/// Never NaN, never a non-finite reset, whatever the case and configuration.
fn assert_finite(net: Option<f32>) {
    for case in fast_cases(net) {
        for config in Config::families() {
            let o = run_scene(&case.scene, &config);
            assert!(
                o.finite && o.non_finite_resets == 0,
                "{}",
                describe(&case, &config, &o)
            );
        }
    }
}

#[test]
fn every_fast_case_stays_finite_without_safety_net() {
    assert_finite(None);
}

#[test]
fn every_fast_case_stays_finite_with_safety_net() {
    assert_finite(Some(10.0));
}

/// Cells that fail at default settings, each listed in the report (`docs/stability.md`) and
/// its findings: (case name, configuration label). A flattened soft vertex–face body (four
/// heights per tetrahedron) expands.
const KNOWN_LIMITS: &[(&str, &str)] = &[("flattened", "vertex-face, soft")];

/// The cells of the whole matrix (every case, the recovery and impact sweeps included, and
/// the material's columns) that fail at default settings, as [`KNOWN_LIMITS`]: the flattened
/// soft vertex–face body at 20 substeps too, and soft tissue dragged by one vertex on the
/// six-tetrahedra grid at 40 substeps, still ringing at 5 s (1.0 % off its volume; within
/// 0.02 % at 7 s).
const MATRIX_KNOWN_LIMITS: &[(&str, &str)] = &[
    ("flattened", "vertex-face, soft"),
    ("flattened, 6 tets/cell, 20 substeps", "vertex-face, soft"),
    (
        "one vertex dragged 100 cells, 6 tets/cell, 40 substeps",
        "material, soft tissue",
    ),
];

fn known_limit(known: &[(&str, &str)], case: &tetpbd_stability::Case, config: &Config) -> bool {
    let label = config.label();
    known
        .iter()
        .any(|&(name, c)| case.name == name && (c == "*" || c == label))
}

/// Every cell of `cases` under `configs` at default settings passes, but the
/// vertex–face-alone shape cells (expected: four heights fix four of six shape degrees of
/// freedom) and the `known` limits; a known limit that passes now is reported too (remove it
/// from the list). One thread per configuration.
fn assert_pass_at_defaults(
    cases: Vec<tetpbd_stability::Case>,
    configs: Vec<Config>,
    known: &[(&str, &str)],
) {
    let cases = &cases;
    let failed: Vec<String> = std::thread::scope(|scope| {
        let runs: Vec<_> = configs
            .into_iter()
            .map(|config| {
                scope.spawn(move || {
                    let mut failed = Vec::new();
                    for case in cases {
                        let o = run_scene(&case.scene, &config);
                        let fails = verdict(&config, &o) == Verdict::Fail;
                        if fails != known_limit(known, case, &config) {
                            let what = if fails {
                                "fails"
                            } else {
                                "known limit passes now"
                            };
                            failed.push(format!("{what}: {}", describe(case, &config, &o)));
                        }
                    }
                    failed
                })
            })
            .collect();
        runs.into_iter()
            .flat_map(|r| r.join().expect("a run panicked"))
            .collect()
    });
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
fn every_fast_cell_passes_at_defaults_but_known_limits() {
    assert_pass_at_defaults(fast_cases(None), Config::families(), KNOWN_LIMITS);
}

/// The whole uncoupled matrix without the net, as `docs/stability.md` shows it: every case,
/// the recovery and impact sweeps at 1–80 substeps, the seed's six configurations and the
/// material's two presets.
#[test]
#[ignore = "long: the whole uncoupled matrix, a few minutes in release (CI runs it)"]
fn every_cell_of_the_matrix_passes_at_defaults_but_known_limits() {
    assert_pass_at_defaults(all_cases(None), Config::all(), MATRIX_KNOWN_LIMITS);
}

/// The Neo-Hookean material (rubber and soft tissue), at default settings with substeps from
/// its stable substep, passes the stiff and large-step cases. (Its other cells, failures
/// included, are in `docs/stability.md`; they are not asserted.)
#[test]
fn material_passes_the_stiff_and_large_step_cases() {
    let mut failed = Vec::new();
    for case in fast_cases(None)
        .into_iter()
        .filter(|c| c.group == "stiff" || c.group == "large steps")
    {
        for soft in [false, true] {
            let config = Config {
                set: ConstraintSet::Material,
                soft,
            };
            let o = run_scene(&case.scene, &config);
            if !o.pass() {
                failed.push(describe(&case, &config, &o));
            }
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
fn collapsed_vertex_face_body_recovers_with_the_degenerate_fallback() {
    let config = Config {
        set: ConstraintSet::VertexFace,
        soft: false,
    };
    let case = all_cases(Some(10.0))
        .into_iter()
        .find(|c| c.name == "collapsed to a point")
        .expect("case exists");
    let o = run_scene(&case.scene, &config);
    assert!(o.pass() && o.recovered_at.is_some(), "{o:?}");
}

#[test]
#[ignore = "long: run in release by .ci/run"]
fn long_cases_pass_with_hard_edges_and_volume() {
    let config = Config {
        set: ConstraintSet::EdgesVolume,
        soft: false,
    };
    for case in all_cases(None)
        .into_iter()
        .filter(|c| c.kind == CaseKind::Long && !c.sweep)
    {
        let o = run_scene(&case.scene, &config);
        assert!(o.pass(), "{}", describe(&case, &config, &o));
        assert!(
            o.final_max_speed < 1e-3,
            "resting speed {} m/s",
            o.final_max_speed
        );
    }
}

mod coupled {
    use tetpbd_stability::{coupled_cases, CaseKind, Config, ConstraintSet};

    fn case(name: &str) -> tetpbd_stability::CoupledCase {
        coupled_cases()
            .into_iter()
            .find(|c| c.name == name)
            .expect("case exists")
    }

    #[test]
    fn light_soft_body_rests_on_a_heavy_free_plank_under_every_configuration() {
        let c = case("soft 1 kg on rigid 1000 kg");
        for config in Config::families() {
            let o = (c.run)(&config);
            assert!(o.pass(), "{}: {o:?}", config.label());
        }
    }

    #[test]
    fn heavy_rigid_box_on_light_soft_slab_holds_with_20_substeps_of_5_iterations() {
        let c = case("rigid 1000 kg on soft 1 kg, 20 × 5");
        for set in [ConstraintSet::EdgesVolume, ConstraintSet::VertexFaceEdges] {
            let config = Config { set, soft: false };
            let o = (c.run)(&config);
            assert!(o.pass(), "{}: {o:?}", config.label());
        }
    }

    /// At 30 m/s under every configuration; at 100 m/s under the hard ones and soft
    /// vertex–face + edges (soft edges + volume lets the ball through, soft vertex–face
    /// alone explodes: see docs/stability.md).
    #[test]
    fn fast_rigid_ball_does_not_tunnel_through_a_one_cell_slab() {
        let slow = case("rigid ball at 30 m/s");
        let fast = case("rigid ball at 100 m/s");
        for config in Config::families() {
            let o = (slow.run)(&config);
            assert!(o.pass(), "30 m/s, {}: {o:?}", config.label());
            if !config.soft || config.set == ConstraintSet::VertexFaceEdges {
                let o = (fast.run)(&config);
                assert!(o.pass(), "100 m/s, {}: {o:?}", config.label());
            }
        }
    }

    #[test]
    #[ignore = "long: run in release by .ci/run"]
    fn soft_cube_rests_100k_frames_on_rigid_ground() {
        let c = coupled_cases()
            .into_iter()
            .find(|c| c.kind == CaseKind::Long)
            .expect("long case");
        let config = Config {
            set: ConstraintSet::EdgesVolume,
            soft: false,
        };
        let o = (c.run)(&config);
        assert!(o.pass(), "{o:?}");
    }
}

mod coupled_overlap {
    use tetpbd_stability::{coupled_cases, Config};

    #[test]
    fn soft_cube_created_half_in_the_ground_separates_under_every_configuration() {
        let c = coupled_cases()
            .into_iter()
            .find(|c| c.name == "created half in the ground")
            .expect("case exists");
        for config in Config::families() {
            let o = (c.run)(&config);
            assert!(o.pass(), "{}: {o:?}", config.label());
        }
    }
}
