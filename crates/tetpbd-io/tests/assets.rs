//! The committed sample assets are what `make_assets` generates, and are usable surfaces.
#![cfg(feature = "mesher")]

use std::path::PathBuf;

use tetpbd_io::{shapes, SurfaceMesh};

fn assets_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/assets")
}

#[test]
fn committed_assets_match_the_generator() {
    for (name, text) in shapes::sample_assets().unwrap() {
        let committed = std::fs::read_to_string(assets_dir().join(name)).unwrap();
        assert!(
            committed == text,
            "{name} differs from the generator: run `cargo run -p tetpbd-io --features cli --bin make_assets`"
        );
    }
}

#[test]
fn assets_are_closed_outward_and_small() {
    let mut bytes = 0;
    for (name, text) in shapes::sample_assets().unwrap() {
        bytes += text.len();
        let surface = SurfaceMesh::from_obj_str(&text).unwrap();
        let closed = surface.closed().unwrap();
        assert_eq!(closed.vertices.len(), surface.vertices.len(), "{name}");
        assert_eq!(
            closed.triangles, surface.triangles,
            "{name} is wound inward"
        );
        assert!(surface.enclosed_volume() > 0.0, "{name}");
    }
    assert!(bytes < 200_000, "assets total {bytes} bytes");
}

#[test]
fn torus_volume_matches_the_formula() {
    // 2π²Rr² for R = 0.3, r = 0.12; the 32 × 16 polygon loses a few per cent.
    let exact = 2.0 * std::f32::consts::PI.powi(2) * 0.3 * 0.12f32.powi(2);
    let v = shapes::torus(0.3, 0.12, 32, 16).enclosed_volume();
    assert!(v < exact && v > 0.95 * exact, "{v} vs {exact}");
}

#[test]
fn icosphere_counts() {
    let s = shapes::icosphere(2);
    assert_eq!((s.vertices.len(), s.triangles.len()), (162, 320));
    assert!(s.vertices.iter().all(|v| (v.norm() - 1.0).abs() < 1e-6));
    s.closed().unwrap();
}
