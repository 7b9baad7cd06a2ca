//! The figures of `catflip size`: the curve of stall torque against no-load
//! speed that just makes the flip from the height (log-log, with its two
//! asymptotes, the configured motor and its gear line), and the least height
//! against the gear ratio.

use super::{FONT, Key, legend, line, log_ticks, marker, perr, style, svg, tick, with_legend};
use crate::error::Result;
use crate::report::Marker;
use crate::size::SizeAnswer;
use plotters::prelude::*;

/// The index.html caption of a figure of `size`, by file name.
pub fn caption(file: &str) -> Option<&'static str> {
    Some(match file {
        crate::size::files::CURVE_SVG => {
            "The motors that just make the flip from the height: each point is a DC motor (stall torque, no-load speed) whose least-time design inside its torque-speed envelope fits the fall exactly; every motor above and right of the curve can, none below or left. The dashed lines are the ends, each a design of its own (a local optimum, which a point of the curve may pass): the least stall torque at any speed (no speed limit) and the least no-load speed at any torque. The black dot is the configured motor; the thin line through it is the same motor behind every gear ratio N (torque times N, speed over N), the open circle its best ratio."
        }
        crate::size::files::GEAR_SVG => {
            "The configured motor's least drop height against the gear ratio N (torque times N, speed over N), each point one least-time design; the level line is the height asked. Below the best ratio the motor is too weak, above it too slow."
        }
        _ => return None,
    })
}

fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.1, 10.0);
    }
    (lo / 1.4, hi * 1.4)
}

/// The curve figure (`size.svg`).
pub fn curve(a: &SizeAnswer) -> Result<String> {
    svg((1000, 620), |root| {
        let (plot, side) = with_legend(root);
        let g = &a.gear;
        let configured = g
            .evaluations
            .iter()
            .find(|e| e.gear_ratio == 1.0)
            .map(|e| (e.design.no_load_speed_rad_s, e.design.stall_torque_nm));
        let pts: Vec<(f64, f64)> = a
            .curve
            .iter()
            .map(|p| (p.no_load_speed_rad_s, p.stall_torque_nm))
            .collect();
        let gears: Vec<(f64, f64)> = g
            .evaluations
            .iter()
            .map(|e| (e.design.no_load_speed_rad_s, e.design.stall_torque_nm))
            .collect();
        let xr = log_range(
            pts.iter()
                .chain(&gears)
                .map(|p| p.0)
                .chain([a.speed_asymptote_rad_s]),
        );
        let yr = log_range(
            pts.iter()
                .chain(&gears)
                .map(|p| p.1)
                .chain([a.torque_asymptote_nm]),
        );
        let mut c = ChartBuilder::on(&plot)
            .caption(
                format!("Motors that just flip {} from {} m", a.name, a.height_m),
                (FONT, 20),
            )
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (xr.0..xr.1).log_scale().with_key_points(log_ticks(xr)),
                (yr.0..yr.1).log_scale().with_key_points(log_ticks(yr)),
            )
            .map_err(perr)?;
        c.configure_mesh()
            .x_desc("no-load speed w0 (rad/s), log scale")
            .y_desc("stall torque T (N m), log scale")
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .x_labels(12)
            .y_labels(12)
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(perr)?;
        for p in [
            vec![(xr.0, a.torque_asymptote_nm), (xr.1, a.torque_asymptote_nm)],
            vec![
                (a.speed_asymptote_rad_s, yr.0),
                (a.speed_asymptote_rad_s, yr.1),
            ],
        ] {
            c.draw_series(DashedLineSeries::new(p, 8, 4, BLACK.stroke_width(1)))
                .map_err(perr)?;
        }
        let st = style(1);
        line(&mut c, &pts, st, 0.0)?;
        let mut keys = vec![
            (
                format!("just makes it from {} m", a.height_m),
                Key::Line(st),
            ),
            (
                format!(
                    "T >= {:.4} N m, w0 >= {:.3} rad/s",
                    a.torque_asymptote_nm, a.speed_asymptote_rad_s
                ),
                Key::DashedLevel,
            ),
        ];
        if let Some((w0, t0)) = configured {
            // the gear line T w0 = T0 w0_0 across the plot
            let power = w0 * t0;
            let n = 60;
            let gear_line: Vec<(f64, f64)> = (0..=n)
                .map(|i| xr.0 * (xr.1 / xr.0).powf(i as f64 / n as f64))
                .map(|w| (w, power / w))
                .filter(|p| p.1 >= yr.0 && p.1 <= yr.1)
                .collect();
            c.draw_series(LineSeries::new(
                gear_line,
                RGBColor(0x88, 0x88, 0x88).stroke_width(1),
            ))
            .map_err(perr)?;
            c.draw_series(std::iter::once(Circle::new((w0, t0), 5, BLACK.filled())))
                .map_err(perr)?;
            keys.push((
                format!("configured motor: {t0:.3} N m, {w0:.3} rad/s"),
                Key::Dot,
            ));
            keys.push(("the same motor geared (T w0 fixed)".into(), Key::Level));
        }
        c.draw_series(std::iter::once(Circle::new(
            (g.no_load_speed_rad_s, g.stall_torque_nm),
            7,
            BLACK.stroke_width(2),
        )))
        .map_err(perr)?;
        keys.push((
            format!("best gear ratio N = {:.3}", g.best_ratio),
            Key::Peak,
        ));
        legend(&side, &keys)
    })
}

/// The gear figure (`size-gear.svg`).
pub fn gear(a: &SizeAnswer) -> Result<String> {
    svg((1000, 560), |root| {
        let (plot, side) = with_legend(root);
        let pts: Vec<(f64, f64)> = a
            .gear
            .evaluations
            .iter()
            .map(|e| (e.gear_ratio, e.design.least_height_m))
            .collect();
        let predicted: Vec<(f64, f64)> = a
            .gear
            .predicted
            .iter()
            .map(|p| (p.gear_ratio, p.least_height_m))
            .collect();
        let xr = log_range(pts.iter().chain(&predicted).map(|p| p.0));
        let (lo, hi) = pts
            .iter()
            .chain(&predicted)
            .map(|p| p.1)
            .chain([a.height_m])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                (l.min(v), h.max(v))
            });
        let pad = 0.08 * (hi - lo).max(0.05 * hi);
        let mut c = ChartBuilder::on(&plot)
            .caption(
                format!("{}: least drop height against the gear ratio", a.name),
                (FONT, 20),
            )
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (xr.0..xr.1).log_scale().with_key_points(log_ticks(xr)),
                (lo - pad).max(0.0)..hi + pad,
            )
            .map_err(perr)?;
        c.configure_mesh()
            .x_desc("gear ratio N (torque x N, speed / N), log scale")
            .y_desc("least drop height (m)")
            .x_label_formatter(&tick)
            .x_labels(12)
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(perr)?;
        c.draw_series(LineSeries::new(
            vec![(xr.0, a.height_m), (xr.1, a.height_m)],
            BLACK.stroke_width(1),
        ))
        .map_err(perr)?;
        let st = style(1);
        let guess = style(0);
        line(&mut c, &predicted, guess, 0.0)?;
        c.draw_series(pts.iter().map(|p| marker(*p, st.marker, st.color)))
            .map_err(perr)?;
        let g = &a.gear;
        c.draw_series(std::iter::once(marker(
            (1.0, g.configured_least_height_m),
            Marker::Square,
            BLACK,
        )))
        .map_err(perr)?;
        c.draw_series(std::iter::once(Circle::new(
            (g.best_ratio, g.least_height_m),
            7,
            BLACK.stroke_width(2),
        )))
        .map_err(perr)?;
        let keys = vec![
            (
                "designed (one least-time design each)".into(),
                Key::Mark(st),
            ),
            (
                "predicted from the curve's designs (F3)".into(),
                Key::Line(guess),
            ),
            (format!("asked: {} m", a.height_m), Key::Level),
            (
                format!("N = 1: {:.3} m", g.configured_least_height_m),
                Key::Mark(super::Style {
                    color: BLACK,
                    dash: None,
                    marker: Marker::Square,
                }),
            ),
            (
                format!("best N = {:.3}: {:.3} m", g.best_ratio, g.least_height_m),
                Key::Peak,
            ),
        ];
        legend(&side, &keys)
    })
}

/// The report page of `size` (`index.html`): the answer first (the
/// configured motor, its best gear ratio, the curve's ends), then the
/// curve's table and both figures.
pub fn page(a: &SizeAnswer) -> String {
    let header = [
        "no-load speed (rad/s)",
        "stall torque (N m)",
        "T / w0^2 (N m s^2)",
        "designed at (N m, rad/s)",
        "design",
    ];
    let rows: Vec<Vec<String>> = a
        .curve
        .iter()
        .map(|p| {
            vec![
                format!("{:.4}", p.no_load_speed_rad_s),
                format!("{:.5}", p.stall_torque_nm),
                format!("{:.4e}", p.ratio_nms2),
                format!(
                    "{:.5}, {:.4}",
                    p.design.stall_torque_nm, p.design.no_load_speed_rad_s
                ),
                format!(
                    "{} {}, scaled by {:.4}",
                    p.design.method, p.design.status, p.scale
                ),
            ]
        })
        .collect();
    // the answer's block, as `run`'s: green when the configured motor, or
    // the best gear ratio of it, makes the flip
    let [first, second, ends] = a.lead();
    let g = &a.gear;
    // the headline is the first sentence alone: the gear sentence goes on
    // with its search and its working ratios, which set in the headline's
    // large bold type buried the answer
    let (headline, second) = match first.split_once(". ") {
        Some((h, rest)) => (format!("{h}."), format!("{rest} {second}")),
        None => (first, second),
    };
    let lead = super::answer::block(
        g.configured_possible || g.possible,
        &headline,
        &second,
        &ends,
    );
    let mut notes = Vec::new();
    notes.push(format!(
        "{} designs in {:.1} s. Each point is one least-time design scaled by time scaling (F3): a motor (T, w0) whose least time is t also fits (k^2 T, k w0) in t / k; see docs/usage.md.",
        a.designs, a.solve_time_s
    ));
    super::index_html(&super::Page {
        title: &format!("catflip size: {} from {} m", a.name, a.height_m),
        lead: Some(&lead),
        header: &header,
        rows: &rows,
        notes: &notes,
        warnings: &a.failed,
        animation: "",
        figures: &[crate::size::files::CURVE_SVG, crate::size::files::GEAR_SVG],
        captions: caption,
        glossary: false,
    })
}
