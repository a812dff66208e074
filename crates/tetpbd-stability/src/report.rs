//! The markdown matrix.

use std::fmt::Write;

use crate::cases::Case;
use crate::config::Config;
use crate::run::Outcome;

fn cell(o: &Outcome) -> String {
    if let Some(e) = &o.build_error {
        return format!("rejected: {e}");
    }
    if let Some(e) = &o.settings_error {
        return format!("rejected: {e}");
    }
    let mut s = String::from(if o.pass() { "**pass**" } else { "**FAIL**" });
    if !o.finite || o.non_finite_resets > 0 {
        let _ = write!(s, " non-finite ({} resets)", o.non_finite_resets);
    }
    let _ = write!(s, " KE {:.2}", o.peak_ke_ratio);
    if o.require_recovery {
        let _ = write!(s, "→{:.1e}", o.final_ke_ratio);
    }
    if o.require_recovery {
        match o.recovered_at {
            Some(f) => {
                let _ = write!(s, ", rec. {f}");
            }
            None => {
                let _ = write!(
                    s,
                    ", not rec. (inv {}, vol {:.0} %)",
                    o.final_inverted,
                    o.final_volume_error * 100.0
                );
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
        for o in row {
            let _ = write!(s, " {} |", cell(o));
        }
        let _ = writeln!(s);
    }
    s
}
