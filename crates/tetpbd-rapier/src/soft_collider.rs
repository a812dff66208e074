//! [`SoftCollider`]: how one soft body collides (an optional hecs component).

use rapier3d::dynamics::CoefficientCombineRule;
use rapier3d::geometry::InteractionGroups;

use crate::error::{check_coefficient, CouplingError};

/// Collision properties of one soft body: a hecs component on the soft body's entity.
///
/// A soft body without this component collides with [`SoftCollider::default`]. Friction and
/// restitution are combined with the collider's own coefficients by the stricter of the two
/// combine rules, exactly as rapier combines two colliders
/// ([`CoefficientCombineRule::combine`]).
///
/// What counts as the inside of a rapier collider, which a soft particle is pushed out of:
///
/// * solid shapes (ball, cuboid, capsule, cylinder, cone, convex polyhedron, compounds of
///   those, their rounded variants): parry's own inside;
/// * a heightfield: everything below its surface (local −y);
/// * a triangle mesh built with `TriMeshFlags::ORIENTED` or `FIX_INTERNAL_EDGES` (it has
///   pseudo-normals): parry's inside of the closed, oriented mesh;
/// * any other triangle mesh is **one-sided**: a particle behind the face it projects onto,
///   against the face's counter-clockwise winding normal, is inside and is pushed out to the
///   front. Wind such a mesh with its faces towards the soft bodies, or build it oriented;
///   a soft body that reaches the back of a one-sided face is pushed through to its front.
///
/// ```
/// use tetpbd_rapier::SoftColliderBuilder;
/// let c = SoftColliderBuilder::new().friction(0.3).restitution(0.5).thickness(0.01).build()?;
/// assert_eq!(c.friction(), 0.3);
/// # Ok::<(), tetpbd_rapier::CouplingError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftCollider {
    pub(crate) collision_groups: InteractionGroups,
    pub(crate) solver_groups: InteractionGroups,
    pub(crate) friction: f32,
    pub(crate) static_friction: f32,
    pub(crate) friction_rule: CoefficientCombineRule,
    pub(crate) restitution: f32,
    pub(crate) restitution_rule: CoefficientCombineRule,
    pub(crate) rolling_resistance: f32,
    pub(crate) thickness: f32,
    pub(crate) triangles: bool,
    pub(crate) enabled: bool,
}

impl Default for SoftCollider {
    fn default() -> Self {
        SoftCollider {
            collision_groups: InteractionGroups::default(),
            solver_groups: InteractionGroups::default(),
            friction: 0.5,
            static_friction: 0.5,
            friction_rule: CoefficientCombineRule::Average,
            restitution: 0.0,
            restitution_rule: CoefficientCombineRule::Average,
            rolling_resistance: SoftCollider::DEFAULT_ROLLING_RESISTANCE,
            thickness: SoftCollider::DEFAULT_THICKNESS,
            triangles: true,
            enabled: true,
        }
    }
}

impl SoftCollider {
    /// Default rolling resistance coefficient, dimensionless: 0, off (see
    /// [`SoftCollider::rolling_resistance`]; 0.01 brings a rocking body to rest within a few
    /// seconds).
    pub const DEFAULT_ROLLING_RESISTANCE: f32 = 0.0;

    /// Default contact thickness, m.
    pub const DEFAULT_THICKNESS: f32 = 0.002;

    /// Largest contact thickness [`SoftColliderBuilder::build`] accepts, m. The thickness is
    /// a skin kept between a particle and every collider; a skin thicker than this is a
    /// modelling error (give the body's mesh its real size instead), and a very thick one
    /// makes every collider near the body a deep overlap.
    pub const MAX_THICKNESS: f32 = 0.1;

    /// Collision groups: a collider is seen only when both groups accept each other.
    pub fn collision_groups(&self) -> InteractionGroups {
        self.collision_groups
    }

    /// Solver groups: a contact seen but rejected by these is reported, not solved.
    pub fn solver_groups(&self) -> InteractionGroups {
        self.solver_groups
    }

    /// Dynamic (sliding) friction coefficient, dimensionless.
    pub fn friction(&self) -> f32 {
        self.friction
    }

    /// Static (sticking) friction coefficient, dimensionless (≥ the dynamic one after
    /// combination).
    pub fn static_friction(&self) -> f32 {
        self.static_friction
    }

    /// Restitution coefficient, dimensionless (0 = no bounce, 1 = elastic).
    pub fn restitution(&self) -> f32 {
        self.restitution
    }

    /// Rolling resistance coefficient, dimensionless: the couple opposing the body's rotation
    /// relative to a collider it touches is at most this times the normal force times the lever
    /// from the body's centre of mass to the contact (`response::rolling` module docs; 0 = none).
    pub fn rolling_resistance(&self) -> f32 {
        self.rolling_resistance
    }

    /// Contact thickness, m: particles are kept this far outside every collider.
    pub fn thickness(&self) -> f32 {
        self.thickness
    }

    /// Whether rigid corners are tested against the soft surface triangles.
    pub fn triangle_collisions(&self) -> bool {
        self.triangles
    }

    /// Whether the body collides at all.
    pub fn is_enabled(&self) -> bool {
        self.enabled
    }

    /// Enables or disables collisions of the body.
    pub fn set_enabled(&mut self, enabled: bool) {
        self.enabled = enabled;
    }

    /// Combined (dynamic, static) friction against a collider.
    pub(crate) fn combined_friction(&self, mu: f32, rule: CoefficientCombineRule) -> (f32, f32) {
        let d = CoefficientCombineRule::combine(mu, self.friction, rule, self.friction_rule);
        let s = CoefficientCombineRule::combine(mu, self.static_friction, rule, self.friction_rule);
        (d.max(0.0), s.max(d).max(0.0))
    }

    /// Combined restitution against a collider.
    pub(crate) fn combined_restitution(&self, e: f32, rule: CoefficientCombineRule) -> f32 {
        CoefficientCombineRule::combine(e, self.restitution, rule, self.restitution_rule)
            .clamp(0.0, 1.0)
    }
}

/// Builds a [`SoftCollider`]; `build` validates every coefficient.
#[derive(Clone, Debug, Default)]
pub struct SoftColliderBuilder {
    inner: SoftCollider,
    static_set: bool,
}

impl SoftColliderBuilder {
    /// Starts from [`SoftCollider::default`] (friction 0.5, restitution 0, rolling resistance 0,
    /// thickness 2 mm, default groups, triangle collisions on).
    pub fn new() -> Self {
        Self::default()
    }

    /// Collision groups of the soft body.
    pub fn collision_groups(mut self, groups: InteractionGroups) -> Self {
        self.inner.collision_groups = groups;
        self
    }

    /// Solver groups of the soft body.
    pub fn solver_groups(mut self, groups: InteractionGroups) -> Self {
        self.inner.solver_groups = groups;
        self
    }

    /// Dynamic friction coefficient (also the static one unless [`Self::static_friction`]
    /// is given).
    pub fn friction(mut self, mu: f32) -> Self {
        self.inner.friction = mu;
        if !self.static_set {
            self.inner.static_friction = mu;
        }
        self
    }

    /// Static friction coefficient.
    pub fn static_friction(mut self, mu: f32) -> Self {
        self.inner.static_friction = mu;
        self.static_set = true;
        self
    }

    /// Combine rule for friction.
    pub fn friction_combine_rule(mut self, rule: CoefficientCombineRule) -> Self {
        self.inner.friction_rule = rule;
        self
    }

    /// Restitution coefficient in [0, 1].
    pub fn restitution(mut self, e: f32) -> Self {
        self.inner.restitution = e;
        self
    }

    /// Combine rule for restitution.
    pub fn restitution_combine_rule(mut self, rule: CoefficientCombineRule) -> Self {
        self.inner.restitution_rule = rule;
        self
    }

    /// Rolling resistance coefficient, dimensionless (≥ 0; 0, the default, turns it off;
    /// about 0.01 stops a rocking or rolling body within seconds).
    pub fn rolling_resistance(mut self, c_rr: f32) -> Self {
        self.inner.rolling_resistance = c_rr;
        self
    }

    /// Contact thickness, m (0 to [`SoftCollider::MAX_THICKNESS`]).
    pub fn thickness(mut self, t: f32) -> Self {
        self.inner.thickness = t;
        self
    }

    /// Turns the rigid-corner-versus-soft-triangle test on or off.
    pub fn triangle_collisions(mut self, on: bool) -> Self {
        self.inner.triangles = on;
        self
    }

    /// Validates and builds.
    pub fn build(self) -> Result<SoftCollider, CouplingError> {
        let c = self.inner;
        check_coefficient("friction", c.friction)?;
        check_coefficient("static_friction", c.static_friction)?;
        check_coefficient("restitution", c.restitution)?;
        if c.restitution > 1.0 {
            return Err(CouplingError::BadCoefficient {
                name: "restitution (must be <= 1)",
                value: c.restitution,
            });
        }
        check_coefficient("rolling_resistance", c.rolling_resistance)?;
        check_coefficient("thickness", c.thickness)?;
        if c.thickness > SoftCollider::MAX_THICKNESS {
            return Err(CouplingError::BadCoefficient {
                name: "thickness (m, must be <= SoftCollider::MAX_THICKNESS)",
                value: c.thickness,
            });
        }
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_combine_like_rapier() {
        let soft = SoftColliderBuilder::new()
            .friction(0.8)
            .static_friction(1.0)
            .restitution(0.5)
            .build()
            .unwrap();
        // Average with the collider's rule Average.
        let (d, s) = soft.combined_friction(0.2, CoefficientCombineRule::Average);
        assert!((d - 0.5).abs() < 1e-6 && (s - 0.6).abs() < 1e-6);
        // The stricter rule wins: Min on the collider.
        let (d, s) = soft.combined_friction(0.2, CoefficientCombineRule::Min);
        assert!((d - 0.2).abs() < 1e-6 && (s - 0.2).abs() < 1e-6);
        // Static friction is never below the dynamic one.
        let low_static = SoftColliderBuilder::new()
            .friction(0.8)
            .static_friction(0.1)
            .build()
            .unwrap();
        let (d, s) = low_static.combined_friction(0.8, CoefficientCombineRule::Average);
        assert!(s >= d);
        let e = soft.combined_restitution(1.0, CoefficientCombineRule::Max);
        assert!((e - 1.0).abs() < 1e-6);
    }
}
