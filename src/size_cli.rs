//! `catflip size`: the command-line face of [`catflip::size`].

use crate::cli::{Common, Status, load, publisher};
use anyhow::Result;
use catflip::output::Output;
use catflip::size::{SizeAnswer, SizeSettings, files};

pub(crate) fn cmd_size(c: &Common, height: f64, settings: SizeSettings) -> Result<Status> {
    let cfg = load(c)?;
    settings.validate()?;
    let q = catflip::size::question(&cfg, height)?;
    let publisher = publisher(c, &cfg, &format!("size-{height}m"))?;
    let dir = publisher.link();
    let a = catflip::size::size(&q, &settings)?;
    let json = serde_json::to_value(&a)?;
    catflip::output::ensure_finite(&json, &[])?;
    let json = serde_json::to_string_pretty(&json)?;
    let mut out = Output::default();
    out.add(files::CURVE_CSV, catflip::size::curve_csv(&a));
    out.add(files::GEAR_CSV, catflip::size::gear_csv(&a));
    out.add(files::JSON, json.clone());
    let written = publisher.publish(out)?;
    let status = if a.is_partial() {
        for f in &a.failed {
            eprintln!("warning: a point of the curve FAILED: {f}");
        }
        Status::Partial
    } else {
        Status::Ok
    };
    if c.json {
        println!("{json}");
        return Ok(status);
    }
    print_table(&a);
    println!(
        "  report: {} ({} files)",
        dir.join("index.html").display(),
        written.len()
    );
    Ok(status)
}

fn print_table(a: &SizeAnswer) {
    println!(
        "catflip size: {} ({} joint, peak norm {}), from {} m ({:.4} s of manoeuvre)",
        a.name,
        a.joint,
        a.peak_norm.name(),
        a.height_m,
        a.manoeuvre_time_s
    );
    println!(
        "  no motor weaker than {:.4} N m stall torque (at any speed) or slower than {:.3} rad/s no-load speed (at any torque) can do it",
        a.torque_asymptote_nm, a.speed_asymptote_rad_s
    );
    println!(
        "  {:>16} {:>16} {:>14}   design",
        "no-load rad/s", "stall torque N m", "T/w0^2 N m s^2"
    );
    for p in &a.curve {
        println!(
            "  {:>16.4} {:>16.5} {:>14.4e}   {} {}, scaled by {:.4}",
            p.no_load_speed_rad_s,
            p.stall_torque_nm,
            p.ratio_nms2,
            p.design.method,
            p.design.status,
            p.scale
        );
    }
    let g = &a.gear;
    let can = |ok: bool| if ok { "makes it" } else { "does not make it" };
    println!(
        "  configured motor (N = 1): least height {:.3} m: {} from {} m",
        g.configured_least_height_m,
        can(g.configured_possible),
        a.height_m
    );
    println!(
        "  best gear ratio N = {:.4} ({:.4} N m, {:.3} rad/s): least height {:.3} m ({:.4} s): {} from {} m",
        g.best_ratio,
        g.stall_torque_nm,
        g.no_load_speed_rad_s,
        g.least_height_m,
        g.least_time_s,
        can(g.possible),
        a.height_m
    );
    println!(
        "  {} designs in {:.1} s",
        a.designs, a.solve_time_s
    );
}
