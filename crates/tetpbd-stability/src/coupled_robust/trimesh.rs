//! Triangle-mesh ground of either winding, open (a 10 m square of two triangles) or closed
//! (a 10 × 1 × 10 m slab), with or without `FIX_INTERNAL_EDGES`. Criterion: soft cubes of
//! 0.3, 0.5 and 1 m dropped at 0.5, 2 and 5 m/s rest on it (lowest particle within −1 to
//! 2 cm of its top, fastest particle < 0.2 m/s after 2 s); beside it, whether a rigid cube
//! rests there too.

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, TriMeshFlags};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd_rapier::CoupledWorld;

use super::body::{world, Engine, Soft};
use super::{merge, run};
use crate::coupled::CoupledOutcome;

/// A triangle mesh: vertices and triangles.
type Mesh = (Vec<Vector>, Vec<[u32; 3]>);

/// The flags tried on every mesh.
const FLAGS: [(&str, TriMeshFlags); 2] = [
    ("no flags", TriMeshFlags::empty()),
    ("FIX_INTERNAL_EDGES", TriMeshFlags::FIX_INTERNAL_EDGES),
];

/// A 10 m square of two triangles at y = 0, wound counter-clockwise seen from above (normal
/// up) or clockwise (normal down).
fn square(clockwise: bool) -> Mesh {
    let v = vec![
        Vector::new(-5.0, 0.0, -5.0),
        Vector::new(5.0, 0.0, -5.0),
        Vector::new(5.0, 0.0, 5.0),
        Vector::new(-5.0, 0.0, 5.0),
    ];
    let idx = if clockwise {
        vec![[0, 1, 2], [0, 2, 3]]
    } else {
        vec![[0, 2, 1], [0, 3, 2]]
    };
    (v, idx)
}

/// A closed 10 × 1 × 10 m slab whose top is at y = 0, wound outwards or inwards.
fn closed_slab(inwards: bool) -> Mesh {
    let v = (0..8)
        .map(|k| {
            let x = if k & 1 == 0 { -5.0 } else { 5.0 };
            let y = if k & 2 == 0 { -1.0 } else { 0.0 };
            let z = if k & 4 == 0 { -5.0 } else { 5.0 };
            Vector::new(x, y, z)
        })
        .collect();
    // Outward faces of the box, corners indexed by the bits (x, y, z).
    let quads = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let mut idx = Vec::new();
    for [a, b, c, d] in quads {
        let (t1, t2) = ([a, b, c], [a, c, d]);
        for t in [t1, t2] {
            idx.push(if inwards { [t[0], t[2], t[1]] } else { t });
        }
    }
    (v, idx)
}

/// Which mesh of the scenes.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Ground {
    /// The open square, wound clockwise seen from above if true.
    Square(bool),
    /// The closed slab, wound inwards if true.
    Slab(bool),
}

impl Ground {
    fn mesh(self) -> Mesh {
        match self {
            Ground::Square(cw) => square(cw),
            Ground::Slab(inwards) => closed_slab(inwards),
        }
    }
}

fn add(s: &mut CoupledWorld, ground: Ground, flags: TriMeshFlags) -> Result<(), String> {
    let (v, idx) = ground.mesh();
    let collider = ColliderBuilder::trimesh_with_flags(v, idx, flags).map_err(|e| e.to_string())?;
    s.physics.insert(RigidBodyBuilder::fixed(), collider);
    Ok(())
}

/// Whether a rigid 0.5 m cube dropped at 2 m/s rests on the mesh after 2 s.
fn rigid_rests(engine: Engine, ground: Ground, flags: TriMeshFlags) -> Result<bool, String> {
    let mut s = world(engine)?;
    add(&mut s, ground, flags)?;
    let (h, _) = s.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.1, 0.3, -0.2))
            .linvel(Vector::new(0.0, -2.0, 0.0)),
        ColliderBuilder::cuboid(0.25, 0.25, 0.25),
    );
    for _ in 0..120 {
        s.step().map_err(|e| e.to_string())?;
    }
    Ok(s.physics
        .bodies
        .get(h)
        .is_some_and(|b| (b.translation().y - 0.25).abs() < 0.02))
}

/// Soft cubes onto `ground` under both flag sets.
pub(crate) fn onto(engine: Engine, ground: Ground) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome {
        finite: true,
        ..CoupledOutcome::default()
    };
    let mut failed = Vec::new();
    let mut rigid = Vec::new();
    let (mut low, mut high, mut fastest) = (f32::INFINITY, f32::NEG_INFINITY, 0.0f32);
    for (name, flags) in FLAGS {
        if !rigid_rests(engine, ground, flags)? {
            rigid.push(name);
        }
        for (size, speed) in [(0.3f32, 0.5f32), (0.5, 2.0), (1.0, 5.0)] {
            let mut s = world(engine)?;
            add(&mut s, ground, flags)?;
            let cells = (size / 0.15).ceil() as u32;
            let mesh = box_grid(Vector3::repeat(size), [cells; 3], CellSplit::Six)
                .map_err(|e| e.to_string())?;
            let at = Vector3::new(0.1, size / 2.0 + 0.05, -0.2);
            let v = Vector3::new(0.0, -speed, 0.0);
            let soft = Soft::spawn(&mut s, engine, mesh, at, v, 1000.0)?;
            let mut one = CoupledOutcome::default();
            run(&mut s, &soft, 120, &mut one, |_, _| {});
            merge(&mut out, &one);
            let look = soft.look(&s);
            if !((-0.01..0.02).contains(&look.lowest) && look.fastest < 0.2) {
                failed.push(format!("{name}, {size} m at {speed} m/s"));
            }
            low = low.min(look.lowest);
            high = high.max(look.lowest);
            fastest = fastest.max(look.fastest);
        }
    }
    out.criterion = (
        failed.is_empty(),
        format!(
            "lowest particle {low:.3} to {high:.3} m, final ≤ {fastest:.3} m/s; rigid cube {}{}",
            if rigid.is_empty() {
                "rests under both".to_string()
            } else {
                format!("falls through with {}", rigid.join(", "))
            },
            if failed.is_empty() {
                String::new()
            } else {
                format!("; failed: {}", failed.join("; "))
            }
        ),
    );
    Ok(out)
}
