//! The torque-speed figure motor sizing is done with: the motor envelope and
//! each method's trajectory in the (speed, torque) plane.
//!
//! `per-motor`: one panel per motor, `(qd_i, tau_i)`, all four quadrants
//! (motoring where torque and speed share a sign, braking where they do not).
//! `euclidean`: the joint's one actuator pushes in any direction of the bend,
//! so the panel shows the torque component along the motion, `tau . u` with
//! `u = qd / |qd|`, against the speed `|qd|`: the disc `|tau + k qd| <= T`
//! projects onto exactly the band `|tau . u + k |qd|| <= T` drawn (a point
//! inside the band may still leave the disc through the sideways component;
//! the table's margin is the exact check).

use super::{
    FONT, Key, MethodTrace, Style, chart, legend, line, perr, range, style_of, svg, with_legend,
};
use crate::error::Result;
use crate::model::TorqueNorm;
use crate::model::motor::Motor;
use plotters::prelude::*;

/// The file name of the figure.
pub const FILE: &str = "torque_speed.svg";

/// The index.html caption of a figure of `run`, by file name.
pub fn caption(file: &str) -> Option<&'static str> {
    Some(match file {
        "angles.svg" => "Joint angles against time; dotted lines are the phase boundaries.",
        "torque.svg" => {
            "Joint torque against time, each curve's peak circled; the least-height schedule, made for its own drop, on a panel of its own. With a stall torque, the torque limit is the black line (named in the key only, when far above the curves); with a torque-speed line, each method's thin line is the torque its motors can give whatever the direction at that instant's speed, T - k|w| (more is available only when braking)."
        }
        FILE => {
            "Torque-speed plane, the figure a motor is sized with: the grey band is the DC-motor envelope |tau + k w| <= T (stall torque T at rest, no torque left at the no-load speed when motoring, more when braking), closed at the speed limit (max_speed, else the no-load speed); the dashed lines continue its edges past the no-load speed, where a joint driven by the other's reaction can only brake (a sound design may pass the no-load speed there; a hard limit is max_speed); each method's trajectory from its schedule (one more than three times faster than the motor's speeds, as a reference beyond the motors, is cut to the plot, 'cut' in its legend). Per-motor joints: one panel per motor, four quadrants. Euclidean (no-twist) joints: the torque component along the motion against the speed. Where a trajectory's torque is under an eighth of its panel's scale, a detail panel follows with the trajectories that fit a quarter above the largest of them, the envelope cut to it."
        }
        "flip.svg" => {
            "Rotation about the initial spine in the forward simulation (motor model applied)."
        }
        "shape_path.svg" => "The shape path in the (q1, q2) plane.",
        "convergence.svg" => {
            "Free-form SCP convergence; a dotted line marks where a finer mesh starts (mesh continuation: from the coarser design when that converged or stopped at its iteration limit, and inside the motor envelope whenever its solve returned; else from the seed again)."
        }
        _ => return None,
    })
}

/// [`caption`] for a run without motor limits: no envelope, limit or
/// least-height schedule is drawn, so none is described.
pub fn caption_without_limits(file: &str) -> Option<&'static str> {
    match file {
        "torque.svg" => Some(
            "Joint torque against time, each curve's peak circled (no motor limits are configured).",
        ),
        FILE => Some(
            "Torque-speed plane, the figure a motor is sized with: each method's trajectory from its schedule (no motor limits are configured, so no envelope is drawn). Per-motor joints: one panel per motor, four quadrants. Euclidean (no-twist) joints: the torque component along the motion against the speed. Where a trajectory's torque is under an eighth of the largest one's, a detail panel follows with the trajectories that fit a quarter above the largest of them.",
        ),
        _ => caption(file),
    }
}

/// One panel's samples: `(speed, torque)` per method.
#[derive(Clone)]
struct Panel {
    title: String,
    xdesc: &'static str,
    ydesc: &'static str,
    /// Whether the speed axis is signed (per motor) or a magnitude (Euclidean).
    signed: bool,
    curves: Vec<Vec<(f64, f64)>>,
}

fn panels(methods: &[MethodTrace], norm: TorqueNorm) -> Vec<Panel> {
    match norm {
        TorqueNorm::PerMotor => (0..2)
            .map(|j| Panel {
                title: format!("Motor {}: torque against speed", j + 1),
                xdesc: "motor speed qd (rad/s)",
                ydesc: "motor torque tau (N m)",
                signed: true,
                curves: methods
                    .iter()
                    .map(|m| {
                        m.qd.iter()
                            .zip(&m.tau_xy)
                            .map(|(w, t)| (w[j], t[j]))
                            .collect()
                    })
                    .collect(),
            })
            .collect(),
        TorqueNorm::Euclidean => vec![Panel {
            title: "Joint actuator: torque along the motion against speed".into(),
            xdesc: "joint speed |qd| (rad/s)",
            ydesc: "torque along the motion, tau . qd/|qd| (N m)",
            signed: false,
            curves: methods
                .iter()
                .map(|m| {
                    m.qd.iter()
                        .zip(&m.tau_xy)
                        .map(|(w, t)| {
                            let s = w[0].hypot(w[1]);
                            // at rest every torque starts a motion: its own direction
                            let along = if s > 1e-12 {
                                (t[0] * w[0] + t[1] * w[1]) / s
                            } else {
                                t[0].hypot(t[1])
                            };
                            (s, along)
                        })
                        .collect()
                })
                .collect(),
        }],
    }
}

/// The envelope's closed polygon `(speed, torque)`: the band between
/// `tau = -T - k w` and `tau = T - k w` for `|w| <= w_c`, `w_c` the speed limit
/// or else the no-load speed (`w >= 0` only when `signed` is false).
/// `None` without a torque limit.
pub fn envelope(motor: &Motor, signed: bool) -> Option<Vec<(f64, f64)>> {
    let t = motor.max_torque?;
    let k = motor.slope();
    let wc = motor.max_speed.or(motor.no_load_speed)?;
    let w0 = if signed { -wc } else { 0.0 };
    Some(vec![
        (w0, t - k * w0),
        (wc, t - k * wc),
        (wc, -t - k * wc),
        (w0, -t - k * w0),
    ])
}

/// The torque-speed figure (see the module doc): a panel per motor (one
/// for a Euclidean joint), each followed by its detail ([`detail`]) where
/// some trajectory is small on its scale.
pub fn torque_speed(methods: &[MethodTrace], motor: &Motor) -> Result<String> {
    let panels: Vec<(Panel, Option<f64>)> = panels(methods, motor.norm)
        .into_iter()
        .flat_map(|p| {
            let window = detail(&p, motor);
            let zoom = window.map(|w| {
                let title = format!(
                    "{}, detail: |tau| up to {} N m",
                    p.title,
                    crate::table::three_digits(w)
                );
                (Panel { title, ..p.clone() }, Some(w))
            });
            std::iter::once((p, None)).chain(zoom)
        })
        .collect();
    let h = 560 * panels.len() as u32;
    svg((1000, h), |root| {
        for (area, (p, window)) in root.split_evenly((panels.len(), 1)).iter().zip(&panels) {
            draw_panel(area, p, methods, motor, *window)?;
        }
        Ok(())
    })
}

/// A trajectory whose largest torque is under this share of its panel's
/// torque scale is drawn again on a detail panel: a design far inside a
/// strong motor's envelope lies flat on its axis.
const SMALL: f64 = 0.125;

/// Below this share of the scale a trajectory is no torque at all (a
/// detail of it would show rounding).
const NOTHING: f64 = 1e-6;

/// A panel's largest torque on its scale (the trajectories', the envelope's
/// and the stall torque's), N m.
fn scale(p: &Panel, motor: &Motor) -> f64 {
    let curves = p.curves.iter().flatten().map(|c| c.1.abs());
    let band = envelope(motor, p.signed)
        .into_iter()
        .flatten()
        .map(|c| c.1.abs());
    curves
        .chain(band)
        .chain(motor.max_torque)
        .fold(0.0, f64::max)
}

/// The detail panel's torque half-range, N m: a quarter more than the
/// largest torque of the trajectories under [`SMALL`] of the panel's scale
/// (the envelope's, or without limits the largest trajectory's: the seed's
/// analytic schedule, 21 N m, flattened the optimised ones, under 1 N m);
/// `None` when there is none.
fn detail(p: &Panel, motor: &Motor) -> Option<f64> {
    let scale = scale(p, motor);
    let small = p
        .curves
        .iter()
        .map(|c| c.iter().fold(0.0f64, |a, p| a.max(p.1.abs())))
        .filter(|&peak| peak > NOTHING * scale && peak < SMALL * scale)
        .fold(0.0, f64::max);
    (small > 0.0).then_some(1.25 * small)
}

/// The polygon `poly` cut to the band `|torque| <= w` (Sutherland-Hodgman,
/// one edge of the band at a time).
fn clipped(poly: &[(f64, f64)], w: f64) -> Vec<(f64, f64)> {
    let mut out = poly.to_vec();
    for side in [1.0, -1.0] {
        let inside = |p: &(f64, f64)| side * p.1 <= w;
        let cross = |a: (f64, f64), b: (f64, f64)| {
            let f = (side * w - a.1) / (b.1 - a.1);
            (a.0 + f * (b.0 - a.0), side * w)
        };
        let input = std::mem::take(&mut out);
        for (i, &b) in input.iter().enumerate() {
            let a = input[(i + input.len() - 1) % input.len()];
            match (inside(&a), inside(&b)) {
                (true, true) => out.push(b),
                (true, false) => out.push(cross(a, b)),
                (false, true) => out.extend([cross(a, b), b]),
                (false, false) => {}
            }
        }
    }
    out
}

/// The part of the segment `a`-`b` within `|torque| <= w`, if any.
fn segment_within(a: (f64, f64), b: (f64, f64), w: f64) -> Option<((f64, f64), (f64, f64))> {
    let at = |f: f64| (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1));
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let dy = b.1 - a.1;
    if dy == 0.0 {
        return (a.1.abs() <= w).then_some((a, b));
    }
    for edge in [w, -w] {
        let f = (edge - a.1) / dy;
        // entering or leaving the band through this edge
        if (edge > 0.0) == (dy > 0.0) {
            hi = hi.min(f);
        } else {
            lo = lo.max(f);
        }
    }
    (lo < hi).then(|| (at(lo), at(hi)))
}

/// A trajectory faster than this multiple of the motor's speeds (the larger
/// of the no-load speed and the speed limit) does not set a panel's scale.
const FAR_SPEED: f64 = 3.0;

/// One panel; with `window` the detail: torques within `+-window` only,
/// the trajectories that stay inside it, the envelope cut to it.
fn draw_panel(
    area: &super::Area,
    p: &Panel,
    methods: &[MethodTrace],
    motor: &Motor,
    window: Option<f64>,
) -> Result<()> {
    let (plot, side) = with_legend(area);
    let k = motor.slope();
    let shown: Vec<bool> = p
        .curves
        .iter()
        .map(|c| window.is_none_or(|w| c.iter().all(|p| p.1.abs() <= w)))
        .collect();
    let poly = envelope(motor, p.signed).map(|e| match window {
        Some(w) => clipped(&e, w),
        None => e,
    });
    // a trajectory far past the motor's speeds (a reference beyond the
    // motors, as the seed's analytic schedule on a servo) would squeeze the
    // envelope into a sliver: it leaves the scale to the others and is
    // drawn cut to the plot
    let speed_scale = motor
        .max_speed
        .into_iter()
        .chain(motor.no_load_speed)
        .fold(0.0f64, f64::max);
    let far: Vec<bool> = p
        .curves
        .iter()
        .map(|c| speed_scale > 0.0 && c.iter().any(|q| q.0.abs() > FAR_SPEED * speed_scale))
        .collect();
    // limits join the scale: the stall torque, the no-load and speed limits
    let drawn = || {
        p.curves
            .iter()
            .zip(shown.iter().zip(&far))
            .filter(|c| *c.1.0 && !*c.1.1)
            .flat_map(|c| c.0)
    };
    let mut xs: Vec<f64> = drawn().map(|c| c.0).collect();
    let mut ys: Vec<f64> = drawn().map(|c| c.1).collect();
    for (w, t) in poly.iter().flatten() {
        xs.push(*w);
        ys.push(*t);
    }
    match (window, motor.max_torque) {
        (Some(w), _) => ys.extend([w, -w]),
        (None, Some(t)) => ys.extend([t, -t]),
        (None, None) => {}
    }
    xs.extend(motor.max_speed.into_iter().chain(motor.no_load_speed));
    if p.signed {
        let r = xs.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        xs.push(-r);
    } else {
        xs.push(0.0);
    }
    let x = range(xs.into_iter());
    let y = range(ys.into_iter().chain([0.0]));
    let mut c = chart(&plot, &p.title, x, y, (p.xdesc, p.ydesc), false)?;
    let grey = RGBColor(0x99, 0x99, 0x99);
    // quadrant axes
    c.draw_series([
        PathElement::new(vec![(x.0, 0.0), (x.1, 0.0)], grey.stroke_width(1)),
        PathElement::new(vec![(0.0, y.0), (0.0, y.1)], grey.stroke_width(1)),
    ])
    .map_err(perr)?;
    let mut keys = Vec::new();
    let text = |s: String, at: (f64, f64), dx: i32, dy: i32| {
        EmptyElement::at(at) + Text::new(s, (dx, dy), (FONT, 13).into_font().color(&BLACK))
    };
    if let Some(t) = motor.max_torque {
        // the band's lines beyond the closing speed: braking past no-load
        // (cut to the plot: the chart clamps each end point on its own,
        // which would tilt a line that leaves it)
        for s in [t, -t] {
            let (mut w_lo, mut w_hi) = (x.0, x.1);
            if k > 0.0 {
                w_lo = w_lo.max((s - y.1) / k);
                w_hi = w_hi.min((s - y.0) / k);
            }
            if w_lo < w_hi {
                c.draw_series(DashedLineSeries::new(
                    [(w_lo, s - k * w_lo), (w_hi, s - k * w_hi)],
                    4,
                    4,
                    grey.stroke_width(1),
                ))
                .map_err(perr)?;
            }
        }
        if let Some(poly) = &poly {
            c.draw_series(std::iter::once(Polygon::new(
                poly.clone(),
                RGBColor(0xbb, 0xbb, 0xbb).mix(0.35).filled(),
            )))
            .map_err(perr)?;
            // the outline: the envelope's own edges (in a detail, the parts
            // inside its window; the cut is not an edge)
            let whole = envelope(motor, p.signed).unwrap_or_default();
            let edges = (0..whole.len()).filter_map(|i| {
                let (a, b) = (whole[i], whole[(i + 1) % whole.len()]);
                match window {
                    Some(w) => segment_within(a, b, w),
                    None => Some((a, b)),
                }
            });
            c.draw_series(edges.map(|(a, b)| PathElement::new(vec![a, b], BLACK.stroke_width(2))))
                .map_err(perr)?;
        }
        if k > 0.0 {
            keys.push(("envelope |tau + k w| <= T".into(), Key::Band));
            keys.push((format!("k = T / w0 = {k:.4} N m s"), Key::Note));
        } else {
            keys.push((format!("envelope |tau| <= T = {t} N m"), Key::Band));
        }
        // the named points: stall (rest, full torque) and no-load (no torque
        // left), by their symbols beside the dots and their values in the key
        // (written out beside the dots they crossed the curves and the frame)
        let mut named = vec![(0.0, t, "T", 8, -18)];
        if p.signed {
            // (below left: outside the band, mirroring T above right)
            named.push((0.0, -t, "-T", -24, 6));
        }
        keys.push((format!("stall T = {t} N m"), Key::Dot));
        if let Some(w0) = motor.no_load_speed {
            named.push((w0, 0.0, "w0", 6, 16));
            if p.signed {
                named.push((-w0, 0.0, "-w0", 6, -32));
            }
            keys.push((format!("no-load w0 = {w0} rad/s"), Key::Dot));
        }
        for (w, s, label, dx, dy) in named.into_iter().filter(|n| n.1.abs() <= y.1.max(-y.0)) {
            c.draw_series(std::iter::once(Circle::new((w, s), 5, BLACK.filled())))
                .map_err(perr)?;
            c.draw_series(std::iter::once(text(label.into(), (w, s), dx, dy)))
                .map_err(perr)?;
        }
    }
    if let Some(wm) = motor.max_speed {
        let at: &[f64] = if p.signed { &[wm, -wm] } else { &[wm] };
        for &w in at {
            c.draw_series(DashedLineSeries::new(
                [(w, y.0), (w, y.1)],
                8,
                4,
                BLACK.stroke_width(1),
            ))
            .map_err(perr)?;
            // the two ends' labels at the top and the bottom: side by side
            // they overlapped at a small max_speed
            // (the top one left of its line: right of it, it ran into the legend;
            // the bottom one a row above the quadrant's name)
            let label = format!("max_speed {w} rad/s");
            let (at_y, dx, dy) = if w < 0.0 {
                (y.0, 4, -34)
            } else {
                (y.1, -4 - 7 * label.len() as i32, 4)
            };
            c.draw_series(std::iter::once(text(label, (w, at_y), dx, dy)))
                .map_err(perr)?;
        }
        keys.push((format!("max_speed {wm} rad/s"), Key::DashedLevel));
    }
    if motor.max_torque.is_none() && motor.max_speed.is_none() {
        keys.push(("no motor limits configured".into(), Key::Note));
    }
    // quadrant names
    let q = |s: &str, at: (f64, f64), dx: i32, dy: i32| text(s.into(), at, dx, dy);
    let mut names = vec![
        q("motoring", (x.1, y.1), -80, 24),
        q("braking", (x.1, y.0), -70, -20),
    ];
    if p.signed {
        names.push(q("braking", (x.0, y.1), 8, 24));
        names.push(q("motoring", (x.0, y.0), 8, -20));
    }
    c.draw_series(names).map_err(perr)?;
    for (i, (m, pts)) in methods.iter().zip(&p.curves).enumerate() {
        if !shown[i] {
            continue;
        }
        let st: Style = style_of(&m.name, i);
        let shift = i as f64 / methods.len() as f64;
        if far[i] {
            // the runs of samples inside the plot, each drawn on its own
            let inside = |q: &(f64, f64)| (x.0..=x.1).contains(&q.0) && (y.0..=y.1).contains(&q.1);
            for run in pts.split(|q| !inside(q)).filter(|r| r.len() >= 2) {
                line(&mut c, run, st, shift)?;
            }
        } else {
            line(&mut c, pts, st, shift)?;
        }
        let tp = pts.iter().fold(0.0f64, |a, p| a.max(p.1.abs()));
        let wp = pts.iter().fold(0.0f64, |a, p| a.max(p.0.abs()));
        let cut = if far[i] { ", cut" } else { "" };
        keys.push((
            format!("{} ({tp:.3} N m, {wp:.2} rad/s{cut})", m.name),
            Key::Line(st),
        ));
    }
    keys.push(("(largest |torque|, |speed|)".into(), Key::Note));
    legend(&side, &keys)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The robot's band (T 1.4 N m, w0 5.969 rad/s) cut at 0.3 N m: six
    /// corners, each on the band's edges or the window's, the area that of
    /// the band's part inside the window; an edge's part inside the window,
    /// or none.
    #[test]
    fn the_envelope_cut_to_a_window_keeps_the_part_inside_it() {
        let (t, w0, w) = (1.4, 5.969, 0.3);
        let k = t / w0;
        let band = [(-w0, 2.0 * t), (w0, 0.0), (w0, -2.0 * t), (-w0, 0.0)];
        let cut = clipped(&band, w);
        assert_eq!(cut.len(), 6, "{cut:?}");
        for &(s, tau) in &cut {
            assert!(tau.abs() <= w + 1e-12);
            let on_band = ((tau + k * s).abs() - t).abs() < 1e-9 || (s.abs() - w0).abs() < 1e-12;
            assert!(on_band || (tau.abs() - w).abs() < 1e-12, "({s}, {tau})");
        }
        let area = |p: &[(f64, f64)]| {
            0.5 * (0..p.len())
                .map(|i| {
                    let (a, b) = (p[i], p[(i + 1) % p.len()]);
                    a.0 * b.1 - b.0 * a.1
                })
                .sum::<f64>()
                .abs()
        };
        // at speed s the band spans -k (w0 + s) to k (w0 - s) (T = k w0):
        // inside the window twice the integral of min(w, k u) over u in
        // [0, 2 w0], a full-width strip 2 w tall less two triangles of legs
        // w and w / k
        let want = 4.0 * w * w0 - w * w / k;
        assert!(
            (area(&cut) - want).abs() < 1e-9,
            "{} against {want}",
            area(&cut)
        );
        // a wide window leaves the band whole
        assert!((area(&clipped(&band, 3.0)) - area(&band)).abs() < 1e-12);
        // the upper edge from (-w0, 2T) to (w0, 0): its part below w
        let (a, b) = segment_within(band[0], band[1], w).unwrap();
        assert!((a.1 - w).abs() < 1e-12 && b == band[1], "{a:?} {b:?}");
        assert_eq!(segment_within((0.0, 1.0), (1.0, 2.0), w), None);
        assert_eq!(
            segment_within((0.0, 0.1), (1.0, 0.1), w),
            Some(((0.0, 0.1), (1.0, 0.1)))
        );
    }
}
