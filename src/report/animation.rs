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
/// adaptive steps are uneven) and adds body B's attitude `R_A R_rel(q)`.
pub fn track(cat: &Cat, norm: TorqueNorm, name: &str, sim: &SimReport, count: usize) -> Track {
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
    let frames = picked
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
    Track {
        name: name.into(),
        status: String::new(),
        frames,
    }
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
