//! Tearing by strain or force: the settings and per-face state of a body that tears.
//!
//! The strain measure, its time smoothing and what a tear does are documented on
//! [`Tearing`], the force measure in `crate::body::face_forces`; the pass that reads them is
//! `crate::solver::tearing_pass`, the split itself `crate::body::split` (mesh) and
//! `crate::body::pieces` (components and entities).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::body::face_forces::FaceForceScratch;
use crate::body::families::EdgeConstraints;
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::error::TearingError;

/// What becomes of a body that falls into disconnected pieces (a tear or a cut).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum Pieces {
    /// Each piece becomes its own entity (the first, holding the body's lowest-numbered
    /// tetrahedron, keeps the body's entity). The default: sleeping, the rigid fit and the
    /// angular-momentum conservation then act on each piece.
    #[default]
    Split,
    /// The pieces stay one entity (one mesh with several connected components).
    KeepOne,
}

/// The settings of a body's tearing (see [`Tearing`]). A face tears when either criterion
/// it has passes its threshold; a body with neither never tears by itself (it can still be
/// cut).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct TearingSettings {
    /// Strain at which a face tears (dimensionless, finite, `> 0`; `None` = never by
    /// strain): the smoothed stretch across the face, `|xₐ − x_b| / |rₐ − r_b| − 1`.
    /// Default `Some(0.5)` (50 % stretch).
    pub strain: Option<f32>,
    /// Force at which a face tears, N (finite, `> 0`; `None` = never by force): the smoothed
    /// force pulling the face open, estimated from the constraint multipliers of every family
    /// acting on its two tetrahedra (see `crate::body::face_forces`). Default `None`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub force: Option<f32>,
    /// Time constant of the exponential filter smoothing each face's strain and force, s
    /// (finite, `≥ 0`; 0 = no smoothing). Default 0.05 s.
    pub smoothing_time: f32,
    /// Whether disconnected pieces become separate entities. Default [`Pieces::Split`].
    pub pieces: Pieces,
}

impl Default for TearingSettings {
    fn default() -> Self {
        TearingSettings {
            strain: Some(0.5),
            force: None,
            smoothing_time: 0.05,
            pieces: Pieces::Split,
        }
    }
}

impl TearingSettings {
    /// Checks every setting, naming the first bad one and its value.
    pub fn validate(&self) -> Result<(), TearingError> {
        if let Some(s) = self.strain {
            if !(s.is_finite() && s > 0.0) {
                return Err(TearingError::BadStrain { value: s });
            }
        }
        if let Some(f) = self.force {
            if !(f.is_finite() && f > 0.0) {
                return Err(TearingError::BadForce { value: f });
            }
        }
        let tau = self.smoothing_time;
        if !(tau.is_finite() && tau >= 0.0) {
            return Err(TearingError::BadSmoothingTime { value: tau });
        }
        Ok(())
    }

    /// The filter's weight of a new sample after `dt` s: `1 − exp(−dt/τ)` (1 without
    /// smoothing).
    pub(crate) fn filter_weight(&self, dt: f32) -> f32 {
        if self.smoothing_time > 0.0 {
            1.0 - (-dt / self.smoothing_time).exp()
        } else {
            1.0
        }
    }
}

/// A face shared by two tetrahedra, with its smoothed strain and force.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub(crate) struct InteriorFace {
    /// The two tetrahedra (indices into [`Tetrahedra::indices`], ascending).
    pub tets: [u32; 2],
    /// The corner of each tetrahedron opposite the face (a particle index each).
    pub apex: [u32; 2],
    /// `1 / |rₐ − r_b|` of the apexes' rest positions, 1/m.
    pub inv_rest: f32,
    /// Smoothed strain (dimensionless).
    pub smoothed: f32,
    /// Smoothed force pulling the face open, N (negative: pressed shut; stays 0 while the
    /// body does not tear by force).
    #[cfg_attr(feature = "serde", serde(default))]
    pub smoothed_force: f32,
    /// Torn, while both tetrahedra still share its particles (the split waits until the
    /// torn faces around a particle separate its tetrahedra).
    pub torn: bool,
}

/// A body's tearing (a hecs component): its [`TearingSettings`] and the smoothed strain and
/// force of each face shared by two tetrahedra. A body without it never tears by itself (it can still be
/// cut, `crate::cut`).
///
/// # Strain
///
/// For a face shared by tetrahedra `t₁` and `t₂`, with `a` and `b` the corners opposite it
/// (one in each), the strain across the face is `s = |xₐ − x_b| / |rₐ − r_b| − 1`
/// (dimensionless; `x` current, `r` rest positions): the stretch of the segment through the
/// face joining both sides, which grows when the face is pulled open or sheared. Once per
/// frame (length `dt`) it is smoothed, `s̄ ← s̄ + (1 − e^{−dt/τ})(s − s̄)`
/// ([`TearingSettings::smoothing_time`] `τ`), so a spike lasting one frame moves `s̄` by
/// only the filter's weight of it. A face tears when `s̄` exceeds
/// [`TearingSettings::strain`]. The rest positions are the built ones: plastic flow does not
/// move the tearing reference, so a body stretched plastically is that much closer to tearing.
///
/// # Force
///
/// With [`TearingSettings::force`], the force pulling each interior face open (N, from the
/// constraint multipliers of the frame's last substep: `crate::body::face_forces` derives
/// it) is smoothed by the same filter, and a face also tears when it exceeds the threshold.
/// The per-tetrahedron scratch this needs (about 80 bytes per tetrahedron) exists only while
/// the body tears by force; it is made with the component by the builder and by a split, and
/// once on the first frame for a component made by [`Tearing::new`] or given a force
/// threshold by [`Tearing::set_settings`].
///
/// # Tear
///
/// A torn face splits when its particles can be duplicated so that the two sides no longer
/// share them: a particle's tetrahedra that are still connected through untorn faces around
/// it keep one copy; each further group gets its own. A torn face whose particles stay
/// connected around it (a crack that does not yet reach across) stays torn until further
/// tears complete the separation. No tetrahedron is ever removed.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Tearing {
    pub(crate) settings: TearingSettings,
    /// The interior faces, sorted by their tetrahedra.
    pub(crate) faces: Vec<InteriorFace>,
    /// The per-tetrahedron forces and edge shares of the force estimate (scratch; empty while
    /// the body does not tear by force).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) forces: FaceForceScratch,
    /// How many tetrahedra and particles the faces need, once measured (scratch: the faces
    /// only change by being rebuilt, which starts it anew).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) largest_index: Option<(u32, u32)>,
}

impl Tearing {
    /// The tearing state of a body with these particles and tetrahedra, no face strained
    /// yet. Errors: a bad setting ([`TearingSettings::validate`]).
    pub fn new(
        settings: TearingSettings,
        particles: &Particles,
        tetrahedra: &Tetrahedra,
    ) -> Result<Tearing, TearingError> {
        settings.validate()?;
        Ok(Tearing {
            settings,
            faces: interior_faces(&tetrahedra.indices, &particles.rest_positions),
            forces: FaceForceScratch::default(),
            largest_index: None,
        })
    }

    /// Makes the force estimate's scratch for a body with these tetrahedra and edges when the
    /// body tears by force (allocates; the builder and a split call it, the tearing pass when
    /// the scratch does not fit).
    pub(crate) fn prepare_forces(
        &mut self,
        tetrahedra: &Tetrahedra,
        edges: Option<&EdgeConstraints>,
    ) {
        if self.settings.force.is_some() {
            self.forces = FaceForceScratch::new(&tetrahedra.indices, edges);
        }
    }

    /// The settings.
    pub fn settings(&self) -> &TearingSettings {
        &self.settings
    }

    /// Replaces the settings; rejects bad ones and keeps the old ones then.
    pub fn set_settings(&mut self, settings: TearingSettings) -> Result<(), TearingError> {
        settings.validate()?;
        self.settings = settings;
        if settings.force.is_none() {
            self.forces = FaceForceScratch::default();
        }
        Ok(())
    }

    /// Number of faces shared by two tetrahedra.
    pub fn interior_faces(&self) -> usize {
        self.faces.len()
    }

    /// Number of faces torn whose particles are still shared (a crack not yet through).
    pub fn torn_faces(&self) -> usize {
        self.faces.iter().filter(|f| f.torn).count()
    }

    /// The largest smoothed strain of any untorn face (0 without interior faces).
    pub fn max_smoothed_strain(&self) -> f32 {
        self.faces
            .iter()
            .filter(|f| !f.torn)
            .map(|f| f.smoothed)
            .fold(0.0, f32::max)
    }

    /// The largest smoothed force pulling an untorn face open, N (0 without interior faces
    /// or while the body does not tear by force).
    pub fn max_smoothed_force(&self) -> f32 {
        self.faces
            .iter()
            .filter(|f| !f.torn)
            .map(|f| f.smoothed_force)
            .fold(0.0, f32::max)
    }

    /// Whether this state was made for a body with these particles and tetrahedra (the
    /// solver skips a body it does not fit).
    pub fn fits(&self, particles: &Particles, tetrahedra: &Tetrahedra) -> bool {
        let needed = self.largest_index.unwrap_or_else(|| self.needed_lengths());
        Self::fits_within(needed, particles, tetrahedra)
    }

    /// [`Self::fits`], measuring the faces' largest indices once (the tearing pass's check:
    /// one comparison per frame instead of a pass over the faces).
    pub(crate) fn fits_cached(&mut self, particles: &Particles, tetrahedra: &Tetrahedra) -> bool {
        let needed = match self.largest_index {
            Some(l) => l,
            None => *self.largest_index.insert(self.needed_lengths()),
        };
        Self::fits_within(needed, particles, tetrahedra)
    }

    fn fits_within(
        (tets, particles_needed): (u32, u32),
        particles: &Particles,
        tetrahedra: &Tetrahedra,
    ) -> bool {
        tets as usize <= tetrahedra.len() && particles_needed as usize <= particles.len()
    }

    /// How many tetrahedra and particles the faces need: one more than the largest index
    /// each names (0 without faces).
    fn needed_lengths(&self) -> (u32, u32) {
        self.faces.iter().fold((0, 0), |(t, n), f| {
            (
                t.max(f.tets[1] + 1),
                n.max(f.apex[0] + 1).max(f.apex[1] + 1),
            )
        })
    }
}

/// The faces shared by two tetrahedra of `tets`, sorted by their tetrahedra, with the
/// apexes' rest distance from `rest` (m). Sorted keys, no hash maps (deterministic).
pub(crate) fn interior_faces(
    tets: &[[u32; 4]],
    rest: &[nalgebra::Vector3<f32>],
) -> Vec<InteriorFace> {
    let mut keyed: Vec<([u32; 3], u32, u8)> = Vec::with_capacity(tets.len() * 4);
    for (t, tet) in tets.iter().enumerate() {
        for opposite in 0..4u8 {
            keyed.push((face_key(tet, opposite as usize), t as u32, opposite));
        }
    }
    keyed.sort_unstable();
    let mut faces = Vec::new();
    for w in keyed.windows(2) {
        let ((k1, t1, o1), (k2, t2, o2)) = (w[0], w[1]);
        if k1 != k2 {
            continue;
        }
        let (a, b) = (
            tets[t1 as usize][o1 as usize],
            tets[t2 as usize][o2 as usize],
        );
        let d = (rest[a as usize] - rest[b as usize]).norm();
        faces.push(InteriorFace {
            tets: [t1, t2],
            apex: [a, b],
            inv_rest: if d > 0.0 { 1.0 / d } else { 0.0 },
            smoothed: 0.0,
            smoothed_force: 0.0,
            torn: false,
        });
    }
    faces.sort_unstable_by_key(|f| f.tets);
    faces
}

/// The sorted particles of `tet`'s face opposite corner `opposite`.
pub(crate) fn face_key(tet: &[u32; 4], opposite: usize) -> [u32; 3] {
    let mut key = [0u32; 3];
    let mut k = 0;
    for (c, &i) in tet.iter().enumerate() {
        if c != opposite {
            key[k] = i;
            k += 1;
        }
    }
    key.sort_unstable();
    key
}
