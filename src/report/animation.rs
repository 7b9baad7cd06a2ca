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
    /// The method's status line of the summary table (flags included).
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
    pub norm: String,
    pub max_torque_nm: Option<f64>,
    pub tracks: Vec<Track>,
}

fn quat(r: &Rotation3<f64>) -> [f64; 4] {
    let q = UnitQuaternion::from_rotation_matrix(r);
    [q.w, q.i, q.j, q.k]
}

/// Picks about `count` trace points evenly spread in time (the simulation's
/// adaptive steps are uneven) and adds body B's attitude `R_A R_rel(q)`.
pub fn track(
    cat: &Cat,
    norm: TorqueNorm,
    name: &str,
    status: &str,
    sim: &SimReport,
    count: usize,
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
                a: p.attitude,
                b: quat(&(ra * rel)),
                flip_deg: p.flip.to_degrees(),
                bend_deg: p.q[0].hypot(p.q[1]).to_degrees(),
                tau_nm: norm.of(p.tau),
            }
        })
        .collect();
    Track {
        name: name.into(),
        status: status.into(),
        frames,
    }
}

/// JSON that is safe inside a `<script>` element.
fn script_json(scene: &Scene) -> String {
    serde_json::to_string(scene)
        .expect("scene serialises")
        .replace("</", "<\\/")
}

/// The animation section of `index.html`: canvases, controls, readouts and
/// the inline player. Open the page with `#selftest` and the player checks
/// itself and writes the result into `<pre id="selftest">`.
pub fn section(scene: &Scene) -> String {
    format!(
        "<section id=\"animation\">\n<h2>The flip, animated</h2>\n\
<p>Forward simulation of each schedule: both halves at true size, in the frame of the common \
centre of mass. Drag a view to turn the camera. The stubs mark the belly (the cat starts upside \
down, belly up); the dashed line is the initial spine.</p>\n\
<div class=\"controls\"><button id=\"play\" type=\"button\">play</button>\n\
<label>time <input id=\"time\" type=\"range\" min=\"0\" max=\"1000\" value=\"0\"></label>\n\
<span id=\"clock\">t = 0.000 s</span>\n\
<label>speed <select id=\"speed\"><option value=\"0.05\">0.05x</option><option value=\"0.1\">0.1x</option>\
<option value=\"0.25\" selected>0.25x</option><option value=\"0.5\">0.5x</option><option value=\"1\">1x (real time)</option></select></label>\n\
<button id=\"reset-view\" type=\"button\">reset view</button></div>\n\
<div id=\"views\"></div>\n\
<pre id=\"selftest\" hidden></pre>\n<pre id=\"errors\"></pre>\n\
<script>window.catflipErrors = []; window.addEventListener('error', e => {{ catflipErrors.push(String(e.message)); \
document.getElementById('errors').textContent = 'script error: ' + catflipErrors.join('; '); }});</script>\n\
<script type=\"application/json\" id=\"scene\">{}</script>\n\
<script>\n{}</script>\n</section>\n",
        script_json(scene),
        include_str!("player.js")
    )
}
