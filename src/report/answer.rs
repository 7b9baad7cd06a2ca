//! The report's first block under a motor limit: the robot builder's answer
//! (can these motors flip it from the configured height, and from what
//! height they can), before the comparison of the methods.

use super::esc;
use crate::design::least_height::HeightAnswer;

/// The block's style (added to the page only when it has the block).
pub const STYLE: &str = concat!(
    "#answer{border:2px solid;border-radius:6px;padding:8px 16px;margin:0 0 1.2em 0}",
    "#answer.possible{border-color:#2c7a2c;background:#effaef}",
    "#answer.impossible{border-color:#b00;background:#fdf0f0}",
    "#answer .headline{font-size:1.5em;font-weight:bold;margin:4px 0}",
    "#answer .height{font-size:1.25em;margin:4px 0}"
);

/// The lower bound on the least drop height, when the answer carries one
/// (`least_height_lower_bound_m` in the answer's JSON; absent, or null,
/// when no bound is known).
pub fn lower_bound(a: &HeightAnswer) -> Option<f64> {
    serde_json::to_value(a)
        .ok()?
        .get("least_height_lower_bound_m")?
        .as_f64()
}

/// The headline: possible or not, from the configured height.
pub fn headline(a: &HeightAnswer) -> String {
    if a.beyond_longest_fall {
        format!(
            "Not possible from {} m with these motors, nor from any drop catflip designs.",
            a.height_m
        )
    } else if !a.possible && !a.verified {
        format!(
            "No verified design flips it from {} m with these motors.",
            a.height_m
        )
    } else if a.possible {
        format!("Possible from {} m with these motors.", a.height_m)
    } else {
        format!("Not possible from {} m with these motors.", a.height_m)
    }
}

/// The least height found and, when known, its lower bound and what the
/// bound is: `... 3.541 m (at least 3.200 m) ...`.
pub fn height_text(a: &HeightAnswer) -> String {
    if a.beyond_longest_fall {
        let t = a.beyond_text();
        return t[..1].to_uppercase() + &t[1..];
    }
    let b = lower_bound(a);
    let bound = b
        .map(|b| format!(" (at least {b:.3} m)"))
        .unwrap_or_default();
    // the bound ignores the torque-speed line: said, lest a bound far below
    // the answer read as a contradiction of "not possible"
    let what = b
        .map(|b| {
            format!(
                " The bound, {b:.3} m, is the least height found for a motor that never gives more than its stall torque and has no speed limit (the best such design found, a local optimum as the answer is, so an estimate, not a proof; and the torque-speed line gives more than the stall torque while braking, T + k |w|); it is given only below the answer. The answer is the best design found, a local optimum; where the two are far apart, the motors' speed, not their torque, is what holds the flip back."
            )
        })
        .unwrap_or_default();
    if !a.verified {
        // (only the phased design is ever unverified: the free-form ones
        // that answer are flown first)
        return format!(
            "No verified least drop height: the phased time design fits the motors from {:.3} m but misses the flip in the simulation (the least-height row below).",
            a.least_height_m
        );
    }
    if a.possible && a.least_height_m > a.height_m {
        // a design fits this fall although the least-height one needs more
        format!(
            "A verified {} design fits this fall; the least-height design found needs {:.3} m{bound}.{what}",
            a.method, a.least_height_m
        )
    } else {
        format!(
            "The least drop height found: {:.3} m{bound}, for a {:.4} s manoeuvre.{what}",
            a.least_height_m, a.least_time_s
        )
    }
}

/// What the least-height schedule is and where it is shown.
fn shown_text(a: &HeightAnswer) -> String {
    if a.beyond_longest_fall {
        return "No least-height schedule is shown or written: its fall would be longer than any catflip simulates.".into();
    }
    if !a.verified {
        return "Its schedule is the least-height row below (flagged), shown and written as least-height.csv so that it can be examined, not flown.".into();
    }
    let proven = if a.status.is_proven() {
        format!("the {} time design, {}", a.method, a.status)
    } else {
        format!(
            "the {} time design, verified but not proven shortest: {}",
            a.method, a.status
        )
    };
    let sizing = if a.possible {
        String::new()
    } else {
        format!(" {}", a.sizing())
    };
    format!(
        "The shortest manoeuvre found inside the motor envelope ({proven}) is the least-height row below: in the animation, the torque and torque-speed figures, and written as least-height.csv with its simulator controls (least-height.mujoco.csv, least-height.pybullet.csv).{sizing}"
    )
}

/// The block: headline, least height (and bound), and where the
/// least-height schedule is shown and written.
pub fn lead(a: &HeightAnswer) -> String {
    lead_with(a, None)
}

/// [`lead`] with what to fly from the configured height (`fly`) first in
/// its paragraph: for a possible answer, the next thing a reader does.
pub fn lead_with(a: &HeightAnswer, fly: Option<&str>) -> String {
    let shown = shown_text(a);
    let more = match fly {
        Some(f) => format!("{f} {shown}"),
        None => shown,
    };
    block(a.possible, &headline(a), &height_text(a), &more)
}

/// The answer's block (green when `possible`, else red): a headline, a
/// larger line under it and a paragraph, in plain text.
pub fn block(possible: bool, headline: &str, second: &str, more: &str) -> String {
    let class = if possible { "possible" } else { "impossible" };
    format!(
        "<section id=\"answer\" class=\"{class}\">\n<p class=\"headline\">{}</p>\n<p class=\"height\">{}</p>\n<p>{}</p>\n</section>\n",
        esc(headline),
        esc(second),
        linked(&esc(more))
    )
}

/// The schedules' files, beside the page, as links where the (escaped) text
/// names them: a reader goes on to open them.
fn linked(html: &str) -> String {
    let mut out = html.to_string();
    for m in ["least-height", "free", "phased"] {
        for f in [
            format!("{m}.csv"),
            format!("{m}.mujoco.csv"),
            format!("{m}.pybullet.csv"),
        ] {
            // (a whole name: `free.csv` is not the end of another)
            out = out.replace(&format!(" {f}"), &format!(" <a href=\"{f}\">{f}</a>"));
            out = out.replace(&format!("({f}"), &format!("(<a href=\"{f}\">{f}</a>"));
        }
    }
    out
}
