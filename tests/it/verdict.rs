//! One verdict: `catflip optimize` and `catflip run` judge the same method on
//! the same config alike, on every bundled config.

use crate::util;
use std::path::Path;

/// The command's JSON, or its exit status and error message.
fn json_or_error(args: &[&str], out: &Path) -> Result<serde_json::Value, (Option<i32>, String)> {
    let o = util::bin()
        .args(args)
        .args(["--json", "--out"])
        .arg(out)
        .current_dir(util::repo())
        .output()
        .unwrap();
    serde_json::from_slice(&o.stdout).map_err(|_| {
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    })
}

fn json(args: &[&str], out: &Path) -> Option<serde_json::Value> {
    json_or_error(args, out).ok()
}

#[test]
fn optimize_and_run_give_the_same_verdict_on_every_bundled_config() {
    let dir = util::temp_dir();
    let configs = util::configs();
    let mut checked = 0;
    for entry in std::fs::read_dir(configs).unwrap() {
        let path = entry.unwrap().path();
        // configs/ also holds the robot descriptions the configs read
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let cfg = format!("configs/{}", path.file_name().unwrap().to_str().unwrap());
        let run = json(&["run", &cfg], dir.path()).expect("run prints its summary");
        for mode in ["phased", "free"] {
            let m = run["methods"]
                .as_array()
                .unwrap()
                .iter()
                .find(|m| m["method"] == mode)
                .unwrap();
            // a method that fails prints no design (an error, exit 1); one the
            // motors cannot do in this fall is not attempted by `run`, and
            // `optimize` refuses it saying so: the answer, exit 4, as `run`'s
            let (verdict, status) =
                match json_or_error(&["optimize", &cfg, "--mode", mode], dir.path()) {
                    Ok(o) => (o["verdict"].clone(), o["status"].clone()),
                    Err((code, e)) if m["verdict"] == "impossible" => {
                        assert!(
                            e.contains("not possible with these motors in this fall"),
                            "{cfg} {mode}: run says impossible, optimize says {e}"
                        );
                        // the free-form design's refusal is run's answer
                        let least = run["answer"]["least_height_m"].as_f64().unwrap();
                        assert!(
                            mode == "phased"
                                || e.contains(&format!("least drop height found is {least:.3} m")),
                            "{cfg}: run answers {least} m, optimize says {e}"
                        );
                        assert_eq!(code, Some(4), "{cfg} {mode}: {e}");
                        ("impossible".into(), "not-attempted".into())
                    }
                    Err((code, e)) => {
                        assert_eq!(code, Some(1), "{cfg} {mode}: {e}");
                        ("failed".into(), "failed".into())
                    }
                };
            if mode == "phased" && m["verdict"] == "impossible" {
                // the phased least height a row names is a verified height
                // unless its design misses the flip (the lopsided box robot,
                // whose spine the phased family tilts), which the row says
                let unverified = m["reason"]
                    .as_str()
                    .unwrap()
                    .contains("misses the flip in the simulation (not a verified height)");
                assert_eq!(unverified, cfg.ends_with("box-robot.toml"), "{cfg}: {m}");
            }
            assert_eq!(m["verdict"], verdict, "{cfg} {mode}: run {m}");
            assert_eq!(m["status"], status, "{cfg} {mode}");
            checked += 1;
        }
    }
    assert!(checked >= 6, "{checked} methods checked");
}
