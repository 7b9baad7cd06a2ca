//! `catflip size`: the command-line face of [`catflip::size`].

use crate::common::{Common, Status, load, publisher, say};
use anyhow::Result;
use catflip::output::Output;
use catflip::size::{SizeAnswer, SizeSettings, files};

pub(crate) fn cmd_size(c: &Common, height: f64, settings: SizeSettings) -> Result<Status> {
    // `--height` replaces `fall.height` before the config is checked: the
    // configured drop is not used, and the margin is judged against this one
    crate::cli::refuse_set_of(c, "fall.height", &format!("--height {height}"))?;
    // (it designs least-time schedules: another objective would be ignored,
    // yet name the set)
    crate::cli::refuse_set_of(c, "design.objective", "`catflip size`")?;
    let with_height = Common {
        set: [c.set.clone(), vec![format!("fall.height={height}")]].concat(),
        ..c.clone()
    };
    let cfg = load(&with_height).map_err(|e| match e.downcast::<catflip::Error>() {
        Ok(e) => catflip::size::height_error(height, e).into(),
        Err(e) => e,
    })?;
    settings.validate()?;
    let q = catflip::size::question(&cfg, height)?;
    let publisher = publisher(c, &cfg, &format!("size-{height}m"))?;
    let dir = publisher.link();
    let progress = crate::common::Progress::new(c.json);
    let clock = std::time::Instant::now();
    let a = catflip::size::size(&q, &settings, |done, total| {
        progress.show(&catflip::console::progress::bar(
            "size",
            done,
            total,
            "steps (the asymptotes, the curve's points, the gear ratio)",
            clock.elapsed().as_secs_f64(),
        ))
    });
    progress.finish();
    let a = a?;
    let json = serde_json::to_value(&a)?;
    catflip::output::ensure_finite(&json, &[])?;
    let json = serde_json::to_string_pretty(&json)?;
    let mut out = Output::default();
    out.add(files::CURVE_CSV, catflip::size::curve_csv(&a));
    out.add(files::GEAR_CSV, catflip::size::gear_csv(&a));
    out.add(files::JSON, json.clone());
    out.add(files::CURVE_SVG, catflip::report::size::curve(&a)?);
    out.add(files::GEAR_SVG, catflip::report::size::gear(&a)?);
    out.add("index.html", catflip::report::size::page(&a));
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
        say!("{json}");
        return Ok(status);
    }
    print_table(&a);
    say!(
        "  report: {} ({} files)",
        dir.join("index.html").display(),
        written.len()
    );
    Ok(status)
}

fn print_table(a: &SizeAnswer) {
    say!(
        "catflip size: {} ({} joint, peak norm {}), from {} m ({:.4} s of manoeuvre)",
        a.name,
        a.joint,
        a.peak_norm.name(),
        a.height_m,
        a.manoeuvre_time_s
    );
    say!(
        "  {:>16} {:>18} {:>16}   design",
        "no-load rad/s",
        "stall torque N m",
        "T/w0^2 N m s^2"
    );
    for p in &a.curve {
        say!(
            "  {:>16.4} {:>18.5} {:>16.4e}   {} {}, scaled by {:.4}",
            p.no_load_speed_rad_s,
            p.stall_torque_nm,
            p.ratio_nms2,
            p.design.method,
            p.design.status,
            p.scale
        );
    }
    for s in a.lead() {
        say!("  {s}");
    }
    say!("  {} designs in {:.1} s", a.designs, a.solve_time_s);
}
