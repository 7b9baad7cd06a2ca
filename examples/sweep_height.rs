//! Sweep the drop height with the library and print the least peak torque of
//! each method (F3: it falls as 1 / height).
//! `cargo run --release --example sweep_height [-- configs/seed.toml]`
use catflip::sweep::{Methods, SweepSpec, sweep};

fn main() -> anyhow::Result<()> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "configs/seed.toml".into());
    let spec: SweepSpec = "fall.height=1:10:5".parse()?;
    let methods = Methods::ALL;
    let points = sweep(
        std::path::Path::new(&path),
        &[],
        &spec,
        methods,
        2,
        |_, _| {},
    )?;
    println!(
        "{:>10} {:>12} {:>12} {:>12}",
        "height m", "analytic", "phased", "free"
    );
    for p in points {
        let f = |x: Option<f64>| x.map(|v| format!("{v:.5}")).unwrap_or_default();
        println!(
            "{:>10.2} {:>12} {:>12} {:>12}",
            p.value,
            f(p.analytic_peak_nm),
            f(p.phased_peak_nm),
            f(p.free_peak_nm)
        );
    }
    Ok(())
}
