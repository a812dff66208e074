//! Mesh generators: a box grid, a ball, a beam, and a shuffled copy of a mesh.

use nalgebra::Vector3;

use crate::body::builder::TetMesh;
use crate::constraints::signed_volume;
use crate::error::BuildError;

/// How a grid cell is split into tetrahedra.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellSplit {
    /// Five tetrahedra per cell (a central one and four corners), mirrored in alternate
    /// cells so neighbouring faces match.
    Five,
    /// Six tetrahedra per cell around the main diagonal (Kuhn / Freudenthal split), the
    /// same in every cell.
    Six,
}

/// A box of `size` (m), centred at the origin, split into `cells` cells per axis and each
/// cell into tetrahedra. All tetrahedra are positively oriented. Vertex `(i, j, k)` has index
/// `i + (cells[0] + 1) * (j + (cells[1] + 1) * k)`.
pub fn box_grid(
    size: Vector3<f32>,
    cells: [u32; 3],
    split: CellSplit,
) -> Result<TetMesh, BuildError> {
    check_grid(size, cells)?;
    let [nx, ny, nz] = cells;
    let (vx, vy) = (nx + 1, ny + 1);
    let id = |i: u32, j: u32, k: u32| i + vx * (j + vy * k);
    let cell = size.component_div(&Vector3::new(nx as f32, ny as f32, nz as f32));
    let mut vertices = Vec::with_capacity(((nx + 1) * (ny + 1) * (nz + 1)) as usize);
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                vertices.push(
                    Vector3::new(i as f32 * cell.x, j as f32 * cell.y, k as f32 * cell.z)
                        - size / 2.0,
                );
            }
        }
    }
    let per_cell = match split {
        CellSplit::Five => 5,
        CellSplit::Six => 6,
    };
    let mut tets = Vec::with_capacity((nx * ny * nz * per_cell) as usize);
    // Corner c of a cell is at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1).
    const FIVE_EVEN: [[usize; 4]; 5] = [
        [0, 1, 2, 4],
        [3, 2, 1, 7],
        [5, 4, 7, 1],
        [6, 7, 4, 2],
        [1, 2, 4, 7],
    ];
    const FIVE_ODD: [[usize; 4]; 5] = [
        [1, 0, 3, 5],
        [2, 3, 0, 6],
        [4, 5, 6, 0],
        [7, 6, 5, 3],
        [0, 3, 5, 6],
    ];
    const SIX: [[usize; 4]; 6] = [
        [0, 1, 3, 7],
        [0, 1, 5, 7],
        [0, 2, 3, 7],
        [0, 2, 6, 7],
        [0, 4, 5, 7],
        [0, 4, 6, 7],
    ];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let corner = |c: usize| {
                    let c = c as u32;
                    id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))
                };
                let pattern: &[[usize; 4]] = match split {
                    CellSplit::Six => &SIX,
                    CellSplit::Five if (i + j + k) % 2 == 0 => &FIVE_EVEN,
                    CellSplit::Five => &FIVE_ODD,
                };
                for t in pattern {
                    let mut tet = t.map(corner);
                    let [a, b, c, d] = tet.map(|v| vertices[v as usize]);
                    if signed_volume(&a, &b, &c, &d) < 0.0 {
                        tet.swap(2, 3);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    Ok(TetMesh { vertices, tets })
}

/// Checks the size (finite, positive) and cell counts (1 to 1024) of a box grid.
fn check_grid(size: Vector3<f32>, cells: [u32; 3]) -> Result<(), BuildError> {
    for (name, v) in [("size.x", size.x), ("size.y", size.y), ("size.z", size.z)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(BuildError::BadGeneratorParameter { name, value: v });
        }
    }
    for (name, c) in [
        ("cells[0]", cells[0]),
        ("cells[1]", cells[1]),
        ("cells[2]", cells[2]),
    ] {
        if c == 0 || c > 1024 {
            return Err(BuildError::BadGeneratorParameter {
                name,
                value: c as f32,
            });
        }
    }
    Ok(())
}

/// A ball of `radius` (m) centred at the origin: a `cells³` box grid mapped onto the ball
/// by the cube-to-sphere map `x' = x √(1 − y²/2 − z²/2 + y²z²/3)` (and cyclically), which
/// keeps every tetrahedron positively oriented.
pub fn ball(radius: f32, cells: u32, split: CellSplit) -> Result<TetMesh, BuildError> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(BuildError::BadGeneratorParameter {
            name: "radius",
            value: radius,
        });
    }
    let mut mesh = box_grid(Vector3::repeat(2.0), [cells; 3], split)?;
    for v in &mut mesh.vertices {
        let (x2, y2, z2) = (v.x * v.x, v.y * v.y, v.z * v.z);
        let s = Vector3::new(
            v.x * (1.0 - y2 / 2.0 - z2 / 2.0 + y2 * z2 / 3.0).max(0.0).sqrt(),
            v.y * (1.0 - z2 / 2.0 - x2 / 2.0 + z2 * x2 / 3.0).max(0.0).sqrt(),
            v.z * (1.0 - x2 / 2.0 - y2 / 2.0 + x2 * y2 / 3.0).max(0.0).sqrt(),
        );
        *v = s * radius;
    }
    Ok(mesh)
}

/// A beam of `length` along x with a square cross-section of side `width` (m), `cells`
/// cells long and `cross` cells across, starting at `x = 0`. Convenient for hanging-beam
/// scenes: the vertices with `x = 0` are [`beam_root`].
pub fn beam(
    length: f32,
    width: f32,
    cells: u32,
    cross: u32,
    split: CellSplit,
) -> Result<TetMesh, BuildError> {
    let mut mesh = box_grid(
        Vector3::new(length, width, width),
        [cells, cross, cross],
        split,
    )?;
    for v in &mut mesh.vertices {
        v.x += length / 2.0;
    }
    Ok(mesh)
}

/// Indices of the vertices of `mesh` with the smallest x (the root of a [`beam`]).
pub fn beam_root(mesh: &TetMesh) -> Vec<u32> {
    let min = mesh
        .vertices
        .iter()
        .map(|v| v.x)
        .fold(f32::INFINITY, f32::min);
    let tol = 1e-6 * (1.0 + min.abs());
    (0..mesh.vertices.len() as u32)
        .filter(|&i| (mesh.vertices[i as usize].x - min).abs() <= tol)
        .collect()
}

/// `mesh` with its vertices and its tetrahedra each in a pseudo-random order (a
/// Fisher–Yates shuffle driven by `seed`; the same seed gives the same mesh), the way mesh
/// files may number them. Returns the mesh and, for each new vertex, its index in `mesh`.
/// Benchmarks and tests use it to measure and check [`crate::SoftBodyBuilder::spatial_order`].
pub fn shuffled(mesh: &TetMesh, seed: u64) -> (TetMesh, Vec<u32>) {
    let mut state = seed ^ 0x9E37_79B9_7F4A_7C15;
    let mut next = move |bound: usize| {
        // xorshift64*; `bound` ≥ 1.
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 33) as usize % bound
    };
    let mut order: Vec<u32> = (0..mesh.vertices.len() as u32).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, next(i + 1));
    }
    let mut new_index = vec![0u32; order.len()];
    for (k, &i) in order.iter().enumerate() {
        new_index[i as usize] = k as u32;
    }
    let mut tets: Vec<[u32; 4]> = mesh
        .tets
        .iter()
        .map(|t| t.map(|i| new_index.get(i as usize).copied().unwrap_or(i)))
        .collect();
    for i in (1..tets.len()).rev() {
        tets.swap(i, next(i + 1));
    }
    let vertices = order.iter().map(|&i| mesh.vertices[i as usize]).collect();
    (TetMesh { vertices, tets }, order)
}
