//! SVG figures and the HTML index of a run, drawn with plotters.
//!
//! Text is laid out with DejaVu Sans bundled through the `dejavu` crate
//! (plotters' `ab_glyph` feature), so no system font library is needed; the
//! SVGs carry real `<text>` elements.

use crate::design::scp::ScpIteration;
use crate::error::{Error, Result};
use plotters::prelude::*;
use std::sync::Once;

/// One method's curves.
#[derive(Debug, Clone)]
pub struct MethodTrace {
    pub name: String,
    pub t: Vec<f64>,
    pub q: Vec<[f64; 2]>,
    /// Joint torque in the peak norm, N m.
    pub tau: Vec<f64>,
    pub phase_bounds: Vec<f64>,
    /// Attitude about the initial spine from the kinematic simulation.
    pub flip_t: Vec<f64>,
    pub flip_deg: Vec<f64>,
}

const FONT: &str = "sans-serif";
const COLORS: [RGBColor; 4] = [
    RGBColor(0x88, 0x88, 0x88),
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
];

fn color(i: usize) -> RGBColor {
    COLORS[i % COLORS.len()]
}

fn font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular())
            .unwrap_or_else(|_| panic!("the bundled DejaVu font parses"));
    });
}

fn perr<E: std::fmt::Debug>(e: E) -> Error {
    Error::Report(format!("{e:?}"))
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

fn chart<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
    xdesc: &str,
    ydesc: &str,
) -> Result<Chart<'a, 'b>> {
    let mut c = ChartBuilder::on(area)
        .caption(title, (FONT, 20))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(perr)?;
    c.configure_mesh()
        .x_desc(xdesc)
        .y_desc(ydesc)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 15))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(perr)?;
    Ok(c)
}

fn legend<'a, 'b: 'a>(c: &mut Chart<'a, 'b>) -> Result<()> {
    c.configure_series_labels()
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(perr)
}

fn phase_marks(c: &mut Chart, m: &MethodTrace, col: RGBColor, y: (f64, f64)) -> Result<()> {
    for &b in &m.phase_bounds[1..m.phase_bounds.len() - 1] {
        c.draw_series(DashedLineSeries::new(
            vec![(b, y.0), (b, y.1)],
            4,
            4,
            col.mix(0.6).stroke_width(1),
        ))
        .map_err(perr)?;
    }
    Ok(())
}

fn svg(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend, plotters::coord::Shift>) -> Result<()>,
) -> Result<String> {
    font();
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, size).into_drawing_area();
        root.fill(&WHITE).map_err(perr)?;
        draw(&root)?;
        root.present().map_err(perr)?;
    }
    Ok(s)
}

/// Joint angles against time, phase boundaries dashed.
pub fn angles(methods: &[MethodTrace]) -> Result<String> {
    svg((900, 700), |root| {
        let tmax = range(methods.iter().flat_map(|m| m.t.iter().copied())).1;
        let panels = root.split_evenly((2, 1));
        for (j, area) in panels.iter().enumerate() {
            let y = range(
                methods
                    .iter()
                    .flat_map(|m| m.q.iter().map(move |q| q[j].to_degrees())),
            );
            let title = format!("Joint angle q{} against time", j + 1);
            let mut c = chart(
                area,
                &title,
                (0.0, tmax),
                y,
                "time (s)",
                &format!("q{} (deg)", j + 1),
            )?;
            for (i, m) in methods.iter().enumerate() {
                let col = color(i);
                c.draw_series(LineSeries::new(
                    m.t.iter().zip(&m.q).map(|(t, q)| (*t, q[j].to_degrees())),
                    col.stroke_width(2),
                ))
                .map_err(perr)?
                .label(m.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                });
                phase_marks(&mut c, m, col, y)?;
            }
            legend(&mut c)?;
        }
        Ok(())
    })
}

/// Joint torque (peak norm) against time, each method's peak marked: all
/// methods on top, and below without the first (the seed's schedule), whose
/// peak is often an order of magnitude larger.
pub fn torque(methods: &[MethodTrace], norm_name: &str) -> Result<String> {
    svg((900, 760), |root| {
        let panels = root.split_evenly((2, 1));
        let tmax = range(methods.iter().flat_map(|m| m.t.iter().copied())).1;
        for (panel, (title, skip)) in [
            ("Joint torque against time", 0),
            ("Joint torque: optimised schedules", 1),
        ]
        .into_iter()
        .enumerate()
        {
            let shown = &methods[skip.min(methods.len() - 1)..];
            let ymax = range(shown.iter().flat_map(|m| m.tau.iter().copied())).1 * 1.1;
            let ydesc = format!("|tau| {norm_name} (N m)");
            let mut c = chart(
                &panels[panel],
                title,
                (0.0, tmax),
                (0.0, ymax),
                "time (s)",
                &ydesc,
            )?;
            for (i, m) in methods.iter().enumerate().skip(skip) {
                let col = color(i);
                c.draw_series(LineSeries::new(
                    m.t.iter().zip(&m.tau).map(|(t, v)| (*t, *v)),
                    col.stroke_width(2),
                ))
                .map_err(perr)?
                .label(format!(
                    "{} (peak {:.4} N m)",
                    m.name,
                    m.tau.iter().cloned().fold(0.0, f64::max)
                ))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                });
                if let Some((k, v)) = m
                    .tau
                    .iter()
                    .enumerate()
                    .max_by(|a, b| a.1.partial_cmp(b.1).unwrap())
                {
                    c.draw_series(std::iter::once(Circle::new((m.t[k], *v), 5, col.filled())))
                        .map_err(perr)?;
                }
                phase_marks(&mut c, m, col, (0.0, ymax))?;
            }
            c.configure_series_labels()
                .label_font((FONT, 13))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::LowerRight)
                .draw()
                .map_err(perr)?;
        }
        Ok(())
    })
}

/// Rotation about the initial spine against time (kinematic simulation).
pub fn flip(methods: &[MethodTrace]) -> Result<String> {
    svg((900, 520), |root| {
        let tmax = range(methods.iter().flat_map(|m| m.flip_t.iter().copied())).1;
        let y = range(
            methods
                .iter()
                .flat_map(|m| m.flip_deg.iter().copied())
                .chain([0.0, 180.0, -180.0]),
        );
        let mut c = chart(
            root,
            "Flip: rotation about the initial spine",
            (0.0, tmax),
            y,
            "time (s)",
            "flip (deg)",
        )?;
        for target in [-180.0, 180.0] {
            c.draw_series(DashedLineSeries::new(
                vec![(0.0, target), (tmax, target)],
                6,
                4,
                BLACK.mix(0.4).stroke_width(1),
            ))
            .map_err(perr)?;
        }
        for (i, m) in methods.iter().enumerate() {
            let col = color(i);
            c.draw_series(LineSeries::new(
                m.flip_t.iter().zip(&m.flip_deg).map(|(t, f)| (*t, *f)),
                col.stroke_width(2),
            ))
            .map_err(perr)?
            .label(m.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
        }
        legend(&mut c)
    })
}

/// The shape path in the (q1, q2) plane.
pub fn shape_path(methods: &[MethodTrace]) -> Result<String> {
    svg((700, 700), |root| {
        let r = methods
            .iter()
            .flat_map(|m| m.q.iter().map(|q| q[0].hypot(q[1]).to_degrees()))
            .fold(1.0, f64::max)
            * 1.1;
        let mut c = chart(root, "Shape path", (-r, r), (-r, r), "q1 (deg)", "q2 (deg)")?;
        for (i, m) in methods.iter().enumerate() {
            let col = color(i);
            c.draw_series(LineSeries::new(
                m.q.iter().map(|q| (q[0].to_degrees(), q[1].to_degrees())),
                col.stroke_width(2),
            ))
            .map_err(perr)?
            .label(m.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
        }
        legend(&mut c)
    })
}

/// SCP convergence: peak and infeasibility per iteration.
pub fn convergence(iters: &[ScpIteration]) -> Result<String> {
    svg((900, 700), |root| {
        let n = iters.len().max(2) as f64;
        let panels = root.split_evenly((2, 1));
        let y = range(iters.iter().map(|i| i.peak));
        let mut c = chart(
            &panels[0],
            "Free-form SCP: peak torque per iteration",
            (0.0, n),
            y,
            "iteration",
            "peak (N m)",
        )?;
        c.draw_series(LineSeries::new(
            iters.iter().map(|i| (i.iteration as f64, i.peak)),
            color(3).stroke_width(2),
        ))
        .map_err(perr)?
        .label("peak at the iterate")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color(3).stroke_width(2)));
        c.draw_series(
            iters
                .iter()
                .filter(|i| !i.accepted)
                .map(|i| Cross::new((i.iteration as f64, i.peak), 4, RED)),
        )
        .map_err(perr)?
        .label("rejected step")
        .legend(|(x, y)| Cross::new((x + 10, y), 4, RED));
        legend(&mut c)?;
        let lg = |v: f64| v.max(1e-16).log10();
        let y = range(
            iters
                .iter()
                .map(|i| lg(i.infeasibility))
                .chain(iters.iter().map(|i| lg(i.radius))),
        );
        let mut c = chart(
            &panels[1],
            "Constraint violation and trust radius",
            (0.0, n),
            y,
            "iteration",
            "log10",
        )?;
        for (k, (name, f)) in [("max |r| (rad)", 0usize), ("trust radius", 1)]
            .into_iter()
            .enumerate()
        {
            let col = color(k + 1);
            c.draw_series(LineSeries::new(
                iters.iter().map(|i| {
                    (
                        i.iteration as f64,
                        lg(if f == 0 { i.infeasibility } else { i.radius }),
                    )
                }),
                col.stroke_width(2),
            ))
            .map_err(perr)?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
        }
        legend(&mut c)
    })
}

/// A line plot of several named series against one variable.
pub fn lines(
    title: &str,
    xdesc: &str,
    ydesc: &str,
    x: &[f64],
    series: &[(String, Vec<f64>)],
) -> Result<String> {
    svg((900, 560), |root| {
        let xr = range(x.iter().copied());
        let yr = range(series.iter().flat_map(|s| s.1.iter().copied()));
        let mut c = chart(root, title, xr, (yr.0.min(0.0), yr.1), xdesc, ydesc)?;
        for (i, (name, ys)) in series.iter().enumerate() {
            // the methods keep their colours across all figures
            let col = match name.as_str() {
                "analytic" => color(0),
                "phased" => color(1),
                "free" => color(2),
                _ => color(i + 1),
            };
            let pts: Vec<(f64, f64)> = x
                .iter()
                .zip(ys)
                .filter(|(_, y)| y.is_finite())
                .map(|(a, b)| (*a, *b))
                .collect();
            c.draw_series(LineSeries::new(pts.clone(), col.stroke_width(2)))
                .map_err(perr)?
                .label(name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                });
            c.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, col.filled())))
                .map_err(perr)?;
        }
        legend(&mut c)
    })
}

/// Escapes text for HTML.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The report page: a summary table and the figures.
pub fn index_html(
    title: &str,
    header: &[&str],
    rows: &[Vec<String>],
    notes: &[String],
    figures: &[&str],
) -> String {
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>");
    h.push_str(&esc(title));
    h.push_str("</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:1000px}table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:4px 8px;text-align:right}th{background:#eee}td:first-child{text-align:left}img{max-width:100%;margin:1em 0}</style></head><body>\n");
    h.push_str(&format!("<h1>{}</h1>\n<table>\n<tr>", esc(title)));
    for c in header {
        h.push_str(&format!("<th>{}</th>", esc(c)));
    }
    h.push_str("</tr>\n");
    for r in rows {
        h.push_str("<tr>");
        for c in r {
            h.push_str(&format!("<td>{}</td>", esc(c)));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
    for n in notes {
        h.push_str(&format!("<p>{}</p>\n", esc(n)));
    }
    for f in figures {
        h.push_str(&format!("<div><img src=\"{f}\" alt=\"{f}\"></div>\n"));
    }
    h.push_str("</body></html>\n");
    h
}
