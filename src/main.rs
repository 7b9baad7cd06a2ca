//! The `catflip` command line: a thin layer over the library.
//!
//! Exit status: 0 every result meets its targets; 1 the computation failed;
//! 2 bad input (config, arguments, files, output folder), nothing computed or
//! written; 3 partial: results written, but some are flagged or failed (the
//! seed's analytic schedule beyond the motor limits, a reference, excepted);
//! 4 impossible: the motors cannot flip the cat from the configured height
//! (`run`: the least drop height and its schedule are written; a design
//! command: the error names the height that would do); 130 interrupted
//! (a sweep or a robustness study publishes what it finished as a partial set;
//! any other command removes what it had not published).
mod cli;
mod common;
mod recovery_cli;
mod robustness;
mod size_cli;

fn main() -> std::process::ExitCode {
    match cli::run() {
        Ok(common::Status::Ok) => std::process::ExitCode::SUCCESS,
        Ok(common::Status::Partial) => std::process::ExitCode::from(3),
        Ok(common::Status::Impossible) => std::process::ExitCode::from(4),
        Ok(common::Status::Interrupted) => {
            std::process::ExitCode::from(catflip::interrupt::EXIT_INTERRUPTED)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::from(match e.downcast_ref::<catflip::Error>() {
                Some(e) if e.is_bad_input() => 2,
                Some(e) if e.is_beyond_motors() => 4,
                _ => 1,
            })
        }
    }
}
