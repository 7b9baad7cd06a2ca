//! Design a torque schedule with the library: phased optimum, then the
//! free-form optimum seeded by it, verified by simulation and written inside the
//! project, to `output/<name>/example-design/` (CSV and JSON).
//! `cargo run --release --example design [-- configs/domestic-cat.toml]`
use catflip::Config;
use catflip::design::plan::Schedule;

fn main() -> anyhow::Result<()> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "configs/domestic-cat.toml".into());
    let cfg = Config::load(std::path::Path::new(&path), &[])?;
    let phased = catflip::design::phased::optimize(&cfg.design_spec(), |_| {})?;
    println!(
        "phased: peak {:.4} N m at bend {:.1} deg",
        phased.peak_torque_nm, phased.bend_deg
    );
    let free = catflip::design::free::FreeDesign::new(&cfg.design_spec())
        .from_plan(&phased.plan, "phased")
        .on_iteration(&mut |it| {
            println!(
                "  SCP {:3}: peak {:.5} N m, max |r| {:.1e}",
                it.iteration, it.objective, it.infeasibility
            )
        })
        .solve()?;
    println!(
        "free-form: peak {:.4} N m ({:.1} % of phased), simulated flip error {:.1e} rad",
        free.peak_torque_nm,
        100.0 * free.peak_torque_nm / phased.peak_torque_nm,
        catflip::verify::simulate::dynamic_spec(&cfg.design_spec(), &free.plan)?.flip_error_rad
    );
    // inside the project, published like the commands' sets: output/<name>/example-design/
    let mut out = catflip::output::Output::default();
    Schedule::sample(&cfg.cat(), &free.plan, cfg.simulate.samples_per_phase)
        .add_to(&mut out, "free");
    let set = std::path::Path::new("output")
        .join(&cfg.name)
        .join("example-design");
    for f in out.commit(&set)? {
        println!("schedule written to {}", f.display());
    }
    Ok(())
}
