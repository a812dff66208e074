//! Frame export files, collider tessellation, progress and the frame-output session.

use nalgebra::Vector3;
use rapier3d::math::{Pose, Vector};
use rapier3d::parry::shape::{
    Ball, Compound, Cuboid, HalfSpace, RoundCuboid, RoundShape, Segment, SharedShape,
};
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder};
use tetpbd_rapier::CoupledWorld;
use tetpbd_viz::{shape_mesh, FrameExport, Progress, Snapshot, VizError, VizOptions};

fn temp_dir(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("tetpbd-viz-{name}-{}", std::process::id()))
}

#[test]
fn every_frame_writes_soft_and_rigid_obj_and_tetrahedra_vtu() {
    let mut scene = CoupledWorld::new(Default::default(), Default::default()).unwrap();
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(2.0, 0.5, 2.0),
    );
    let mesh = box_grid(Vector3::repeat(0.4), [2, 2, 2], CellSplit::Six).unwrap();
    let tets = mesh.tets.len();
    let cube = SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .volume(0.0)
        .translation(Vector3::new(0.0, 0.5, 0.0))
        .build()
        .unwrap()
        .spawn(&mut scene.soft);
    let dir = temp_dir("export");
    let mut export = FrameExport::new(&dir).unwrap();
    for _ in 0..3 {
        scene.step().unwrap();
        let snapshot = Snapshot::capture(&scene);
        export.write(&scene, &snapshot).unwrap();
    }
    assert_eq!(export.frames(), 3);
    let soft = format!("soft{}", cube.id());
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    let mut expected = Vec::new();
    for f in 0..3 {
        expected.push(format!("rigid0_{f:04}.obj"));
        expected.push(format!("{soft}_{f:04}.obj"));
        expected.push(format!("{soft}_{f:04}.vtu"));
    }
    expected.sort();
    assert_eq!(names, expected);

    // The ground box: 8 corners at x, z = ±2 m, y = 0 or −1 m; 12 triangles.
    let ground = std::fs::read_to_string(dir.join("rigid0_0002.obj")).unwrap();
    let corners: Vec<Vec<f32>> = ground
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(corners.len(), 8);
    for c in &corners {
        assert_eq!(c[0].abs(), 2.0);
        assert!(c[1] == 0.0 || c[1] == -1.0, "y = {}", c[1]);
        assert_eq!(c[2].abs(), 2.0);
    }
    assert_eq!(ground.lines().filter(|l| l.starts_with("f ")).count(), 12);

    // The soft surface OBJ holds the body's current positions.
    let obj = std::fs::read_to_string(dir.join(format!("{soft}_0002.obj"))).unwrap();
    let lowest = obj
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| l.split(' ').nth(1).unwrap().parse::<f32>().unwrap())
        .fold(f32::MAX, f32::min);
    let aabb_low = scene.soft.get::<&Particles>(cube).unwrap().aabb().0.y;
    assert_eq!(lowest, aabb_low);
    let vtu = std::fs::read_to_string(dir.join(format!("{soft}_0002.vtu"))).unwrap();
    assert!(vtu.contains(&format!("NumberOfCells=\"{tets}\"")));
    assert!(vtu.contains("Name=\"volume_ratio\"") && vtu.contains("Name=\"inverted\""));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unwritable_folder_is_a_typed_error() {
    let file = temp_dir("not-a-folder");
    std::fs::write(&file, "x").unwrap();
    let err = FrameExport::new(file.join("sub")).unwrap_err();
    assert!(matches!(err, VizError::Io { .. }), "{err}");
    assert!(err.to_string().contains("not-a-folder"));
    std::fs::remove_file(&file).unwrap();
}

#[test]
fn collider_shapes_become_triangle_meshes_of_their_size() {
    let ball = shape_mesh(&Ball::new(0.3)).unwrap();
    assert!(ball.triangles.len() > 100);
    assert!(ball.positions.iter().all(|p| (p.norm() - 0.3).abs() < 1e-5));

    let cuboid = shape_mesh(&Cuboid::new(Vector::new(1.0, 2.0, 3.0))).unwrap();
    assert_eq!(cuboid.triangles.len(), 12);
    assert_eq!(
        cuboid.aabb(),
        Some((Vector3::new(-1.0, -2.0, -3.0), Vector3::new(1.0, 2.0, 3.0)))
    );

    let round = RoundCuboid {
        inner_shape: Cuboid::new(Vector::splat(1.0)),
        border_radius: 0.5,
    };
    let rounded = shape_mesh(&round as &RoundShape<Cuboid>).unwrap();
    let (lo, hi) = rounded.aabb().unwrap();
    assert!((hi - Vector3::repeat(1.5)).amax() < 1e-4, "{hi}");
    assert!((lo + Vector3::repeat(1.5)).amax() < 1e-4, "{lo}");

    let parts = vec![
        (
            Pose::from_translation(Vector::new(5.0, 0.0, 0.0)),
            SharedShape::cuboid(0.5, 0.5, 0.5),
        ),
        (Pose::IDENTITY, SharedShape::ball(0.5)),
    ];
    let compound = shape_mesh(&Compound::new(parts)).unwrap();
    let (lo, hi) = compound.aabb().unwrap();
    assert!((hi.x - 5.5).abs() < 1e-5 && (lo.x + 0.5).abs() < 1e-5);
    assert!(compound.triangles.len() > 12 + 100);

    let plane = shape_mesh(&HalfSpace::new(Vector::Y)).unwrap();
    assert_eq!(plane.triangles.len(), 2);
    assert!(plane.positions.iter().all(|p| p.y == 0.0));

    assert!(shape_mesh(&Segment::new(Vector::ZERO, Vector::X)).is_none());
}

#[test]
fn progress_counts_and_reports_its_count() {
    let mut p = Progress::with_terminal("frames", 40, false);
    for _ in 0..10 {
        p.inc(3);
    }
    assert_eq!(p.done(), 30);
    assert!(
        p.line().starts_with("frames: 30/40 (75 %), "),
        "{}",
        p.line()
    );
    p.finish();
    let mut bar = Progress::with_terminal("bar", 5, true);
    bar.inc(5);
    assert_eq!(bar.done(), 5);
    bar.finish();
}

#[test]
fn a_viz_session_writes_every_output_it_was_asked_for() {
    use tetpbd::{Solver, SolverSettings};
    use tetpbd_viz::{RenderSettings, Viz};

    let dir = temp_dir("session");
    let options = VizOptions {
        export: Some(dir.join("frames")),
        render: Some(dir.join("png")),
        strip: Some(dir.join("strip.png")),
        strip_frames: 3,
        animate: Some(dir.join("anim.png")),
    };
    let settings = RenderSettings {
        width: 40,
        height: 30,
        ..Default::default()
    };
    let mut viz = Viz::new(options, settings).unwrap();
    assert!(viz.is_active());
    let mut world = tetpbd::hecs::World::new();
    let mesh = box_grid(Vector3::repeat(0.5), [1, 1, 1], CellSplit::Six).unwrap();
    SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .build()
        .unwrap()
        .spawn(&mut world);
    let mut solver = Solver::new(SolverSettings::default()).unwrap();
    for _ in 0..5 {
        solver.step(&mut world).unwrap();
        viz.frame(&world).unwrap();
    }
    viz.finish().unwrap();
    let count = |sub: &str| std::fs::read_dir(dir.join(sub)).unwrap().count();
    assert_eq!(count("frames"), 10, "5 frames × (OBJ + VTU)");
    assert_eq!(count("png"), 5);
    let size = |name: &str| {
        let reader = png::Decoder::new(std::fs::File::open(dir.join(name)).unwrap())
            .read_info()
            .unwrap();
        let frames = reader
            .info()
            .animation_control()
            .map_or(1, |a| a.num_frames);
        (reader.info().width, reader.info().height, frames)
    };
    assert_eq!(size("strip.png"), (3 * 40 + 2 * 2, 30, 1));
    assert_eq!(size("anim.png"), (40, 30, 5));
    assert_eq!(size("png/frame_0004.png"), (40, 30, 1));
    std::fs::remove_dir_all(&dir).unwrap();

    let mut idle = Viz::new(VizOptions::default(), RenderSettings::default()).unwrap();
    assert!(!idle.is_active());
    idle.frame(&world).unwrap();
    idle.finish().unwrap();
}
