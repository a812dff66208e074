//! The markdown matrix.

use std::fmt::Write;

use crate::cases::Case;
use crate::config::{Config, ConstraintSet};
use crate::run::Outcome;

/// How a cell counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Passes every criterion.
    Pass,
    /// The vertex–face family alone did not recover its shape but kept every other
    /// criterion (finite, no energy gained, calm): four heights fix four of a tetrahedron's
    /// six shape degrees of freedom, so its shape is not asked of it. Thrown at the ground,
    /// it need only stay finite and keep its energy ([`Outcome::sound`]): a shape it cannot
    /// hold may also keep moving inside itself.
    Expected,
    /// Fails.
    Fail,
}

/// The verdict of outcome `o` under configuration `config`.
pub fn verdict(config: &Config, o: &Outcome) -> Verdict {
    if o.pass() {
        Verdict::Pass
    } else if config.set == ConstraintSet::VertexFace && o.require_recovery && o.pass_but_shape() {
        Verdict::Expected
    } else if config.set == ConstraintSet::VertexFace && o.rebound.is_some() && o.sound() {
        // Thrown at the ground, the family alone need only keep its energy: a body it
        // cannot hold in shape may stretch without bound and keep moving inside itself.
        Verdict::Expected
    } else {
        Verdict::Fail
    }
}

fn cell(config: &Config, o: &Outcome) -> String {
    if let Some(e) = &o.build_error {
        return format!("rejected: {e}");
    }
    if let Some(e) = &o.settings_error {
        return format!("rejected: {e}");
    }
    let mut s = String::from(match verdict(config, o) {
        Verdict::Pass => "**pass**",
        Verdict::Expected => "*shape (vf alone)*",
        Verdict::Fail => "**FAIL**",
    });
    if !o.finite || o.non_finite_resets > 0 {
        let _ = write!(s, " non-finite ({} resets)", o.non_finite_resets);
    }
    let _ = write!(s, " KE {:.2}", o.peak_ke_ratio);
    if o.require_recovery {
        let _ = write!(s, "→{:.1e}", o.final_ke_ratio);
    }
    if o.rebound.is_some() {
        let _ = write!(
            s,
            ", int. {:.2}→{:.1e}",
            o.peak_internal_ratio, o.final_internal_ratio
        );
    }
    let _ = write!(s, ", ΔE {:.0e}", o.energy_gain);
    if let Some((came, rose)) = o.rebound {
        let _ = write!(s, ", rises {rose:.1} of {came:.0} m/s");
    }
    if o.require_recovery {
        match o.recovered_at {
            Some(f) if o.intact() => {
                let _ = write!(s, ", rec. {f}");
            }
            Some(f) => {
                let _ = write!(
                    s,
                    ", rec. {f}, at the end inv {}, vol {:.1} %",
                    o.final_inverted,
                    o.final_volume_error * 100.0
                );
                if let Some(r) = o.resting_volume_ratio {
                    let _ = write!(s, ", at rest vol {:.1} %", (r - 1.0) * 100.0);
                }
            }
            None => {
                let _ = write!(
                    s,
                    ", not rec. (inv {}, vol {:.0} %)",
                    o.final_inverted,
                    o.final_volume_error * 100.0
                );
                if let Some(r) = o.resting_volume_ratio {
                    let _ = write!(s, ", at rest vol {:.1} %", (r - 1.0) * 100.0);
                }
            }
        }
    } else if o.final_inverted > 0 {
        let _ = write!(s, ", inv {}", o.final_inverted);
    }
    let names = ["e", "vf", "vol"];
    for (k, c) in o.final_max_c.iter().enumerate() {
        if let Some(c) = c {
            let _ = write!(s, ", {} {:.1e}", names[k], c);
        }
    }
    if o.velocity_clamps > 0 {
        let _ = write!(s, ", clamps {}", o.velocity_clamps);
    }
    if config.set == ConstraintSet::Material {
        let _ = write!(s, ", {} substeps", o.substeps);
    }
    s
}

/// The matrix as a markdown table: rows cases, columns configurations.
pub fn markdown(cases: &[Case], configs: &[Config], results: &[Vec<Outcome>]) -> String {
    let mut s = String::new();
    let _ = write!(s, "| group | case |");
    for c in configs {
        let _ = write!(s, " {} |", c.label());
    }
    let _ = writeln!(s);
    let _ = write!(s, "|---|---|");
    for _ in configs {
        let _ = write!(s, "---|");
    }
    let _ = writeln!(s);
    for (case, row) in cases.iter().zip(results) {
        let _ = write!(s, "| {} | {} |", case.group, case.name);
        for (c, o) in configs.iter().zip(row) {
            let _ = write!(s, " {} |", cell(c, o));
        }
        let _ = writeln!(s);
    }
    s
}
