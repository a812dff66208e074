//! [`SoftQueryFilter`]: which soft bodies a scene query sees, like rapier's `QueryFilter`.

use hecs::Entity;
use rapier3d::geometry::InteractionGroups;

use super::body::QueryBody;

/// Which soft bodies a scene query sees, like rapier's
/// [`QueryFilter`](rapier3d::pipeline::QueryFilter): by collision groups, by an entity to
/// exclude and by a predicate. The default sees every body.
///
/// A body's groups are the collision groups of its [`SoftCollider`](crate::SoftCollider)
/// (or of [`SoftQueries::default_collider`](super::SoftQueries::default_collider) without
/// one), tested as rapier tests a collider's: `body_groups.test(filter_groups)`. Bodies
/// whose `SoftCollider` is disabled are never seen, as rapier's queries never see a
/// disabled collider.
///
/// ```
/// use rapier3d::prelude::{Group, InteractionGroups, InteractionTestMode};
/// use tetpbd_rapier::SoftQueryFilter;
///
/// let keep = |e: hecs::Entity| e.id() % 2 == 0;
/// let groups = InteractionGroups::new(Group::GROUP_2, Group::ALL, InteractionTestMode::And);
/// let filter = SoftQueryFilter::new().groups(groups).predicate(&keep);
/// assert!(filter.groups.is_some());
/// ```
#[derive(Clone, Copy, Default)]
pub struct SoftQueryFilter<'a> {
    /// When set, only bodies whose collision groups accept these are seen.
    pub groups: Option<InteractionGroups>,
    /// When set, this body is not seen.
    pub exclude_entity: Option<Entity>,
    /// When set, a body is seen only when this returns `true` for its entity.
    #[allow(clippy::type_complexity)]
    pub predicate: Option<&'a dyn Fn(Entity) -> bool>,
}

impl<'a> SoftQueryFilter<'a> {
    /// A filter that sees every (enabled) soft body.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sees only bodies whose collision groups accept `groups`.
    pub fn groups(mut self, groups: InteractionGroups) -> Self {
        self.groups = Some(groups);
        self
    }

    /// Does not see `entity`.
    pub fn exclude_entity(mut self, entity: Entity) -> Self {
        self.exclude_entity = Some(entity);
        self
    }

    /// Sees a body only when `predicate` returns `true` for its entity.
    pub fn predicate(mut self, predicate: &'a impl Fn(Entity) -> bool) -> Self {
        self.predicate = Some(predicate);
        self
    }

    /// `true` when the query sees `body`.
    pub(crate) fn test(&self, body: &QueryBody) -> bool {
        self.exclude_entity != Some(body.entity)
            && self.groups.is_none_or(|g| body.groups.test(g))
            && self.predicate.is_none_or(|p| p(body.entity))
    }
}

impl std::fmt::Debug for SoftQueryFilter<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SoftQueryFilter")
            .field("groups", &self.groups)
            .field("exclude_entity", &self.exclude_entity)
            .field("predicate", &self.predicate.is_some())
            .finish()
    }
}

impl From<InteractionGroups> for SoftQueryFilter<'_> {
    fn from(groups: InteractionGroups) -> Self {
        Self::new().groups(groups)
    }
}
