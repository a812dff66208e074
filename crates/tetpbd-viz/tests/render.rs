//! The software rasterizer, views and PNG output, on scenes whose pictures are known.

use nalgebra::Vector3;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::SoftBodyBuilder;
use tetpbd_rapier::CoupledWorld;
use tetpbd_viz::{
    strip, write_png, Camera, Item, ItemKind, Raster, RenderSettings, Snapshot, TriangleMesh, View,
};

const BG: [u8; 3] = [10, 20, 30];
const RED: [u8; 3] = [200, 0, 0];
const BLUE: [u8; 3] = [0, 0, 200];

/// A camera on the +z axis at 5 m looking at the origin, 90° field of view.
fn camera() -> Camera {
    Camera {
        eye: Vector3::new(0.0, 0.0, 5.0),
        target: Vector3::zeros(),
        fov_y: 90f32.to_radians(),
        near: 0.1,
    }
}

/// A square of half side `h` at height `z`, facing the camera, as two triangles.
fn square(h: f32, z: f32) -> [[Vector3<f32>; 3]; 2] {
    let v = |x, y| Vector3::new(x, y, z);
    [
        [v(-h, -h), v(h, -h), v(h, h)],
        [v(-h, -h), v(h, h), v(-h, h)],
    ]
}

#[test]
fn a_square_covers_the_centre_and_leaves_the_corners() {
    let mut r = Raster::new(64, 48, BG).unwrap();
    for t in square(1.0, 0.0) {
        r.triangle(&camera(), t, RED);
    }
    // At 5 m with a 90° field of view the image is 10 m tall: a 2 m square spans ~20 % of it.
    assert_eq!(r.pixel(32, 24), Some(RED));
    assert_eq!(r.pixel(0, 0), Some(BG));
    assert_eq!(r.pixel(63, 47), Some(BG));
    assert_eq!(r.pixel(32, 24 - 8), Some(BG), "above the square's top edge");
    assert_eq!(
        r.pixel(32, 24 - 4),
        Some(RED),
        "inside the square's top edge"
    );
    assert_eq!(r.pixel(64, 0), None);
}

#[test]
fn the_nearer_of_two_overlapping_triangles_wins_in_either_drawing_order() {
    for near_first in [true, false] {
        let mut r = Raster::new(40, 40, BG).unwrap();
        let near = square(1.0, 1.0);
        let far = square(2.0, -1.0);
        let mut draws = vec![(near, RED), (far, BLUE)];
        if !near_first {
            draws.reverse();
        }
        for (tris, color) in draws {
            for t in tris {
                r.triangle(&camera(), t, color);
            }
        }
        assert_eq!(r.pixel(20, 20), Some(RED), "near_first = {near_first}");
        // The far square is larger: its rim shows around the near one.
        // Half sides on the picture: near 1 m / 4 m × 20 px = 5 px, far 2 m / 6 m × 20 px ≈ 6.7 px.
        assert_eq!(r.pixel(20, 14), Some(BLUE), "near_first = {near_first}");
    }
}

#[test]
fn triangles_through_the_near_plane_are_cut_not_dropped_or_flipped() {
    let mut r = Raster::new(40, 40, BG).unwrap();
    // A floor 1 m under the eye reaching from in front of the camera to behind it.
    let v = |x, z| Vector3::new(x, -1.0, z);
    r.triangle(&camera(), [v(-3.0, 0.0), v(3.0, 0.0), v(0.0, 10.0)], RED);
    // The part in front of the camera covers the bottom middle of the picture…
    assert_eq!(r.pixel(20, 38), Some(RED));
    // …and nothing behind the eye is mirrored into the upper half.
    for y in 0..20 {
        for x in 0..40 {
            assert_eq!(r.pixel(x, y), Some(BG), "pixel ({x}, {y})");
        }
    }
}

#[test]
fn lines_show_on_the_plane_they_lie_on() {
    let mut r = Raster::new(40, 40, BG).unwrap();
    for t in square(2.0, 0.0) {
        r.triangle(&camera(), t, BLUE);
    }
    r.line(
        &camera(),
        Vector3::new(-2.0, 0.0, 0.0),
        Vector3::new(2.0, 0.0, 0.0),
        RED,
        1e-3,
    );
    assert_eq!(r.pixel(20, 20), Some(RED));
    assert_eq!(r.pixel(20, 15), Some(BLUE));
    // Without the bias towards the camera a line behind the square is hidden.
    r.line(
        &camera(),
        Vector3::new(0.0, -1.0, -0.5),
        Vector3::new(0.0, 1.0, -0.5),
        RED,
        1e-3,
    );
    assert_eq!(r.pixel(20, 15), Some(BLUE));
}

#[test]
fn bad_image_sizes_are_typed_errors() {
    assert!(Raster::new(0, 10, BG).is_err());
    assert!(Raster::new(10, 20_000, BG).is_err());
    assert!(strip(&[], BG).is_err());
    let a = Raster::new(4, 4, BG).unwrap();
    let b = Raster::new(4, 5, BG).unwrap();
    assert!(strip(&[a, b], BG).is_err());
}

#[test]
fn png_and_strip_decode_to_the_right_size_and_pixels() {
    let dir = std::env::temp_dir().join(format!("tetpbd-viz-png-{}", std::process::id()));
    let mut a = Raster::new(30, 20, BG).unwrap();
    for t in square(1.0, 0.0) {
        a.triangle(&camera(), t, RED);
    }
    let b = Raster::new(30, 20, [255, 255, 255]).unwrap();
    let s = strip(&[a.clone(), b.clone()], [0, 0, 0]).unwrap();
    assert_eq!((s.width(), s.height()), (62, 20));
    assert_eq!(s.pixel(31, 5), Some([0, 0, 0]), "the gap");
    assert_eq!(s.pixel(40, 5), Some([255, 255, 255]), "the second frame");

    let path = dir.join("strip.png");
    write_png(&path, &[s], 0).unwrap();
    let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (62, 20));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let px = |x: usize, y: usize| &buf[3 * (y * 62 + x)..3 * (y * 62 + x) + 3];
    assert_eq!(px(15, 10), &RED[..]);
    assert_eq!(px(0, 0), &BG[..]);

    let anim = dir.join("anim.png");
    write_png(&anim, &[a, b], 50).unwrap();
    let reader = png::Decoder::new(std::fs::File::open(&anim).unwrap())
        .read_info()
        .unwrap();
    let control = reader.info().animation_control().expect("an APNG");
    assert_eq!(control.num_frames, 2);
    std::fs::remove_dir_all(&dir).unwrap();
}

fn cube_item(kind: ItemKind, half: f32, center: Vector3<f32>) -> Item {
    let mesh = tetpbd_viz::shape_mesh(&rapier3d::parry::shape::Cuboid::new(
        rapier3d::math::Vector::splat(half),
    ))
    .unwrap();
    let iso = nalgebra::Isometry3::translation(center.x, center.y, center.z);
    Item {
        kind,
        name: "cube".into(),
        mesh: mesh.transformed(&iso),
    }
}

#[test]
fn a_view_frames_the_moving_bodies_and_stands_them_on_the_fixed_ground() {
    let ground = cube_item(ItemKind::Fixed, 5.0, Vector3::new(0.0, -5.0, 0.0));
    let body = cube_item(ItemKind::Dynamic, 0.25, Vector3::new(1.0, 0.25, 0.0));
    let snapshot = Snapshot {
        items: vec![ground, body],
    };
    let settings = RenderSettings {
        width: 80,
        height: 60,
        ..Default::default()
    };
    let view = View::fit(&[&snapshot], &settings);
    assert!((view.camera.target - Vector3::new(1.0, 0.25, 0.0)).norm() < 1e-5);
    assert_eq!(view.ground.y, 0.0, "the fixed box's top");
    assert!(!view.ground.fill, "the fixed box is the ground");
    let picture = view.render(&snapshot, &settings).unwrap();
    let centre = picture.pixel(40, 30).unwrap();
    assert!(
        centre[2] > centre[0] && centre[2] > centre[1],
        "the dynamic (blue) box is at the centre: {centre:?}"
    );
    assert_eq!(picture.pixel(0, 0), Some(settings.background));
}

#[test]
fn a_coupled_scene_renders_its_soft_body_and_its_ball() {
    let mut scene = CoupledWorld::new(Default::default(), Default::default()).unwrap();
    scene.physics.insert(
        RigidBodyBuilder::dynamic().translation(rapier3d::math::Vector::new(2.0, 0.5, 0.0)),
        ColliderBuilder::ball(0.5),
    );
    let mesh = box_grid(Vector3::repeat(1.0), [2, 2, 2], CellSplit::Six).unwrap();
    SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .translation(Vector3::new(-2.0, 0.5, 0.0))
        .build()
        .unwrap()
        .spawn(&mut scene.soft);
    let snapshot = Snapshot::capture(&scene);
    let kinds: Vec<ItemKind> = snapshot.items.iter().map(|i| i.kind).collect();
    assert_eq!(kinds, vec![ItemKind::Soft, ItemKind::Dynamic]);
    let ball = &snapshot.items[1].mesh;
    for p in &ball.positions {
        let r = (p - Vector3::new(2.0, 0.5, 0.0)).norm();
        assert!(
            (r - 0.5).abs() < 1e-4,
            "ball vertex at {r} m from its centre"
        );
    }
    let settings = RenderSettings {
        width: 120,
        height: 60,
        view_from: Vector3::new(0.0, 0.0, 1.0),
        ..Default::default()
    };
    let view = View::fit(&[&snapshot], &settings);
    assert!(view.ground.fill, "no fixed collider: a plane of its own");
    assert!(view.ground.y.abs() < 1e-5, "under the lowest point, y = 0");
    let picture = view.render(&snapshot, &settings).unwrap();
    // Seen from +z: the soft body (orange: red > blue) on the left, the ball (blue) right.
    let count = |f: &dyn Fn([u8; 3]) -> bool, xs: std::ops::Range<u32>| {
        xs.flat_map(|x| (0..60).map(move |y| (x, y)))
            .filter(|&(x, y)| f(picture.pixel(x, y).unwrap()))
            .count()
    };
    let orange = |c: [u8; 3]| i32::from(c[0]) > i32::from(c[2]) + 60;
    let blue = |c: [u8; 3]| i32::from(c[2]) > i32::from(c[0]) + 60;
    assert!(count(&orange, 0..60) > 50);
    assert_eq!(count(&orange, 60..120), 0);
    assert!(count(&blue, 60..120) > 30);
    assert_eq!(count(&blue, 0..60), 0);
}

#[test]
fn meshes_append_and_bound() {
    let mut m = TriangleMesh {
        positions: vec![Vector3::zeros(), Vector3::x(), Vector3::y()],
        triangles: vec![[0, 1, 2]],
    };
    m.append(m.clone());
    assert_eq!(m.triangles[1], [3, 4, 5]);
    assert_eq!(
        m.aabb(),
        Some((Vector3::zeros(), Vector3::new(1.0, 1.0, 0.0)))
    );
    assert_eq!(TriangleMesh::default().aabb(), None);
}
