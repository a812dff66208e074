//! The [`tetpbd::SubstepHook`] that runs the coupling inside the soft solver's substeps.

use hecs::World;
use rapier3d::dynamics::{ImpulseJointSet, MultibodyJointSet};
use rapier3d::geometry::NarrowPhase;
use rapier3d::pipeline::QueryPipeline;
use tetpbd::{
    applied_acceleration, ExternalAcceleration, FrameContext, Grab, Particles, SubstepContext,
    SubstepHook, Surface, UserForces,
};

use crate::attachments::{anchor_of, project_attachments, Attachments};
use crate::contacts::approach::limit_approach;
use crate::contacts::corner::CornerContact;
use crate::contacts::corner::{project_corners, CornerPass};
use crate::contacts::particle::ParticleContact;
use crate::contacts::particle::{
    finish_substep, friction_on_pivoting, project_contacts, velocity_pass,
};
use crate::contacts::support::{
    end_substep_supports, hold_supported, measure_clearance, project_supports,
};
use crate::depenetration::{cap_depenetration, settle_substeps};
use crate::gather::{Frame, GatherInput};
use crate::heavy_loads::{immovable, stacked_velocity_pass, stacking_pass, Stacking};
use crate::joints::project_joints;
use crate::report::{ContactReport, SoftFeature};
use crate::response::passivity::{only_immovable_contacts, stop_approach, Passivity};
use crate::response::restitution::active_colliders;
use crate::response::restitution::restitution_pass;
use crate::response::rolling::rolling_pass;
use crate::rigid::body::BodyProxy;
use crate::rigid::collider::ColliderProxy;
use crate::rigid::shape_query::surface_point;
use crate::soft_collider::SoftCollider;
use crate::soft_soft::SoftContacts;
use tetpbd::ImpactReach;

/// Borrows the frame state and rapier's query pipeline for one soft step.
pub(crate) struct CouplingHook<'q, 'a> {
    pub frame: &'q mut Frame,
    pub qp: QueryPipeline<'a>,
    pub narrow_phase: &'a NarrowPhase,
    pub impulse_joints: &'a ImpulseJointSet,
    pub multibody_joints: &'a MultibodyJointSet,
    pub default_collider: SoftCollider,
    pub margin: f32,
    /// The soft–soft contact margin, m (`None`: soft–soft contacts off).
    pub soft_margin: Option<f32>,
    pub max_depenetration_speed: f32,
    /// `CouplingSettings::stacking_mass_ratio()`.
    pub stacking_mass_ratio: f32,
    /// `StackingSettings::self_weight` (false when stacking is off).
    pub self_weight_stacking: bool,
    pub reports: &'q mut Vec<ContactReport>,
}

/// The coupling's hooks in the order they run at every point: soft–rigid, then soft–soft
/// contacts (when on), then the caller's. Before the soft–soft projection of an iteration
/// the soft–soft contacts learn which soft bodies touch an immovable support in the substep
/// (`soft_soft::carrying` module docs).
pub(crate) struct CoupledHooks<'q, 'a, 'e> {
    pub rigid: CouplingHook<'q, 'a>,
    pub soft: Option<&'q mut SoftContacts>,
    pub extra: &'e mut dyn SubstepHook,
}

impl SubstepHook for CoupledHooks<'_, '_, '_> {
    fn begin_frame(&mut self, world: &mut World, frame: FrameContext) {
        self.rigid.begin_frame(world, frame);
        if let Some(soft) = self.soft.as_deref_mut() {
            soft.begin_frame(world, frame);
        }
        self.extra.begin_frame(world, frame);
    }

    fn begin_substep(&mut self, world: &mut World, substep: SubstepContext) {
        self.rigid.begin_substep(world, substep);
        if let Some(soft) = self.soft.as_deref_mut() {
            soft.begin_substep(world, substep);
        }
        self.extra.begin_substep(world, substep);
    }

    fn project(&mut self, world: &mut World, substep: SubstepContext) {
        self.rigid.project(world, substep);
        if let Some(soft) = self.soft.as_deref_mut() {
            let f = &*self.rigid.frame;
            soft.set_supported(f.soft.iter().filter_map(|s| {
                let on_support = f.contacts[s.contacts.clone()]
                    .iter()
                    .any(|c| c.active && c.solve && immovable(&f.colliders[c.collider], &f.bodies));
                on_support.then(|| s.entity.to_bits().get())
            }));
            soft.project(world, substep);
        }
        self.extra.project(world, substep);
    }

    fn end_substep(&mut self, world: &mut World, substep: SubstepContext) {
        self.rigid.end_substep(world, substep);
        if let Some(soft) = self.soft.as_deref_mut() {
            soft.end_substep(world, substep);
        }
        self.extra.end_substep(world, substep);
    }

    fn end_frame(&mut self, world: &mut World, frame: FrameContext) {
        self.rigid.end_frame(world, frame);
        if let Some(soft) = self.soft.as_deref_mut() {
            soft.end_frame(world, frame);
        }
        self.extra.end_frame(world, frame);
    }

    fn touching(&mut self, world: &mut World, touching: &mut tetpbd::Touching) {
        self.rigid.touching(world, touching);
        if let Some(soft) = self.soft.as_deref_mut() {
            soft.touching(world, touching);
        }
        self.extra.touching(world, touching);
    }
}

/// Runs the passivity episode of soft body `s` (`response::passivity`) when its contacts are
/// all immovable and nothing else acts on its rigid motion (no pinned particle, attachment,
/// grab or user force, no soft body within reach); `accel` is gravity plus the applied
/// uniform acceleration (m/s²), `given` the energy restitution gave it (J). Returns the
/// body's rigid fit when it took one.
#[allow(clippy::too_many_arguments)]
fn passivity_pass(
    passivity: &mut Passivity,
    active: &mut Vec<usize>,
    s: &crate::gather::SoftEntry,
    (contacts, corners): (&[ParticleContact], &[CornerContact]),
    p: &mut Particles,
    (bodies, colliders): (&[BodyProxy], &[ColliderProxy]),
    (forces, grab, attached): (Option<&UserForces>, Option<&Grab>, bool),
    (accel, given): (&nalgebra::Vector3<f32>, f32),
) -> Option<tetpbd::RigidFit> {
    let pushed =
        forces.is_some_and(|f| f.forces().iter().any(|f| *f != nalgebra::Vector3::zeros()));
    if s.near_soft
        || attached
        || grab.is_some()
        || pushed
        || !only_immovable_contacts(contacts, corners, bodies, colliders)
        || p.inv_masses().contains(&0.0)
    {
        return None;
    }
    let mut fit = p.rigid_fit()?;
    active_colliders(active, contacts, corners);
    stop_approach(active, contacts, corners, p, &mut fit);
    passivity.run(s.entity.to_bits().get(), p, &mut fit, accel, given);
    Some(fit)
}

/// The fraction of the frame elapsed at the end of `substep`: where the rigid bodies stand
/// on their `P₀ → P₁` path during it.
fn frac(substep: &SubstepContext) -> f32 {
    ((substep.substep() + 1) as f32 / substep.substeps().max(1) as f32).min(1.0)
}

impl SubstepHook for CouplingHook<'_, '_> {
    fn begin_frame(&mut self, world: &mut World, frame: FrameContext) {
        self.frame.dt = frame.dt();
        self.frame.gravity = frame.gravity().norm();
        let input = GatherInput {
            qp: &self.qp,
            narrow_phase: self.narrow_phase,
            impulse_joints: self.impulse_joints,
            multibody_joints: self.multibody_joints,
            default_collider: &self.default_collider,
            margin: self.margin,
            soft_margin: self.soft_margin,
        };
        self.frame.gather(world, &input);
    }

    fn begin_substep(&mut self, world: &mut World, substep: SubstepContext) {
        let h = substep.h();
        for s in &mut self.frame.soft {
            s.stacked = false;
            if let Ok(p) = world.query_one_mut::<&Particles>(s.entity) {
                s.v_cm_pre = p
                    .free_velocity()
                    .map_or(nalgebra::Vector3::zeros(), |v| v.0);
            }
        }
        let frac = frac(&substep);
        for b in &mut self.frame.bodies {
            b.begin_substep(frac, h);
        }
        let slop = self.frame.rigid_slop;
        let max_push = self.max_depenetration_speed * h;
        hold_supported(
            &mut self.frame.supports,
            &mut self.frame.bodies,
            slop,
            max_push,
        );
        for a in &mut self.frame.attachments {
            a.lambda = 0.0;
        }
    }

    fn project(&mut self, world: &mut World, substep: SubstepContext) {
        let (frac, h) = (frac(&substep), substep.h());
        let Frame {
            soft,
            bodies,
            colliders,
            contacts,
            corners,
            attachments,
            supports,
            stats,
            sweeps,
            pinned,
            joints,
            ..
        } = &mut *self.frame;
        if sweeps.len() < soft.len() {
            sweeps.resize_with(soft.len(), Default::default);
        }
        measure_clearance(supports, bodies);
        for (s, sweep) in soft.iter_mut().zip(sweeps.iter_mut()) {
            let Ok((p, surface)) = world.query_one_mut::<(&mut Particles, &Surface)>(s.entity)
            else {
                continue;
            };
            let mut impact = ImpactReach::new(s.reach);
            project_corners(
                &mut corners[s.corners.clone()],
                &contacts[s.contacts.clone()],
                p,
                surface,
                bodies,
                colliders,
                self.qp.colliders,
                CornerPass::Crossing,
                self.max_depenetration_speed * h,
                &mut impact,
            );
            stats.degenerate_contacts += project_contacts(
                &mut contacts[s.contacts.clone()],
                p,
                bodies,
                colliders,
                self.qp.colliders,
                self.max_depenetration_speed * h,
                &mut impact,
            );
            project_corners(
                &mut corners[s.corners.clone()],
                &contacts[s.contacts.clone()],
                p,
                surface,
                bodies,
                colliders,
                self.qp.colliders,
                CornerPass::Ordinary,
                self.max_depenetration_speed * h,
                &mut impact,
            );
            limit_approach(
                &mut contacts[s.contacts.clone()],
                &mut corners[s.corners.clone()],
                p,
                bodies,
                colliders,
                &mut impact,
                tetpbd::impact_speed::approach_limit(s.reach, s.wave_speed, h),
            );
            project_attachments(&mut attachments[s.attachments.clone()], p, bodies, frac, h);
            let mut stacking = Stacking {
                bodies,
                colliders,
                set: self.qp.colliders,
                sweep,
                pinned,
                ratio: self.stacking_mass_ratio,
                self_weight: self.self_weight_stacking,
                substep,
                max_push: self.max_depenetration_speed * h,
            };
            let t = std::time::Instant::now();
            if let Some(heavy) = stacking_pass(
                world,
                s.entity,
                &mut contacts[s.contacts.clone()],
                &mut corners[s.corners.clone()],
                &mut stacking,
            ) {
                stats.stacking_passes += 1;
                s.stacked |= heavy;
            }
            stats.stacking_time += t.elapsed();
        }
        project_supports(supports, bodies);
        project_joints(joints, bodies);
        // Friction against pivoting bodies once more, against where the iteration left them
        // (`rigid::body::pivoting` module docs, "Friction on a pivoting body").
        for s in soft.iter() {
            if let Ok(p) = world.query_one_mut::<&mut Particles>(s.entity) {
                friction_on_pivoting(&mut contacts[s.contacts.clone()], p, bodies, colliders);
            }
        }
    }

    fn end_substep(&mut self, world: &mut World, substep: SubstepContext) {
        let h = substep.h();
        let threshold = 2.0 * self.frame.gravity * h;
        let Frame {
            soft,
            bodies,
            colliders,
            contacts,
            corners,
            episodes,
            passivity,
            active_colliders,
            supports,
            stats,
            depenetrating,
            attachments,
            ..
        } = &mut *self.frame;
        for b in bodies.iter_mut() {
            b.end_substep(h);
        }
        end_substep_supports(supports, h, self.max_depenetration_speed * h);
        for s in soft.iter() {
            let Ok((p, surface, sc, loads)) = world.query_one_mut::<(
                &mut Particles,
                &Surface,
                Option<&SoftCollider>,
                (
                    Option<&UserForces>,
                    Option<&Grab>,
                    Option<&ExternalAcceleration>,
                ),
            )>(s.entity) else {
                continue;
            };
            let (forces, grab, external) = loads;
            let pull = (substep.gravity() + applied_acceleration(p, forces, grab, external)) * h;
            let rolling = sc.unwrap_or(&self.default_collider).rolling_resistance();
            let range = s.contacts.clone();
            if s.stacked {
                let t = std::time::Instant::now();
                stacked_velocity_pass(
                    &contacts[range.clone()],
                    &corners[s.corners.clone()],
                    p,
                    surface,
                    bodies,
                    colliders,
                );
                stats.stacking_time += t.elapsed();
            }
            velocity_pass(&mut contacts[range.clone()], p, bodies, colliders);
            let given = restitution_pass(
                episodes,
                active_colliders,
                s.entity,
                &mut contacts[range.clone()],
                &mut corners[s.corners.clone()],
                p,
                &s.v_cm_pre,
                &pull,
                bodies,
                colliders,
                &attachments[s.attachments.clone()],
                threshold,
            );
            let fit = passivity_pass(
                passivity,
                active_colliders,
                s,
                (&contacts[range.clone()], &corners[s.corners.clone()]),
                p,
                (bodies, colliders),
                (forces, grab, !attachments[s.attachments.clone()].is_empty()),
                (&(pull / h), given),
            );
            rolling_pass(
                active_colliders,
                &contacts[range.clone()],
                &corners[s.corners.clone()],
                p,
                bodies,
                colliders,
                rolling,
                h,
                fit,
            );
            cap_depenetration(
                depenetrating,
                s.entity,
                &contacts[range.clone()],
                p,
                &s.v_cm_pre,
                settle_substeps(h),
            );
            finish_substep(&mut contacts[range], h, self.max_depenetration_speed * h);
        }
        episodes.end_substep();
        passivity.end_substep();
        let max_push = self.max_depenetration_speed * h;
        for k in corners.iter_mut() {
            k.allowance = (k.allowance - max_push).max(0.0);
            k.active = false;
            k.impulse += k.sub_impulse / h;
            k.sub_impulse = nalgebra::Vector3::zeros();
            k.lambda_n = 0.0;
            k.lambda_t = 0.0;
        }
    }

    fn touching(&mut self, _world: &mut World, touching: &mut tetpbd::Touching) {
        crate::sleeping::touching(self.frame, self.qp.bodies, touching);
    }

    fn end_frame(&mut self, world: &mut World, _frame: FrameContext) {
        self.frame.remember_touching();
        let frame = &mut *self.frame;
        // A sleeping body keeps reporting the contacts it fell asleep on (`sleeping` module
        // docs); the others are reported afresh.
        self.reports
            .retain(|r| tetpbd::is_sleeping(world, r.entity));
        let mut max_pen = 0.0f32;
        let mut max_att = 0.0f32;
        for s in &frame.soft {
            let Ok((p, att)) =
                world.query_one_mut::<(&Particles, Option<&mut Attachments>)>(s.entity)
            else {
                continue;
            };
            for c in &frame.contacts[s.contacts.clone()] {
                let cp = &frame.colliders[c.collider];
                if let Some(shape) = self.qp.colliders.get(cp.handle).map(|co| co.shape()) {
                    let pose = cp.pose(&frame.bodies);
                    let x = p.positions()[c.particle as usize];
                    let fb = c.has_normal.then_some(c.normal);
                    if let Some(sp) = surface_point(shape, cp.rule, &pose, &x, fb, fb) {
                        if c.solve {
                            max_pen = max_pen.max(-sp.distance);
                        }
                    }
                }
                if c.ever_active {
                    self.reports.push(ContactReport {
                        collider: cp.handle,
                        entity: s.entity,
                        feature: SoftFeature::Particle(c.particle),
                        point: c.point,
                        normal: c.normal,
                        depth: c.depth,
                        impulse: c.impulse,
                        solved: c.solve,
                    });
                }
            }
            for k in &frame.corners[s.corners.clone()] {
                if k.ever_active {
                    self.reports.push(ContactReport {
                        collider: frame.colliders[k.collider].handle,
                        entity: s.entity,
                        feature: SoftFeature::Triangle(k.triangle),
                        point: k.point,
                        normal: k.normal,
                        depth: k.depth,
                        impulse: k.impulse,
                        solved: true,
                    });
                }
            }
            for a in &frame.attachments[s.attachments.clone()] {
                let anchor = anchor_of(a, &frame.bodies, 1.0);
                let x = p.positions()[a.particle as usize];
                max_att = max_att.max((x - anchor).norm());
            }
            if let Some(att) = att {
                att.roll_targets();
            }
        }
        frame.stats.max_penetration = max_pen.max(0.0);
        frame.stats.max_attachment_error = max_att;
        frame.stats.contacts = self.reports.len();
    }
}
