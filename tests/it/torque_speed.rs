//! The torque-speed figure of `run`, read back from the SVG through the real
//! binary: its envelope corners sit at the configured stall torque and
//! no-load speed, and a schedule the JSON calls inside the envelope is drawn
//! inside it (one that leaves it is drawn outside: the check can fail).

use crate::util;

use util::{bin, config_path, temp_dir};

/// `(pixel, value)` of each numeric tick label, by text anchor ("end": y
/// axis, "middle": x axis), for the panel whose pixel rows are `rows`.
fn ticks(svg: &str, anchor: &str, rows: (f64, f64)) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for piece in svg.split("<text ").skip(1) {
        let (attrs, rest) = piece.split_once('>').unwrap();
        let body = rest.split('<').next().unwrap();
        let attr = |name: &str| -> Option<f64> {
            let v = format!(" {attrs}");
            let v = v.split(&format!(" {name}=\"")).nth(1)?;
            v.split('"').next()?.parse().ok()
        };
        let (Some(x), Some(y), Ok(v)) = (attr("x"), attr("y"), body.trim().parse::<f64>()) else {
            continue;
        };
        if !attrs.contains(&format!("text-anchor=\"{anchor}\"")) || y < rows.0 || y >= rows.1 {
            continue;
        }
        out.push((if anchor == "end" { y } else { x }, v));
    }
    out
}

/// The linear pixel -> value map through the extreme ticks.
fn axis(t: &[(f64, f64)]) -> impl Fn(f64) -> f64 + use<> {
    assert!(t.len() >= 3, "too few ticks: {t:?}");
    let (a, b) = (t[0], t[t.len() - 1]);
    move |p| a.1 + (p - a.0) * (b.1 - a.1) / (b.0 - a.0)
}

fn points(el: &str) -> Vec<(f64, f64)> {
    let p = el
        .split("points=\"")
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap();
    p.split_whitespace()
        .map(|xy| {
            let (x, y) = xy.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect()
}

/// Elements `<tag ...>` whose attributes contain every one of `needles`.
fn elements<'a>(svg: &'a str, tag: &str, needles: &[&str]) -> Vec<&'a str> {
    svg.split(&format!("<{tag} "))
        .skip(1)
        .map(|p| p.split('>').next().unwrap())
        .filter(|a| needles.iter().all(|n| a.contains(n)))
        .collect()
}

#[test]
fn torque_speed_figure_draws_the_configured_envelope_and_the_schedules_in_it() {
    let dir = temp_dir();
    let cfg = config_path("robot-universal");
    // from 6 m the phased design fits the servo (the analytic one does not)
    let o = bin()
        .args(["run", cfg.to_str().unwrap(), "--set", "fall.height=6"])
        .args(["--set", "free.nodes=20", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        matches!(o.status.code(), Some(0 | 3)),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let base = dir
        .path()
        .join("robot-universal/run@fall.height=6,free.nodes=20");
    let svg = std::fs::read_to_string(base.join("torque_speed.svg")).unwrap();
    let html = std::fs::read_to_string(base.join("index.html")).unwrap();
    assert!(html.contains("<img src=\"torque_speed.svg\""));
    assert!(html.contains("<figcaption>Torque-speed plane"));
    assert!(html.contains("the grey band is the DC-motor envelope"));
    assert!(html.contains("the least-height schedule, made for its own drop"));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(base.join("summary.json")).unwrap()).unwrap();
    // the config: XL430 stall torque and no-load speed, per motor, no max_speed
    let (t, w0) = (1.4, 5.969);
    let k = t / w0;
    assert!(svg.contains("stall T = 1.4 N m") && svg.contains("no-load w0 = 5.969 rad/s"));
    // beside the dots, their symbols only (the values, written there, crossed
    // the curves and ran past the frame)
    for symbol in ["T", "-T", "w0", "-w0"] {
        assert!(svg.lines().any(|l| l.trim() == symbol), "{symbol}");
    }
    assert!(!svg.contains("stall / no-load point"));
    // the reference cut to the plot says so in its legend; the designs are whole
    let cut = svg.matches("rad/s, cut)").count();
    assert!(cut >= 2, "the analytic's, per motor: {cut}");
    assert_eq!(
        cut,
        svg.matches("analytic (").count(),
        "the analytic's alone"
    );
    // the torque figure draws the limits: the stall torque and T - k|w| along each method
    let torque = std::fs::read_to_string(base.join("torque.svg")).unwrap();
    // (with a torque-speed line the limit line is the stall torque, which braking passes)
    // (its note on a line of its own: beside the limit it ran off the figure)
    let text = |t: &str| torque.lines().any(|l| l.trim() == t);
    assert!(
        text("stall torque 1.4 N m") && text("(more while braking)") && torque.contains("T - k|w|")
    );

    let polys = elements(&svg, "polygon", &["fill=\"#BBBBBB\""]);
    // the free design (0.026 N m) is small on the motors' scale: each
    // motor's panel is followed by its detail
    assert_eq!(polys.len(), 4, "one envelope per motor and per detail");
    assert_eq!(svg.matches(", detail: |tau| up to ").count(), 2);
    // each panel is 560 px tall
    for (j, poly) in polys.iter().enumerate() {
        let rows = (560.0 * j as f64, 560.0 * (j + 1) as f64);
        if j % 2 == 1 {
            detail_panel(&svg, poly, rows, (t, k), &summary);
            continue;
        }
        let j = j / 2;
        // the analytic reference (23 rad/s, over three times w0) does not set
        // the speed scale: the ticks stay near the envelope's
        let speed_ticks = ticks(&svg, "middle", rows);
        let widest = speed_ticks.iter().fold(0.0f64, |a, t| a.max(t.1.abs()));
        assert!(
            widest < 1.5 * w0,
            "motor {}: speed ticks to {widest} rad/s",
            j + 1
        );
        let (fx, fy) = (axis(&speed_ticks), axis(&ticks(&svg, "end", rows)));
        // one pixel in data units, the resolution of the check
        let (px, py) = ((fx(1.0) - fx(0.0)).abs(), (fy(1.0) - fy(0.0)).abs());
        let corners: Vec<(f64, f64)> = points(poly).iter().map(|p| (fx(p.0), fy(p.1))).collect();
        // the band |tau + k w| <= T closed at the no-load speed
        let want = [(-w0, 2.0 * t), (w0, 0.0), (w0, -2.0 * t), (-w0, 0.0)];
        assert_eq!(corners.len(), 4);
        for (c, w) in corners.iter().zip(want) {
            assert!(
                (c.0 - w.0).abs() <= 1.5 * px && (c.1 - w.1).abs() <= 1.5 * py,
                "motor {}: corner {c:?}, want {w:?}",
                j + 1
            );
        }
        // each method's drawn trace against the envelope, from its line's colour
        for m in summary["methods"].as_array().unwrap() {
            let name = m["method"].as_str().unwrap();
            let color = match name {
                "analytic" => "#555555",
                "phased" => "#1F77B4",
                _ => "#D62728",
            };
            // a failed method has no schedule, hence no trace
            let Some(margin) = m["min_envelope_margin"].as_f64() else {
                continue;
            };
            let drawn = trace(&svg, color, rows, (&fx, &fy));
            assert!(drawn.len() > 50, "{name}: {} points drawn", drawn.len());
            // worst excess over the band, in pixels of torque
            let excess = drawn
                .iter()
                .map(|(w, tau)| ((tau + k * w).abs() - t) / py)
                .fold(f64::NEG_INFINITY, f64::max);
            if margin >= 0.0 {
                assert!(excess <= 1.5, "{name} motor {}: {excess} px outside", j + 1);
            } else if name == "analytic" {
                // the seed schedule is far outside (23 rad/s against 5.97)
                assert!(excess > 10.0, "{name}: drawn inside ({excess} px)");
            }
        }
    }
}

/// The points of the schedule drawn in `color` within a panel's plot area
/// (pixel rows `rows`, left of the legend), in data units through the
/// panel's axes `(fx, fy)`.
fn trace(
    svg: &str,
    color: &str,
    rows: (f64, f64),
    (fx, fy): (&dyn Fn(f64) -> f64, &dyn Fn(f64) -> f64),
) -> Vec<(f64, f64)> {
    elements(
        svg,
        "polyline",
        &[&format!("stroke=\"{color}\""), "stroke-width=\"2\""],
    )
    .into_iter()
    .flat_map(points)
    .filter(|p| p.1 >= rows.0 && p.1 < rows.1 && p.0 < 740.0)
    .map(|p| (fx(p.0), fy(p.1)))
    .collect()
}

/// A detail panel (pixel rows `rows`): the envelope cut to its window, and
/// the free design's trace, which fits it, inside the band `(T, k)`.
fn detail_panel(
    svg: &str,
    poly: &str,
    rows: (f64, f64),
    (t, k): (f64, f64),
    summary: &serde_json::Value,
) {
    let (fx, fy) = (
        axis(&ticks(svg, "middle", rows)),
        axis(&ticks(svg, "end", rows)),
    );
    // one pixel in data units: the torque's, and the band's torque k w
    // across one pixel of speed (the detail's torque pixel is finer)
    let (px, py) = ((fx(1.0) - fx(0.0)).abs(), (fy(1.0) - fy(0.0)).abs());
    let slack = 1.5 * (py + k * px);
    let corners: Vec<(f64, f64)> = points(poly).iter().map(|p| (fx(p.0), fy(p.1))).collect();
    // the band cut at +-w: six corners, the highest torque the window's
    let w = corners.iter().fold(0.0f64, |a, c| a.max(c.1.abs()));
    assert_eq!(corners.len(), 6, "{corners:?}");
    assert!(w < 0.25 * t, "the window {w} N m is a detail of {t} N m");
    let free = summary["methods"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["method"] == "free")
        .unwrap();
    assert!(free["min_envelope_margin"].as_f64().unwrap() >= 0.0);
    let drawn = trace(svg, "#D62728", rows, (&fx, &fy));
    assert!(drawn.len() > 50, "free: {} points drawn", drawn.len());
    for (speed, tau) in &drawn {
        assert!(
            tau.abs() <= w + 1.5 * py,
            "free at {tau} N m, past the window {w}"
        );
        let excess = (tau + k * speed).abs() - t;
        assert!(
            excess <= slack,
            "free outside the band at ({speed}, {tau}): {excess} N m"
        );
    }
}
