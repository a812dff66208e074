use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings, Tetrahedra};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, SoftCollider};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let set = args.get(1).map_or("ev", |s| s.as_str());
    let soft = args.get(2).is_some_and(|s| s == "soft");
    let sub: u32 = args.get(3).map_or(10, |s| s.parse().unwrap());
    let it: u32 = args.get(4).map_or(1, |s| s.parse().unwrap());
    let ratio: f32 = args.get(5).map_or(10.0, |s| s.parse().unwrap());
    let frames: usize = args.get(6).map_or(180, |s| s.parse().unwrap());
    let solver = SolverSettings {
        substeps: sub,
        iterations: it,
        ..Default::default()
    };
    let mut cs = CouplingSettings::default();
    cs.stacking_mass_ratio = ratio;
    let mut s = CoupledWorld::new(solver, cs).unwrap();
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(20.0, 0.5, 20.0),
    );
    let mesh = box_grid(Vector3::new(2.0, 0.2, 2.0), [4, 1, 4], CellSplit::Six).unwrap();
    let b = SoftBodyBuilder::new(mesh)
        .density(1.25)
        .translation(Vector3::new(0.0, 0.1, 0.0));
    let (l, v) = if soft { (1e-6, 1e-9) } else { (0.0, 0.0) };
    let b = match set {
        "ev" => b.edges(l).volume(v),
        "vf" => b.vertex_face(l),
        _ => b.vertex_face(l).edges(l),
    };
    let e = b.build().unwrap().spawn(&mut s.soft);
    s.soft.insert_one(e, SoftCollider::default()).unwrap();
    let (rb, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.45, 0.0)),
        ColliderBuilder::cuboid(0.25, 0.25, 0.25).mass(1000.0),
    );
    for f in 0..frames {
        let st = s.step().unwrap();
        let b = &s.physics.bodies[rb];
        let p = s.soft.get::<&Particles>(e).unwrap();
        let t = s.soft.get::<&Tetrahedra>(e).unwrap();
        let (lo, hi) = p.aabb();
        if f < 20 || f % 10 == 0 {
            println!("f {f:3} box y {:.4} vy {:.4} w {:.3} | slab y {:.4}..{:.4} vmax {:.3} inv {} | passes {} contacts {}",
                b.translation().y - 0.25, b.linvel().y, b.angvel().length(), lo.y, hi.y, p.max_speed(), t.count_inverted(p.positions()), st.stacking_passes, st.contacts);
        }
    }
}
