//! µs per scene query against soft bodies ([`tetpbd_rapier::SoftQueries`]), single-threaded:
//! ray casts (first hit and all hits), point projection and containment, and the snapshot
//! refresh, on one ~10k-tetrahedron body and on a scene of 100 bodies.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin queries [-- --cells N --queries Q --repeats R]
//! ```
//!
//! `--cells` (default 12: 12³ × 6 = 10 368 tetrahedra) sizes the single body; the scene is
//! 10 × 10 cubes of 4³ × 6 = 384 tetrahedra each. Rays start on a sphere around the scene
//! and aim at random points inside a random body's box, so nearly every ray hits; points
//! are random within the scene's box grown by 0.5 m. Each sample times `--queries`
//! (default 2000) queries; the median, min and max over `--repeats` (default 21) samples are
//! printed (CPU time of the thread), and for the first-hit ray cast the ratio to testing
//! every surface triangle of every body (what the BVHs save). The snapshot refresh
//! (`SoftQueries::update`) is timed with the bodies at rest and after every particle moved
//! by 1 mm (as after a step: every BVH is refitted).

use clap::Parser;
use hecs::World;
use nalgebra::Vector3;
use rapier3d::geometry::Ray;
use rapier3d::math::Vector;
use std::hint::black_box;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, Surface};
use tetpbd_bench::thread_cpu_ms;

/// µs per scene query against soft bodies (ray casts, point projection and containment,
/// snapshot refresh) on one body and on a scene of 100 bodies, single-threaded.
#[derive(Parser)]
#[command(name = "queries")]
struct Args {
    /// Cells per side of the single body (12: 10 368 tetrahedra).
    #[arg(long, default_value_t = 12)]
    cells: u32,
    /// Queries timed per sample.
    #[arg(long, default_value_t = 2000)]
    queries: usize,
    /// Samples per query kind (median, min and max printed).
    #[arg(long, default_value_t = 21)]
    repeats: usize,
}
use tetpbd_rapier::{SoftQueries, SoftQueryFilter};

/// A small deterministic generator (xorshift64*), uniform in `[0, 1)`.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32 / (1u64 << 24) as f32
    }

    fn in_box(&mut self, lo: &Vector3<f32>, hi: &Vector3<f32>) -> Vector3<f32> {
        Vector3::new(
            lo.x + (hi.x - lo.x) * self.unit(),
            lo.y + (hi.y - lo.y) * self.unit(),
            lo.z + (hi.z - lo.z) * self.unit(),
        )
    }

    fn direction(&mut self) -> Vector3<f32> {
        loop {
            let v = self.in_box(&Vector3::repeat(-1.0), &Vector3::repeat(1.0));
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
}

/// One scene: the world, its bodies' boxes, and the query snapshot.
struct Scene {
    name: String,
    world: World,
    boxes: Vec<(Vector3<f32>, Vector3<f32>)>,
    queries: SoftQueries,
}

impl Scene {
    fn new(
        name: String,
        bodies: &[(f32, u32, Vector3<f32>)],
    ) -> Result<Scene, Box<dyn std::error::Error>> {
        let mut world = World::new();
        let mut boxes = Vec::new();
        for &(size, cells, at) in bodies {
            let mesh = box_grid(Vector3::repeat(size), [cells; 3], CellSplit::Six)?;
            SoftBodyBuilder::new(mesh)
                .translation(at)
                .build()?
                .spawn(&mut world);
            boxes.push((
                at - Vector3::repeat(size / 2.0),
                at + Vector3::repeat(size / 2.0),
            ));
        }
        let mut queries = SoftQueries::new();
        queries.update(&world);
        Ok(Scene {
            name,
            world,
            boxes,
            queries,
        })
    }

    fn bounds(&self) -> (Vector3<f32>, Vector3<f32>) {
        self.boxes.iter().fold(
            (Vector3::repeat(f32::MAX), Vector3::repeat(f32::MIN)),
            |(lo, hi), (a, b)| (lo.inf(a), hi.sup(b)),
        )
    }

    /// Rays from a sphere around the scene at random points of random bodies.
    fn rays(&self, rng: &mut Rng, n: usize) -> Vec<Ray> {
        let (lo, hi) = self.bounds();
        let (centre, radius) = ((lo + hi) / 2.0, (hi - lo).norm());
        (0..n)
            .map(|_| {
                let (a, b) =
                    self.boxes[(rng.unit() * self.boxes.len() as f32) as usize % self.boxes.len()];
                let target = rng.in_box(&a, &b);
                let origin = centre + rng.direction() * radius;
                let d = (target - origin).normalize();
                Ray::new(
                    Vector::new(origin.x, origin.y, origin.z),
                    Vector::new(d.x, d.y, d.z),
                )
            })
            .collect()
    }

    fn points(&self, rng: &mut Rng, n: usize) -> Vec<Vector> {
        let (lo, hi) = self.bounds();
        let m = Vector3::repeat(0.5);
        (0..n)
            .map(|_| {
                let p = rng.in_box(&(lo - m), &(hi + m));
                Vector::new(p.x, p.y, p.z)
            })
            .collect()
    }

    /// Every surface triangle of every body, for the brute-force reference.
    fn triangles(&self) -> Vec<[Vector3<f32>; 3]> {
        let mut out = Vec::new();
        for (p, s) in self.world.query::<(&Particles, &Surface)>().iter() {
            out.extend(
                s.triangles()
                    .iter()
                    .map(|t| t.map(|i| p.positions()[i as usize])),
            );
        }
        out
    }
}

/// Möller–Trumbore over every triangle: the nearest hit (the brute-force reference).
fn brute_force(tris: &[[Vector3<f32>; 3]], ray: &Ray) -> Option<f32> {
    let o = Vector3::new(ray.origin.x, ray.origin.y, ray.origin.z);
    let d = Vector3::new(ray.dir.x, ray.dir.y, ray.dir.z);
    let mut best: Option<f32> = None;
    for [a, b, c] in tris {
        let (e1, e2) = (b - a, c - a);
        let pv = d.cross(&e2);
        let det = e1.dot(&pv);
        if det.abs() < 1e-12 {
            continue;
        }
        let tv = o - a;
        let u = tv.dot(&pv) / det;
        let qv = tv.cross(&e1);
        let v = d.dot(&qv) / det;
        let t = e2.dot(&qv) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t >= 0.0 && best.is_none_or(|b| t < b) {
            best = Some(t);
        }
    }
    best
}

/// Median, min and max of µs per item over `repeats` samples of `run` over `items`, in CPU
/// time of the calling thread (what a loaded, shared machine inflates least).
fn time<T>(items: &[T], repeats: usize, mut run: impl FnMut(&T)) -> [f64; 3] {
    let mut samples: Vec<f64> = (0..repeats)
        .map(|_| {
            let start = thread_cpu_ms();
            for item in items {
                run(item);
            }
            (thread_cpu_ms() - start) * 1e3 / items.len() as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    [
        samples[samples.len() / 2],
        samples[0],
        samples[samples.len() - 1],
    ]
}

fn row(what: &str, [median, min, max]: [f64; 3], extra: &str) {
    println!("  {what:<34} {median:>10.3} {min:>10.3} {max:>10.3}  {extra}");
}

fn measure(scene: &mut Scene, n: usize, repeats: usize) -> Result<(), Box<dyn std::error::Error>> {
    let tets: usize = scene
        .world
        .query::<&tetpbd::Tetrahedra>()
        .iter()
        .map(|t| t.len())
        .sum();
    let tris = scene.triangles();
    println!(
        "{}: {} bodies, {tets} tetrahedra, {} surface triangles; {n} queries per sample, {repeats} samples",
        scene.name,
        scene.boxes.len(),
        tris.len()
    );
    println!(
        "  {:<34} {:>10} {:>10} {:>10}",
        "query", "median µs", "min", "max"
    );
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let rays = scene.rays(&mut rng, n);
    let points = scene.points(&mut rng, n);
    let f = SoftQueryFilter::new();
    let q = &scene.queries;
    let hits = rays
        .iter()
        .filter(|r| q.cast_ray(r, f32::MAX, true, f).ok().flatten().is_some())
        .count();
    let first = time(&rays, repeats, |r| {
        black_box(q.cast_ray(r, f32::MAX, true, f).ok());
    });
    row(
        "cast_ray (first hit), per ray",
        first,
        &format!("{hits}/{n} rays hit"),
    );
    let all = time(&rays, repeats, |r| {
        black_box(q.intersect_ray(r, f32::MAX, true, f).ok());
    });
    row("intersect_ray (all hits), per ray", all, "");
    let brute_rays = &rays[..(n / 20).max(1)];
    let brute = time(brute_rays, repeats.min(5), |r| {
        black_box(brute_force(&tris, r));
    });
    row(
        "every triangle (reference), per ray",
        brute,
        &format!("{:.0}× the BVH cast", brute[0] / first[0]),
    );
    let proj = time(&points, repeats, |p| {
        black_box(q.project_point(*p, f32::MAX, f).ok());
    });
    row("project_point, per point", proj, "");
    let inside = points
        .iter()
        .filter(|p| q.contains_point(**p, f).ok().flatten().is_some())
        .count();
    let contains = time(&points, repeats, |p| {
        black_box(q.contains_point(*p, f).ok());
    });
    row(
        "contains_point, per point",
        contains,
        &format!("{inside}/{n} points inside"),
    );
    time_update(scene, repeats);
    Ok(())
}

/// Times `SoftQueries::update` on a copy of the scene's snapshot: bodies at rest, then after
/// every particle moved by 1 mm (as after a step).
fn time_update(scene: &mut Scene, repeats: usize) {
    let mut snapshot = scene.queries.clone();
    let world = &mut scene.world;
    let rest = time(&[()], repeats, |_| snapshot.update(world));
    row("update, bodies at rest, per call", rest, "");
    let mut moved = [0.0f64; 3];
    let mut samples = Vec::new();
    for k in 0..repeats {
        // Every particle moves a little (as after a step): every BVH is refitted.
        for p in world.query_mut::<&mut Particles>() {
            for x in p.positions_mut() {
                x.y += if k % 2 == 0 { 1e-3 } else { -1e-3 };
            }
        }
        samples.push(time(&[()], 1, |_| snapshot.update(world))[0]);
    }
    samples.sort_by(f64::total_cmp);
    moved[0] = samples[samples.len() / 2];
    moved[1] = samples[0];
    moved[2] = samples[samples.len() - 1];
    row("update, every body moved, per call", moved, "");
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args {
        cells,
        queries: n,
        repeats,
    } = Args::parse();
    let mut one = Scene::new(
        format!("one body, {cells}³ cells"),
        &[(1.0, cells, Vector3::zeros())],
    )?;
    measure(&mut one, n, repeats)?;
    let grid: Vec<_> = (0..100)
        .map(|i| {
            (
                0.5,
                4,
                Vector3::new((i % 10) as f32, 0.25 * (i % 3) as f32, (i / 10) as f32),
            )
        })
        .collect();
    let mut many = Scene::new("100 bodies of 4³ cells".to_string(), &grid)?;
    measure(&mut many, n, repeats)?;
    deformed(cells, n, repeats)
}

/// Rays on the single body after a strong deformation (stretched 2× along x, sheared by
/// 0.5 y along x): its trees refitted since they were built on the undeformed shape, against
/// trees built on the deformed shape (what the refit costs in tree quality).
fn deformed(cells: u32, n: usize, repeats: usize) -> Result<(), Box<dyn std::error::Error>> {
    let mut scene = Scene::new(String::new(), &[(1.0, cells, Vector3::zeros())])?;
    for p in scene.world.query_mut::<&mut Particles>() {
        for x in p.positions_mut() {
            *x = Vector3::new(2.0 * x.x + 0.5 * x.y, x.y, x.z);
        }
    }
    scene.queries.update(&scene.world);
    let mut fresh = SoftQueries::new();
    fresh.update(&scene.world);
    // The deformed box, for aiming the rays.
    scene.boxes = vec![(
        Vector3::new(-1.25, -0.5, -0.5),
        Vector3::new(1.25, 0.5, 0.5),
    )];
    let rays = scene.rays(&mut Rng(0x2545_f491_4f6c_dd1d), n);
    let f = SoftQueryFilter::new();
    println!("one body, {cells}³ cells, stretched 2× and sheared 0.5 after its trees were built");
    let refitted = time(&rays, repeats, |r| {
        black_box(scene.queries.cast_ray(r, f32::MAX, true, f).ok());
    });
    row("cast_ray, refitted trees", refitted, "");
    let rebuilt = time(&rays, repeats, |r| {
        black_box(fresh.cast_ray(r, f32::MAX, true, f).ok());
    });
    let ratio = format!("refitted / built: {:.2}", refitted[0] / rebuilt[0]);
    row("cast_ray, trees built on this shape", rebuilt, &ratio);
    Ok(())
}
