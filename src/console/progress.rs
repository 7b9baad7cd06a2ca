//! Progress on stderr while a command works: `run`'s stage lines (with live
//! iteration counters on a terminal) and `optimize --verbose`'s iteration
//! tables.

use super::table::maybe;
use crate::design::free::Observer;
use crate::design::phased::BendEvaluation;
use crate::design::scp::ScpIteration;
use crate::run::Progress;
use std::io::{IsTerminal, Write};

/// Stage lines on stderr; live iteration counters when stderr is a
/// terminal; nothing when `quiet` (`--json`).
pub fn stages(quiet: bool) -> impl FnMut(Progress) {
    let live = std::io::stderr().is_terminal() && !quiet;
    move |p| {
        if quiet {
            return;
        }
        let mut e = std::io::stderr();
        match p {
            Progress::Stage { index, total, name } => {
                let _ = write!(e, "[{index}/{total}] {name} ...");
                if live {
                    let _ = writeln!(e);
                }
            }
            Progress::StageDone { seconds } => {
                if live {
                    let _ = write!(e, "\r\x1b[2K");
                }
                let _ = writeln!(e, " done in {seconds:.2} s");
            }
            Progress::StageFailed { seconds, reason } => {
                if live {
                    let _ = write!(e, "\r\x1b[2K");
                }
                let _ = writeln!(e, " FAILED after {seconds:.2} s: {reason}");
            }
            Progress::StageSkipped { reason } => {
                if live {
                    let _ = write!(e, "\r\x1b[2K");
                }
                let _ = writeln!(e, " not attempted: {reason}");
            }
            Progress::Bend {
                evaluations,
                bend_deg,
                peak_nm,
            } if live => {
                let _ = write!(
                    e,
                    "\r\x1b[2K      bend evaluation {evaluations:3}: {bend_deg:7.2} deg -> {} N m",
                    maybe(peak_nm, 5)
                );
            }
            Progress::Scp(it) if live => {
                let _ = write!(
                    e,
                    "\r\x1b[2K      SCP iteration {:3}: peak {:.5} N m, max |r| {:.1e}, radius {:.1e}",
                    it.iteration, it.objective, it.infeasibility, it.radius
                );
            }
            _ => {}
        }
        let _ = e.flush();
    }
}

/// `optimize --mode phased --verbose`: one line per bend evaluated.
pub fn bend_line(e: &BendEvaluation) -> String {
    format!(
        "  bend {:8.3} deg   unit peak {:>10} N m s^2   peak {:>9} N m",
        e.bend_deg,
        maybe(e.unit_peak, 5),
        maybe(e.peak_nm, 5)
    )
}

/// `optimize --mode free --verbose`'s header above [`IterationTable`]'s lines.
pub fn iteration_header(objective: &str) -> String {
    format!("  iter      merit {objective:>10}     infeas     radius        rho  step   ms")
}

/// `--verbose`: one line per SCP iteration on stderr under
/// [`iteration_header`], and a line where each mesh begins (mesh
/// continuation: the trust radius starts again there, but inside the motor
/// envelope, where the fine mesh carries the coarse one's radius and
/// penalty weight).
pub struct IterationTable {
    verbose: bool,
    /// The header, until the first line is printed under it (after the
    /// notes on how the start was found).
    header: Option<String>,
}

impl IterationTable {
    /// The table of a design of `objective` (its short name), printed only
    /// when `verbose`.
    pub fn new(verbose: bool, objective: &str) -> Self {
        IterationTable {
            verbose,
            header: verbose.then(|| iteration_header(objective)),
        }
    }

    fn print_header(&mut self) {
        if let Some(h) = self.header.take() {
            eprintln!("{h}");
        }
    }
}

impl Observer for IterationTable {
    fn iteration(&mut self, it: &ScpIteration) {
        if self.verbose {
            self.print_header();
            eprintln!(
                "  {:4} {:10.5} {:10.5} {:10.2e} {:10.2e} {:10.3} {:>5} {:5.1}",
                it.iteration,
                it.merit,
                it.objective,
                it.infeasibility,
                it.radius,
                it.rho,
                if it.accepted {
                    "ok"
                } else if it.tentative {
                    "try"
                } else {
                    "rej"
                },
                it.solve_ms
            );
        }
    }
    fn mesh(&mut self, nodes: usize) {
        if self.verbose {
            self.print_header();
            eprintln!("  -- {nodes} nodes per phase");
        }
    }
}

/// The progress bar of a long job (`sweep`, `recovery`, `robustness`):
/// `what [####....] done/total units, elapsed, ETA` (the time left from the
/// mean time per unit so far).
pub fn bar(what: &str, done: usize, total: usize, units: &str, elapsed: f64) -> String {
    let width = 24;
    let filled = (width * done.min(total)) / total.max(1);
    let eta = if done > 0 {
        elapsed / done as f64 * total.saturating_sub(done) as f64
    } else {
        f64::NAN
    };
    let eta = if eta.is_finite() {
        format!("ETA {eta:.0} s")
    } else {
        "ETA -".into()
    };
    format!(
        "{what} [{}{}] {done}/{total} {units}, {elapsed:.0} s, {eta}",
        "#".repeat(filled),
        ".".repeat(width - filled)
    )
}
