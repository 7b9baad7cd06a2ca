//! Shape trajectories in time (plans) and their sampled form (schedules).

use crate::error::{Error, Result};
use crate::model::dynamics::inverse_dynamics;
use crate::model::{Cat, TorqueNorm};
use serde::Serialize;

/// The three phases of the manoeuvre.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    Fold,
    Twist,
    Unfold,
}

impl Phase {
    pub const ALL: [Phase; 3] = [Phase::Fold, Phase::Twist, Phase::Unfold];
    pub fn name(self) -> &'static str {
        match self {
            Phase::Fold => "fold",
            Phase::Twist => "twist",
            Phase::Unfold => "unfold",
        }
    }
    pub fn parse(s: &str) -> Option<Phase> {
        Phase::ALL.into_iter().find(|p| p.name() == s)
    }
}

/// Shape, rate and acceleration at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeState {
    pub q: [f64; 2],
    pub qd: [f64; 2],
    pub qdd: [f64; 2],
    pub phase: Phase,
}

/// A prescribed shape trajectory over `[0, duration]`.
pub trait ShapePlan {
    /// Phase boundaries `[0, t1, t2, T]` (four instants, non-decreasing).
    fn phase_bounds(&self) -> Vec<f64>;
    /// State at `t` in phase `i` (`t` within that phase's bounds). Phases meet at
    /// rest but their accelerations, and so their torques, may jump at a junction:
    /// this gives each side its own value.
    fn state_in(&self, i: usize, t: f64) -> ShapeState;
    /// State at `t`, in the phase that starts at or before `t`.
    fn state(&self, t: f64) -> ShapeState {
        let b = self.phase_bounds();
        let i = (0..3).find(|&i| t < b[i + 1]).unwrap_or(2);
        self.state_in(i, t)
    }
    fn duration(&self) -> f64 {
        *self.phase_bounds().last().unwrap()
    }
    /// The instants in `(0, T]` where the torque may jump (a long integrator
    /// step must not straddle them): by default the phase junctions and the end.
    fn breaks(&self) -> Vec<f64> {
        self.phase_bounds()[1..].to_vec()
    }
    /// Feed-forward torque at `t` in phase `i`: by default the inverse dynamics along the plan.
    fn torque_in(&self, cat: &Cat, i: usize, t: f64) -> [f64; 2] {
        let s = self.state_in(i, t);
        inverse_dynamics(cat, s.q, s.qd, s.qdd)
    }
    /// The plan turning the body `k` times as far about its spine, where
    /// its form says how (a phased plan: its twist scaled, F1); by default
    /// none. A seed made for the half turn then serves a start that needs
    /// less (`design::mirror`).
    fn turn_scaled(&self, _k: f64) -> Option<Box<dyn ShapePlan>> {
        None
    }
    /// Where the torque steps at `t` inside phase `i` (a peak design's
    /// nodes, `free.torque_jumps`), the state and torque just before it and
    /// at it; by default none. A written schedule carries both as two rows
    /// of one instant.
    fn step_at(&self, _cat: &Cat, _i: usize, _t: f64) -> Option<[(ShapeState, [f64; 2]); 2]> {
        None
    }
}

/// A borrowed plan is the plan (a wrapper such as a mirror image may hold
/// either).
impl<T: ShapePlan + ?Sized> ShapePlan for &T {
    fn phase_bounds(&self) -> Vec<f64> {
        (**self).phase_bounds()
    }
    fn state_in(&self, i: usize, t: f64) -> ShapeState {
        (**self).state_in(i, t)
    }
    fn state(&self, t: f64) -> ShapeState {
        (**self).state(t)
    }
    fn duration(&self) -> f64 {
        (**self).duration()
    }
    fn breaks(&self) -> Vec<f64> {
        (**self).breaks()
    }
    fn torque_in(&self, cat: &Cat, i: usize, t: f64) -> [f64; 2] {
        (**self).torque_in(cat, i, t)
    }
    fn turn_scaled(&self, k: f64) -> Option<Box<dyn ShapePlan>> {
        (**self).turn_scaled(k)
    }
    fn step_at(&self, cat: &Cat, i: usize, t: f64) -> Option<[(ShapeState, [f64; 2]); 2]> {
        (**self).step_at(cat, i, t)
    }
}

/// One row of a torque schedule (SI units; JSON names carry the units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Row {
    #[serde(rename = "t_s")]
    pub t: f64,
    pub phase: Phase,
    #[serde(rename = "q_rad")]
    pub q: [f64; 2],
    #[serde(rename = "qd_rad_s")]
    pub qd: [f64; 2],
    #[serde(rename = "qdd_rad_s2")]
    pub qdd: [f64; 2],
    #[serde(rename = "tau_nm")]
    pub tau: [f64; 2],
}

/// A plan sampled in time with its joint torque: what a user feeds to a
/// simulator or a motor controller.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Schedule {
    pub rows: Vec<Row>,
}

pub const CSV_HEADER: &str =
    "t_s,phase,q1_rad,q2_rad,qd1_rad_s,qd2_rad_s,qdd1_rad_s2,qdd2_rad_s2,tau1_nm,tau2_nm";

impl Schedule {
    /// Samples `per_phase` intervals in each phase, both ends included: a
    /// junction instant appears twice, once as the end of a phase and once as
    /// the start of the next, so that a torque jump there is kept exactly.
    pub fn sample(cat: &Cat, plan: &dyn ShapePlan, per_phase: usize) -> Schedule {
        let b = plan.phase_bounds();
        let breaks = plan.breaks();
        let mut rows = Vec::with_capacity(3 * per_phase + 1);
        let row = |s: ShapeState, tau: [f64; 2], t: f64| Row {
            t,
            phase: s.phase,
            q: s.q,
            qd: s.qd,
            qdd: s.qdd,
            tau,
        };
        for i in 0..3 {
            // inside the phase the instants where the torque steps, two
            // rows each (just before, and at it)
            let steps: Vec<_> = breaks
                .iter()
                .filter(|&&t| t > b[i] && t < b[i + 1])
                .filter_map(|&t| plan.step_at(cat, i, t).map(|sides| (t, sides)))
                .collect();
            // a regular sample on a step (to rounding: the two are computed
            // apart, and the CSV prints nine decimals) gives way to the step
            let near = (1e-6 * (b[i + 1] - b[i])).max(1e-8);
            let mut phase: Vec<Row> = (0..=per_phase)
                .map(|k| {
                    // the phase's end is the next one's start to the bit, so
                    // the junction's two rows read back as one instant
                    if k == per_phase {
                        b[i + 1]
                    } else {
                        b[i] + (b[i + 1] - b[i]) * k as f64 / per_phase as f64
                    }
                })
                .filter(|t| steps.iter().all(|(s, _)| (t - s).abs() > near))
                .map(|t| row(plan.state_in(i, t), plan.torque_in(cat, i, t), t))
                .collect();
            phase.extend(
                steps
                    .iter()
                    .flat_map(|&(t, sides)| sides.map(|(s, tau)| row(s, tau, t))),
            );
            // (stable: a step's two rows keep their order)
            phase.sort_by(|x, y| x.t.total_cmp(&y.t));
            rows.extend(phase);
        }
        Schedule { rows }
    }

    pub fn peak(&self, norm: TorqueNorm) -> f64 {
        self.rows.iter().map(|r| norm.of(r.tau)).fold(0.0, f64::max)
    }

    /// `integral |tau|^2 dt` over the rows (trapezoid; a junction's two rows
    /// bound a zero-length interval), N^2 m^2 s: the energy objective.
    pub fn torque_squared_integral(&self) -> f64 {
        self.rows
            .windows(2)
            .map(|w| {
                let sq = |r: &Row| r.tau[0] * r.tau[0] + r.tau[1] * r.tau[1];
                0.5 * (w[1].t - w[0].t) * (sq(&w[0]) + sq(&w[1]))
            })
            .sum()
    }

    /// The schedule as JSON: `{"rows": [{"t_s", "phase", "q_rad", "qd_rad_s",
    /// "qdd_rad_s2", "tau_nm"}, ...]}`, the same rows as the CSV.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("a schedule serialises")
    }

    /// Adds `<stem>.csv` and `<stem>.schedule.json` to an output.
    pub fn add_to(&self, out: &mut crate::output::Output, stem: &str) {
        out.add(format!("{stem}.csv"), self.to_csv());
        out.add(format!("{stem}.schedule.json"), self.to_json());
    }

    pub fn to_csv(&self) -> String {
        let mut s = String::from(CSV_HEADER);
        s.push('\n');
        for r in &self.rows {
            s.push_str(&format!(
                "{:.9},{},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e}\n",
                r.t,
                r.phase.name(),
                r.q[0],
                r.q[1],
                r.qd[0],
                r.qd[1],
                r.qdd[0],
                r.qdd[1],
                r.tau[0],
                r.tau[1]
            ));
        }
        s
    }

    /// Parses a schedule CSV written by [`Schedule::to_csv`] (columns by header name).
    pub fn from_csv(text: &str, origin: &str) -> Result<Schedule> {
        let bad = |line: usize, msg: String| Error::Schedule {
            file: origin.to_string(),
            line,
            message: msg,
        };
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines
            .next()
            .ok_or_else(|| bad(1, "empty file; expected a header line".into()))?;
        if header.trim_start().starts_with(['{', '[']) {
            return Self::from_json(text, origin);
        }
        let cols: Vec<&str> = header.split(',').map(str::trim).collect();
        let want = [
            "t_s",
            "phase",
            "q1_rad",
            "q2_rad",
            "qd1_rad_s",
            "qd2_rad_s",
            "tau1_nm",
            "tau2_nm",
        ];
        let mut idx = [0usize; 8];
        for (k, w) in want.iter().enumerate() {
            idx[k] = cols.iter().position(|c| c == w).ok_or_else(|| {
                bad(
                    1,
                    format!("missing column `{w}`; a schedule needs the columns of `{CSV_HEADER}`"),
                )
            })?;
        }
        let qdd_idx = [
            cols.iter().position(|c| *c == "qdd1_rad_s2"),
            cols.iter().position(|c| *c == "qdd2_rad_s2"),
        ];
        let mut rows: Vec<Row> = Vec::new();
        let mut last_line = 1;
        for (n, line) in lines {
            last_line = n + 1;
            let f: Vec<&str> = line.split(',').map(str::trim).collect();
            let num = |i: usize| -> Result<f64> {
                let v = f
                    .get(i)
                    .ok_or_else(|| bad(n + 1, format!("only {} fields", f.len())))?;
                let x: f64 = v.parse().map_err(|_| {
                    bad(
                        n + 1,
                        format!("`{v}` is not a number (column `{}`)", cols[i]),
                    )
                })?;
                if !x.is_finite() {
                    return Err(bad(
                        n + 1,
                        format!("non-finite value in column `{}`", cols[i]),
                    ));
                }
                Ok(x)
            };
            let ph = f.get(idx[1]).copied().unwrap_or("");
            let phase = Phase::parse(ph).ok_or_else(|| {
                bad(
                    n + 1,
                    format!("unknown phase `{ph}`; use fold, twist or unfold"),
                )
            })?;
            let qdd = match qdd_idx {
                [Some(a), Some(b)] => [num(a)?, num(b)?],
                _ => [f64::NAN; 2],
            };
            let mut t = num(idx[0])?;
            // a phase that begins a rounding before the last one's end (files
            // written before the junction's two rows were the same instant)
            if let Some(p) = rows.last()
                && phase > p.phase
                && t < p.t
                && p.t - t <= 1e-12 * p.t.abs().max(1.0)
            {
                t = p.t;
            }
            let row = Row {
                t,
                phase,
                q: [num(idx[2])?, num(idx[3])?],
                qd: [num(idx[4])?, num(idx[5])?],
                qdd,
                tau: [num(idx[6])?, num(idx[7])?],
            };
            if let Some(prev) = rows.last() {
                let p: &Row = prev;
                // a phase does not end on a step (its instant twice): its
                // last interval would have no length
                if row.phase > p.phase && ends_on_a_step(&rows) {
                    return Err(bad(
                        n,
                        format!(
                            "phase {} ends with its last time {} twice: a repeated instant inside a phase is a torque step, and a row of the phase must follow it",
                            p.phase.name(),
                            p.t
                        ),
                    ));
                }
                // an instant repeats where a phase begins, or once where the
                // torque steps inside a phase
                let twice = rows.len() >= 2 && rows[rows.len() - 2].t == p.t;
                let ok = row.t > p.t || (row.t == p.t && (row.phase > p.phase || !twice));
                if !ok || row.phase < p.phase {
                    return Err(bad(
                        n + 1,
                        format!(
                            "time {} / phase {} after time {} / phase {}: times must increase, repeating only where a phase begins or, once, where the torque steps, and phases must come in the order fold, twist, unfold",
                            row.t,
                            row.phase.name(),
                            p.t,
                            p.phase.name()
                        ),
                    ));
                }
            }
            rows.push(row);
        }
        if ends_on_a_step(&rows) {
            return Err(bad(
                last_line,
                "the last phase ends with its last time twice: a repeated instant inside a phase is a torque step, and a row of the phase must follow it".into(),
            ));
        }
        let sched = Schedule { rows };
        for p in Phase::ALL {
            let n = sched.phase_range(p).len();
            if n < 2 {
                return Err(bad(
                    last_line,
                    format!(
                        "phase {} has {n} row{} where each phase needs at least two (its start and its end): is the file cut short?",
                        p.name(),
                        if n == 1 { "" } else { "s" }
                    ),
                ));
            }
        }
        Ok(sched)
    }

    /// Parses a schedule JSON written by [`Schedule::to_json`] (the same rows
    /// as the CSV, `qdd_rad_s2` optional), checked as the CSV is. JSON is one
    /// line: an error names the row.
    pub fn from_json(text: &str, origin: &str) -> Result<Schedule> {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct JsonSchedule {
            rows: Vec<JsonRow>,
        }
        #[derive(serde::Deserialize)]
        struct JsonRow {
            t_s: f64,
            phase: String,
            q_rad: [f64; 2],
            qd_rad_s: [f64; 2],
            qdd_rad_s2: Option<[f64; 2]>,
            tau_nm: [f64; 2],
        }
        const HINT: &str = "(read as a schedule JSON; the CSV catflip writes beside it, e.g. `free.csv` for `free.schedule.json`, holds the same rows)";
        let js: JsonSchedule = serde_json::from_str(text).map_err(|e| Error::Schedule {
            file: origin.to_string(),
            line: e.line(),
            message: format!("{e} {HINT}"),
        })?;
        // written as the CSV and read by its one checker
        let qdd = js.rows.iter().all(|r| r.qdd_rad_s2.is_some());
        let mut csv = String::from(if qdd {
            CSV_HEADER
        } else {
            "t_s,phase,q1_rad,q2_rad,qd1_rad_s,qd2_rad_s,tau1_nm,tau2_nm"
        });
        csv.push('\n');
        for r in &js.rows {
            let mut cells = vec![
                r.t_s.to_string(),
                r.phase.replace([',', '\n'], " "),
                r.q_rad[0].to_string(),
                r.q_rad[1].to_string(),
                r.qd_rad_s[0].to_string(),
                r.qd_rad_s[1].to_string(),
            ];
            if let (true, Some(a)) = (qdd, r.qdd_rad_s2) {
                cells.extend([a[0].to_string(), a[1].to_string()]);
            }
            cells.extend([r.tau_nm[0].to_string(), r.tau_nm[1].to_string()]);
            csv.push_str(&cells.join(","));
            csv.push('\n');
        }
        Self::from_csv(&csv, origin).map_err(|e| match e {
            Error::Schedule {
                file,
                line,
                message,
            } => Error::Schedule {
                file,
                line: 1,
                message: if line > 1 {
                    format!("row {} of `rows`: {message} {HINT}", line - 2)
                } else {
                    format!("{message} {HINT}")
                },
            },
            e => e,
        })
    }

    /// Rows of one phase (phases are stored in order).
    fn phase_range(&self, p: Phase) -> std::ops::Range<usize> {
        self.rows.partition_point(|r| r.phase < p)..self.rows.partition_point(|r| r.phase <= p)
    }

    /// Interval `k` (rows `k`, `k + 1` of phase `i`) holding `t`, and `t` clamped to it.
    fn locate(&self, i: usize, t: f64) -> (usize, f64) {
        let r = self.phase_range(Phase::ALL[i]);
        let rows = &self.rows[r.clone()];
        let n = rows.len();
        let k = rows
            .partition_point(|x| x.t <= t)
            .saturating_sub(1)
            .min(n - 2);
        (r.start + k, t.clamp(rows[k].t, rows[k + 1].t))
    }
}

/// Whether the last two rows are one instant of one phase (a torque step
/// with nothing after it in its phase).
fn ends_on_a_step(rows: &[Row]) -> bool {
    matches!(rows, [.., a, b] if a.t == b.t && a.phase == b.phase)
}

/// A sampled schedule is itself a plan: cubic Hermite in `q` (from `q`, `q_dot`),
/// linear in the recorded torque, which is the feed-forward.
impl ShapePlan for Schedule {
    /// The phase junctions, the end, and the instants where the torque
    /// steps inside a phase (two rows of one time).
    fn breaks(&self) -> Vec<f64> {
        let mut out: Vec<f64> = self
            .rows
            .windows(2)
            .filter(|w| w[0].t == w[1].t && w[0].phase == w[1].phase)
            .map(|w| w[0].t)
            .collect();
        out.extend(&self.phase_bounds()[1..]);
        out.sort_by(f64::total_cmp);
        out
    }

    fn phase_bounds(&self) -> Vec<f64> {
        let mut b = vec![self.rows[0].t];
        for p in [Phase::Twist, Phase::Unfold] {
            b.push(self.rows[self.phase_range(p).start].t);
        }
        b.push(self.rows.last().unwrap().t);
        b
    }

    fn state_in(&self, i: usize, t: f64) -> ShapeState {
        let (k, t) = self.locate(i, t);
        let (a, b) = (&self.rows[k], &self.rows[k + 1]);
        let h = b.t - a.t;
        let x = (t - a.t) / h;
        let (h00, h10, h01, h11) = (
            2.0 * x * x * x - 3.0 * x * x + 1.0,
            x * x * x - 2.0 * x * x + x,
            -2.0 * x * x * x + 3.0 * x * x,
            x * x * x - x * x,
        );
        let (d00, d10, d01, d11) = (
            6.0 * x * x - 6.0 * x,
            3.0 * x * x - 4.0 * x + 1.0,
            -6.0 * x * x + 6.0 * x,
            3.0 * x * x - 2.0 * x,
        );
        let (s00, s10, s01, s11) = (
            12.0 * x - 6.0,
            6.0 * x - 4.0,
            -12.0 * x + 6.0,
            6.0 * x - 2.0,
        );
        let mut st = ShapeState {
            q: [0.0; 2],
            qd: [0.0; 2],
            qdd: [0.0; 2],
            phase: a.phase,
        };
        for j in 0..2 {
            st.q[j] = h00 * a.q[j] + h10 * h * a.qd[j] + h01 * b.q[j] + h11 * h * b.qd[j];
            st.qd[j] = (d00 * a.q[j] + d10 * h * a.qd[j] + d01 * b.q[j] + d11 * h * b.qd[j]) / h;
            st.qdd[j] =
                (s00 * a.q[j] + s10 * h * a.qd[j] + s01 * b.q[j] + s11 * h * b.qd[j]) / (h * h);
        }
        st
    }

    fn torque_in(&self, _cat: &Cat, i: usize, t: f64) -> [f64; 2] {
        let (k, t) = self.locate(i, t);
        let (a, b) = (&self.rows[k], &self.rows[k + 1]);
        let x = (t - a.t) / (b.t - a.t);
        [
            a.tau[0] + x * (b.tau[0] - a.tau[0]),
            a.tau[1] + x * (b.tau[1] - a.tau[1]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    /// The seed's analytic schedule as catflip writes it.
    fn written() -> String {
        let spec = crate::test_support::spec_of(
            &std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml"))
                .unwrap(),
            "seed.toml",
            &[],
        );
        let plan = crate::design::analytic::analytic_plan(&spec);
        Schedule::sample(&spec.cat, &plan, 20).to_csv()
    }

    fn message(text: &str) -> (usize, String) {
        match Schedule::from_csv(text, "s.csv") {
            Err(Error::Schedule { line, message, .. }) => (line, message),
            other => panic!("expected a schedule error, got {other:?}"),
        }
    }

    #[test]
    fn a_schedule_cut_short_is_named_at_its_last_line() {
        let full = written();
        assert!(Schedule::from_csv(&full, "s.csv").is_ok());
        // cut inside the twist: unfold has no rows
        let lines: Vec<&str> = full.lines().collect();
        let twist = lines.iter().position(|l| l.contains(",twist,")).unwrap();
        let cut = lines[..twist + 3].join("\n");
        let (line, msg) = message(&cut);
        assert_eq!(line, twist + 3, "{msg}");
        assert!(
            msg.contains("phase unfold has 0 rows") && msg.contains("cut short"),
            "{msg}"
        );
    }

    /// An instant may repeat once inside a phase (a torque step), but a
    /// phase may not end on one (its last interval would have no length:
    /// the state read there was NaN), nor hold it three times.
    #[test]
    fn a_torque_step_is_an_instant_twice_inside_a_phase_never_at_its_end() {
        let full = written();
        let lines: Vec<&str> = full.lines().collect();
        let with = |i: usize| {
            let mut l = lines.clone();
            l.insert(i, lines[i]);
            l.join("\n")
        };
        // a step in the twist's middle reads back, its instant a break
        let twist = lines.iter().position(|l| l.contains(",twist,")).unwrap();
        let s = Schedule::from_csv(&with(twist + 5), "s.csv").unwrap();
        let t: f64 = lines[twist + 5].split(',').next().unwrap().parse().unwrap();
        assert!(s.breaks().contains(&t));
        // three times is refused
        let mut thrice = lines.clone();
        thrice.insert(twist + 5, lines[twist + 5]);
        thrice.insert(twist + 5, lines[twist + 5]);
        assert!(
            message(&thrice.join("\n"))
                .1
                .contains("times must increase")
        );
        // the fold's last row twice, and the file's last row twice
        let (_, msg) = message(&with(twist - 1));
        assert!(msg.contains("phase fold ends with its last time"), "{msg}");
        let (_, msg) = message(&with(lines.len() - 1));
        assert!(
            msg.contains("the last phase ends with its last time twice"),
            "{msg}"
        );
    }

    /// A straight cat held still over phases with awkward bounds: in floating
    /// point `t1 + (t2 - t1)` is not `t2` for these.
    struct Still(Vec<f64>);

    impl ShapePlan for Still {
        fn phase_bounds(&self) -> Vec<f64> {
            self.0.clone()
        }
        fn state_in(&self, i: usize, _t: f64) -> ShapeState {
            ShapeState {
                q: [0.0; 2],
                qd: [0.0; 2],
                qdd: [0.0; 2],
                phase: Phase::ALL[i],
            }
        }
    }

    #[test]
    fn a_schedules_junction_rows_are_one_instant_and_its_json_reads_back() {
        let b = vec![0.0, 0.16134679851370037, 0.5192466093788269, 0.7];
        assert_ne!(b[1] + (b[2] - b[1]) * 7.0 / 7.0, b[2], "bounds that round");
        let spec = crate::test_support::spec_of(
            &std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/configs/seed.toml"))
                .unwrap(),
            "seed.toml",
            &[],
        );
        let s = Schedule::sample(&spec.cat, &Still(b.clone()), 7);
        for w in s.rows.windows(2).filter(|w| w[0].phase != w[1].phase) {
            assert_eq!(w[0].t.to_bits(), w[1].t.to_bits(), "{:?}", w);
        }
        let back = Schedule::from_json(&s.to_json(), "s.schedule.json").unwrap();
        assert_eq!(back.rows, s.rows);
        // a file whose next phase begins a rounding early (as written before)
        // reads as one instant; a real step back in time is still refused
        let early = s.to_json().replacen(
            "\"t_s\":0.5192466093788269,\"phase\":\"unfold\"",
            "\"t_s\":0.5192466093788268,\"phase\":\"unfold\"",
            1,
        );
        assert_ne!(early, s.to_json());
        let back = Schedule::from_json(&early, "s.schedule.json").unwrap();
        assert_eq!(back.rows, s.rows);
        let back_in_time = s.to_json().replacen(
            "\"t_s\":0.5192466093788269,\"phase\":\"unfold\"",
            "\"t_s\":0.5192,\"phase\":\"unfold\"",
            1,
        );
        assert!(Schedule::from_json(&back_in_time, "s.schedule.json").is_err());
    }

    #[test]
    fn a_json_schedule_is_pointed_at_its_csv() {
        let (line, msg) = message("{\"rows\": []}\n");
        assert_eq!(line, 1);
        assert!(msg.contains("JSON") && msg.contains("free.csv"), "{msg}");
    }
}
