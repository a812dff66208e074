//! A slab pulled apart by two rigid bodies at 1, 5 and 20 m/s tears into pieces that stay
//! finite, keep positive masses and uninverted rest shapes, and end on the ground; under the
//! hard families (α = 0) no tetrahedron is left inverted. The fastest fragment is printed,
//! not asserted: released elastic energy launches fragments of the stiff slab well past the
//! boxes' speed (a known limit).

use tetpbd_bench::{SlabPull, TearEngine};
use tetpbd_stability::{pull_apart, Config, ConstraintSet, PULL_SPEEDS};

/// The sweep under the scene's own families and the suite's hard ones.
fn sweep() -> Vec<(String, tetpbd_stability::PullFigures)> {
    let mut out = Vec::new();
    for speed in PULL_SPEEDS {
        let f = pull_apart(TearEngine::Tetpbd, speed, SlabPull::stiff).unwrap();
        out.push(("stiff".to_string(), f));
        for set in [ConstraintSet::EdgesVolume, ConstraintSet::VertexFaceEdges] {
            let c = Config { set, soft: false };
            let f = pull_apart(TearEngine::Tetpbd, speed, move |b| c.apply(b, 1.0)).unwrap();
            out.push((c.label(), f));
        }
    }
    out
}

#[test]
fn a_slab_pulled_apart_at_1_to_20_m_s_tears_into_sound_pieces() {
    for (label, f) in sweep() {
        println!("{label} at {} m/s: {f:?}", f.speed);
        let at = format!("{label} at {} m/s", f.speed);
        assert!(f.finite && !f.blown_up, "{at}: not finite or blown up");
        assert!(f.events > 0 && f.pieces > 1, "{at}: did not come apart");
        assert!(f.min_mass > 0.0, "{at}: a particle of mass {}", f.min_mass);
        assert_eq!(f.inverted_rest, 0, "{at}: inverted rest shapes");
        // Known limit: the compliant slab leaves some fragments' tetrahedra inverted.
        if label != "stiff" {
            assert_eq!(f.inverted, 0, "{at}: inverted tetrahedra at the end");
        }
        // Pieces end on the ground, not in it, at every speed (fragments that fly past the
        // ground's edge fall, and are not counted). While it tears, the compliant slab
        // (`stiff`) dips about 6 cm into the ground for a few frames at 1 m/s: not asserted.
        assert!(
            f.on_the_ground(),
            "{at}: a particle {} m under the ground at the end",
            f.final_lowest
        );
    }
}
