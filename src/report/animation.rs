//! The 3-D animation of the report: frames of the forward simulation of each
//! schedule (the attitude of both halves) embedded as JSON in `index.html`,
//! played by a small self-contained canvas renderer (`player.js`).
//!
//! Frames come from the simulation, not the plan, so the page shows what the
//! verified motion does. The world frame is body A's initial frame; the view
//! follows the common centre of mass (the fall itself is only a readout).

use crate::model::body::Half;
use crate::model::so3::to_na;
use crate::model::{Cat, TorqueNorm};
use crate::verify::simulate::SimReport;
use nalgebra::{Quaternion, Rotation3, UnitQuaternion};
use serde::Serialize;

/// Frames per method: enough for a smooth slider at any speed, small enough
/// to keep the page light (the player interpolates between frames).
pub const FRAMES: usize = 240;

/// One instant of one method's simulation.
#[derive(Debug, Clone, Serialize)]
pub struct Frame {
    pub t: f64,
    /// Body A's and body B's attitude quaternions `[w, x, y, z]`.
    pub a: [f64; 4],
    pub b: [f64; 4],
    /// Rotation about the initial spine (unwrapped), bend `|q|`, degrees.
    pub flip_deg: f64,
    pub bend_deg: f64,
    /// Applied joint torque in the peak norm, N m.
    pub tau_nm: f64,
}

/// One method's animation.
#[derive(Debug, Clone, Serialize)]
pub struct Track {
    pub name: String,
    /// The method's status and verdict from the summary table (set by the run).
    pub status: String,
    pub frames: Vec<Frame>,
}

/// Everything the player needs.
#[derive(Debug, Clone, Serialize)]
pub struct Scene {
    /// The rear half A and the front half B (drawn at true size).
    pub rear: Half,
    pub front: Half,
    pub joint: &'static str,
    /// General halves (`[body]`), drawn as their inertia-equivalent boxes
    /// ([`boxes`]); none: the cylinders `rear` and `front`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub boxes: Option<[BoxView; 2]>,
    pub norm: String,
    pub max_torque_nm: Option<f64>,
    pub tracks: Vec<Track>,
}

/// A general half as the player draws it: the uniform box of its mass and
/// principal moments, centred on its centre of mass.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct BoxView {
    /// From the centre of mass to the joint, in the half's frame, m.
    pub to_joint: [f64; 3],
    /// Edges along the box's own axes, m.
    pub edges: [f64; 3],
    /// The box's axes in the half's frame, `[w, x, y, z]`.
    pub quat: [f64; 4],
}

/// Both halves' boxes, for general halves only.
pub fn boxes(cat: &Cat) -> Option<[BoxView; 2]> {
    let h = cat.general?;
    let view = |r: &crate::model::Rigid| {
        let (_, mut axes) = r.principal();
        if axes.determinant() < 0.0 {
            axes.column_mut(2).neg_mut();
        }
        BoxView {
            to_joint: r.com_to_joint(),
            edges: r.box_edges(),
            quat: quat(&Rotation3::from_matrix_unchecked(axes)),
        }
    };
    Some([view(&h.rear), view(&h.front)])
}

/// Quaternion components to 1e-7 (far below a pixel), which halves the page.
fn short(q: [f64; 4]) -> [f64; 4] {
    q.map(|x| (x * 1e7).round() / 1e7)
}

fn quat(r: &Rotation3<f64>) -> [f64; 4] {
    let q = UnitQuaternion::from_rotation_matrix(r);
    short([q.w, q.i, q.j, q.k])
}

/// Picks about `count` trace points evenly spread in time (the simulation's
/// adaptive steps are uneven) and adds body B's attitude `R_A R_rel(q)`;
/// then the `margin` to touchdown, the cat held in its last shape and
/// turning rigidly with its momentum (F8, the landing error's own model),
/// so that the track ends where the landing is judged.
pub fn track(
    cat: &Cat,
    norm: TorqueNorm,
    name: &str,
    sim: &SimReport,
    (count, margin): (usize, f64),
) -> Track {
    let tr = &sim.trace;
    let mut picked: Vec<usize> = Vec::new();
    if let (Some(first), Some(last)) = (tr.first(), tr.last()) {
        let n = count.max(2) - 1;
        let mut k = 0;
        for i in 0..=n {
            let target = first.t + (last.t - first.t) * i as f64 / n as f64;
            while k + 1 < tr.len() && (tr[k + 1].t - target).abs() <= (tr[k].t - target).abs() {
                k += 1;
            }
            if picked.last() != Some(&k) {
                picked.push(k);
            }
        }
    }
    let mut frames: Vec<Frame> = picked
        .into_iter()
        .map(|k| {
            let p = &tr[k];
            let [w, x, y, z] = p.attitude;
            let ra =
                UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)).to_rotation_matrix();
            let rel = Rotation3::from_matrix_unchecked(to_na(&cat.rel_rotation(p.q)));
            Frame {
                t: p.t,
                a: short(p.attitude),
                b: quat(&(ra * rel)),
                flip_deg: p.flip.to_degrees(),
                bend_deg: p.q[0].hypot(p.q[1]).to_degrees(),
                tau_nm: norm.of(p.tau),
            }
        })
        .collect();
    if let (Some(last), Some(end)) = (tr.last(), frames.last().cloned())
        && margin > 0.0
    {
        frames.extend(touchdown(cat, norm, sim, last.q, &end, (count, margin)));
    }
    Track {
        name: name.into(),
        status: String::new(),
        frames,
    }
}

/// The frames after the manoeuvre's `end` to touchdown, `margin` s on, at
/// the track's frame rate (`count` frames over its manoeuvre): the
/// simulation's own landing flight where it flew one (the shape held
/// straight by the motors), else the straight cat in shape `q` turning
/// rigidly ([`rigid_turn`](crate::model::momentum::rigid_turn), no torque);
/// the flip unwrapped on from `end`'s, the quaternions' signs kept
/// continuous.
fn touchdown(
    cat: &Cat,
    norm: TorqueNorm,
    sim: &SimReport,
    q: [f64; 2],
    end: &Frame,
    (count, margin): (usize, f64),
) -> Vec<Frame> {
    use crate::model::so3::{flip_and_tilt, quat_from, wrap};
    let steps = ((count as f64 * margin / end.t.max(1e-9)).ceil() as usize).clamp(2, count);
    let r0 = *quat_from(&sim.final_attitude).to_rotation_matrix().matrix();
    let held = &sim.landing_trace;
    // (attitude of A, shape, torque) `dt` after the manoeuvre
    let at = |dt: f64| -> (Rotation3<f64>, [f64; 2], [f64; 2]) {
        if let Some(p) = held
            .iter()
            .min_by(|a, b| (a.t - dt).abs().total_cmp(&(b.t - dt).abs()))
        {
            (quat_from(&p.attitude).to_rotation_matrix(), p.q, p.tau)
        } else {
            let r = crate::model::momentum::rigid_turn(cat, &r0, sim.final_body_momentum, dt);
            (Rotation3::from_matrix_unchecked(r), q, [0.0; 2])
        }
    };
    let continuous = |q: [f64; 4], before: [f64; 4]| {
        let dot: f64 = q.iter().zip(before).map(|(a, b)| a * b).sum();
        if dot < 0.0 { q.map(|v| -v) } else { q }
    };
    let mut flip = end.flip_deg.to_radians();
    let mut before = flip_and_tilt(&UnitQuaternion::from_matrix(&r0)).0;
    let (mut last_a, mut last_b) = (end.a, end.b);
    (1..=steps)
        .map(|i| {
            let dt = margin * i as f64 / steps as f64;
            let (ra, shape, tau) = at(dt);
            let rel = Rotation3::from_matrix_unchecked(to_na(&cat.rel_rotation(shape)));
            let f = flip_and_tilt(&UnitQuaternion::from_rotation_matrix(&ra)).0;
            flip += wrap(f - before);
            before = f;
            last_a = continuous(quat(&ra), last_a);
            last_b = continuous(quat(&(ra * rel)), last_b);
            Frame {
                t: end.t + dt,
                a: last_a,
                b: last_b,
                flip_deg: flip.to_degrees(),
                bend_deg: shape[0].hypot(shape[1]).to_degrees(),
                tau_nm: norm.of(tau),
            }
        })
        .collect()
}

/// JSON that is safe inside a `<script>` element.
fn script_json(scene: &Scene) -> String {
    serde_json::to_string(scene)
        .expect("scene serialises")
        .replace("</", "<\\/")
}

/// The animation section of `index.html` (`player.html` with the scene and
/// `player.js` filled in): canvases, controls, readouts and the inline
/// player. Open the page with `#selftest` and the player checks itself and
/// writes the result into `<pre id="selftest">`.
pub fn section(scene: &Scene) -> String {
    include_str!("player.html")
        .replace("{{SCENE}}", &script_json(scene))
        .replace("{{PLAYER}}", include_str!("player.js"))
}
