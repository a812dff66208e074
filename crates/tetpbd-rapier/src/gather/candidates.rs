//! Once per frame: the colliders near each soft body (rapier's broad-phase BVH, never all
//! pairs, plus fast bodies that crossed it during rapier's step), and from them the
//! particle–collider and corner–triangle candidates, the attachments and the supports of
//! anchored bodies.

use hecs::{Entity, World};
use nalgebra::Vector3;
use rapier3d::geometry::{Aabb, Collider, ColliderHandle};
use rapier3d::parry::bounding_volume::BoundingVolume;
use tetpbd::{Particles, Surface};

use super::corners::gather_corners;
use super::{AttachRun, Frame, GatherInput, SoftEntry};
use crate::attachments::{AttachTarget, Attachments};
use crate::contacts::particle::ParticleContact;
use crate::contacts::support::gather_supports;
use crate::convert::{pose_to_na, to_glam};
use crate::rigid::body::BodyKind;
use crate::soft_collider::SoftCollider;

/// One soft body while its candidates are gathered.
struct SoftInFrame<'b> {
    entity: Entity,
    p: &'b Particles,
    surface: &'b Surface,
    sc: SoftCollider,
    /// Index of the body's first particle contact.
    c0: usize,
    /// How far a collider may be and still be reached within the frame, m.
    reach: f32,
}

impl Frame {
    /// Clears the previous frame and gathers this frame's candidates.
    pub fn gather(&mut self, world: &mut World, input: &GatherInput<'_, '_>) {
        self.soft.clear();
        self.bodies.clear();
        self.body_index.clear();
        self.colliders.clear();
        self.collider_index.clear();
        self.contacts.clear();
        self.corners.clear();
        self.attachments.clear();
        self.supports.clear();
        let qp = input.qp;
        crate::ccd::fast_colliders(
            &mut self.fast,
            &self.start_poses,
            qp.bodies,
            qp.colliders,
            input.margin,
        );
        let dt = self.dt;
        self.waking
            .run(world, input, &self.fast, input.soft_margin, dt);
        let fall = 0.5 * self.gravity * dt * dt;
        // Sleeping bodies take no part (`sleeping` module docs).
        for (entity, p, surface, sc, att, families) in world
            .query_mut::<(
                Entity,
                &Particles,
                &Surface,
                Option<&SoftCollider>,
                Option<&Attachments>,
                Families<'_>,
            )>()
            .without::<&tetpbd::Asleep>()
        {
            let sc = sc.copied().unwrap_or(*input.default_collider);
            let c0 = self.contacts.len();
            let k0 = self.corners.len();
            let a0 = self.attachments.len();
            let travel = p.max_speed() * dt + fall;
            let mut bounds = None;
            if sc.enabled && !surface.vertices().is_empty() {
                let reach = input.margin + sc.thickness + travel;
                let body = SoftInFrame {
                    entity,
                    p,
                    surface,
                    sc,
                    c0,
                    reach,
                };
                let (lo, hi) = surface_bounds(p, surface);
                self.gather_contacts(&body, input, (&lo, &hi));
                bounds = input.soft_margin.map(|m| {
                    let grow = Vector3::repeat(m + sc.thickness + travel);
                    (lo - grow, hi + grow)
                });
            }
            if let Some(att) = att {
                self.gather_attachments(att, p, input);
            }
            self.soft.push(SoftEntry {
                entity,
                v_cm_pre: Vector3::zeros(),
                contacts: c0..self.contacts.len(),
                corners: k0..self.corners.len(),
                attachments: a0..self.attachments.len(),
                stacked: false,
                reach: tetpbd::local_reach(p, surface),
                bounds,
                near_soft: false,
                wave_speed: if self.contacts.len() > c0 {
                    wave_speed(p, families)
                } else {
                    f32::INFINITY
                },
            });
        }
        self.mark_near_soft();
        self.anchor_supported_bodies(input);
        self.weld_jointed_bodies(input);
        self.gather_joints(input);
        self.stats.candidates = self.contacts.len();
        self.stats.corner_candidates = self.corners.len();
        self.stats.attachments = self.attachments.len();
    }

    /// Marks the soft bodies whose bounds, grown by how far they may move in the frame and
    /// the soft–soft margin, meet another's: they may touch another soft body within the
    /// frame (`response::passivity`). All pairs of the frame's bodies, once per frame.
    fn mark_near_soft(&mut self) {
        for a in 0..self.soft.len() {
            let Some((lo, hi)) = self.soft[a].bounds else {
                continue;
            };
            let near = self.soft.iter().enumerate().any(|(b, o)| {
                b != a
                    && o.bounds
                        .is_some_and(|(l, h)| (0..3).all(|k| lo[k] <= h[k] && l[k] <= hi[k]))
            });
            self.soft[a].near_soft = near;
        }
    }

    /// The colliders near one soft body (surface bounds `lo`, `hi`, m) and its candidates
    /// against each.
    fn gather_contacts(
        &mut self,
        body: &SoftInFrame<'_>,
        input: &GatherInput<'_, '_>,
        (lo, hi): (&Vector3<f32>, &Vector3<f32>),
    ) {
        let qp = input.qp;
        let sc = &body.sc;
        let aabb = Aabb::new(to_glam(lo), to_glam(hi)).loosened(body.reach);
        let mut near = std::mem::take(&mut self.near);
        near.clear();
        let keep = |co: &Collider| {
            co.is_enabled() && !co.is_sensor() && sc.collision_groups.test(co.collision_groups())
        };
        near.extend(
            qp.intersect_aabb_conservative(aabb)
                .filter(|(_, co)| keep(co))
                .map(|(h, _)| h),
        );
        // Fast bodies that crossed the soft body during rapier's step.
        for (h, swept) in &self.fast {
            if swept.intersects(&aabb)
                && !near.contains(h)
                && qp.colliders.get(*h).is_some_and(keep)
            {
                near.push(*h);
            }
        }
        for &handle in &near {
            self.gather_collider(body, handle, input);
        }
        self.near = near;
    }

    /// The particle–collider and corner–triangle candidates of one soft body against one
    /// collider.
    fn gather_collider(
        &mut self,
        body: &SoftInFrame<'_>,
        handle: ColliderHandle,
        input: &GatherInput<'_, '_>,
    ) {
        let qp = input.qp;
        let (p, sc, dt) = (body.p, &body.sc, self.dt);
        let Some(ci) = self.collider_proxy(handle, qp.bodies, qp.colliders, input.narrow_phase)
        else {
            return;
        };
        let Some(caabb) = self.swept_aabb(ci, qp.colliders) else {
            return;
        };
        // Loosened by the body's fastest motion too, not only by each particle's own path
        // below: a slow particle of a body being struck (another body landing on it) is sped
        // up within the frame and would sink through the collider until the next gathering.
        let caabb = caabb.loosened(body.reach);
        let Some(co) = qp.colliders.get(handle) else {
            return;
        };
        let solve = sc.solver_groups.test(co.solver_groups());
        let cp = &self.colliders[ci];
        // Does not move over the frame (`gather_corners`).
        let still = cp
            .body
            .is_none_or(|b| self.bodies[b].kind == BodyKind::Fixed);
        let (mu_d, mu_s) = sc.combined_friction(cp.friction, cp.friction_rule);
        let e = sc.combined_restitution(cp.restitution, cp.restitution_rule);
        let first = self.contacts.len();
        let material = (mu_d, mu_s, e);
        self.gather_particle_contacts(body, handle, ci, &caabb, solve, material);
        if sc.triangles && solve {
            let mut vertex_contacts = std::mem::take(&mut self.vertex_contacts);
            vertex_contacts.clear();
            vertex_contacts.extend(
                (first..self.contacts.len()).map(|k| (self.contacts[k].particle, k - body.c0)),
            );
            gather_corners(
                &mut self.corners,
                co.shape(),
                ci,
                &caabb,
                &pose_to_na(co.position()),
                still,
                p,
                body.surface,
                dt,
                sc.thickness,
                (mu_d, mu_s, e),
                &vertex_contacts,
                &mut self.shape_corners,
            );
            self.vertex_contacts = vertex_contacts;
        }
    }

    /// The particle–collider candidates of one soft body against collider proxy `ci`: its
    /// surface particles whose path over the frame meets the collider's swept bounds.
    fn gather_particle_contacts(
        &mut self,
        body: &SoftInFrame<'_>,
        handle: ColliderHandle,
        ci: usize,
        caabb: &Aabb,
        solve: bool,
        (mu_d, mu_s, e): (f32, f32, f32),
    ) {
        let (p, dt) = (body.p, self.dt);
        for &i in body.surface.vertices() {
            let x = p.positions()[i as usize];
            let y = x + p.velocities()[i as usize] * dt;
            let pa = Aabb::new(to_glam(&x.inf(&y)), to_glam(&x.sup(&y)));
            if !pa.intersects(caabb) {
                continue;
            }
            let key = (body.entity.to_bits().get(), handle.into_raw_parts(), i);
            let previous = self.touching.binary_search_by_key(&key, |t| t.0).ok();
            self.contacts.push(ParticleContact {
                particle: i,
                collider: ci,
                mu_d,
                mu_s,
                restitution: e,
                thickness: body.sc.thickness,
                solve,
                lambda_n: 0.0,
                lambda_t: 0.0,
                active: false,
                ever_active: false,
                has_normal: false,
                normal: Vector3::zeros(),
                point: Vector3::zeros(),
                depth: 0.0,
                // Touching in the previous frame: an ongoing contact, which keeps what is
                // left of its overlap allowance (usually nothing).
                allowance: previous.map_or(0.0, |k| self.touching[k].1),
                allowance_fresh: false,
                sub_impulse: Vector3::zeros(),
                impulse: Vector3::zeros(),
                side: None,
            });
        }
    }

    /// The attachments of one soft body; those to missing particles or bodies are skipped
    /// and counted.
    fn gather_attachments(
        &mut self,
        att: &Attachments,
        p: &Particles,
        input: &GatherInput<'_, '_>,
    ) {
        for a in &att.items {
            if a.particle as usize >= p.len() {
                self.stats.skipped_attachments += 1;
                continue;
            }
            let run = match a.target {
                AttachTarget::Body {
                    handle,
                    local_point,
                } => match self.body_proxy(handle, input.qp.bodies, input.narrow_phase) {
                    Some(b) => AttachRun {
                        particle: a.particle,
                        body: Some(b),
                        local: local_point,
                        start: Vector3::zeros(),
                        end: Vector3::zeros(),
                        compliance: a.compliance,
                        lambda: 0.0,
                    },
                    None => {
                        self.stats.skipped_attachments += 1;
                        continue;
                    }
                },
                AttachTarget::Point { position, previous } => AttachRun {
                    particle: a.particle,
                    body: None,
                    local: Vector3::zeros(),
                    start: previous,
                    end: position,
                    compliance: a.compliance,
                    lambda: 0.0,
                },
            };
            self.attachments.push(run);
        }
    }

    /// Every supported body a soft body may touch is anchored: it takes part with its own
    /// mass, its rigid contacts kept as constraints (`contacts::support` module docs; the
    /// decision and its measured alternatives: `docs/decisions/coupled-rigid-supports.md`).
    fn anchor_supported_bodies(&mut self, input: &GatherInput<'_, '_>) {
        let qp = input.qp;
        for b in 0..self.bodies.len() {
            if self.bodies[b].kind == BodyKind::Supported {
                let first = self.supports.len();
                gather_supports(
                    &mut self.supports,
                    b,
                    &self.bodies[b],
                    qp.bodies,
                    qp.colliders,
                    input.narrow_phase,
                );
                let normal = self.supports[first..].iter().map(|s| s.normal).sum();
                let friction = self.supports[first..]
                    .iter()
                    .map(|s| s.friction)
                    .fold(f32::INFINITY, f32::min);
                let radius = self.supports[first..]
                    .iter()
                    .map(|s| self.bodies[b].distance_from_com(s.local()))
                    .fold(0.0, f32::max);
                self.bodies[b].anchor(normal, friction, radius);
            }
        }
    }
}

/// The components a soft body's wave speed is computed from.
type Families<'a> = (
    Option<&'a tetpbd::Tetrahedra>,
    Option<&'a tetpbd::EdgeConstraints>,
    Option<&'a tetpbd::VertexFaceConstraints>,
    Option<&'a tetpbd::VolumeConstraints>,
    Option<&'a tetpbd::NeoHookeanMaterial>,
);

/// [`tetpbd::impact_speed::wave_speed`] of a body; `f32::INFINITY` without tetrahedra.
fn wave_speed(p: &Particles, (tets, edges, vf, volume, material): Families<'_>) -> f32 {
    tets.map_or(f32::INFINITY, |t| {
        tetpbd::impact_speed::wave_speed(p, t, edges, vf, volume, material)
    })
}

/// Bounds of a body's surface particles, m.
fn surface_bounds(p: &Particles, surface: &Surface) -> (Vector3<f32>, Vector3<f32>) {
    let mut lo = Vector3::repeat(f32::INFINITY);
    let mut hi = Vector3::repeat(f32::NEG_INFINITY);
    for &i in surface.vertices() {
        let x = p.positions()[i as usize];
        lo = lo.inf(&x);
        hi = hi.sup(&x);
    }
    (lo, hi)
}
