//! SVG plots with plotters: a simulated trajectory (coordinates, energy drift and
//! constraint violations against time) and a work-precision diagram (error against
//! wall time, log-log, one curve per method).

use std::path::Path;

use pfaff::sim::{Row, Run};
use pfaff::{Mechanism, MechanismExt};
use plotters::prelude::*;

use super::error::{failed, CliError};

/// Floor for values drawn on a logarithmic axis (exact zeros happen).
const LOG_FLOOR: f64 = 1e-17;

fn err(path: &Path) -> impl Fn(String) -> CliError + '_ {
    move |e| failed(format!("cannot write the plot `{}`: {e}", path.display()))
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-12 * (1.0 + lo.abs().max(hi.abs())));
    (lo - pad, hi + pad)
}

fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .map(|v| v.max(LOG_FLOOR))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (LOG_FLOOR, 1.0);
    }
    (lo / 2.0, (hi * 2.0).max(lo * 10.0))
}

/// Writes the three-panel plot of `run` to `path`.
pub fn trajectory(model: &dyn Mechanism, run: &Run, path: &Path) -> Result<(), CliError> {
    let mut svg = String::new();
    draw_trajectory(model, run, &mut svg).map_err(err(path))?;
    super::out::write_file(path, |w| std::io::Write::write_all(w, svg.as_bytes()))
}

/// Draws the three-panel plot of `run` as SVG into `svg`.
fn draw_trajectory(model: &dyn Mechanism, run: &Run, svg: &mut String) -> Result<(), String> {
    let e = |x: String| x;
    let info = model.info();
    let tr = &run.trajectory;
    let t = &tr.t;
    let n = info.nq();
    let root = SVGBackend::with_string(svg, (960, 1080)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
    let root = root
        .titled(
            &format!(
                "pfaff: {} over [0, {}] s",
                info.name,
                t.last().copied().unwrap_or(0.0)
            ),
            ("sans-serif", 22),
        )
        .map_err(|x| e(x.to_string()))?;
    let panels = root.split_evenly((3, 1));
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(1.0).max(1e-300),
    );

    // Coordinates.
    let (lo, hi) = range(tr.q.iter().copied());
    let mut chart = ChartBuilder::on(&panels[0])
        .caption("coordinates q", ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, lo..hi)
        .map_err(|x| e(x.to_string()))?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .draw()
        .map_err(|x| e(x.to_string()))?;
    for j in 0..n {
        let color = Palette99::pick(j).to_rgba();
        chart
            .draw_series(LineSeries::new(
                (0..tr.len()).map(|i| (t[i], tr.q(i)[j])),
                color.stroke_width(2),
            ))
            .map_err(|x| e(x.to_string()))?
            .label(info.coordinates[j].name)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    if !run.impacts.is_empty() {
        // Impacts: a vertical mark at each.
        let mark = BLACK.mix(0.5);
        chart
            .draw_series(
                run.impacts
                    .iter()
                    .map(|imp| PathElement::new([(imp.t, lo), (imp.t, hi)], mark.stroke_width(1))),
            )
            .map_err(|x| e(x.to_string()))?
            .label("impacts")
            .legend(move |(x, y)| PathElement::new([(x + 10, y - 6), (x + 10, y + 6)], mark));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(|x| e(x.to_string()))?;

    // Energy drift E(t) − E(0).
    let energy: Vec<f64> = (0..tr.len())
        .map(|i| model.energy(t[i], tr.q(i), tr.qd(i)))
        .collect();
    let e0 = energy.first().copied().unwrap_or(0.0);
    let drift: Vec<f64> = energy.iter().map(|v| v - e0).collect();
    let (lo, hi) = range(drift.iter().copied());
    let caption = if info.conservative {
        "energy drift E(t) - E(0) [J]"
    } else {
        "energy change E(t) - E(0) [J] (not conserved: applied forces or explicit time)"
    };
    let mut chart = ChartBuilder::on(&panels[1])
        .caption(caption, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, lo..hi)
        .map_err(|x| e(x.to_string()))?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .draw()
        .map_err(|x| e(x.to_string()))?;
    chart
        .draw_series(LineSeries::new(
            t.iter().copied().zip(drift.iter().copied()),
            BLUE.stroke_width(2),
        ))
        .map_err(|x| e(x.to_string()))?;

    // Constraint violations, log scale.
    let (lo, hi) = log_range(
        tr.position_violation
            .iter()
            .chain(&tr.velocity_violation)
            .copied(),
    );
    let mut chart = ChartBuilder::on(&panels[2])
        .caption("constraint violation (infinity norm)", ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, (lo..hi).log_scale())
        .map_err(|x| e(x.to_string()))?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|x| e(x.to_string()))?;
    for (k, (label, values)) in [
        ("position |C|", &tr.position_violation),
        ("velocity |J q' + c|", &tr.velocity_violation),
    ]
    .into_iter()
    .enumerate()
    {
        let color = if k == 0 { RED } else { GREEN };
        chart
            .draw_series(LineSeries::new(
                t.iter()
                    .copied()
                    .zip(values.iter().map(|v| v.max(LOG_FLOOR))),
                color.stroke_width(2),
            ))
            .map_err(|x| e(x.to_string()))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|x| e(x.to_string()))?;
    root.present().map_err(|x| e(x.to_string()))
}

/// Writes the work-precision diagram of `rows` (error against wall time, log-log).
pub fn work_precision(model: &str, t_end: f64, rows: &[Row], path: &Path) -> Result<(), CliError> {
    let mut svg = String::new();
    draw_work_precision(model, t_end, rows, &mut svg).map_err(err(path))?;
    super::out::write_file(path, |w| std::io::Write::write_all(w, svg.as_bytes()))
}

/// Draws the work-precision diagram of `rows` as SVG into `svg`.
fn draw_work_precision(
    model: &str,
    t_end: f64,
    rows: &[Row],
    svg: &mut String,
) -> Result<(), String> {
    let e = |x: String| x;
    let ok: Vec<&Row> = rows
        .iter()
        .filter(|r| r.failure.is_none() && r.error.is_finite())
        .collect();
    let (x0, x1) = log_range(ok.iter().map(|r| r.wall_time.as_secs_f64().max(1e-7)));
    let (y0, y1) = log_range(ok.iter().map(|r| r.error));
    let root = SVGBackend::with_string(svg, (960, 720)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("work-precision: {model} over [0, {}] s", super::time(t_end)),
            ("sans-serif", 22),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(|x| e(x.to_string()))?;
    chart
        .configure_mesh()
        .x_desc("wall time [s]")
        .y_desc("final error (relative)")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|x| e(x.to_string()))?;
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for r in &ok {
        let name = format!("{} + {}", r.formulation.name(), r.method.name());
        let point = (r.wall_time.as_secs_f64().max(1e-7), r.error.max(LOG_FLOOR));
        match curves.iter_mut().find(|c| c.0 == name) {
            Some(c) => c.1.push(point),
            None => curves.push((name, vec![point])),
        }
    }
    // Points stay in the order of the sweep (tightening tolerance), which is the
    // order of a work-precision curve even when the timings are noisy.
    for (k, (name, points)) in curves.into_iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let style = color.stroke_width(2);
        chart
            .draw_series(LineSeries::new(points.iter().copied(), style))
            .map_err(|x| e(x.to_string()))?
            .label(name)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))
            .map_err(|x| e(x.to_string()))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|x| e(x.to_string()))?;
    root.present().map_err(|x| e(x.to_string()))
}
