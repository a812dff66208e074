//! The contact scenes' plot: settled max |v| and volume error at rest (log) against median ms
//! per frame (log), for c) drop and d) pile, one curve per engine set-up over its substep
//! counts: `contacts.png` and `contacts.svg`.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use tetpbd_bench::{ContactEngine, ContactKind, ContactScene};

use crate::contacts::ContactRow;
use crate::plot::{error_time_chart, FONT};

const SIZE: (u32, u32) = (1800, 1150);
const FLOOR: f64 = 1e-9;

type Metric = (&'static str, fn(&ContactRow) -> f64);

const METRICS: [Metric; 2] = [
    ("settled max |v| m/s (last 0.5 s)", |r| {
        f64::from(r.res.settled_speed)
    }),
    ("largest |volume error| % of a body at rest", |r| {
        f64::from(r.res.rest_volume_err_pct)
    }),
];

/// Engine set-ups in plotting order (first appearance).
fn engines(rows: &[ContactRow]) -> Vec<ContactEngine> {
    let mut e: Vec<ContactEngine> = Vec::new();
    for r in rows {
        if !e.contains(&r.engine) {
            e.push(r.engine);
        }
    }
    e
}

fn color(e: &ContactEngine, k: usize) -> RGBColor {
    const OURS: [RGBColor; 3] = [
        RGBColor(0, 90, 200),
        RGBColor(0, 150, 150),
        RGBColor(20, 160, 40),
    ];
    const RAPIER: [RGBColor; 3] = [
        RGBColor(200, 0, 0),
        RGBColor(150, 0, 150),
        RGBColor(240, 120, 0),
    ];
    match e {
        ContactEngine::Tetpbd { .. } => OURS[k % OURS.len()],
        ContactEngine::Rapier { .. } => RAPIER[k % RAPIER.len()],
    }
}

/// Writes the two files into `out`.
pub fn draw(out: &Path, scenes: &[ContactScene], rows: &[ContactRow]) -> Result<(), String> {
    register_font("sans-serif", FontStyle::Normal, FONT).map_err(|_| "invalid embedded font")?;
    let png = out.join("contacts.png");
    let svg = out.join("contacts.svg");
    {
        let root = BitMapBackend::new(&png, SIZE).into_drawing_area();
        draw_on(&root, scenes, rows).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    let root = SVGBackend::new(&svg, SIZE).into_drawing_area();
    draw_on(&root, scenes, rows).map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    scenes: &[ContactScene],
    rows: &[ContactRow],
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let root = root.titled(
        "Contact scenes, tetpbd vs rapier 0.36 soft bodies (frame 1/60 s, 1 thread; log-log)",
        ("sans-serif", 26),
    )?;
    let (main, legend) = root.split_horizontally(SIZE.0 - 440);
    let all = engines(rows);
    let (mut o, mut r) = (0, 0);
    let colors: Vec<RGBColor> = all
        .iter()
        .map(|e| match e {
            ContactEngine::Tetpbd { .. } => {
                o += 1;
                color(e, o - 1)
            }
            ContactEngine::Rapier { .. } => {
                r += 1;
                color(e, r - 1)
            }
        })
        .collect();
    let cells = main.split_evenly((2, 2));
    let panels = [ContactKind::Drop, ContactKind::Pile]
        .into_iter()
        .flat_map(|k| METRICS.iter().map(move |m| (k, m)));
    for ((kind, metric), area) in panels.zip(cells.iter()) {
        let Some(sc) = scenes.iter().find(|s| s.kind == kind && s.cells == 4) else {
            continue;
        };
        let sel: Vec<&ContactRow> = rows
            .iter()
            .filter(|r| r.scene == sc.name && r.threads == 1)
            .collect();
        draw_panel(area, sc.name, metric, &sel, &all, &colors)?;
    }
    let text = ("sans-serif", 15).into_font();
    let mut y = 60;
    for (e, c) in all.iter().zip(&colors) {
        legend.draw(&PathElement::new(vec![(10, y), (40, y)], c.stroke_width(3)))?;
        legend.draw(&Text::new(e.label(), (48, y - 8), text.clone()))?;
        y += 28;
    }
    for n in [
        "points: substeps per 1/60 s frame",
        "   (tetpbd 5–40/80, rapier 5–20)",
        "time: median over the resting phase",
        "values below 1e-9 drawn at 1e-9",
        "runs with non-finite values left out",
        "×: did not come to rest (unstable)",
    ] {
        legend.draw(&Text::new(n, (10, y + 14), text.clone()))?;
        y += 22;
    }
    Ok(())
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    scene: &str,
    metric: &Metric,
    rows: &[&ContactRow],
    engines: &[ContactEngine],
    colors: &[RGBColor],
) -> DrawResult<DB> {
    let value = |r: &ContactRow| {
        let y = (metric.1)(r);
        (r.res.ms_median.is_finite() && r.res.ms_median > 0.0 && y.is_finite())
            .then(|| (r.res.ms_median, y.max(FLOOR)))
    };
    let points: Vec<(f64, f64)> = rows.iter().filter_map(|r| value(r)).collect();
    let mut chart = error_time_chart(area, format!("{scene}: {}", metric.0), &points)?;
    for (e, c) in engines.iter().zip(colors) {
        let mut line: Vec<(u32, (f64, f64), bool)> = rows
            .iter()
            .filter(|r| r.engine == *e)
            .filter_map(|r| value(r).map(|p| (r.substeps, p, r.res.came_to_rest())))
            .collect();
        line.sort_by_key(|(s, _, _)| *s);
        chart.draw_series(LineSeries::new(
            line.iter().map(|(_, p, _)| *p),
            c.stroke_width(2),
        ))?;
        for (_, p, rest) in &line {
            if !rest {
                chart.draw_series([Cross::new(*p, 7, c.stroke_width(3))])?;
                continue;
            }
            match e {
                ContactEngine::Tetpbd { .. } => {
                    chart.draw_series([Circle::new(*p, 4, c.filled())])?
                }
                ContactEngine::Rapier { .. } => chart.draw_series([
                    EmptyElement::at(*p) + Rectangle::new([(-4, -4), (4, 4)], c.filled())
                ])?,
            };
        }
    }
    Ok(())
}
