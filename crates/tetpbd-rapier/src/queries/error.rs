//! [`QueryError`]: why a scene query was rejected.

use std::fmt;

/// Why a scene query was rejected: an input that is NaN or infinite (or out of range),
/// named with the value given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum QueryError {
    /// A point or vector of the query has a NaN or infinite component.
    NonFiniteVector {
        /// What it is (`"ray origin"`, `"ray direction"`, `"point"`, …).
        what: &'static str,
        /// The value given, m (a direction: m per unit of time of impact).
        value: [f32; 3],
    },
    /// A scalar of the query is NaN (or, where it must be finite, infinite) or negative.
    BadScalar {
        /// What it is (`"max_toi"`, `"max_dist"`).
        what: &'static str,
        /// The value given.
        value: f32,
    },
}

impl fmt::Display for QueryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            QueryError::NonFiniteVector { what, value } => {
                write!(f, "query {what} is not finite: {value:?}")
            }
            QueryError::BadScalar { what, value } => {
                write!(f, "query {what} must be >= 0 and not NaN, got {value}")
            }
        }
    }
}

impl std::error::Error for QueryError {}

/// Checks that every component of `v` is finite.
pub(crate) fn check_vector(
    what: &'static str,
    v: rapier3d::math::Vector,
) -> Result<(), QueryError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(QueryError::NonFiniteVector {
            what,
            value: [v.x, v.y, v.z],
        })
    }
}

/// Checks that a limit (`max_toi`, `max_dist`) is ≥ 0 and not NaN (+∞ means no limit).
pub(crate) fn check_limit(what: &'static str, value: f32) -> Result<(), QueryError> {
    if value >= 0.0 {
        Ok(())
    } else {
        Err(QueryError::BadScalar { what, value })
    }
}
