//! The coupled cases' scenes with rapier 0.36's own soft bodies in place of `tetpbd`'s, for
//! comparison: hard edges and volumes (its `Constraints` solver, `Volume` cell model), the
//! same lumped masses, rapier's solver iterations equal to the soft substeps.

use std::fmt::Write;

use crate::coupled::{CoupledCase, CoupledOutcome};

/// One cell: pass/FAIL (finite, no inverted tetrahedron at the end, the case's criterion),
/// the criterion's figures and the peak particle speed.
fn cell(o: &CoupledOutcome) -> String {
    match &o.error {
        Some(e) => format!("rejected: {e}"),
        None => format!(
            "{} {}, peak {:.1} m/s{}",
            if o.pass() { "**pass**" } else { "**FAIL**" },
            o.criterion.1,
            o.peak_speed,
            if o.inverted > 0 {
                format!(", inv {}", o.inverted)
            } else {
                String::new()
            }
        ),
    }
}

/// A markdown section with one row per case of `cases` that has a rapier variant, run now
/// (`progress` is called after each with the case's name). Empty if no case has one.
pub fn rapier_comparison(cases: &[CoupledCase], mut progress: impl FnMut(&str)) -> String {
    let rows: Vec<_> = cases.iter().filter_map(|c| Some((c, c.rapier?))).collect();
    if rows.is_empty() {
        return String::new();
    }
    let mut s = String::new();
    let _ = writeln!(s, "## The same scenes with rapier 0.36's own soft bodies\n");
    let _ = writeln!(
        s,
        "rapier's soft body in place of `tetpbd`'s in the same rapier scene (`Constraints` solver, `Volume` \
         cell model with edges and volumes at 10⁶ Hz, the same lumped masses, `num_solver_iterations` = 10, \
         particles attached with `SoftBody::attach_particle`), judged by the same criterion.\n"
    );
    let _ = writeln!(s, "| case | rapier 0.36 soft body |\n|---|---|");
    let mut passed = 0;
    for (case, run) in &rows {
        let o = run();
        passed += usize::from(o.pass());
        let _ = writeln!(s, "| {} | {} |", case.name, cell(&o));
        progress(case.name);
    }
    let _ = writeln!(s, "\n{passed} of {} cells pass.\n", rows.len());
    s
}
