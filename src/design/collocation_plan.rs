//! The solved transcription as a shape plan: the collocation scheme's own
//! interpolation between nodes, and the attitude track that brings the
//! momentum into the feed-forward torque from a spinning start. Apart from
//! `collocation` so that the transcription does not depend on the release
//! (`release` builds on `collocation`).

use crate::design::collocation::Transcription;
use crate::design::plan::{Phase, ShapePlan, ShapeState};
use crate::design::release::Track;

/// A transcribed solution as a plan, with the scheme's interpolation.
#[derive(Debug, Clone)]
pub struct CollocationPlan {
    pub tr: Transcription,
    pub z: Vec<f64>,
    /// From a start with angular momentum: the attitude along the plan, whose
    /// momentum enters the feed-forward torque (docs/model.md section 8).
    pub track: Option<Track>,
}

impl CollocationPlan {
    /// A plan at zero momentum.
    pub fn new(tr: Transcription, z: Vec<f64>) -> Self {
        CollocationPlan { tr, z, track: None }
    }
}

impl CollocationPlan {
    /// The state at fraction `c` of interval `k` of phase `i`, the phase
    /// lasting `dur` s (its rates in physical time).
    fn on_interval(&self, i: usize, k: usize, c: f64, dur: f64) -> ShapeState {
        let it = self.tr.interval(&self.z, i, k).at(c);
        ShapeState {
            q: it.q,
            qd: it.v.map(|x| x / dur),
            qdd: it.a.map(|x| x / (dur * dur)),
            phase: Phase::ALL[i.min(2)],
        }
    }
}

impl ShapePlan for CollocationPlan {
    fn phase_bounds(&self) -> Vec<f64> {
        let mut b = vec![0.0];
        for p in 0..self.tr.phases {
            b.push(b[p] + self.z[self.tr.duration(p)]);
        }
        b
    }

    /// The nodes too: a plan one SCP iteration from its start leaves its
    /// accelerations, so its torques, jumping a little at the nodes.
    fn breaks(&self) -> Vec<f64> {
        let b = self.phase_bounds();
        let h = self.tr.h();
        let mut out = Vec::new();
        for i in 0..self.tr.phases {
            let dur = b[i + 1] - b[i];
            out.extend((1..self.tr.nodes - 1).map(|k| b[i] + k as f64 * h * dur));
            out.push(b[i + 1]);
        }
        out
    }

    fn state_in(&self, i: usize, t: f64) -> ShapeState {
        let b = self.phase_bounds();
        let dur = b[i + 1] - b[i];
        let s = ((t - b[i]) / dur).clamp(0.0, 1.0);
        let h = self.tr.h();
        let k = ((s / h).floor() as usize).min(self.tr.nodes - 2);
        let c = ((s - k as f64 * h) / h).clamp(0.0, 1.0);
        self.on_interval(i, k, c, dur)
    }

    /// At an interior node of a grid whose acceleration jumps there
    /// ([`Transcription::with_jumps`], never from a spinning start) the end
    /// of the interval before it and the start of the one after.
    fn step_at(
        &self,
        cat: &crate::model::Cat,
        i: usize,
        t: f64,
    ) -> Option<[(ShapeState, [f64; 2]); 2]> {
        if !self.tr.jumps || self.track.is_some() {
            return None;
        }
        let b = self.phase_bounds();
        let dur = b[i + 1] - b[i];
        if dur.is_nan() || dur <= 0.0 {
            return None;
        }
        let s = (t - b[i]) / dur;
        let h = self.tr.h();
        let k = (s / h).round();
        if (s - k * h).abs() > 1e-9 * h || k < 1.0 || k > (self.tr.nodes - 2) as f64 {
            return None;
        }
        let side = |interval: usize, c: f64| {
            let st = self.on_interval(i, interval, c, dur);
            (
                st,
                crate::model::dynamics::inverse_dynamics(cat, st.q, st.qd, st.qdd),
            )
        };
        let k = k as usize;
        Some([side(k - 1, 1.0), side(k, 0.0)])
    }

    /// The inverse dynamics along the plan, with the momentum's part
    /// `g(q, q_dot, lambda)` when the plan starts with angular momentum.
    fn torque_in(&self, cat: &crate::model::Cat, i: usize, t: f64) -> [f64; 2] {
        let st = self.state_in(i, t);
        let tau = crate::model::dynamics::inverse_dynamics(cat, st.q, st.qd, st.qdd);
        let Some(track) = &self.track else {
            return tau;
        };
        let b = self.phase_bounds();
        let s = ((t - b[i]) / (b[i + 1] - b[i])).clamp(0.0, 1.0);
        let lam = track.body_momentum(cat, &self.tr, &self.z, i, s);
        let g = crate::model::momentum::momentum_torque(cat, st.q, st.qd, lam);
        [tau[0] + g[0], tau[1] + g[1]]
    }
}
