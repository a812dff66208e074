//! The squash scene's volume error over time, one curve per model at one budget:
//! `squash_volume.png` and `squash_volume.svg`.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use crate::plot::{models, palette, FONT};
use crate::report::Row;
use crate::scenes::DT;

const SIZE: (u32, u32) = (1300, 700);
const FLOOR: f64 = 1e-6;

/// The budget drawn: 8 substeps × 1 iteration when the sweep has it, else the largest
/// substep count below it.
fn budget(rows: &[Row]) -> u32 {
    rows.iter()
        .filter(|r| r.iterations == 1 && r.substeps <= 8)
        .map(|r| r.substeps)
        .max()
        .unwrap_or(1)
}

/// Writes the two files into `out`; `squash` names the squash scene.
pub fn draw(out: &Path, rows: &[Row], squash: &str) -> Result<(), String> {
    register_font("sans-serif", FontStyle::Normal, FONT).map_err(|_| "invalid embedded font")?;
    let sel: Vec<&Row> = rows.iter().filter(|r| r.scene == squash).collect();
    let owned: Vec<Row> = sel.iter().map(|r| (*r).clone()).collect();
    let substeps = budget(&owned);
    let png = out.join("squash_volume.png");
    let svg = out.join("squash_volume.svg");
    {
        let root = BitMapBackend::new(&png, SIZE).into_drawing_area();
        draw_on(&root, &owned, substeps).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    let root = SVGBackend::new(&svg, SIZE).into_drawing_area();
    draw_on(&root, &owned, substeps).map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[Row],
    substeps: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let all = models(rows);
    let colors = palette(&all);
    let frames = rows
        .iter()
        .map(|r| r.volume_series.len())
        .max()
        .unwrap_or(1);
    let t_end = frames as f64 * f64::from(DT);
    let y_max = rows
        .iter()
        .flat_map(|r| r.volume_series.iter())
        .map(|v| f64::from(v.abs()))
        .filter(|v| v.is_finite())
        .fold(1.0, f64::max)
        * 1.5;
    let (plot, legend) = root.split_horizontally(SIZE.0 - 330);
    let mut chart = ChartBuilder::on(&plot)
        .caption(
            format!("b) squash to 50 % and release: |total-volume error| over time, {substeps} substeps × 1 iteration"),
            ("sans-serif", 19),
        )
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(74)
        .build_cartesian_2d(0.0..t_end, (FLOOR..y_max).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("time after release, s")
        .y_desc("|volume error| %")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    let text = ("sans-serif", 15).into_font();
    let mut y = 60;
    for (m, c) in all.iter().zip(&colors) {
        let Some(r) = rows
            .iter()
            .find(|r| r.model == *m && r.substeps == substeps && r.iterations == 1)
        else {
            continue;
        };
        let pts = r.volume_series.iter().enumerate().filter_map(|(f, v)| {
            let v = f64::from(v.abs());
            v.is_finite()
                .then_some(((f + 1) as f64 * f64::from(DT), v.max(FLOOR)))
        });
        chart.draw_series(LineSeries::new(pts, c.stroke_width(2)))?;
        legend.draw(&PathElement::new(vec![(10, y), (40, y)], c.stroke_width(3)))?;
        legend.draw(&Text::new(m.label(), (48, y - 8), text.clone()))?;
        y += 28;
    }
    legend.draw(&Text::new(
        format!("values below {FLOOR:.0e} % drawn at {FLOOR:.0e}"),
        (10, y + 14),
        text,
    ))?;
    Ok(())
}
