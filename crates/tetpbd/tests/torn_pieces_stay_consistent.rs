//! Every structure derived from a torn or cut mesh is rebuilt consistently: each piece's
//! surface is the boundary of its tetrahedra, its edges are its tetrahedra's edges, its
//! colour classes share no particle, and its rest state (rest lengths, heights, volumes and
//! plastic stretch) is what the body had for the same tetrahedra and particles.

mod common;

use std::collections::BTreeMap;

use common::plastic::{solver, spawn_bar, Bar, Families};
use common::tearing::{pinned_bar, pull_ends};
use hecs::{Entity, World};
use nalgebra::{Matrix3, Vector3};
use tetpbd::{
    cut, unique_edges, Blade, ColourClasses, EdgeConstraints, Material, Particles, Plasticity,
    PlasticitySettings, Solver, SolverSettings, Surface, TearingSettings, Tetrahedra,
    VertexFaceConstraints, VolumeConstraints,
};

/// No two items of an independent class share a particle.
fn classes_are_independent<const N: usize>(
    classes: &ColourClasses,
    items: &[[u32; N]],
    what: &str,
) {
    for (range, independent) in classes.ranges() {
        if !independent {
            continue;
        }
        let mut seen = std::collections::BTreeSet::new();
        for item in &items[range] {
            for &i in item {
                assert!(seen.insert(i), "{what}: particle {i} twice in one class");
            }
        }
    }
}

fn sorted<T: Ord + Clone>(v: &[T]) -> Vec<T> {
    let mut v = v.to_vec();
    v.sort();
    v
}

/// Checks one body's derived structures against its tetrahedra and particles.
fn assert_consistent(world: &World, e: Entity) {
    let p = world.get::<&Particles>(e).unwrap();
    let t = world.get::<&Tetrahedra>(e).unwrap();
    let s = world.get::<&Surface>(e).unwrap();
    let n = p.len() as u32;
    let mut used = vec![false; p.len()];
    for tet in t.indices() {
        for &i in tet {
            assert!(i < n, "index {i} of {n} particles");
            used[i as usize] = true;
        }
    }
    assert!(used.iter().all(|&u| u), "a particle no tetrahedron uses");
    assert!(p.masses().iter().all(|&m| m > 0.0 && m.is_finite()));
    assert_eq!(
        t.count_inverted(p.rest_positions()),
        0,
        "an inverted rest shape"
    );
    let fresh = Surface::from_tetrahedra(t.indices(), p.positions());
    let norm = |tris: &[[u32; 3]]| -> Vec<[u32; 3]> {
        let mut v: Vec<[u32; 3]> = tris
            .iter()
            .map(|&[a, b, c]| {
                // The same triangle, same winding, starting at its smallest index.
                let k = [a, b, c].iter().enumerate().min_by_key(|x| x.1).unwrap().0;
                [[a, b, c][k], [a, b, c][(k + 1) % 3], [a, b, c][(k + 2) % 3]]
            })
            .collect();
        v.sort();
        v
    };
    assert_eq!(norm(s.triangles()), norm(fresh.triangles()), "surface");
    assert_eq!(
        sorted(s.vertices()),
        sorted(fresh.vertices()),
        "surface vertices"
    );
    classes_are_independent(t.classes(), t.indices(), "tetrahedra");
    if let Ok(edges) = world.get::<&EdgeConstraints>(e) {
        let own: Vec<[u32; 2]> = edges
            .edges()
            .iter()
            .map(|&[a, b]| [a.min(b), a.max(b)])
            .collect();
        assert_eq!(sorted(&own), unique_edges(t.indices()), "edges");
        classes_are_independent(edges.classes(), edges.edges(), "edges");
    }
    if let Ok(vf) = world.get::<&VertexFaceConstraints>(e) {
        assert_eq!(vf.rest_heights().len(), t.len());
    }
    if let Ok(v) = world.get::<&VolumeConstraints>(e) {
        assert_eq!(v.len(), t.len());
    }
}

/// Bars of each family pulled apart at both ends until they fall into pieces: after every
/// frame that tore, every body is consistent.
#[test]
fn torn_pieces_keep_consistent_meshes_and_families() {
    for family in 0..3 {
        let mut world = World::new();
        let settings = TearingSettings {
            strain: Some(0.15),
            smoothing_time: 0.02,
            ..Default::default()
        };
        let size = Vector3::new(2.0, 0.4, 0.4);
        pinned_bar(&mut world, size, [8, 2, 2], settings, |b| match family {
            0 => b.material(Material::new(1e6, 0.3).unwrap()),
            1 => b.edges(1e-6).vertex_face(1e-6),
            _ => b.edges(0.0).volume(0.0),
        });
        let mut solver = Solver::new(SolverSettings::default()).unwrap();
        let mut tears = 0;
        for _ in 0..90 {
            pull_ends(&mut world, 2.0 / 60.0);
            solver.step(&mut world).unwrap();
            if !solver.tear_events().is_empty() {
                tears += 1;
                let bodies: Vec<Entity> = world
                    .query::<(Entity, &Particles)>()
                    .iter()
                    .map(|(e, _)| e)
                    .collect();
                for e in bodies {
                    assert_consistent(&world, e);
                }
            }
        }
        assert!(tears > 0 && world.len() > 1, "family {family}: no split");
    }
}

/// The body particle a piece's particle comes from.
fn origin(event: &tetpbd::TearEvent, from: u32) -> u32 {
    let before = event.particles_before as u32;
    if from < before {
        from
    } else {
        event.copies[(from - before) as usize]
    }
}

/// How many tetrahedra hold each edge, the particles named through `map`.
fn edge_holders(tets: &[[u32; 4]], map: impl Fn(u32) -> u32) -> BTreeMap<[u32; 2], usize> {
    let mut by_edge = BTreeMap::new();
    for tet in tets {
        for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
            let (a, b) = (map(tet[i]), map(tet[j]));
            *by_edge.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    by_edge
}

/// A plastic bar bent and flowed, then cut in two: each piece keeps, for each of its
/// tetrahedra, the body's plastic stretch, rest heights and rest volume, and for each edge
/// the body's rest length between the same particles.
#[test]
fn a_cut_plastic_bar_keeps_its_rest_state_in_each_piece() {
    let bar = Bar {
        length: 1.0,
        cells: 8,
        substeps: 5,
        families: Families::EdgesVertexFace,
    };
    let mut world = World::new();
    let e = spawn_bar(&mut world, bar, Some(PlasticitySettings::default()));
    {
        let mut p = world.get::<&mut Particles>(e).unwrap();
        for i in 0..p.len() {
            let x = p.positions()[i];
            let bent = Vector3::new(1.3 * x.x, x.y + 0.4 * x.x * x.x, x.z);
            p.set_position(i, bent).unwrap();
        }
    }
    let mut solver = solver(bar.substeps, 0.0);
    for _ in 0..5 {
        solver.step(&mut world).unwrap();
    }
    // The body's rest state, by source tetrahedron and by particle pair.
    let (stretch, heights, volumes, lengths) = {
        let t = world.get::<&Tetrahedra>(e).unwrap();
        let pl = world.get::<&Plasticity>(e).unwrap();
        let vf = world.get::<&VertexFaceConstraints>(e).unwrap();
        let ed = world.get::<&EdgeConstraints>(e).unwrap();
        assert!(pl.max_plastic_strain() > 0.01, "the bar flowed");
        let mut stretch: BTreeMap<u32, Matrix3<f64>> = BTreeMap::new();
        let mut heights = BTreeMap::new();
        let mut volumes = BTreeMap::new();
        for (k, &src) in t.source().iter().enumerate() {
            stretch.insert(src, pl.stretches()[k]);
            heights.insert(src, vf.rest_heights()[k]);
            volumes.insert(src, t.rest_volumes()[k]);
        }
        let lengths: BTreeMap<[u32; 2], f32> = ed
            .edges()
            .iter()
            .zip(ed.rest_lengths())
            .map(|(&[a, b], &l)| ([a.min(b), a.max(b)], l))
            .collect();
        (stretch, heights, volumes, lengths)
    };
    let holders_before = edge_holders(world.get::<&Tetrahedra>(e).unwrap().indices(), |i| i);
    let blade = Blade::Plane {
        point: Vector3::new(0.01, 0.0, 0.0),
        normal: Vector3::x(),
    };
    let event = cut(&mut world, e, &blade)
        .unwrap()
        .expect("the cut split the bar");
    assert_eq!(event.pieces.len(), 2);
    for piece in &event.pieces {
        assert_consistent(&world, piece.entity);
        let t = world.get::<&Tetrahedra>(piece.entity).unwrap();
        let pl = world.get::<&Plasticity>(piece.entity).unwrap();
        let vf = world.get::<&VertexFaceConstraints>(piece.entity).unwrap();
        let ed = world.get::<&EdgeConstraints>(piece.entity).unwrap();
        for (k, src) in t.source().iter().enumerate() {
            assert_eq!(
                pl.stretches()[k],
                stretch[src],
                "stretch of tetrahedron {src}"
            );
            assert_eq!(vf.rest_heights()[k], heights[src], "heights of {src}");
            assert_eq!(t.rest_volumes()[k], volumes[src], "volume of {src}");
        }
        // A plastic edge's rest length is the mean of what its tetrahedra say: an edge all of
        // whose tetrahedra went to this piece keeps its length exactly; one on the cut is
        // averaged over the tetrahedra on its side.
        let in_piece = edge_holders(t.indices(), |i| origin(&event, piece.particles[i as usize]));
        let mut kept = 0;
        for (&[a, b], &l) in ed.edges().iter().zip(ed.rest_lengths()) {
            let (oa, ob) = (
                origin(&event, piece.particles[a as usize]),
                origin(&event, piece.particles[b as usize]),
            );
            let key = [oa.min(ob), oa.max(ob)];
            if in_piece[&key] == holders_before[&key] {
                assert_eq!(l, lengths[&key], "edge {oa}–{ob}");
                kept += 1;
            } else {
                assert!(
                    (l / lengths[&key] - 1.0).abs() < 0.2,
                    "edge {oa}–{ob}: {l} m"
                );
            }
        }
        assert!(kept > ed.len() / 2, "{kept} of {} edges whole", ed.len());
    }
}
