//! `catflip size`: the command-line face of [`catflip::size`].

use crate::common::{Common, Status, load, publisher, say};
use anyhow::Result;
use catflip::output::Output;
use catflip::size::{SizeAnswer, SizeSettings, files};

/// The keys `catflip size` sets itself, so a `--set` of them is refused,
/// each with what sets it: `--height` replaces `fall.height` (the configured
/// drop is not used, and the margin is judged against this one), and it
/// designs least-time schedules (another objective would be ignored, yet
/// name the set).
fn sets_itself(height: f64) -> [(&'static str, String); 2] {
    [
        ("fall.height", format!("--height {height}")),
        ("design.objective", "`catflip size`".into()),
    ]
}

pub(crate) fn cmd_size(c: &Common, height: f64, settings: SizeSettings) -> Result<Status> {
    for (key, by) in sets_itself(height) {
        crate::cli::refuse_set_of(c, key, &by)?;
    }
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
    // (not a --set, refused above: the file's own; `time` is size's own)
    use catflip::design::objective::Objective;
    let objective = cfg.design.objective;
    if !matches!(objective, Objective::PeakTorque | Objective::Time) {
        eprintln!(
            "warning: {} sets design.objective = \"{}\", which `catflip size` does not use: \
             it sizes the motors for the least height, a least-time design",
            c.config.display(),
            objective.name()
        );
    }
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

/// The `catflip size` command line that asks `run`'s question backwards
/// (up to its `--height`), as a message advises it: the config and its
/// `--set`s, without those `size` refuses (the keys it sets itself, a
/// spin), and at rest where the config's release spins (`size` sizes the
/// motors for a release at rest: time scaling, F9).
pub(crate) fn advised(c: &Common, height: f64) -> String {
    let refused = |s: &String| {
        let key = crate::common::set_key(s);
        sets_itself(height).iter().any(|(k, _)| *k == key) || key == "start.angular_velocity"
    };
    let mut kept = Common {
        set: c.set.iter().filter(|s| !refused(s)).cloned().collect(),
        ..c.clone()
    };
    // (the spin may be the config file's own, which a dropped `--set` held
    // at rest; loaded as size would, at a drop of its own, without warning
    // again about what the run's load warned of)
    let with_drop = [kept.set.clone(), vec![format!("fall.height={height}")]].concat();
    let spins = catflip::Config::load(&kept.config, &with_drop)
        .is_ok_and(|cfg| cfg.start.angular_velocity.iter().any(|w| *w != 0.0));
    if spins {
        kept.set.push("start.angular_velocity=[0, 0, 0]".into());
    }
    format!("{} --height", kept.command("size"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// The advice leaves out what `size` refuses and sizes a spinning
    /// release at rest, whether the spin was a `--set` or the file's own.
    #[test]
    fn the_advised_size_command_holds_only_what_size_takes() {
        let dir = tempfile::tempdir().unwrap();
        let robot = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("configs/robot-universal.toml");
        let spinning = dir.path().join("spinning.toml");
        let text = std::fs::read_to_string(&robot).unwrap();
        // (the robot's own `[start]` table, or a new one)
        let text = if text.contains("[start]") {
            text.replace("[start]", "[start]\nangular_velocity = [0.0, 0.0, 0.5]")
        } else {
            format!("{text}\n[start]\nangular_velocity = [0.0, 0.0, 0.5]\n")
        };
        std::fs::write(&spinning, text).unwrap();
        let common = |config: &PathBuf, set: &[&str]| Common {
            config: config.clone(),
            set: set.iter().map(|s| s.to_string()).collect(),
            json: false,
            out: PathBuf::from("output"),
        };
        let advised_for = |c: &Common| advised(c, 2.0);
        let sets = [
            "fall.height=1",
            "design.objective=time",
            "cat.mass=0.46",
            "start.angular_velocity=[0, 0, 1]",
        ];
        let at = |path: &PathBuf| path.display().to_string();
        assert_eq!(
            advised_for(&common(&robot, &sets)),
            format!("catflip size {} --set cat.mass=0.46 --height", at(&robot))
        );
        assert_eq!(
            advised_for(&common(&spinning, &sets)),
            format!(
                "catflip size {} --set cat.mass=0.46 --set 'start.angular_velocity=[0, 0, 0]' --height",
                at(&spinning)
            )
        );
        // the file's spin held at rest by the user: at rest still
        assert_eq!(
            advised_for(&common(&spinning, &["start.angular_velocity=[0,0,0]"])),
            format!(
                "catflip size {} --set 'start.angular_velocity=[0, 0, 0]' --height",
                at(&spinning)
            )
        );
    }
}
