//! What every command shares: the config arguments, loading the config,
//! starting the output set, printing to stdout, and how a command ended.

use anyhow::Result;
use catflip::Config;
use catflip::output::Publisher;
use clap::Args;
use std::path::PathBuf;

/// Set once stdout turned out to be a closed pipe: later lines are dropped.
pub(crate) static STDOUT_GONE: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// `println!` that stops printing, instead of panicking, when stdout is a
/// closed pipe (`catflip ... --json | head`); the command still finishes
/// and exits with its own status (3 partial, 4 impossible), which a
/// `pipefail` script needs.
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        use std::sync::atomic::Ordering;
        if !$crate::common::STDOUT_GONE.load(Ordering::Relaxed) {
            if let Err(e) = writeln!(std::io::stdout(), $($t)*) {
                if e.kind() != std::io::ErrorKind::BrokenPipe {
                    eprintln!("error: writing to stdout: {e}");
                }
                $crate::common::STDOUT_GONE.store(true, Ordering::Relaxed);
            }
        }
    }};
}
pub(crate) use say;

/// Prints a table's lines with [`say!`].
pub(crate) fn say_lines<S: AsRef<str>>(lines: impl IntoIterator<Item = S>) {
    for l in lines {
        say!("{}", l.as_ref());
    }
}

/// A long command's progress on stderr: one line rewritten in place on a
/// terminal, a line per report in a log, nothing with `--json`.
#[derive(Clone, Copy)]
pub(crate) struct Progress {
    quiet: bool,
    live: bool,
}

impl Progress {
    pub(crate) fn new(quiet: bool) -> Progress {
        let live = std::io::IsTerminal::is_terminal(&std::io::stderr());
        Progress { quiet, live }
    }

    /// Whether the line is rewritten in place (a terminal), so every report can be shown.
    pub(crate) fn is_live(&self) -> bool {
        self.live
    }

    pub(crate) fn show(&self, line: &str) {
        if self.quiet {
        } else if self.live {
            eprint!("\r  {line}");
        } else {
            eprintln!("  {line}");
        }
    }

    /// Ends the line rewritten in place.
    pub(crate) fn finish(&self) {
        if !self.quiet && self.live {
            eprintln!();
        }
    }
}

#[derive(Args, Clone)]
pub(crate) struct Common {
    /// TOML configuration (see configs/).
    pub(crate) config: PathBuf,
    /// Override a config key, e.g. `--set cat.joint=universal` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub(crate) set: Vec<String>,
    /// Print JSON instead of the table: one object (`sweep`: an array of
    /// its points; `export` has no table and lists the files it wrote
    /// either way).
    #[arg(long)]
    pub(crate) json: bool,
    /// Folder that receives `<name>/`.
    #[arg(long, default_value = "output")]
    pub(crate) out: PathBuf,
}

impl Common {
    /// The command line of `command` on the same config and `--set`s, as a
    /// shell takes it: what a message advises the user to run next.
    pub(crate) fn command(&self, command: &str) -> String {
        let mut words = vec![
            "catflip".to_string(),
            command.to_string(),
            shell_word(&self.config.display().to_string()),
        ];
        for s in &self.set {
            words.extend(["--set".to_string(), shell_word(s)]);
        }
        words.join(" ")
    }
}

/// `word` quoted for a POSIX shell where it needs quoting (`'it'\''s'`).
fn shell_word(word: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_./=:,@+-%".contains(c);
    if !word.is_empty() && word.chars().all(plain) {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}

/// The key of a `--set KEY=VALUE`, as the config reads it (spaces dropped).
pub(crate) fn set_key(arg: &str) -> &str {
    arg.split('=').next().unwrap_or(arg).trim()
}

/// Loads and checks the config; likely unit slips are warned about on stderr.
pub(crate) fn load(c: &Common) -> Result<Config> {
    // the last would win silently, yet both would name the output set
    for (i, s) in c.set.iter().enumerate() {
        if let Some(first) = c.set[..i].iter().find(|f| set_key(f) == set_key(s)) {
            return Err(catflip::Error::Usage(format!(
                "--set {s} gives the key of --set {first} again: give each key once"
            ))
            .into());
        }
    }
    let cfg = Config::load(&c.config, &c.set)?;
    for s in cfg.slips() {
        eprintln!("warning: {s}");
    }
    Ok(cfg)
}

/// Starts the command's output set `<out>/<name>/<set>` before any work, so
/// that an unwritable `--out` fails at once. With `--set` overrides the set
/// is named after them too ([`catflip::output::set_name`]).
pub(crate) fn publisher(c: &Common, cfg: &Config, set: &str) -> Result<Publisher> {
    Ok(Publisher::begin(
        &c.out.join(&cfg.name),
        &catflip::output::set_name(set, &c.set),
    )?)
}

/// Publishes an interrupted command's finished part as a partial set,
/// prints its JSON when `--json` asked, and says on stderr what finished
/// (`done`, e.g. "11 of 20 trials") and how to go on (`then`, may be empty).
pub(crate) fn publish_partial(
    publisher: Publisher,
    out: catflip::output::Output,
    json: Option<&str>,
    done: &str,
    then: &str,
) -> Result<Status> {
    let dir = publisher.link();
    publisher.publish(out)?;
    if let Some(json) = json {
        say!("{json}");
    }
    eprintln!(
        "interrupted: {done} finished, published as a partial set in {} (its JSON says \"status\": \"partial\"){then}; exit status 130",
        dir.display()
    );
    Ok(Status::Interrupted)
}

/// How a command that finished ended: the exit status tells them apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Every result meets its targets (exit 0).
    Ok,
    /// Results were written, but some are flagged or failed (exit 3).
    Partial,
    /// The motors cannot flip the cat from the configured height; the least
    /// height and its schedule were written (exit 4).
    Impossible,
    /// A signal stopped the command; what it finished was published as a
    /// partial set (exit 130).
    Interrupted,
}

impl Status {
    pub(crate) fn of(partial: bool) -> Status {
        if partial { Status::Partial } else { Status::Ok }
    }
}

impl From<catflip::run::Outcome> for Status {
    fn from(o: catflip::run::Outcome) -> Status {
        match o {
            catflip::run::Outcome::Ok => Status::Ok,
            catflip::run::Outcome::Partial => Status::Partial,
            catflip::run::Outcome::Impossible => Status::Impossible,
        }
    }
}

/// Prints a flagged verdict on stderr and says whether there was one.
pub(crate) fn flag(what: &str, reason: Option<String>) -> bool {
    if let Some(r) = &reason {
        eprintln!("warning: {what} is FLAGGED: {r}");
    }
    reason.is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The advised command reads back as the same words in a shell.
    #[test]
    fn an_advised_command_quotes_what_a_shell_would_split() {
        let c = Common {
            config: PathBuf::from("my robot's.toml"),
            set: vec!["fall.height=3".into(), "name=a b".into()],
            json: false,
            out: PathBuf::from("output"),
        };
        assert_eq!(
            c.command("size"),
            "catflip size 'my robot'\\''s.toml' --set fall.height=3 --set 'name=a b'"
        );
        let words = std::process::Command::new("sh")
            .args(["-c", &format!("printf '%s|' {}", c.command("size"))])
            .output()
            .unwrap()
            .stdout;
        assert_eq!(
            String::from_utf8(words).unwrap(),
            "catflip|size|my robot's.toml|--set|fall.height=3|--set|name=a b|"
        );
    }
}
