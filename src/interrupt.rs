//! Long studies (sweeps, Monte Carlo trials) that stop on SIGINT or SIGTERM
//! within a fraction of a second and keep what they finished.
//!
//! A study runs its work on a thread of its own ([`supervise`]) and records
//! each finished item in a store it shares with the caller. The caller's
//! thread waits for the work or for a signal: on a signal it returns at
//! once with [`Outcome::Interrupted`], and the caller publishes the finished
//! items as a partial set and ends the process (exit 130), leaving the items
//! in progress unfinished. A second signal while that happens ends the
//! process at once; the same signal repeated within [`REPEAT`] is the same
//! request (GNU `timeout` signals the command, then its whole process group,
//! so the command gets it twice at once). Work in progress need not poll
//! anything, so the optimisers stay free of cancellation checks.
//!
//! The signals are caught with `signal-hook`, whose registrations undo
//! cleanly; the handler only reads a monotonic clock, swaps atomics and, for
//! a second signal, calls `_exit` (all async-signal-safe).

use crate::error::{Error, Result};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

/// Exit status of an interrupted command: 128 + SIGINT, what a shell
/// reports for a program that Ctrl-C ended.
pub const EXIT_INTERRUPTED: u8 = 130;

/// A signal this soon after the first is the same request, not a second
/// one (a person pressing Ctrl-C again takes longer).
pub const REPEAT: Duration = Duration::from_millis(250);

/// Monotonic nanoseconds (`clock_gettime` is async-signal-safe), at least 1.
fn now_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime only writes the struct it is given
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    (ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64).max(1)
}

/// How often the waiting thread looks at the flag and the work.
const POLL: Duration = Duration::from_millis(20);

/// SIGINT and SIGTERM caught for as long as this lives.
#[derive(Debug)]
pub struct Interrupt {
    flag: Arc<AtomicBool>,
    ids: Vec<signal_hook::SigId>,
}

impl Interrupt {
    /// Catches SIGINT and SIGTERM: the first sets the flag; a second, more
    /// than [`REPEAT`] after it, ends the process at once with
    /// [`EXIT_INTERRUPTED`].
    pub fn catch() -> Result<Interrupt> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let flag = Arc::new(AtomicBool::new(false));
        // when the first signal came, ns (0: none yet)
        let first = Arc::new(AtomicU64::new(0));
        let mut ids = Vec::new();
        for sig in [SIGINT, SIGTERM] {
            let (flag, first) = (Arc::clone(&flag), Arc::clone(&first));
            let handler = move || {
                let now = now_ns();
                match first.compare_exchange(0, now, Ordering::SeqCst, Ordering::SeqCst) {
                    Ok(_) => flag.store(true, Ordering::SeqCst),
                    Err(t0) if now.saturating_sub(t0) > REPEAT.as_nanos() as u64 => {
                        // SAFETY: _exit is async-signal-safe
                        unsafe { libc::_exit(EXIT_INTERRUPTED as i32) }
                    }
                    Err(_) => {}
                }
            };
            // SAFETY: the handler only reads the clock, swaps atomics and
            // calls _exit, all async-signal-safe
            let id = unsafe { signal_hook::low_level::register(sig, handler) }.map_err(|e| {
                Error::Usage(format!("cannot catch signal {sig} to stop safely: {e}"))
            })?;
            ids.push(id);
        }
        Ok(Interrupt { flag, ids })
    }

    /// An interrupt that no signal sets (library callers, tests).
    pub fn never() -> Interrupt {
        Interrupt {
            flag: Arc::new(AtomicBool::new(false)),
            ids: Vec::new(),
        }
    }

    /// Whether a signal arrived.
    pub fn requested(&self) -> bool {
        self.flag.load(Ordering::SeqCst)
    }

    /// Sets the flag as a signal would (tests, a study's own stop).
    pub fn request(&self) {
        self.flag.store(true, Ordering::SeqCst)
    }
}

impl Drop for Interrupt {
    fn drop(&mut self) {
        for id in self.ids.drain(..) {
            signal_hook::low_level::unregister(id);
        }
    }
}

/// While it lives, SIGINT or SIGTERM ends a command that publishes no
/// partial set (`run`, `size`, a design): the sets it has not published are
/// removed ([`crate::output::abandon_unpublished`]), what it published stays,
/// and it exits with [`EXIT_INTERRUPTED`].
pub struct ExitOnSignal {
    _interrupt: Interrupt,
    done: Arc<AtomicBool>,
}

impl ExitOnSignal {
    pub fn install() -> Result<ExitOnSignal> {
        let interrupt = Interrupt::catch()?;
        let (flag, done) = (
            Arc::clone(&interrupt.flag),
            Arc::new(AtomicBool::new(false)),
        );
        let watching = Arc::clone(&done);
        std::thread::spawn(move || {
            while !watching.load(Ordering::SeqCst) {
                if flag.load(Ordering::SeqCst) {
                    crate::output::abandon_unpublished(
                        EXIT_INTERRUPTED as i32,
                        "\ninterrupted: stopped, and the files it had not published were removed; exit status 130",
                    );
                }
                std::thread::sleep(POLL);
            }
        });
        Ok(ExitOnSignal {
            _interrupt: interrupt,
            done,
        })
    }
}

impl Drop for ExitOnSignal {
    fn drop(&mut self) {
        self.done.store(true, Ordering::SeqCst);
    }
}

/// How supervised work ended.
#[derive(Debug)]
pub enum Outcome<T> {
    /// The work returned.
    Finished(T),
    /// A signal came first; the work's thread is still running.
    Interrupted,
}

impl<T> Outcome<T> {
    pub fn is_interrupted(&self) -> bool {
        matches!(self, Outcome::Interrupted)
    }
}

/// Runs `work` on its own thread and waits for it or for `interrupt`,
/// whichever comes first (within [`POLL`]). A panic in the work is resumed
/// on the caller's thread. When interrupted, the caller is expected to
/// publish what the work's shared store holds and end the process.
pub fn supervise<T: Send + 'static>(
    interrupt: &Interrupt,
    work: impl FnOnce() -> T + Send + 'static,
) -> Outcome<T> {
    let (tx, rx) = std::sync::mpsc::channel();
    let handle = std::thread::spawn(move || {
        let _ = tx.send(work());
    });
    loop {
        match rx.recv_timeout(POLL) {
            Ok(v) => {
                let _ = handle.join();
                return Outcome::Finished(v);
            }
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                // the work panicked before sending
                match handle.join() {
                    Err(p) => std::panic::resume_unwind(p),
                    Ok(()) => unreachable!("the work sends before it ends"),
                }
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                if interrupt.requested() {
                    return Outcome::Interrupted;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finished_work_returns_its_value_and_a_request_returns_at_once() {
        let i = Interrupt::never();
        assert!(matches!(supervise(&i, || 7), Outcome::Finished(7)));
        i.request();
        let t = std::time::Instant::now();
        let o = supervise(&i, || std::thread::sleep(Duration::from_secs(30)));
        assert!(o.is_interrupted());
        assert!(t.elapsed() < Duration::from_secs(1), "{:?}", t.elapsed());
    }
}
