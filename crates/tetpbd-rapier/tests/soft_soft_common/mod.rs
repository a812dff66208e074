//! Shared helpers of the soft–soft contact tests (`tests/soft_soft_*.rs`): scenes on the
//! core solver with [`SoftContacts`] as its hook, and an independent brute-force
//! interpenetration measure.
#![allow(dead_code)]

use hecs::{Entity, World};
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::parry::query::PointQuery;
use rapier3d::parry::shape::Triangle;
use tetpbd::generators::{self, CellSplit};
use tetpbd::{
    Activation, Particles, SoftBodyBuilder, Solver, SolverSettings, StepStats, Surface, Tetrahedra,
};
use tetpbd_rapier::{SoftContactSettings, SoftContactStats, SoftContacts};

/// A scene: soft bodies, the core solver at 60 Hz and the soft contacts.
pub struct Scene {
    pub world: World,
    pub solver: Solver,
    pub contacts: SoftContacts,
}

impl Scene {
    /// 60 Hz, `substeps` substeps of one iteration, default contact settings.
    pub fn new(substeps: u32) -> Scene {
        let solver = Solver::new(SolverSettings {
            substeps,
            ..SolverSettings::default()
        })
        .expect("solver settings");
        Scene {
            world: World::new(),
            solver,
            contacts: SoftContacts::new(SoftContactSettings::default()).expect("settings"),
        }
    }

    /// One frame with the soft contacts.
    pub fn step(&mut self) -> (StepStats, SoftContactStats) {
        let s = self
            .solver
            .step_with(&mut self.world, &mut self.contacts)
            .expect("step");
        assert_eq!(s.non_finite_resets, 0, "non-finite state");
        (s, *self.contacts.stats())
    }

    /// One frame without any contacts (the control).
    pub fn step_without_contacts(&mut self) {
        self.solver.step(&mut self.world).expect("step");
    }

    /// A copy of a body's particles.
    pub fn particles(&self, e: Entity) -> Particles {
        (*self.world.get::<&Particles>(e).expect("soft body")).clone()
    }

    /// Largest particle speed over all bodies, m/s.
    pub fn max_speed(&self) -> f32 {
        let mut v = 0.0f32;
        for p in self.world.query::<&Particles>().iter() {
            v = v.max(p.max_speed());
        }
        v
    }

    /// Largest interpenetration over all ordered pairs of distinct bodies (see
    /// [`penetration`]), m.
    pub fn max_interpenetration(&self, bodies: &[Entity]) -> f32 {
        let boxes: Vec<_> = bodies.iter().map(|&e| self.particles(e).aabb()).collect();
        let mut pen = 0.0f32;
        for (i, &a) in bodies.iter().enumerate() {
            for (j, &b) in bodies.iter().enumerate() {
                let (la, ha) = boxes[i];
                let (lb, hb) = boxes[j];
                let overlap = (0..3).all(|k| la[k] <= hb[k] && lb[k] <= ha[k]);
                if a != b && overlap {
                    pen = pen.max(penetration(&self.world, a, b).1);
                }
            }
        }
        pen
    }
}

/// A soft box of `size` (m), `cells` per axis, centred at `at`, density 1000 kg/m³, edge
/// compliance `edge` (m/N), hard volume.
pub fn soft_box(
    world: &mut World,
    size: Vector3<f32>,
    cells: [u32; 3],
    at: Vector3<f32>,
    edge: f32,
) -> Entity {
    let mesh = generators::box_grid(size, cells, CellSplit::Six).expect("mesh");
    let e = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(edge)
        .volume(0.0)
        .translation(at)
        .build()
        .expect("body")
        .spawn(world);
    awake(world, e)
}

/// A soft slab of `size` (m) whose top face is at `top` (m), with every particle of its
/// bottom face and of its four sides pinned.
pub fn pinned_slab(world: &mut World, size: Vector3<f32>, cells: [u32; 3], top: f32) -> Entity {
    let mesh = generators::box_grid(size, cells, CellSplit::Six).expect("mesh");
    let h = size / 2.0;
    let tol = 1e-4;
    let pinned: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| {
            let v = mesh.vertices[i as usize];
            v.y < -h.y + tol || v.x.abs() > h.x - tol || v.z.abs() > h.z - tol
        })
        .collect();
    let e = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .pinned(pinned)
        .translation(Vector3::new(0.0, top - h.y, 0.0))
        .build()
        .expect("slab")
        .spawn(world);
    awake(world, e)
}

/// A soft ball of `radius` (m) centred at `at` with velocity `v` (m/s).
pub fn soft_ball(
    world: &mut World,
    radius: f32,
    cells: u32,
    at: Vector3<f32>,
    v: Vector3<f32>,
) -> Entity {
    let mesh = generators::ball(radius, cells, CellSplit::Six).expect("mesh");
    let e = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .translation(at)
        .velocity(v)
        .build()
        .expect("ball")
        .spawn(world);
    awake(world, e)
}

/// Makes `e` never sleep and returns it: these scenes watch the contacts and the rest they
/// bring, which sleeping would freeze.
pub fn awake(world: &mut World, e: Entity) -> Entity {
    *world.get::<&mut Activation>(e).expect("soft body") = Activation::never_sleeps();
    e
}

/// Independent measure (brute force, parry's triangle distance): the surface particles of
/// `a` strictly inside a tetrahedron of `b`, and the largest distance of one of them to `b`'s
/// surface (m). `(0, 0.0)` when the bodies do not interpenetrate.
pub fn penetration(world: &World, a: Entity, b: Entity) -> (usize, f32) {
    let pa = world.get::<&Particles>(a).expect("a");
    let sa = world.get::<&Surface>(a).expect("a");
    let pb = world.get::<&Particles>(b).expect("b");
    let sb = world.get::<&Surface>(b).expect("b");
    let tb = world.get::<&Tetrahedra>(b).expect("b");
    let xb = pb.positions();
    let (lo, hi) = pb.aabb();
    let mut count = 0;
    let mut depth = 0.0f32;
    for &i in sa.vertices() {
        let x = pa.positions()[i as usize];
        if (0..3).any(|k| x[k] < lo[k] || x[k] > hi[k]) {
            continue;
        }
        let inside = tb.indices().iter().any(|t| {
            let [p0, p1, p2, p3] = t.map(|j| xb[j as usize]);
            let v = |a: &Vector3<f32>, b: &Vector3<f32>, c: &Vector3<f32>, d: &Vector3<f32>| {
                (b - a).dot(&(c - a).cross(&(d - a)))
            };
            let s = v(&p0, &p1, &p2, &p3).signum();
            v(&x, &p1, &p2, &p3) * s > 0.0
                && v(&p0, &x, &p2, &p3) * s > 0.0
                && v(&p0, &p1, &x, &p3) * s > 0.0
                && v(&p0, &p1, &p2, &x) * s > 0.0
        });
        if !inside {
            continue;
        }
        count += 1;
        let q = Vector::new(x.x, x.y, x.z);
        let g = |j: u32| {
            let p = xb[j as usize];
            Vector::new(p.x, p.y, p.z)
        };
        let d = sb
            .triangles()
            .iter()
            .map(|t| Triangle::new(g(t[0]), g(t[1]), g(t[2])).distance_to_local_point(q, true))
            .fold(f32::INFINITY, f32::min);
        depth = depth.max(d);
    }
    (count, depth)
}
