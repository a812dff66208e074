//! A committed sample asset, tetrahedralized with `tetpbd-io`, drops on fixed ground and
//! comes to rest there, with its skinned render mesh following it.

mod asset_drop_common;

use asset_drop_common::{asset_drop, AssetDrop};
use nalgebra::Vector3;
use tetpbd::{Particles, Tetrahedra};
use tetpbd_io::SurfaceMesh;
use tetpbd_rapier::SoftColliderBuilder;

/// What one drop measured.
struct Drop {
    /// Largest particle speed at the end, m/s.
    speed: f32,
    /// Largest end-of-step penetration over the last 0.5 s, m.
    penetration: f32,
    /// Lowest particle at the end, m (ground top at 0).
    sim_low: f32,
    /// Lowest skinned render vertex at the end, m.
    skin_low: f32,
    /// Inverted tetrahedra at the end, and most at any frame.
    inverted: usize,
    inverted_peak: usize,
    /// Volume ratio at the end.
    volume_ratio: f32,
    /// Centre of mass height at the end, m.
    com_y: f32,
    /// Volume enclosed by the skinned render mesh over its volume at rest.
    skin_volume_ratio: f32,
    /// Number of tetrahedra.
    tets: usize,
}

fn drop_asset(name: &str, cell: f32, smoothing: u32, height: f32, frames: usize) -> Drop {
    let collider = SoftColliderBuilder::new()
        .friction(0.6)
        .build()
        .expect("collider");
    let AssetDrop {
        mut scene,
        body: e,
        render,
        points,
        skin,
        tets,
    } = asset_drop(name, cell, smoothing, height, collider);
    assert_eq!(
        skin.outside_count(),
        0,
        "{name}: render vertices outside the tetrahedra"
    );
    let mut penetration = 0.0f32;
    let mut inverted_peak = 0;
    for frame in 0..frames {
        let stats = scene.step().expect("step");
        if frame + 30 >= frames {
            penetration = penetration.max(stats.max_penetration);
        }
        let (p, t) = scene
            .soft
            .query_one_mut::<(&Particles, &Tetrahedra)>(e)
            .expect("body");
        inverted_peak = inverted_peak.max(t.count_inverted(p.positions()));
    }
    let (p, t) = scene
        .soft
        .query_one_mut::<(&Particles, &Tetrahedra)>(e)
        .expect("body");
    let mut skinned = vec![Vector3::zeros(); points.len()];
    skin.deform(p.positions(), &mut skinned).expect("deform");
    let d = Drop {
        speed: p.max_speed(),
        penetration,
        sim_low: p.aabb().0.y,
        skin_low: skinned.iter().map(|v| v.y).fold(f32::MAX, f32::min),
        inverted: t.count_inverted(p.positions()),
        inverted_peak,
        volume_ratio: t.volume_ratio(p.positions()),
        com_y: p.center_of_mass().y,
        skin_volume_ratio: SurfaceMesh {
            vertices: skinned,
            triangles: render.triangles.clone(),
        }
        .enclosed_volume()
            / render.enclosed_volume(),
        tets,
    };
    println!(
        "{name}: {} tets, max|v| {:.5} m/s, penetration {:.6} m, sim low {:.4} m, skin low \
         {:.4} m, inverted {} (peak {}), volume ratio {:.4} (skin {:.4}), com y {:.4} m",
        d.tets,
        d.speed,
        d.penetration,
        d.sim_low,
        d.skin_low,
        d.inverted,
        d.inverted_peak,
        d.volume_ratio,
        d.skin_volume_ratio,
        d.com_y
    );
    d
}

/// The checks of a drop that came to rest lying flat on the ground (top at y = 0) after
/// 3 s: max |v| < 0.01 m/s, penetration < 1 % of the cell, no inverted tetrahedra, the
/// skinned render mesh above the simulated body's lowest point and within `gap` (m) of
/// the ground, and its enclosed volume within 1 % of the rest volume.
fn assert_at_rest(d: &Drop, cell: f32, gap: f32) {
    assert!(d.speed < 0.01, "still moving at {} m/s", d.speed);
    assert!(
        d.penetration < 0.01 * cell,
        "penetration {} m",
        d.penetration
    );
    assert!(
        d.sim_low > -0.01 * cell,
        "body below the ground: {} m",
        d.sim_low
    );
    assert_eq!(d.inverted, 0, "inverted tetrahedra at rest");
    assert!(
        (d.volume_ratio - 1.0).abs() < 0.01,
        "volume ratio {}",
        d.volume_ratio
    );
    assert!(
        d.skin_low >= d.sim_low,
        "skin below the body: {} m",
        d.skin_low
    );
    assert!(
        d.skin_low < gap,
        "skin floats {} m above the ground",
        d.skin_low
    );
    assert!(
        (d.skin_volume_ratio - 1.0).abs() < 0.01,
        "skin volume {}",
        d.skin_volume_ratio
    );
}

#[test]
fn raw_cover_torus_drops_and_rests_flat() {
    let d = drop_asset("torus.obj", 0.08, 0, 0.3, 180);
    assert_at_rest(&d, 0.08, 0.06);
    // Lying flat: the centre of mass about a tube radius (0.12 m) plus the cover's margin up.
    assert!(
        d.com_y > 0.12 && d.com_y < 0.12 + 0.08,
        "com at {} m",
        d.com_y
    );
    assert_eq!(d.inverted_peak, 0, "tetrahedra inverted during the impact");
}

#[test]
fn smoothed_cover_torus_drops_and_rests_flat_closer_to_the_skin() {
    let d = drop_asset("torus.obj", 0.08, 3, 0.3, 180);
    // Shrink-wrapping brings the skin within a quarter cell of the ground.
    assert_at_rest(&d, 0.08, 0.02);
    assert!(
        d.com_y > 0.12 && d.com_y < 0.12 + 0.04,
        "com at {} m",
        d.com_y
    );
}
