//! SVG figures and the HTML index of a run, drawn with plotters.
//!
//! Text is laid out with DejaVu Sans bundled through the `dejavu` crate
//! (plotters' `ab_glyph` feature), so no system font library is needed; the
//! SVGs carry real `<text>` elements. Every series has a colour, a dash
//! pattern and a marker ([`Style`]), so a grey print still tells them apart;
//! legends sit in a column beside the plot, never over the data.

pub mod animation;
pub mod answer;
mod glossary;
pub mod size;
mod torque_speed;

pub use torque_speed::{
    FILE as TORQUE_SPEED_SVG, caption, caption_without_limits, envelope, torque_speed,
};

use crate::design::scp::ScpIteration;
use crate::error::{Error, Result};
use crate::model::motor::Motor;
use plotters::coord::Shift;
use plotters::element::{DashedPathElement, Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::DrawingErrorKind;
use std::sync::Once;

/// One method's curves.
#[derive(Debug, Clone)]
pub struct MethodTrace {
    pub name: String,
    pub t: Vec<f64>,
    pub q: Vec<[f64; 2]>,
    /// Joint torque in the peak norm, N m.
    pub tau: Vec<f64>,
    /// Joint rates at the same instants, rad/s (the motors' speeds).
    pub qd: Vec<[f64; 2]>,
    /// Joint torque components at the same instants, N m.
    pub tau_xy: Vec<[f64; 2]>,
    /// The dense peak torque (the one the table reports), N m; the curve's
    /// samples may fall just short of it.
    pub peak_nm: f64,
    /// Whether that peak breaks `limits.max_torque` by the verdicts' rule
    /// ([`crate::verdict::Targets::over_torque`]).
    pub over_limit: bool,
    pub phase_bounds: Vec<f64>,
    /// Attitude about the initial spine from the forward simulation.
    pub flip_t: Vec<f64>,
    pub flip_deg: Vec<f64>,
}

/// A point marker, drawn every few samples along a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    Square,
    Circle,
    Triangle,
    Cross,
}

/// How one series is drawn: colour, dash pattern (`None` is solid) and marker.
#[derive(Debug, Clone, Copy)]
pub struct Style {
    pub color: RGBColor,
    pub dash: Option<(u32, u32)>,
    pub marker: Marker,
}

const STYLES: [Style; 4] = [
    Style {
        color: RGBColor(0x55, 0x55, 0x55),
        dash: Some((10, 5)),
        marker: Marker::Square,
    },
    Style {
        color: RGBColor(0x1f, 0x77, 0xb4),
        dash: None,
        marker: Marker::Circle,
    },
    Style {
        color: RGBColor(0xd6, 0x27, 0x28),
        dash: Some((3, 3)),
        marker: Marker::Triangle,
    },
    Style {
        color: RGBColor(0x2c, 0xa0, 0x2c),
        dash: Some((12, 3)),
        marker: Marker::Cross,
    },
];

/// The `i`-th series style.
pub fn style(i: usize) -> Style {
    STYLES[i % STYLES.len()]
}

/// The `i`-th of many series (more than the methods' four styles tell
/// apart): eight colours, each with a dash and marker that turn with the
/// index; the first 32 are distinct.
pub fn distinct_style(i: usize) -> Style {
    const COLORS: [RGBColor; 8] = [
        RGBColor(0x1f, 0x77, 0xb4),
        RGBColor(0xd6, 0x27, 0x28),
        RGBColor(0x2c, 0xa0, 0x2c),
        RGBColor(0x55, 0x55, 0x55),
        RGBColor(0x94, 0x67, 0xbd),
        RGBColor(0xff, 0x7f, 0x0e),
        RGBColor(0x17, 0xbe, 0xcf),
        RGBColor(0x8c, 0x56, 0x4b),
    ];
    const LOOKS: [(Option<(u32, u32)>, Marker); 4] = [
        (None, Marker::Circle),
        (Some((10, 5)), Marker::Triangle),
        (Some((3, 3)), Marker::Square),
        (Some((12, 3)), Marker::Cross),
    ];
    // the dash turns with each series too: two series on the same numbers
    // (a recovery map's symmetric axes) show both colours through the gaps
    let (dash, marker) = LOOKS[(i + i / COLORS.len()) % LOOKS.len()];
    Style {
        color: COLORS[i % COLORS.len()],
        dash,
        marker,
    }
}

/// A method keeps its style across all figures; other series count from `i`.
pub fn style_of(name: &str, i: usize) -> Style {
    match name {
        "analytic" => STYLES[0],
        "phased" => STYLES[1],
        "free" => STYLES[2],
        "least-height" => STYLES[3],
        _ => style(i),
    }
}

const FONT: &str = "sans-serif";
/// Width of the legend column right of each plot, px.
const LEGEND_W: u32 = 260;
/// Markers along a line (enough to tell the lines apart, few enough not to clutter).
const MARKS: usize = 9;

type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;

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
    // a flat series still gets room above and below
    let pad = 0.05 * (hi - lo).max(0.2 * hi.abs().max(lo.abs())).max(1e-9);
    (lo - pad, hi + pad)
}

fn peak(v: &[f64]) -> f64 {
    v.iter().cloned().fold(0.0, f64::max)
}

/// Tick labels for whole numbers (iteration counts): "5", never "5.0" or "2.5".
fn whole(v: &f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("{}", v.round() as i64)
    } else {
        String::new()
    }
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// A linear chart; `whole_x` labels the x axis with whole numbers only.
fn chart<'a, 'b>(
    area: &'a Area<'b>,
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
    desc: (&str, &str),
    whole_x: bool,
) -> Result<Chart<'a, 'b>> {
    let mut c = ChartBuilder::on(area)
        .caption(title, (FONT, 20))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(70)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(perr)?;
    let xf: &dyn Fn(&f64) -> String = if whole_x { &whole } else { &axis_number };
    let mut mesh = c.configure_mesh();
    mesh.x_desc(desc.0)
        .y_desc(desc.1)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 15))
        .light_line_style(WHITE.mix(0.0))
        .x_label_formatter(xf)
        .y_label_formatter(&axis_number);
    mesh.draw().map_err(perr)?;
    Ok(c)
}

/// A tick's number as plotters prints it, without the sign of a zero (a
/// tick at -1e-17 read "-0.0" on a detail panel).
fn axis_number(v: &f64) -> String {
    let s = plotters::data::float::FloatPrettyPrinter {
        allow_scientific: false,
        min_decimal: 1,
        max_decimal: 5,
    }
    .print(*v);
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// A marker at `at` (data or pixel coordinates), a fixed size in pixels.
struct Mark<C> {
    at: C,
    kind: Marker,
    color: RGBColor,
}

fn marker<C>(at: C, kind: Marker, color: RGBColor) -> Mark<C> {
    Mark { at, kind, color }
}

impl<'a, C> PointCollection<'a, C> for &'a Mark<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for Mark<C> {
    fn draw<I: Iterator<Item = (i32, i32)>>(
        &self,
        mut pos: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> std::result::Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = pos.next() else {
            return Ok(());
        };
        let fill = self.color.filled();
        match self.kind {
            Marker::Square => backend.draw_rect((x - 4, y - 4), (x + 4, y + 4), &fill, true),
            Marker::Circle => backend.draw_circle((x, y), 4, &fill, true),
            Marker::Triangle => {
                backend.fill_polygon([(x, y - 6), (x - 5, y + 4), (x + 5, y + 4)], &fill)
            }
            Marker::Cross => {
                let s = self.color.stroke_width(2);
                backend.draw_line((x - 4, y - 4), (x + 4, y + 4), &s)?;
                backend.draw_line((x - 4, y + 4), (x + 4, y - 4), &s)
            }
        }
    }
}

/// Draws a line in `st` with markers: `MARKS` spread along a dense curve,
/// shifted by `shift` (0..1 of a marker gap) so that coinciding lines show
/// all their markers, or one on each point of a short series.
fn line<'a, 'b, CT>(
    c: &mut ChartContext<'a, SVGBackend<'b>, CT>,
    pts: &[(f64, f64)],
    st: Style,
    shift: f64,
) -> Result<()>
where
    CT: CoordTranslate<From = (f64, f64)>,
{
    let stroke = st.color.stroke_width(2);
    match st.dash {
        None => c
            .draw_series(LineSeries::new(pts.iter().copied(), stroke))
            .map(|_| ()),
        Some((on, off)) => c
            .draw_series(DashedLineSeries::new(pts.iter().copied(), on, off, stroke))
            .map(|_| ()),
    }
    .map_err(perr)?;
    // a few points (a sweep's samples) are each marked; a dense curve gets MARKS
    let marks: Vec<(f64, f64)> = if pts.len() <= 4 * MARKS {
        pts.to_vec()
    } else {
        let gap = (pts.len() - 1) as f64 / MARKS as f64;
        (0..MARKS)
            .map(|k| pts[((k as f64 + 0.25 + 0.5 * shift) * gap) as usize])
            .collect()
    };
    c.draw_series(marks.into_iter().map(|p| marker(p, st.marker, st.color)))
        .map_err(perr)?;
    Ok(())
}

/// What a legend row shows beside its label.
enum Key {
    Line(Style),
    /// A marker alone (e.g. rejected SCP steps).
    Mark(Style),
    /// Phase boundaries (thin dotted black, each topped with the method's
    /// marker), or where a finer mesh starts in the convergence figure.
    Boundary,
    /// A reference level (torque limit, +-180 deg): solid black, thin.
    Level,
    /// The open circle around each curve's peak.
    Peak,
    /// A filled region with its outline (the motor envelope).
    Band,
    /// A filled black dot (a named point).
    Dot,
    /// A dashed reference level (a speed limit).
    DashedLevel,
    /// Text alone, continuing the row above.
    Note,
}

/// The legend column beside a plot.
fn legend(area: &Area, rows: &[(String, Key)]) -> Result<()> {
    let text = TextStyle::from((FONT, 13).into_font()).color(&BLACK);
    let mut y = 48;
    for (label, key) in rows {
        let (x0, x1) = (4, 40);
        match key {
            Key::Line(st) | Key::Mark(st) => {
                if let Key::Line(_) = key {
                    let stroke = st.color.stroke_width(2);
                    let path = vec![(x0, y), (x1, y)];
                    match st.dash {
                        None => area.draw(&PathElement::new(path, stroke)),
                        Some((on, off)) => {
                            area.draw(&DashedPathElement::new(path, on, off, stroke))
                        }
                    }
                    .map_err(perr)?;
                }
                area.draw(&marker((22, y), st.marker, st.color))
                    .map_err(perr)?;
            }
            Key::Boundary => {
                area.draw(&DashedPathElement::new(
                    vec![(22, y - 9), (22, y + 9)],
                    2,
                    3,
                    BLACK.stroke_width(1),
                ))
                .map_err(perr)?;
            }
            Key::Peak => {
                area.draw(&Circle::new((22, y), 7, BLACK.stroke_width(2)))
                    .map_err(perr)?;
            }
            Key::Level => {
                area.draw(&PathElement::new(
                    vec![(x0, y), (x1, y)],
                    BLACK.stroke_width(1),
                ))
                .map_err(perr)?;
            }
            Key::Band => {
                area.draw(&Rectangle::new(
                    [(x0, y - 7), (x1, y + 7)],
                    RGBColor(0xbb, 0xbb, 0xbb).mix(0.35).filled(),
                ))
                .map_err(perr)?;
                area.draw(&Rectangle::new(
                    [(x0, y - 7), (x1, y + 7)],
                    BLACK.stroke_width(2),
                ))
                .map_err(perr)?;
            }
            Key::Dot => {
                area.draw(&Circle::new((22, y), 5, BLACK.filled()))
                    .map_err(perr)?;
            }
            Key::DashedLevel => {
                area.draw(&DashedPathElement::new(
                    vec![(x0, y), (x1, y)],
                    8,
                    4,
                    BLACK.stroke_width(1),
                ))
                .map_err(perr)?;
            }
            Key::Note => {}
        }
        area.draw_text(label, &text, (48, y - 7)).map_err(perr)?;
        y += 22;
    }
    Ok(())
}

/// Splits off the legend column.
fn with_legend<'b>(area: &Area<'b>) -> (Area<'b>, Area<'b>) {
    let w = area.dim_in_pixel().0;
    area.split_horizontally(w.saturating_sub(LEGEND_W))
}

/// A thin dotted black vertical line at `x` (a boundary, [`Key::Boundary`]).
fn boundary_line(c: &mut Chart, x: f64, y: (f64, f64)) -> Result<()> {
    c.draw_series(DashedLineSeries::new(
        vec![(x, y.0), (x, y.1)],
        2,
        3,
        BLACK.stroke_width(1),
    ))
    .map_err(perr)?;
    Ok(())
}

/// Dotted vertical lines at the inner phase boundaries, one style for all
/// methods, each topped with the method's marker.
fn phase_marks(c: &mut Chart, m: &MethodTrace, st: Style, y: (f64, f64)) -> Result<()> {
    for &b in &m.phase_bounds[1..m.phase_bounds.len() - 1] {
        boundary_line(c, b, y)?;
        c.draw_series(std::iter::once(marker((b, y.1), st.marker, st.color)))
            .map_err(perr)?;
    }
    Ok(())
}

fn boundary_key() -> (String, Key) {
    ("phase boundary (marker: method)".into(), Key::Boundary)
}

fn svg(size: (u32, u32), draw: impl FnOnce(&Area) -> Result<()>) -> Result<String> {
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

/// Joint angles against time, phase boundaries dotted.
pub fn angles(methods: &[MethodTrace]) -> Result<String> {
    svg((1000, 700), |root| {
        let tmax = range(methods.iter().flat_map(|m| m.t.iter().copied())).1;
        for (j, panel) in root.split_evenly((2, 1)).iter().enumerate() {
            let (plot, side) = with_legend(panel);
            let y = range(
                methods
                    .iter()
                    .flat_map(|m| m.q.iter().map(move |q| q[j].to_degrees())),
            );
            let title = format!("Joint angle q{} against time", j + 1);
            let ydesc = format!("q{} (deg)", j + 1);
            let mut c = chart(&plot, &title, (0.0, tmax), y, ("time (s)", &ydesc), false)?;
            let mut keys = Vec::new();
            for (i, m) in methods.iter().enumerate() {
                let st = style_of(&m.name, i);
                let pts: Vec<_> =
                    m.t.iter()
                        .zip(&m.q)
                        .map(|(t, q)| (*t, q[j].to_degrees()))
                        .collect();
                line(&mut c, &pts, st, i as f64 / methods.len() as f64)?;
                phase_marks(&mut c, m, st, y)?;
                keys.push((m.name.clone(), Key::Line(st)));
            }
            keys.push(boundary_key());
            legend(&side, &keys)?;
        }
        Ok(())
    })
}

/// Joint torque (peak norm) against time, each method's peak marked. The
/// seed's schedule (`analytic`) has its own panel: its peak is often
/// an order of magnitude above the optimised ones and would flatten them.
/// With a torque limit the limit is drawn (or named, when off the panel's scale).
/// With a torque-speed line the torque available at each instant depends on
/// the speed: each method gets a thin line `T - k |qd|` in its colour, the
/// torque its motors give in any direction at that instant's speed (a torque
/// below it is inside the envelope; above it, only when braking).
pub fn torque(methods: &[MethodTrace], norm_name: &str, motor: &Motor) -> Result<String> {
    let limit = motor.max_torque;
    let of = |pick: &dyn Fn(&str) -> bool| -> Vec<&MethodTrace> {
        methods.iter().filter(|m| pick(&m.name)).collect()
    };
    // the least-height schedule answers for its own drop: on the axes of
    // the configured drop's designs its torque (the robot's 2.0 N m against
    // 0.03 to 0.1 N m from 6 m) flattens theirs
    let groups = [
        (
            "Joint torque: the seed's analytic schedule",
            of(&|n| n == "analytic"),
        ),
        (
            "Joint torque: optimised schedules",
            of(&|n| n != "analytic" && n != "least-height"),
        ),
        (
            "Joint torque: the least-height schedule (for its own drop height)",
            of(&|n| n == "least-height"),
        ),
    ];
    // a run where a method failed may leave one group empty: no panel for it
    let groups: Vec<_> = groups.into_iter().filter(|g| !g.1.is_empty()).collect();
    let tall = 380 * groups.len().max(2) as u32;
    svg((1000, tall), |root| {
        let tmax = range(methods.iter().flat_map(|m| m.t.iter().copied())).1;
        let panels = root.split_evenly((groups.len().max(1), 1));
        for (panel, (title, shown)) in panels.iter().zip(&groups) {
            let title = *title;
            let (plot, side) = with_legend(panel);
            let data_max = shown.iter().map(|m| peak(&m.tau)).fold(0.0, f64::max);
            // the limit joins the scale unless it would squash the curves
            let lim_on_scale = limit.filter(|l| *l <= 2.0 * data_max);
            let ymax = data_max.max(lim_on_scale.unwrap_or(0.0)) * 1.12;
            let ydesc = format!("|tau|, {norm_name} (N m)");
            let mut c = chart(
                &plot,
                title,
                (0.0, tmax),
                (0.0, ymax),
                ("time (s)", &ydesc),
                false,
            )?;
            let mut keys = Vec::new();
            for &m in shown {
                let i = methods.iter().position(|x| x.name == m.name).unwrap_or(0);
                let st = style_of(&m.name, i);
                let pts: Vec<_> = m.t.iter().zip(&m.tau).map(|(t, v)| (*t, *v)).collect();
                line(&mut c, &pts, st, i as f64 / methods.len() as f64)?;
                let p = peak(&m.tau);
                if let Some(k) = m.tau.iter().position(|v| *v == p) {
                    c.draw_series(std::iter::once(Circle::new(
                        (m.t[k], p),
                        7,
                        st.color.stroke_width(2),
                    )))
                    .map_err(perr)?;
                }
                phase_marks(&mut c, m, st, (0.0, ymax))?;
                if let (Some(l), true) = (limit, motor.slope() > 0.0) {
                    // drawn where it is on the panel's scale, in runs
                    let avail =
                        m.t.iter()
                            .zip(&m.qd)
                            .map(|(t, w)| (*t, (l - motor.slope() * motor.speed(*w)).max(0.0)));
                    let mut run: Vec<(f64, f64)> = Vec::new();
                    for p in avail.chain([(f64::NAN, f64::INFINITY)]) {
                        if p.1 <= ymax {
                            run.push(p);
                        } else if !run.is_empty() {
                            let pts = std::mem::take(&mut run);
                            c.draw_series(LineSeries::new(pts, st.color.mix(0.6).stroke_width(1)))
                                .map_err(perr)?;
                        }
                    }
                }
                let over = if m.over_limit { ", OVER LIMIT" } else { "" };
                keys.push((
                    format!("{} (peak {:.4} N m{over})", m.name, m.peak_nm),
                    Key::Line(st),
                ));
            }
            keys.push(("peak of each curve".into(), Key::Peak));
            keys.push(boundary_key());
            if limit.is_some() && motor.slope() > 0.0 {
                // (in each method's colour, not the limit's black: a line
                // sample here read as one more black level)
                keys.push(("thin, in each method's colour:".into(), Key::Note));
                keys.push(("T - k|w| at its speed, the".into(), Key::Note));
                keys.push(("motoring limit (cut at the top)".into(), Key::Note));
            }
            match (limit, lim_on_scale) {
                (Some(l), Some(_)) => {
                    c.draw_series(LineSeries::new(
                        vec![(0.0, l), (tmax, l)],
                        BLACK.stroke_width(1),
                    ))
                    .map_err(perr)?;
                    keys.push((limit_name(l, motor), Key::Level));
                }
                (Some(l), None) => {
                    keys.push((format!("{}, above", limit_name(l, motor)), Key::Level))
                }
                _ => {}
            }
            // (a line of its own: beside the limit's it ran off the figure)
            if limit.is_some() && motor.slope() > 0.0 {
                keys.push(("(more while braking)".into(), Key::Note));
            }
            legend(&side, &keys)?;
        }
        Ok(())
    })
}

/// The torque figure's limit line: a torque limit, or with a torque-speed
/// line the stall torque, which a braking joint may pass.
fn limit_name(l: f64, motor: &Motor) -> String {
    if motor.slope() > 0.0 {
        format!("stall torque {l} N m")
    } else {
        format!("torque limit {l} N m")
    }
}

/// Rotation about the initial spine against time (forward simulation).
pub fn flip(methods: &[MethodTrace]) -> Result<String> {
    svg((1000, 520), |root| {
        let (plot, side) = with_legend(root);
        let tmax = range(methods.iter().flat_map(|m| m.flip_t.iter().copied())).1;
        let y = range(
            methods
                .iter()
                .flat_map(|m| m.flip_deg.iter().copied())
                .chain([0.0, 180.0, -180.0]),
        );
        let mut c = chart(
            &plot,
            "Flip: rotation about the initial spine",
            (0.0, tmax),
            y,
            ("time (s)", "flip (deg)"),
            false,
        )?;
        for target in [-180.0, 180.0] {
            c.draw_series(LineSeries::new(
                vec![(0.0, target), (tmax, target)],
                BLACK.stroke_width(1),
            ))
            .map_err(perr)?;
        }
        let mut keys = Vec::new();
        for (i, m) in methods.iter().enumerate() {
            let st = style_of(&m.name, i);
            let pts: Vec<_> = m
                .flip_t
                .iter()
                .zip(&m.flip_deg)
                .map(|(t, f)| (*t, *f))
                .collect();
            line(&mut c, &pts, st, i as f64 / methods.len() as f64)?;
            keys.push((m.name.clone(), Key::Line(st)));
        }
        keys.push(("+-180 deg: a half turn".into(), Key::Level));
        legend(&side, &keys)
    })
}

/// The shape path in the (q1, q2) plane.
pub fn shape_path(methods: &[MethodTrace]) -> Result<String> {
    svg((700 + LEGEND_W, 700), |root| {
        let (plot, side) = with_legend(root);
        let r = methods
            .iter()
            .flat_map(|m| m.q.iter().map(|q| q[0].hypot(q[1]).to_degrees()))
            .fold(1.0, f64::max)
            * 1.1;
        let mut c = chart(
            &plot,
            "Shape path",
            (-r, r),
            (-r, r),
            ("q1 (deg)", "q2 (deg)"),
            false,
        )?;
        let mut keys = Vec::new();
        for (i, m) in methods.iter().enumerate() {
            let st = style_of(&m.name, i);
            let pts: Vec<_> =
                m.q.iter()
                    .map(|q| (q[0].to_degrees(), q[1].to_degrees()))
                    .collect();
            line(&mut c, &pts, st, i as f64 / methods.len() as f64)?;
            keys.push((m.name.clone(), Key::Line(st)));
        }
        legend(&side, &keys)
    })
}

/// Where each finer mesh of the continuation starts (a dotted line).
fn mesh_switches(
    c: &mut Chart,
    levels: &[crate::design::free::MeshLevel],
    y: (f64, f64),
) -> Result<()> {
    let mut at = 0;
    for l in &levels[..levels.len().saturating_sub(1)] {
        at += l.scp_iterations;
        boundary_line(c, at as f64, y)?;
    }
    Ok(())
}

/// SCP convergence: peak and infeasibility per iteration.
/// `objective` names what the SCP minimised (its [`Objective`](crate::design::objective::Objective));
/// `levels` the meshes the iterations ran on (coarse to fine).
pub fn convergence(
    iters: &[ScpIteration],
    levels: &[crate::design::free::MeshLevel],
    objective: crate::design::objective::Objective,
) -> Result<String> {
    let title = format!("Free-form SCP: {} per iteration", objective.name());
    let axis = format!("{} ({})", objective.name(), objective.unit());
    svg((1000, 700), |root| {
        let n = iters.len().max(2) as f64;
        let panels = root.split_evenly((2, 1));
        let (plot, side) = with_legend(&panels[0]);
        let y = range(iters.iter().map(|i| i.objective));
        let mut c = chart(&plot, &title, (0.0, n), y, ("iteration", &axis), true)?;
        mesh_switches(&mut c, levels, y)?;
        let st = style(1);
        let pts: Vec<_> = iters
            .iter()
            .map(|i| (i.iteration as f64, i.objective))
            .collect();
        line(&mut c, &pts, st, 0.0)?;
        let rejected = style(2);
        let tentative = style(3);
        for (keep, shape, st) in [
            (false, Marker::Cross, rejected),
            (true, Marker::Circle, tentative),
        ] {
            c.draw_series(
                iters
                    .iter()
                    .filter(|i| !i.accepted && i.tentative == keep)
                    .map(|i| marker((i.iteration as f64, i.objective), shape, st.color)),
            )
            .map_err(perr)?;
        }
        let mut keys = vec![
            (
                format!("{} at the iterate", objective.short_name()),
                Key::Line(st),
            ),
            (
                "rejected step".into(),
                Key::Mark(Style {
                    marker: Marker::Cross,
                    ..rejected
                }),
            ),
            (
                "tentative step (watchdog)".into(),
                Key::Mark(Style {
                    marker: Marker::Circle,
                    ..tentative
                }),
            ),
        ];
        if levels.len() > 1 {
            let nodes: Vec<String> = levels.iter().map(|l| l.nodes_label()).collect();
            keys.push((
                format!("finer mesh ({} nodes per phase)", nodes.join(" / ")),
                Key::Boundary,
            ));
        }
        legend(&side, &keys)?;
        let (plot, side) = with_legend(&panels[1]);
        let lg = |v: f64| v.max(1e-16).log10();
        let y = range(
            iters
                .iter()
                .map(|i| lg(i.infeasibility))
                .chain(iters.iter().map(|i| lg(i.radius))),
        );
        let mut c = chart(
            &plot,
            "Constraint violation and trust radius",
            (0.0, n),
            y,
            ("iteration", "log10 of max |r| (rad) or of radius"),
            true,
        )?;
        mesh_switches(&mut c, levels, y)?;
        let mut keys = Vec::new();
        for (k, name) in [
            "max |r|, constraint violation (rad)",
            "trust radius (scaled)",
        ]
        .into_iter()
        .enumerate()
        {
            let st = style(k + 1);
            let pts: Vec<_> = iters
                .iter()
                .map(|i| {
                    let v = if k == 0 { i.infeasibility } else { i.radius };
                    (i.iteration as f64, lg(v))
                })
                .collect();
            line(&mut c, &pts, st, k as f64 / 2.0)?;
            keys.push((name.to_string(), Key::Line(st)));
        }
        legend(&side, &keys)
    })
}

/// A plot of several named series against one variable. When every value
/// is positive and they span more than a factor 20, the y axis is
/// logarithmic, so that a large series does not flatten the small ones.
pub fn lines(
    title: &str,
    xdesc: &str,
    ydesc: &str,
    x: &[f64],
    series: &[(String, Vec<f64>)],
) -> Result<String> {
    lines_styled(title, xdesc, ydesc, x, series, |name, i| {
        style_of(name, i + 1)
    })
}

/// [`lines`] with each series' style from `style_of(name, index)` (for more
/// series than the methods' four styles tell apart).
pub fn lines_styled(
    title: &str,
    xdesc: &str,
    ydesc: &str,
    x: &[f64],
    series: &[(String, Vec<f64>)],
    style_of: impl Fn(&str, usize) -> Style,
) -> Result<String> {
    svg((1000, 560), |root| {
        let (plot, side) = with_legend(root);
        let xr = range(x.iter().copied());
        let finite = || {
            series
                .iter()
                .flat_map(|s| s.1.iter().copied())
                .filter(|v| v.is_finite())
        };
        let (lo, hi) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let log = lo > 0.0 && hi / lo > 20.0;
        let curves: Vec<(Style, Vec<(f64, f64)>)> = series
            .iter()
            .enumerate()
            .map(|(i, (name, ys))| {
                let pts = x
                    .iter()
                    .zip(ys)
                    .filter(|(_, y)| y.is_finite())
                    .map(|(a, b)| (*a, *b))
                    .collect();
                (style_of(name, i), pts)
            })
            .collect();
        let keys: Vec<(String, Key)> = series
            .iter()
            .zip(&curves)
            .map(|((name, _), (st, _))| (name.clone(), Key::Line(*st)))
            .collect();
        if log {
            let mut c = ChartBuilder::on(&plot)
                .caption(title, (FONT, 20))
                .margin(12)
                .x_label_area_size(42)
                .y_label_area_size(70)
                .build_cartesian_2d(
                    xr.0..xr.1,
                    (lo / 1.3..hi * 1.3)
                        .log_scale()
                        .with_key_points(log_ticks((lo / 1.3, hi * 1.3))),
                )
                .map_err(perr)?;
            let ydesc = format!("{ydesc}, log scale");
            c.configure_mesh()
                .x_desc(xdesc)
                .y_desc(ydesc)
                .y_label_formatter(&tick)
                .y_labels(12)
                .label_style((FONT, 13))
                .axis_desc_style((FONT, 15))
                .light_line_style(WHITE.mix(0.0))
                .draw()
                .map_err(perr)?;
            for (k, (st, pts)) in curves.iter().enumerate() {
                line(&mut c, pts, *st, k as f64 / curves.len() as f64)?;
            }
        } else {
            let yr = range(finite());
            let mut c = chart(
                &plot,
                title,
                xr,
                (yr.0.min(0.0), yr.1),
                (xdesc, ydesc),
                false,
            )?;
            for (k, (st, pts)) in curves.iter().enumerate() {
                line(&mut c, pts, *st, k as f64 / curves.len() as f64)?;
            }
        }
        legend(&side, &keys)
    })
}

/// A rate measured on a sample, with its confidence interval (`NaN`
/// rate: no sample).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rate {
    pub x: f64,
    pub rate: f64,
    pub lo: f64,
    pub hi: f64,
}

/// One panel of [`rate_panels`]: its title, its `x` axis (what, with its
/// unit, from 0 to `xmax`) and a named series of rates per line.
pub struct RatePanel {
    pub title: String,
    pub xdesc: String,
    pub xmax: f64,
    pub series: Vec<(String, Vec<Rate>)>,
}

/// Rates (0 to 1) against `x`, one panel side by side for each
/// of `panels`, a style per series name ([`distinct_style`] by position,
/// the same in every panel): each rate a marker on its series' line, its
/// interval a bar, nudged apart where the series share an `x`, so that a
/// rate from few trials shows how little it says. `interval` names the
/// bars in the legend.
pub fn rate_panels(
    title: &str,
    ydesc: &str,
    panels: &[RatePanel],
    interval: &str,
) -> Result<String> {
    let n = panels.len().max(1) as u32;
    svg((360 * n + LEGEND_W, 460), |root| {
        let (plot, side) = with_legend(root);
        let (top, plot) = plot.split_vertically(36);
        top.draw_text(
            title,
            &TextStyle::from((FONT, 20).into_font()).color(&BLACK),
            (12, 10),
        )
        .map_err(perr)?;
        let areas = plot.split_evenly((1, panels.len().max(1)));
        // a series' style by its name's first appearance, the same in every panel
        let solid = |i| Style {
            dash: None,
            ..distinct_style(i)
        };
        let mut names: Vec<&str> = Vec::new();
        for (area, panel) in areas.iter().zip(panels) {
            let w = panel.xmax;
            let mut c = chart(
                area,
                &panel.title,
                (0.0, w),
                (-0.03, 1.03),
                (&panel.xdesc, ydesc),
                false,
            )?;
            let count = panel.series.len() as f64;
            for (k, (name, rates)) in panel.series.iter().enumerate() {
                let i = names.iter().position(|n| n == name).unwrap_or_else(|| {
                    names.push(name);
                    names.len() - 1
                });
                let st = solid(i);
                let dx = (k as f64 - 0.5 * (count - 1.0)) * 0.02 * w;
                let pts: Vec<(f64, f64)> = rates
                    .iter()
                    .filter(|r| r.rate.is_finite())
                    .map(|r| (r.x + dx, r.rate))
                    .collect();
                let stroke = st.color.stroke_width(1);
                for r in rates.iter().filter(|r| r.rate.is_finite()) {
                    let x = r.x + dx;
                    c.draw_series(LineSeries::new([(x, r.lo), (x, r.hi)], stroke))
                        .map_err(perr)?;
                    for y in [r.lo, r.hi] {
                        let tick = 0.008 * w;
                        c.draw_series(LineSeries::new([(x - tick, y), (x + tick, y)], stroke))
                            .map_err(perr)?;
                    }
                }
                line(&mut c, &pts, st, 0.0)?;
            }
        }
        let mut keys: Vec<(String, Key)> = names
            .iter()
            .enumerate()
            .map(|(i, name)| (name.to_string(), Key::Line(solid(i))))
            .collect();
        keys.push((format!("bars: {interval}"), Key::Note));
        legend(&side, &keys)
    })
}

/// A quantity known only to lie in `[lo, hi)`: the largest value found to
/// hold and the smallest found not to (`hi` `None`: every value tried held,
/// up to the figure's `top`, so it is at least `lo`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bracket {
    pub x: f64,
    pub lo: f64,
    pub hi: Option<f64>,
}

/// Brackets ([`Bracket`]) against separate cases `x` (not joined: nothing
/// is known between them), a style per series, nudged apart where they
/// share an `x`: a marker at `lo`, a cross at `hi` with a bar between them,
/// or a dashed bar up past `top` (the largest value tried, a thin level)
/// where every value held. `legend_words` name, in words of the quantity,
/// the marker, the cross, the dashed bar (listed only when one is drawn)
/// and the level.
pub fn brackets(
    title: &str,
    desc: (&str, &str),
    series: &[(String, Vec<Bracket>)],
    top: f64,
    legend_words: [&str; 4],
) -> Result<String> {
    svg((1000, 560), |root| {
        let (plot, side) = with_legend(root);
        let xs = || series.iter().flat_map(|s| s.1.iter().map(|b| b.x));
        let (x0, x1) = xs().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        let pad = (0.08 * (x1 - x0)).max(5.0);
        let y1 = 1.12 * top;
        let mut c = chart(&plot, title, (x0 - pad, x1 + pad), (0.0, y1), desc, false)?;
        c.draw_series(LineSeries::new(
            [(x0 - pad, top), (x1 + pad, top)],
            BLACK.stroke_width(1),
        ))
        .map_err(perr)?;
        let nudge = 0.012 * (x1 - x0 + 2.0 * pad);
        let mut keys = Vec::new();
        for (k, (name, bs)) in series.iter().enumerate() {
            let st = distinct_style(k);
            let dx = (k as f64 - 0.5 * (series.len() as f64 - 1.0)) * nudge;
            let stroke = st.color.stroke_width(2);
            for b in bs {
                let x = b.x + dx;
                match b.hi {
                    Some(hi) => {
                        c.draw_series(LineSeries::new([(x, b.lo), (x, hi)], stroke))
                            .map_err(perr)?;
                        c.draw_series(std::iter::once(marker((x, hi), Marker::Cross, st.color)))
                            .map_err(perr)?;
                    }
                    None => {
                        c.draw_series(DashedLineSeries::new([(x, b.lo), (x, y1)], 5, 4, stroke))
                            .map_err(perr)?;
                    }
                }
                c.draw_series(std::iter::once(marker((x, b.lo), st.marker, st.color)))
                    .map_err(perr)?;
            }
            keys.push((name.clone(), Key::Mark(st)));
        }
        let [lo, hi, open, level] = legend_words;
        keys.push((format!("marker: {lo}"), Key::Note));
        keys.push((format!("cross: {hi}"), Key::Note));
        if series.iter().flat_map(|s| &s.1).any(|b| b.hi.is_none()) {
            keys.push((format!("dashed: {open}"), Key::Note));
        }
        keys.push((level.to_string(), Key::Level));
        legend(&side, &keys)
    })
}

/// Ticks at 1, 2, 3 and 5 times each power of ten inside `(lo, hi)`, at
/// every digit where that gives fewer than four: the chart's own log ticks
/// left a 1.6-decade axis's ends without a number.
pub(crate) fn log_ticks((lo, hi): (f64, f64)) -> Vec<f64> {
    let first = lo.log10().floor() as i32;
    let last = hi.log10().ceil() as i32;
    let at = |mantissas: &[f64]| -> Vec<f64> {
        (first..=last)
            .flat_map(|d| mantissas.iter().map(move |m| m * 10f64.powi(d)))
            .filter(|v| (lo..=hi).contains(v))
            .collect()
    };
    let ticks = at(&[1.0, 2.0, 3.0, 5.0]);
    // a narrow range (within a decade or so) reads from every digit
    if ticks.len() >= 4 {
        ticks
    } else {
        at(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    }
}

/// A log axis's label: the number without float noise (`0.3`, not
/// `0.30000000000000004`).
pub(crate) fn tick(v: &f64) -> String {
    let s = format!("{:.6}", v);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// Escapes text for HTML.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// What the report page shows, top to bottom.
pub struct Page<'a> {
    pub title: &'a str,
    /// The answer block ([`answer::lead`]), first under the title.
    pub lead: Option<&'a str>,
    pub header: &'a [&'a str],
    pub rows: &'a [Vec<String>],
    pub notes: &'a [String],
    pub warnings: &'a [String],
    pub animation: &'a str,
    pub figures: &'a [&'a str],
    /// Each figure's caption, by file name (the command's own).
    pub captions: fn(&str) -> Option<&'static str>,
    /// Whether the glossary follows the table: the words of `run`'s table.
    pub glossary: bool,
}

/// The report page: the answer when there is one ([`answer::lead`]), a
/// summary table, warnings, the animation and the figures.
pub fn index_html(page: &Page) -> String {
    let Page {
        title,
        lead,
        header,
        rows,
        notes,
        warnings,
        animation,
        figures,
        captions,
        glossary: with_glossary,
    } = *page;
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>");
    h.push_str(&esc(title));
    h.push_str(concat!(
        "</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:1100px}",
        // the comparison fits the page: headers and the verdict (a sentence
        // when flagged) wrap, numbers do not; a narrow window scrolls the
        // table alone
        ".wide{overflow-x:auto}table{border-collapse:collapse;font-size:14px}",
        "td,th{border:1px solid #bbb;padding:3px 6px;text-align:right;white-space:nowrap}",
        "th{background:#eee;white-space:normal}td:first-child{text-align:left}img{max-width:100%;margin:1em 0}",
        "td:last-child,th:last-child{white-space:normal;text-align:left;min-width:12em}",
        ".warn{border-left:4px solid #b00;padding:2px 8px;background:#fee}",
        "#views{display:flex;flex-wrap:wrap;gap:12px}.view h3{margin:4px 0}",
        // (a view as wide as its canvas: a long status wraps instead of
        // pushing the others onto rows of their own)
        ".view{width:min-content}",
        ".view canvas{border:1px solid #bbb;cursor:grab;touch-action:none}",
        ".readout{font-family:monospace;font-size:13px}.status{font-size:13px;color:#444}",
        ".controls{display:flex;gap:14px;align-items:center;margin:8px 0}#time{width:320px}",
        "#errors{color:#b00}"
    ));
    if lead.is_some() {
        h.push_str(answer::STYLE);
    }
    h.push_str("</style></head><body>\n");
    h.push_str(&format!("<h1>{}</h1>\n", esc(title)));
    // the robot builder's answer first, above the comparison
    if let Some(lead) = lead {
        h.push_str(lead);
    }
    h.push_str("<div class=\"wide\"><table>\n<tr>");
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
    h.push_str("</table></div>\n");
    for w in warnings {
        h.push_str(&format!("<p class=\"warn\">{}</p>\n", esc(w)));
    }
    for n in notes {
        h.push_str(&format!("<p>{}</p>\n", esc(n)));
    }
    if with_glossary {
        h.push_str(&glossary::section());
    }
    h.push_str(animation);
    for f in figures {
        h.push_str(&format!("<figure><img src=\"{f}\" alt=\"{f}\">"));
        if let Some(c) = captions(f) {
            h.push_str(&format!("<figcaption>{}</figcaption>", esc(c)));
        }
        h.push_str("</figure>\n");
    }
    h.push_str("</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_number_both_ends_of_the_axis() {
        // the gear figure's axis: a tick left of its first point (0.065)
        let t = log_ticks((0.046, 1.4));
        let want = [0.05, 0.1, 0.2, 0.3, 0.5, 1.0];
        assert_eq!(t.len(), want.len(), "{t:?}");
        assert!(
            t.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12),
            "{t:?}"
        );
        // within a decade: every digit
        let t = log_ticks((0.15, 0.45));
        let want = [0.2, 0.3, 0.4];
        assert_eq!(t.len(), want.len(), "{t:?}");
        assert!(
            t.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12),
            "{t:?}"
        );
    }

    #[test]
    fn a_tick_at_zero_has_no_sign() {
        assert_eq!(axis_number(&-1e-17), "0.0");
        assert_eq!(axis_number(&-0.0), "0.0");
        assert_eq!(axis_number(&-0.2), "-0.2");
        assert_eq!(axis_number(&1.5), "1.5");
    }
    use crate::design::objective::Objective;

    /// Separate cases are drawn apart: every line of the figure is vertical
    /// (a bracket, a grid line) or horizontal (the level, a grid line), none
    /// joins two cases; an open bracket rises above the largest value tried,
    /// a closed one stops at its cross.
    #[test]
    fn brackets_are_never_joined_and_an_open_one_rises_past_the_top() {
        let b = |x, lo, hi| Bracket { x, lo, hi };
        let series = [
            (
                "yz".to_string(),
                vec![
                    b(0.0, 1.0, None),
                    b(90.0, 0.0, Some(0.0625)),
                    b(180.0, 0.5, Some(0.75)),
                ],
            ),
            (
                "xz".to_string(),
                vec![b(90.0, 1.0, None), b(270.0, 0.25, Some(0.5))],
            ),
        ];
        let svg = brackets("t", ("x", "y"), &series, 1.0, ["a", "b", "c", "d"]).unwrap();
        let doc = roxmltree::Document::parse(&svg).unwrap();
        // (stroke, points) of every line drawn
        let lines: Vec<(&str, Vec<(f64, f64)>)> = doc
            .descendants()
            .filter(|e| e.has_tag_name("polyline"))
            .map(|e| {
                let pts = e
                    .attribute("points")
                    .unwrap()
                    .split_whitespace()
                    .map(|p| {
                        let (x, y) = p.split_once(',').unwrap();
                        (x.parse().unwrap(), y.parse().unwrap())
                    })
                    .collect();
                (e.attribute("stroke").unwrap(), pts)
            })
            .collect();
        let along = |pts: &[(f64, f64)], f: fn(&(f64, f64)) -> f64| {
            pts.iter().all(|p| (f(p) - f(&pts[0])).abs() < 0.5)
        };
        for (_, pts) in &lines {
            assert!(
                along(pts, |p| p.0) || along(pts, |p| p.1),
                "a joining line: {pts:?}"
            );
        }
        // the level: the highest long black horizontal line (pixel rows
        // grow downwards); the brackets: the coloured vertical ones
        let level = lines
            .iter()
            .filter(|(st, p)| *st == "#000000" && along(p, |p| p.1) && p[1].0 - p[0].0 > 300.0)
            .map(|(_, p)| p[0].1)
            .fold(f64::INFINITY, f64::min);
        let mut xs = Vec::new();
        let mut open = Vec::new();
        for (_, p) in lines
            .iter()
            .filter(|(st, p)| *st != "#000000" && along(p, |p| p.0))
        {
            let x = p[0].0.round() as i64;
            xs.push(x);
            if p.iter().any(|q| q.1 < level - 3.0) {
                open.push(x);
            }
        }
        for v in [&mut xs, &mut open] {
            v.sort();
            v.dedup();
        }
        assert_eq!(xs.len(), 5, "one bar a bracket: {xs:?}");
        assert_eq!(open.len(), 2, "the open ones rise past the level: {open:?}");
        assert!(svg.contains("dashed: c") && svg.contains("marker: a"));
    }

    /// A log axis (a sweep's peaks over two decades) labels 1, 2, 3 and 5
    /// times each power of ten, without float noise (it printed
    /// 0.30000000000000001).
    #[test]
    fn a_log_axis_labels_round_numbers() {
        let x = [0.18, 0.2, 0.22, 0.24];
        let series = [
            ("analytic".to_string(), vec![1.5, 1.8, 2.0, 2.3]),
            ("free".to_string(), vec![0.05, 0.053, 0.056, 0.06]),
        ];
        let svg = lines("t", "x", "y", &x, &series).unwrap();
        let labels: Vec<&str> = svg
            .split("</text>")
            .filter_map(|t| t.rsplit('>').next().map(str::trim))
            .collect();
        for want in ["0.05", "0.1", "0.2", "0.3", "0.5", "1", "2"] {
            assert!(labels.contains(&want), "{want} in {labels:?}");
        }
        assert!(labels.iter().all(|l| !l.contains("0000")), "{labels:?}");
    }

    /// Many series (a recovery map's release axes) are drawn as many ways.
    #[test]
    fn the_first_32_distinct_styles_differ() {
        let key = |i: usize| {
            let s = distinct_style(i);
            (s.color.0, s.color.1, s.color.2, s.dash, s.marker)
        };
        for i in 0..32 {
            for j in 0..i {
                assert_ne!(key(i), key(j), "{i} and {j}");
            }
        }
    }

    #[test]
    fn the_convergence_figure_names_the_objective_it_plots() {
        let it = |iteration: usize, objective: f64| ScpIteration {
            iteration,
            merit: objective,
            objective,
            infeasibility: 1e-3,
            radius: 0.5,
            weight: 1.0,
            predicted: 0.1,
            actual: 0.1,
            rho: 1.0,
            accepted: true,
            tentative: false,
            merit_after: objective,
            step: 0.5,
            model_step: 0.5,
            solve_ms: 1.0,
        };
        let iters = [it(0, 0.9), it(1, 0.8)];
        let levels = [crate::design::free::MeshLevel {
            nodes: 40,
            scp_iterations: 2,
            converged: true,
            starts: 1,
            other_iterations: 0,
        }];
        for (objective, word) in [
            (Objective::Time, "time"),
            (Objective::Energy, "energy"),
            (Objective::PeakTorque, "peak"),
        ] {
            let svg = convergence(&iters, &levels, objective).unwrap();
            assert!(svg.contains(&format!("{word} at the iterate")), "{word}");
            let others = ["time", "energy", "peak"]
                .into_iter()
                .filter(|w| *w != word);
            for other in others {
                assert!(!svg.contains(&format!("{other} at the iterate")), "{word}");
            }
        }
    }
}
