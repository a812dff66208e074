//! The plots: error (log) against median ms per frame (log), one curve per model; plot.png has
//! four panels (two per scene a and b), materials.png two (the deviation panels of the
//! material scenes e and f); each drawn once as PNG and once as SVG with plotters. Text uses a subset of
//! DejaVu Sans shipped in `assets/`, so no system font is needed.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use crate::engines::Model;
use crate::report::Row;
use crate::scenes::{Scene, SceneKind};

pub const FONT: &[u8] = include_bytes!("../../../assets/DejaVuSans-subset.ttf");
const SIZE: (u32, u32) = (1800, 1150);
const FLOOR: f64 = 1e-9;

/// One panel: which rows, which metric.
struct Panel {
    kind: SceneKind,
    /// A panel of a material scene (see [`Scene::material`]).
    material: bool,
    title: &'static str,
    metric: fn(&Row) -> f64,
    only_hard: bool,
    /// Leave out the rows whose reference did not converge (see [`Row::reference_ok`]).
    needs_reference: bool,
}

const PANELS: [Panel; 4] = [
    Panel {
        kind: SceneKind::HangingBeam,
        material: false,
        title: "a) hanging beam at rest: max deviation from converged reference / length",
        metric: |r| f64::from(r.dev.max),
        only_hard: false,
        needs_reference: true,
    },
    Panel {
        kind: SceneKind::HangingBeam,
        material: false,
        title: "a) hanging beam, hard models: RMS edge strain at rest (exact: 0)",
        metric: |r| f64::from(r.edge_strain_rms),
        only_hard: true,
        needs_reference: false,
    },
    Panel {
        kind: SceneKind::Squash,
        material: false,
        title: "b) squash & release: max deviation from converged reference / size",
        metric: |r| f64::from(r.dev.max),
        only_hard: false,
        needs_reference: true,
    },
    Panel {
        kind: SceneKind::Squash,
        material: false,
        title: "b) squash & release: max |volume error| %, second half of the run",
        metric: |r| f64::from(r.late_volume_err_pct),
        only_hard: false,
        needs_reference: false,
    },
];

const MATERIAL_PANELS: [Panel; 2] = [
    Panel {
        kind: SceneKind::HangingBeam,
        material: true,
        title: "e) material beam at rest: max deviation from converged reference / length",
        metric: |r| f64::from(r.dev.max),
        only_hard: false,
        needs_reference: true,
    },
    Panel {
        kind: SceneKind::Squash,
        material: true,
        title: "f) material squash & release: max deviation from converged reference / size",
        metric: |r| f64::from(r.dev.max),
        only_hard: false,
        needs_reference: true,
    },
];

/// The models in plotting order (first appearance in `rows`).
pub fn models(rows: &[Row]) -> Vec<Model> {
    let mut m: Vec<Model> = Vec::new();
    for r in rows {
        if !m.contains(&r.model) {
            m.push(r.model);
        }
    }
    m
}

fn color(model: &Model, k: usize) -> RGBColor {
    const OURS: [RGBColor; 6] = [
        RGBColor(0, 90, 200),
        RGBColor(0, 150, 150),
        RGBColor(40, 160, 40),
        RGBColor(110, 160, 255),
        RGBColor(90, 210, 200),
        RGBColor(140, 210, 90),
    ];
    const RAPIER: [RGBColor; 7] = [
        RGBColor(200, 0, 0),
        RGBColor(240, 120, 0),
        RGBColor(150, 0, 150),
        RGBColor(210, 80, 150),
        RGBColor(110, 0, 0),
        RGBColor(120, 70, 20),
        RGBColor(200, 170, 0),
    ];

    if model.is_ours() {
        OURS[k % OURS.len()]
    } else {
        RAPIER[k % RAPIER.len()]
    }
}

/// Colours by model, ours and rapier counted separately.
pub fn palette(models: &[Model]) -> Vec<RGBColor> {
    let (mut o, mut r) = (0, 0);
    models
        .iter()
        .map(|m| {
            let k = if m.is_ours() { &mut o } else { &mut r };
            *k += 1;
            color(m, *k - 1)
        })
        .collect()
}

/// Writes `plot.png` and `plot.svg` (scenes a and b), and `materials.png` and
/// `materials.svg` (the material scenes) into `out`.
pub fn draw(out: &Path, scenes: &[Scene], rows: &[Row]) -> Result<(), String> {
    // Registering twice (a second call of `draw`) is harmless: the first font stays.
    register_font("sans-serif", FontStyle::Normal, FONT).map_err(|_| "invalid embedded font")?;
    let (material_rows, constraint_rows): (Vec<Row>, Vec<Row>) = rows
        .iter()
        .cloned()
        .partition(|r| matches!(r.model, Model::Material | Model::RapierMaterial { .. }));
    for (stem, panels, rows, size) in [
        ("plot", &PANELS[..], &constraint_rows[..], SIZE),
        (
            "materials",
            &MATERIAL_PANELS[..],
            &material_rows[..],
            (SIZE.0, 650),
        ),
    ] {
        let png = out.join(format!("{stem}.png"));
        let svg = out.join(format!("{stem}.svg"));
        {
            let root = BitMapBackend::new(&png, size).into_drawing_area();
            draw_on(&root, panels, scenes, rows).map_err(|e| e.to_string())?;
            root.present().map_err(|e| e.to_string())?;
        }
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        draw_on(&root, panels, scenes, rows).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(())
}

type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    panels: &[Panel],
    scenes: &[Scene],
    rows: &[Row],
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let root = root.titled(
        "Error against run time, tetpbd vs rapier 0.36 soft bodies (frame 1/60 s, 1 core; log-log)",
        ("sans-serif", 26),
    )?;
    let (main, legend) = root.split_horizontally(SIZE.0 - 330);
    let all_models = models(rows);
    let colors = palette(&all_models);
    let cells = main.split_evenly((panels.len().div_ceil(2), 2));
    for (panel, area) in panels.iter().zip(cells.iter()) {
        let Some(scene) = scenes
            .iter()
            .find(|s| s.kind == panel.kind && s.material.is_some() == panel.material)
        else {
            continue;
        };
        let sel: Vec<&Row> = rows
            .iter()
            .filter(|r| {
                r.scene == scene.name
                    && (!panel.only_hard || r.model.is_hard())
                    && (!panel.needs_reference || r.reference_ok())
            })
            .collect();
        draw_panel(area, panel, &sel, &all_models, &colors)?;
    }
    draw_legend(&legend, &all_models, &colors)
}

fn value(panel: &Panel, r: &Row) -> Option<(f64, f64)> {
    let y = (panel.metric)(r);
    (r.ms.is_finite() && r.ms > 0.0 && y.is_finite()).then(|| (r.ms, y.max(FLOOR)))
}

/// Log-axis ranges around `points` (padded by 1.6× each way).
pub fn bounds(points: &[(f64, f64)]) -> ((f64, f64), (f64, f64)) {
    let fold = |f: fn(&(f64, f64)) -> f64| {
        points
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    };
    let pad = |(lo, hi): (f64, f64)| {
        if lo.is_finite() && hi.is_finite() {
            (lo / 1.6, hi * 1.6)
        } else {
            (1e-3, 1.0)
        }
    };
    (pad(fold(|p| p.0)), pad(fold(|p| p.1)))
}

/// A chart with log–log axes.
pub type LogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// A log–log chart of error against median ms per frame over `points`, axes drawn.
pub fn error_time_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: impl AsRef<str>,
    points: &[(f64, f64)],
) -> Result<LogChart<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    let ((x0, x1), (y0, y1)) = bounds(points);
    let mut chart = ChartBuilder::on(area)
        .caption(caption.as_ref(), ("sans-serif", 17))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(78)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("median ms per frame")
        .y_desc("error")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .x_label_formatter(&|v| format!("{v:.1e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    Ok(chart)
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    rows: &[&Row],
    models: &[Model],
    colors: &[RGBColor],
) -> DrawResult<DB> {
    let points: Vec<(f64, f64)> = rows.iter().filter_map(|r| value(panel, r)).collect();
    let mut chart = error_time_chart(area, panel.title, &points)?;
    for (model, c) in models.iter().zip(colors) {
        let mine: Vec<&&Row> = rows.iter().filter(|r| r.model == *model).collect();
        let mut line: Vec<(u32, (f64, f64))> = mine
            .iter()
            .filter(|r| r.iterations == 1)
            .filter_map(|r| value(panel, r).map(|p| (r.substeps, p)))
            .collect();
        line.sort_by_key(|(s, _)| *s);
        let width = if model.is_ours() { 2 } else { 3 };
        chart.draw_series(LineSeries::new(
            line.iter().map(|(_, p)| *p),
            c.stroke_width(width),
        ))?;
        for (_, p) in &line {
            if model.is_ours() {
                chart.draw_series([Circle::new(*p, 4, c.filled())])?;
            } else {
                chart.draw_series([
                    EmptyElement::at(*p) + Rectangle::new([(-4, -4), (4, 4)], c.filled())
                ])?;
            }
        }
        let iterated = mine
            .iter()
            .filter(|r| r.iterations > 1)
            .filter_map(|r| value(panel, r));
        chart.draw_series(iterated.map(|p| TriangleMarker::new(p, 6, c.stroke_width(2))))?;
    }
    Ok(())
}

fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    models: &[Model],
    colors: &[RGBColor],
) -> DrawResult<DB> {
    let text = ("sans-serif", 15).into_font();
    let mut y = 60;
    for (m, c) in models.iter().zip(colors) {
        area.draw(&PathElement::new(vec![(10, y), (40, y)], c.stroke_width(3)))?;
        if m.is_ours() {
            area.draw(&Circle::new((25, y), 4, c.filled()))?;
        } else {
            area.draw(&Rectangle::new([(21, y - 4), (29, y + 4)], c.filled()))?;
        }
        area.draw(&Text::new(m.label(), (48, y - 8), text.clone()))?;
        y += 28;
    }
    y += 14;
    let notes = [
        "lines: substeps × 1 iteration",
        "   (1, 2, 4, … per 1/60 s frame)",
        "open triangles: tetpbd 1×4, 1×16,",
        "   1×32 and 4×4 (iterations)",
        "squares: rapier num_solver_iterations",
        "error of each model vs its own",
        "   converged reference (see summary)",
        "errors below 1e-9 drawn at 1e-9",
        "deviation panels leave out models",
        "   whose reference moved > 1e-3",
    ];
    for n in notes {
        area.draw(&Text::new(n, (10, y), text.clone()))?;
        y += 22;
    }
    Ok(())
}
