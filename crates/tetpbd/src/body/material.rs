//! [`Material`]: a continuum material in physical units (Young's modulus in Pa, Poisson's
//! ratio, a damping time in s), its Lamé parameters, presets with their sources, and
//! [`MaterialError`] for values out of range.

use std::fmt;

/// A material's parameters out of range: the value given, by name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialError {
    /// Young's modulus must be finite and > 0, Pa.
    BadYoungsModulus {
        /// The value given, Pa.
        value: f32,
    },
    /// Poisson's ratio must be finite, ≥ 0 and < 0.5 (0.5 is incompressible, where the
    /// hydrostatic compliance would vanish).
    BadPoissonRatio {
        /// The value given.
        value: f32,
    },
    /// The damping time must be finite and ≥ 0, s.
    BadDamping {
        /// The value given, s.
        value: f32,
    },
}

impl fmt::Display for MaterialError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MaterialError::BadYoungsModulus { value } => {
                write!(f, "Young's modulus {value} Pa: must be finite and > 0")
            }
            MaterialError::BadPoissonRatio { value } => {
                write!(f, "Poisson's ratio {value}: must be finite, ≥ 0 and < 0.5")
            }
            MaterialError::BadDamping { value } => {
                write!(f, "material damping {value} s: must be finite and ≥ 0")
            }
        }
    }
}

impl std::error::Error for MaterialError {}

/// An isotropic elastic material: Young's modulus `E` (Pa), Poisson's ratio `ν` and a
/// damping time `β` (s), validated on construction.
///
/// A body given one with [`crate::SoftBodyBuilder::material`] gets a
/// [`crate::NeoHookeanMaterial`] component: the stable Neo-Hookean energy with the Lamé
/// parameters of `E` and `ν`, so its stiffness is the same at every mesh resolution and
/// substep count. The damping is stiffness-proportional (Rayleigh) in the XPBD form: a
/// vibration mode of angular frequency `ω` decays with damping ratio `β ω / 2`, whatever the
/// substeps.
///
/// ```
/// use tetpbd::{Material, MaterialError};
/// let m = Material::new(1e6, 0.45)?.with_damping(1e-3)?;
/// assert_eq!(m.young_modulus(), 1e6);
/// assert!(Material::new(1e6, 0.5).is_err());
/// assert_eq!(Material::new(-1.0, 0.3), Err(MaterialError::BadYoungsModulus { value: -1.0 }));
/// # Ok::<(), MaterialError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "MaterialParameters"))]
pub struct Material {
    young: f32,
    poisson: f32,
    damping: f32,
}

/// The fields of a [`Material`] as they are (de)serialized; validated into one.
#[cfg(feature = "serde")]
#[derive(serde::Deserialize)]
struct MaterialParameters {
    young: f32,
    poisson: f32,
    damping: f32,
}

#[cfg(feature = "serde")]
impl TryFrom<MaterialParameters> for Material {
    type Error = MaterialError;
    fn try_from(p: MaterialParameters) -> Result<Material, MaterialError> {
        Material::new(p.young, p.poisson)?.with_damping(p.damping)
    }
}

impl Material {
    /// Natural rubber (vulcanised, soft): `E = 1.2 MPa`, `ν = 0.49`, damping 0.5 ms.
    /// Source: the shear modulus of about 0.4 MPa of Treloar's vulcanised natural rubber
    /// (L. R. G. Treloar, *The Physics of Rubber Elasticity*, 3rd ed., 1975), `E = 3G`. Real
    /// rubber is nearer 0.4999; 0.49 keeps the bulk stiffness 50 times the shear stiffness.
    pub const RUBBER: Material = Material {
        young: 1.2e6,
        poisson: 0.49,
        damping: 5e-4,
    };

    /// A gelatin jelly: `E = 5 kPa`, `ν = 0.45`, damping 5 ms (wobbles a few times and
    /// settles). Source: gelatin gels of a few per cent by weight measure Young's moduli of
    /// 1–20 kPa (e.g. Markidou, Shih & Shih, "Soft-materials elastic and shear moduli
    /// measurement using piezoelectric cantilevers", Rev. Sci. Instrum. 76, 2005). Water
    /// makes a gel nearly incompressible; 0.45 trades some of that for a softer bulk term.
    pub const JELLY: Material = Material {
        young: 5e3,
        poisson: 0.45,
        damping: 5e-3,
    };

    /// Soft tissue (organ parenchyma, relaxed muscle): `E = 10 kPa`, `ν = 0.45`, damping
    /// 5 ms. Source: the review of McKee, Last, Russell & Murphy, "Indentation versus tensile
    /// measurements of Young's modulus for soft biological tissues", Tissue Eng. Part B 17
    /// (2011), whose soft organs lie between about 1 and 100 kPa.
    pub const SOFT_TISSUE: Material = Material {
        young: 1e4,
        poisson: 0.45,
        damping: 5e-3,
    };

    /// Flexible open-cell polymer foam (upholstery polyurethane): `E = 50 kPa`, `ν = 0.3`,
    /// damping 2 ms. Source: L. J. Gibson & M. F. Ashby, *Cellular Solids*, 2nd ed., 1997:
    /// flexible foams of relative density a few per cent have moduli of tens of kPa, and
    /// open-cell foams a Poisson's ratio of about 1/3.
    pub const FOAM: Material = Material {
        young: 5e4,
        poisson: 0.3,
        damping: 2e-3,
    };

    /// A material of Young's modulus `young` (Pa, finite and > 0) and Poisson's ratio
    /// `poisson` (finite, `0 ≤ ν < 0.5`), undamped.
    pub fn new(young: f32, poisson: f32) -> Result<Material, MaterialError> {
        if !(young.is_finite() && young > 0.0) {
            return Err(MaterialError::BadYoungsModulus { value: young });
        }
        if !(poisson.is_finite() && (0.0..0.5).contains(&poisson)) {
            return Err(MaterialError::BadPoissonRatio { value: poisson });
        }
        Ok(Material {
            young,
            poisson,
            damping: 0.0,
        })
    }

    /// The same material with damping time `beta` (s, finite and ≥ 0; 0 = undamped): a
    /// damping force `β k Ċ` on each constraint of stiffness `k`, stiffness-proportional.
    pub fn with_damping(self, beta: f32) -> Result<Material, MaterialError> {
        if beta.is_finite() && beta >= 0.0 {
            Ok(Material {
                damping: beta,
                ..self
            })
        } else {
            Err(MaterialError::BadDamping { value: beta })
        }
    }

    /// Young's modulus `E`, Pa.
    pub fn young_modulus(&self) -> f32 {
        self.young
    }

    /// Poisson's ratio `ν`.
    pub fn poisson_ratio(&self) -> f32 {
        self.poisson
    }

    /// Damping time `β`, s.
    pub fn damping(&self) -> f32 {
        self.damping
    }

    /// The Lamé parameters `(μ, λ)`, Pa: `μ = E / (2(1 + ν))`, `λ = E ν / ((1 + ν)(1 − 2ν))`.
    pub fn lame(&self) -> (f32, f32) {
        let (e, nu) = (f64::from(self.young), f64::from(self.poisson));
        let mu = e / (2.0 * (1.0 + nu));
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        (mu as f32, lambda as f32)
    }
}
