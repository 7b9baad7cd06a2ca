//! catflip's joint torque along a smooth shape schedule, for MuJoCo's inverse
//! dynamics of the same model to check (examples/inverse_dynamics_mujoco.py,
//! run by .ci/run): for each body, its MJCF and URDF as catflip exports them
//! and `<name>.csv` with `t, q1, q2, qd1, qd2, qdd1, qdd2, tau1, tau2`.
//! The bodies: the bundled box robot (configs/box-robot.urdf, whose own file
//! the check also loads) and a lopsided body with products of inertia, off-axis
//! centres of mass and tilted motor axes (tests/it/import.rs). Universal joints.
//! `cargo run --release --example inverse_dynamics -- OUT_DIR`
use catflip::Config;
use catflip::model::dynamics::inverse_dynamics;
use std::path::Path;

/// The lopsided body's config: the `[body]` keys tests/it/import.rs uses.
fn lopsided() -> String {
    format!(
        "name = \"lopsided\"\n[cat]\njoint = \"universal\"\n[fall]\nheight = 10.0\n{}",
        include_str!("../tests/data/lopsided-body.toml")
    )
}

fn main() -> anyhow::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "target/ci-id".into());
    let out = Path::new(&out);
    std::fs::create_dir_all(out)?;
    let bodies = [
        (
            "box-robot",
            Config::load(Path::new("configs/box-robot.toml"), &[])?,
        ),
        ("lopsided", Config::from_toml(&lopsided(), "lopsided", &[])?),
    ];
    for (name, cfg) in bodies {
        let cat = cfg.cat();
        std::fs::write(
            out.join(format!("{name}.mjcf.xml")),
            catflip::export::mjcf(&cfg),
        )?;
        std::fs::write(
            out.join(format!("{name}.urdf")),
            catflip::export::urdf(&cfg),
        )?;
        // a smooth schedule through large, unsymmetric shapes
        let mut csv = String::from("t,q1,q2,qd1,qd2,qdd1,qdd2,tau1,tau2\n");
        let (w1, w2) = (2.0 * std::f64::consts::PI, 3.0 * std::f64::consts::PI);
        for k in 0..=60 {
            let t = k as f64 / 60.0;
            let q = [
                0.3 + 0.9 * (w1 * t).sin(),
                -0.2 + 0.7 * (w2 * t + 0.4).sin(),
            ];
            let qd = [0.9 * w1 * (w1 * t).cos(), 0.7 * w2 * (w2 * t + 0.4).cos()];
            let qdd = [
                -0.9 * w1 * w1 * (w1 * t).sin(),
                -0.7 * w2 * w2 * (w2 * t + 0.4).sin(),
            ];
            let tau = inverse_dynamics(&cat, q, qd, qdd);
            let row = [t, q[0], q[1], qd[0], qd[1], qdd[0], qdd[1], tau[0], tau[1]];
            let cells: Vec<String> = row.iter().map(|x| format!("{x:e}")).collect();
            csv.push_str(&cells.join(","));
            csv.push('\n');
        }
        std::fs::write(out.join(format!("{name}.csv")), csv)?;
        println!("wrote {name}: {}", out.display());
    }
    Ok(())
}
