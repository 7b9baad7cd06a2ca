//! The Python module `catflip._catflip`: thin calls into the catflip library.
//!
//! One file on purpose: every function here takes the user's objects, calls
//! one high-level library function with the GIL released, and hands the
//! result back as numpy arrays and plain Python values. When the library's
//! entry points move, only the calls in this file change. The public
//! Python names, their docstrings and their stubs live in `catflip/`.

use catflip::config::Config as Cfg;
use catflip::design::plan::{Schedule, ShapePlan};
use catflip::verify::simulate::SimReport;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::PathBuf;
use std::sync::Mutex;

create_exception!(
    catflip,
    CatflipError,
    PyException,
    "Base of catflip's errors."
);
create_exception!(
    catflip,
    ConfigError,
    CatflipError,
    "Bad input: config, key, value or file (the CLI's exit status 2)."
);
create_exception!(
    catflip,
    DesignError,
    CatflipError,
    "A computation failed: solver, simulation (the CLI's exit status 1)."
);
create_exception!(
    catflip,
    UnitSlipWarning,
    pyo3::exceptions::PyUserWarning,
    "A config value that is valid but likely a unit slip (the CLI's `warning:` lines)."
);
create_exception!(
    catflip,
    ImpossibleError,
    DesignError,
    "The motors cannot flip the cat from this height; the message names the least height, or how to find it."
);

/// The library's error as the exception of its kind, with the CLI's message.
/// A parse error of the TOML made from a dict (`message`, which points
/// at `text`'s line and column), said of the dict's key: `fall.heigth`:
/// unknown key ... .
fn dict_error(text: &str, message: &str) -> String {
    let reason = message.trim().lines().last().unwrap_or(message).trim();
    let line = message
        .split_once("at line ")
        .and_then(|(_, rest)| rest.split(',').next()?.trim().parse::<usize>().ok());
    let key = line.filter(|&n| n > 0).and_then(|n| {
        let lines: Vec<&str> = text.lines().collect();
        let name = lines.get(n - 1)?.split_once('=')?.0.trim().to_string();
        let section = lines[..n - 1]
            .iter()
            .rev()
            .find(|l| l.starts_with('['))
            .map(|l| l.trim_matches(|c| c == '[' || c == ']').to_string());
        Some(match section {
            Some(s) => format!("{s}.{name}"),
            None => name,
        })
    });
    match key {
        Some(k) => format!(
            "config dict: key `{k}`: {}",
            reason.replace("unknown field", "unknown key")
        ),
        None => format!("config dict: {reason}"),
    }
}

/// The library's advice in the package's words: its messages name the
/// command line's flags and commands where Python has arguments and functions.
const PYTHONIC: [(&str, &str); 12] = [
    (
        "out of the config and its --set",
        "out of the config and its config.set calls",
    ),
    ("--methods names neither", "methods names neither"),
    ("to --methods", "to methods"),
    (
        "or sweep without --least-height-only",
        "or sweep with least_height_only=False",
    ),
    ("--least-height-only", "least_height_only=True"),
    (
        "another seed (--seed)",
        "another seed (seed=\"analytic\" or \"phased\")",
    ),
    (
        "`--seed analytic` starts it",
        "`seed=\"analytic\"` starts it",
    ),
    (
        "`catflip run` finds the least drop height",
        "`catflip.least_height(config)` finds the least drop height",
    ),
    (
        "`catflip run` writes its schedule as least-height.csv",
        "`catflip.least_height(config).to_csv()` gives its schedule",
    ),
    (" in least-height.csv)", ": least_height(config).to_csv())"),
    ("`catflip run`", "`catflip.run(config)`"),
    (
        "(catflip size names them for a height)",
        "(catflip.size(config, height) names them)",
    ),
];

/// The library's advice in this package's words: [`PYTHONIC`], and `catflip
/// size CONFIG --height H.` as the call `catflip.size(config, H).`.
fn pythonic(message: String) -> String {
    let mut m = PYTHONIC
        .iter()
        .fold(message, |m, (cli, py)| m.replace(cli, py));
    // `with --set KEY=VALUE` (a key to set) as the call that sets it
    const SET: &str = "with --set ";
    let mut from = 0;
    while let Some(at) = m[from..].find(SET).map(|i| from + i) {
        let rest = &m[at + SET.len()..];
        let len = rest.find(char::is_whitespace).unwrap_or(rest.len());
        let token = rest[..len].trim_end_matches(['.', ',', ';', ')']);
        let Some((key, value)) = token.split_once('=') else {
            from = at + SET.len();
            continue;
        };
        let call = format!("with config.set(\"{key}\", {value})");
        m.replace_range(at..at + SET.len() + token.len(), &call);
        from = at + call.len();
    }
    const SIZE: &str = "catflip size CONFIG --height ";
    while let Some(at) = m.find(SIZE) {
        let rest = &m[at + SIZE.len()..];
        // the height's digits, without the sentence's full stop
        let len = rest
            .find(|c: char| !(c.is_ascii_digit() || ".e+-".contains(c)))
            .unwrap_or(rest.len());
        let height = rest[..len].trim_end_matches('.');
        let call = format!("catflip.size(config, {height})");
        m.replace_range(at..at + SIZE.len() + height.len(), &call);
    }
    m
}

fn err(e: catflip::Error) -> PyErr {
    use catflip::Error as E;
    let msg = pythonic(e.to_string());
    match e {
        E::BeyondMotors { .. } => ImpossibleError::new_err(msg),
        e if e.is_bad_input() => ConfigError::new_err(msg),
        _ => DesignError::new_err(msg),
    }
}

/// Runs `work` on a thread of its own, with the GIL released, while this
/// thread looks for Python's signals every 50 ms: Ctrl-C raises
/// KeyboardInterrupt at once (after `on_interrupt`, which may ask the work to
/// stop; work that cannot stop finishes in the background, its result dropped).
fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    on_interrupt: impl FnOnce(),
    work: impl FnOnce() -> PyResult<T> + Send + 'static,
) -> PyResult<T> {
    use std::sync::mpsc::RecvTimeoutError;
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::Builder::new()
        .name("catflip".into())
        .spawn(move || {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(work));
            let _ = tx.send(r);
        })
        .map_err(|e| DesignError::new_err(format!("cannot start a thread: {e}")))?;
    // (a receiver is not Sync; the lock lets the GIL-free wait borrow it)
    let rx = Mutex::new(rx);
    loop {
        let wait = || {
            rx.lock()
                .unwrap_or_else(|e| e.into_inner())
                .recv_timeout(std::time::Duration::from_millis(50))
        };
        match py.detach(wait) {
            Ok(Ok(r)) => return r,
            Ok(Err(panic)) => std::panic::resume_unwind(panic),
            Err(RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    on_interrupt();
                    return Err(e);
                }
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(DesignError::new_err(
                    "the computation's thread ended without a result",
                ));
            }
        }
    }
}

fn json_loads<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (v.to_string(),))
}

/// `rows` x 2 (or x k) float64 array from fixed-size rows.
fn matrix<'py, const K: usize>(py: Python<'py>, rows: &[[f64; K]]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), K), flat)
        .expect("rows of equal length")
        .into_pyarray(py)
}

fn matrix_vec<'py>(py: Python<'py>, rows: &[Vec<f64>]) -> Bound<'py, PyArray2<f64>> {
    let k = rows.first().map_or(0, Vec::len);
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), k), flat)
        .expect("rows of equal length")
        .into_pyarray(py)
}

fn vector<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

// --- Config -----------------------------------------------------------------

/// The user's text and overrides: every change re-reads them as the CLI
/// would (`catflip CMD FILE --set ... --set ...`), so the messages match.
#[derive(Clone)]
struct Source {
    text: String,
    origin: String,
    overrides: Vec<String>,
    /// The folder a file's relative paths (`body.urdf`) are read from, as the CLI's.
    base: PathBuf,
}

impl Source {
    fn load(&self, extra: Option<&str>) -> catflip::Result<Cfg> {
        let mut ov = self.overrides.clone();
        ov.extend(extra.map(String::from));
        Cfg::from_toml_at(&self.text, &self.origin, &ov, &self.base).map_err(|e| match e {
            // the folder itself: a config from text or a dict has no file,
            // and reads its robot file from the folder it was made in
            catflip::Error::Invalid {
                key,
                value,
                expected,
            } => catflip::Error::Invalid {
                key,
                value,
                expected: expected.replace(
                    "relative to the config file",
                    &format!("relative to {}", self.base.display()),
                ),
            },
            e => e,
        })
    }
}

struct Snapshot {
    source: Source,
    cfg: Cfg,
}

/// A checked catflip configuration: the CLI's TOML keys, defaults and checks.
///
/// Safe to share between threads: `set` takes a lock, and every computation
/// works on a copy taken when it starts.
#[pyclass(frozen, module = "catflip")]
struct Config {
    inner: Mutex<Snapshot>,
}

/// The config's likely unit slips, as Python warnings (the CLI's `warning: ...` lines).
fn warn_slips(py: Python<'_>, cfg: &Cfg) -> PyResult<()> {
    for slip in cfg.slips() {
        let text = std::ffi::CString::new(slip.to_string()).unwrap_or_default();
        PyErr::warn(py, &py.get_type::<UnitSlipWarning>(), &text, 1)?;
    }
    Ok(())
}

impl Config {
    fn from_source(py: Python<'_>, source: Source) -> PyResult<Config> {
        let cfg = source.load(None).map_err(err)?;
        warn_slips(py, &cfg)?;
        Ok(Config {
            inner: Mutex::new(Snapshot { source, cfg }),
        })
    }

    /// The config as `to_dict` and `to_toml` give it, and whether it has a
    /// `[body]`: its robot file's path made absolute, so that its keys read
    /// back from another folder. (With a `[body]` the `[cat]` cylinders are
    /// its equivalent ones, which the keys leave out: the body gives them.)
    fn portable(&self) -> (bool, Cfg) {
        let (source, mut cfg) = self.snapshot();
        if let Some(b) = cfg.body.as_mut() {
            for p in [&mut b.urdf, &mut b.mjcf].into_iter().flatten() {
                let joined = source.base.join(&*p);
                *p = std::path::absolute(&joined)
                    .unwrap_or(joined)
                    .display()
                    .to_string();
            }
        }
        (cfg.body.is_some(), cfg)
    }

    /// A consistent copy to compute with (the lock is not held during solves).
    fn snapshot(&self) -> (Source, Cfg) {
        let s = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        (s.source.clone(), s.cfg.clone())
    }
}

/// A folder made absolute now, so that a config's relative paths (`body.urdf`)
/// are read from where it was loaded, whatever the current folder later.
fn folder(p: &std::path::Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

/// The `[cat]` keys a `[body]` replaces (`cat.joint` stays).
const CYLINDER_KEYS: [&str; 4] = ["mass", "length", "radius", "front"];

/// A numpy array or scalar (anything with `tolist`, not a plain Python value)
/// as the list or number it holds.
fn plain<'py>(v: &Bound<'py, PyAny>) -> PyResult<Option<Bound<'py, PyAny>>> {
    let python = v.is_instance_of::<PyBool>()
        || v.is_instance_of::<PyInt>()
        || v.is_instance_of::<PyFloat>()
        || v.is_instance_of::<PyString>()
        || v.is_instance_of::<PyList>()
        || v.is_instance_of::<PyTuple>()
        || v.is_instance_of::<PyDict>();
    if !python && v.hasattr("tolist")? {
        return Ok(Some(v.call_method0("tolist")?));
    }
    Ok(None)
}

/// A Python value as a TOML value (a config dict's): numbers, true/false,
/// strings, lists, dicts and numpy arrays; `None` leaves the key out (an
/// unset key, as `Config.to_dict` gives it). NaN and infinities pass, so the
/// config's own check names the key.
fn toml_value(v: &Bound<'_, PyAny>, key: &str) -> PyResult<Option<toml::Value>> {
    if let Some(p) = plain(v)? {
        return toml_value(&p, key);
    }
    if v.is_none() {
        return Ok(None);
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(Some(toml::Value::Boolean(v.extract()?)));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(Some(toml::Value::Integer(v.extract().map_err(|_| {
            ConfigError::new_err(format!("{key}: {v} does not fit a 64-bit integer"))
        })?)));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(Some(toml::Value::String(v.extract()?)));
    }
    // a float, or anything that is one (`Decimal`, `Fraction`)
    if v.is_instance_of::<PyFloat>() || v.hasattr("__float__")? {
        return Ok(Some(toml::Value::Float(v.extract()?)));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let k: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "config dict: the keys of `{key}` are strings, not {k}"
                ))
            })?;
            let name = if key.is_empty() {
                k.clone()
            } else {
                format!("{key}.{k}")
            };
            if let Some(x) = toml_value(&x, &name)? {
                t.insert(k, x);
            }
        }
        return Ok(Some(toml::Value::Table(t)));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for x in v.try_iter()? {
            let x = x?;
            items
                .push(toml_value(&x, key)?.ok_or_else(|| {
                    ConfigError::new_err(format!("`{key}` holds None in a list"))
                })?);
        }
        return Ok(Some(toml::Value::Array(items)));
    }
    Err(PyTypeError::new_err(format!(
        "`{key}`: a config value is a number, true/false, a string, a list or a dict, not {}",
        v.get_type().name()?
    )))
}

/// `overrides`: one `"KEY=VALUE"` or a list of them.
fn override_list(v: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    if let Ok(s) = v.extract::<String>() {
        return Ok(vec![s]);
    }
    v.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "overrides is a list of \"KEY=VALUE\" strings (or one), not {}",
            v.get_type()
                .name()
                .map_or_else(|_| "that".into(), |n| n.to_string())
        ))
    })
}

/// A count or index from Python: not negative.
fn count(v: i64, what: &str) -> PyResult<usize> {
    usize::try_from(v).map_err(|_| ConfigError::new_err(format!("{what} = {v}: give 0 or more")))
}

/// A Python value (of key `key`) as the TOML text of a `--set KEY=VALUE`.
fn toml_text(v: &Bound<'_, PyAny>, key: &str) -> PyResult<String> {
    if v.is_instance_of::<PyString>() {
        let s: String = v.extract()?;
        // as the user would type it after `--set KEY=` when the CLI reads it as
        // that string (so the messages are the CLI's), else quoted
        let plain = toml::from_str::<toml::Table>(&format!("v = {s}")).is_err()
            && s.trim() == s
            && !s.is_empty()
            && !s.contains(['\n', '\r']);
        if plain {
            return Ok(s);
        }
    }
    match toml_value(v, key)? {
        Some(x) => Ok(text_of(&x)),
        None => Err(ConfigError::new_err(format!(
            "`{key}`: None is no value (give a number, true/false, a string or a list); to unset an optional key, set it to None in `config.to_dict()` and read that with `Config.from_dict`"
        ))),
    }
}

/// A float with no fractional part as a whole number's text (`40.0` as
/// `40`); `None` for anything else.
fn whole_number(v: &Bound<'_, PyAny>) -> Option<String> {
    if v.is_instance_of::<PyString>() || v.is_instance_of::<pyo3::types::PyBool>() {
        return None;
    }
    let x: f64 = v.extract().ok()?;
    // (below 2^53 every whole float is an exact integer)
    (x.is_finite() && x.fract() == 0.0 && x.abs() < 9.007_199_254_740_992e15)
        .then(|| format!("{}", x as i64))
}

/// A TOML value as typed after `--set KEY=` (a float as Rust writes it, so
/// the recorded overrides read as the CLI's).
fn text_of(x: &toml::Value) -> String {
    match x {
        toml::Value::Float(f) if f.is_nan() => "nan".into(),
        toml::Value::Float(f) if f.is_infinite() => if *f > 0.0 { "inf" } else { "-inf" }.into(),
        toml::Value::Float(f) => format!("{f:?}"),
        toml::Value::String(s) => serde_json::to_string(s).expect("a string serialises"),
        toml::Value::Array(a) => {
            format!("[{}]", a.iter().map(text_of).collect::<Vec<_>>().join(", "))
        }
        other => other.to_string(),
    }
}

#[pymethods]
impl Config {
    /// Reads and checks a TOML config file with the CLI's `--set KEY=VALUE` `overrides`
    /// (as `catflip CMD FILE --set ...`); raises ConfigError.
    #[staticmethod]
    #[pyo3(signature = (path, overrides = None))]
    fn from_toml(
        py: Python<'_>,
        path: PathBuf,
        overrides: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Config> {
        let overrides = overrides.map(override_list).transpose()?;
        let text = std::fs::read_to_string(&path).map_err(|e| {
            err(catflip::Error::ConfigRead {
                path: path.clone(),
                message: e.to_string(),
            })
        })?;
        Config::from_source(
            py,
            Source {
                text,
                origin: path.display().to_string(),
                overrides: overrides.unwrap_or_default(),
                base: folder(path.parent().unwrap_or(std::path::Path::new("."))),
            },
        )
    }

    /// Checks a config given as TOML text; `origin` names it in messages. A relative robot
    /// file (`body.urdf`) is read from the current folder.
    #[staticmethod]
    #[pyo3(signature = (text, origin = "<string>"))]
    fn from_text(py: Python<'_>, text: String, origin: &str) -> PyResult<Config> {
        Config::from_source(
            py,
            Source {
                text,
                origin: origin.into(),
                overrides: Vec::new(),
                base: folder(std::path::Path::new(".")),
            },
        )
    }

    /// Checks a config given as a dict of the TOML's tables (`{"name": ..., "cat": {...}, "fall": {...}}`);
    /// a key whose value is None is left unset (as `to_dict` gives it), numpy arrays are lists.
    #[staticmethod]
    fn from_dict(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<Config> {
        let table = toml_value(d.as_any(), "")?.unwrap_or(toml::Value::Table(Default::default()));
        let text = toml::to_string(&table).map_err(|e| ConfigError::new_err(e.to_string()))?;
        let source = Source {
            text: text.clone(),
            origin: "dict".into(),
            overrides: Vec::new(),
            base: folder(std::path::Path::new(".")),
        };
        // a parse error points into TOML the user never wrote: name the dict's key
        match source.load(None) {
            Err(catflip::Error::ConfigParse { message, .. }) => {
                Err(ConfigError::new_err(dict_error(&text, &message)))
            }
            Err(e) => Err(err(e)),
            Ok(cfg) => {
                warn_slips(py, &cfg)?;
                Ok(Config {
                    inner: Mutex::new(Snapshot { source, cfg }),
                })
            }
        }
    }

    /// Sets one key, e.g. `set("fall.height", 6)`, with the CLI's `--set` checks and messages
    /// (a whole float such as `40.0` sets a whole-number key, as `sweep` takes its values);
    /// on a ConfigError the config is left as it was.
    fn set(&self, py: Python<'_>, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut arg = format!("{key}={}", toml_text(value, key)?);
        let cfg = {
            let mut s = self.inner.lock().unwrap_or_else(|e| e.into_inner());
            let cfg = match s.source.load(Some(&arg)) {
                Ok(cfg) => cfg,
                // a whole float (numpy's 40.0) where a whole number is
                // expected, as `sweep` takes its values; where that is refused
                // too, its reason (the value's, not its type's)
                Err(e) => match whole_number(value).filter(|_| {
                    matches!(
                        e,
                        catflip::Error::Override {
                            expects: Some(catflip::error::ValueKind::Number),
                            ..
                        }
                    )
                }) {
                    Some(w) => {
                        let whole = format!("{key}={w}");
                        let cfg = s.source.load(Some(&whole)).map_err(err)?;
                        arg = whole;
                        cfg
                    }
                    None => return Err(err(e)),
                },
            };
            s.source.overrides.push(arg);
            s.cfg = cfg.clone();
            cfg
        };
        // outside the lock: a warnings filter may run Python code
        warn_slips(py, &cfg)
    }

    /// The config's likely unit slips (the CLI's warnings), in words.
    #[getter]
    fn slips(&self) -> Vec<String> {
        self.snapshot()
            .1
            .slips()
            .iter()
            .map(ToString::to_string)
            .collect()
    }

    /// An independent copy (later `set`s on either leave the other alone).
    fn copy(&self) -> Config {
        let (source, cfg) = self.snapshot();
        Config {
            inner: Mutex::new(Snapshot { source, cfg }),
        }
    }

    fn __copy__(&self) -> Config {
        self.copy()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Config {
        self.copy()
    }

    /// Pickled as its text, origin, overrides and folder: unpickling reads
    /// and checks them again (the robot file too, from the same path).
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let (s, _) = self.snapshot();
        let restore = py.import("catflip")?.getattr("_restore_config")?;
        let args = (s.text, s.origin, s.overrides, s.base).into_pyobject(py)?;
        Ok((restore, args))
    }

    /// The config `__reduce__` describes (for pickle).
    #[staticmethod]
    fn _from_state(
        text: String,
        origin: String,
        overrides: Vec<String>,
        base: PathBuf,
    ) -> PyResult<Config> {
        let source = Source {
            text,
            origin,
            overrides,
            base,
        };
        let cfg = source.load(None).map_err(err)?;
        Ok(Config {
            inner: Mutex::new(Snapshot { source, cfg }),
        })
    }

    /// Every key that has a value, defaults included, as nested dicts (an optional key left
    /// unset is absent or None; `None` leaves a key unset in `from_dict`);
    /// `Config.from_dict` reads it back. A robot file's path (`body.urdf`) is absolute.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (body, cfg) = self.portable();
        let mut v = serde_json::to_value(cfg).expect("a config serialises");
        if body && let Some(cat) = v.get_mut("cat").and_then(|c| c.as_object_mut()) {
            for k in CYLINDER_KEYS {
                cat.remove(k);
            }
        }
        json_loads(py, &v)
    }

    /// Every key with its value, defaults included, as TOML text (`Config.from_text`
    /// reads it back). A robot file's path (`body.urdf`) is absolute.
    fn to_toml(&self) -> String {
        let (body, cfg) = self.portable();
        let mut v = toml::Table::try_from(cfg).expect("a config serialises");
        if body && let Some(toml::Value::Table(cat)) = v.get_mut("cat") {
            for k in CYLINDER_KEYS {
                cat.remove(k);
            }
        }
        toml::to_string(&v).expect("a config serialises")
    }

    /// The config's `name` (the CLI's output folder `output/<name>/`).
    #[getter]
    fn name(&self) -> String {
        self.snapshot().1.name
    }

    /// The `KEY=VALUE` overrides applied so far (`from_toml`'s, then each `set`), in order.
    #[getter]
    fn overrides(&self) -> Vec<String> {
        self.snapshot().0.overrides
    }

    /// `sqrt(2 h / g)`, s.
    #[getter]
    fn fall_time(&self) -> f64 {
        self.snapshot().1.fall_time()
    }

    /// Time for the manoeuvre: fall time minus `fall.margin`, s.
    #[getter]
    fn manoeuvre_time(&self) -> f64 {
        self.snapshot().1.available_time()
    }

    fn __repr__(&self) -> String {
        let (s, c) = self.snapshot();
        format!(
            "Config(name={:?}, origin={:?}, overrides={:?})",
            c.name, s.origin, s.overrides
        )
    }
}

// --- Design -----------------------------------------------------------------

fn with_verdict(mut json: serde_json::Value, reason: &Option<String>) -> serde_json::Value {
    json["verdict"] = (if reason.is_some() { "flagged" } else { "ok" }).into();
    if let Some(r) = reason {
        json["reason"] = r.clone().into();
    }
    json
}

type Plan = std::sync::Arc<dyn ShapePlan + Send + Sync>;

#[pyclass(frozen, module = "catflip")]
/// A designed schedule: what `catflip optimize --mode free|phased` (or `analyze`) writes.
///
/// Immutable; the arrays are fresh copies on each access. N rows: 3 phases
/// of `simulate.samples_per_phase + 1` samples (a phase junction appears twice).
struct Design {
    method: &'static str,
    source: Source,
    cfg: Cfg,
    plan: Plan,
    schedule: Schedule,
    /// The CLI's `<method>.json` (`analyze.json` for the analytic schedule).
    json: serde_json::Value,
    status: String,
    reason: Option<String>,
    peak: f64,
    durations: [f64; 3],
}

/// An optimised design as the CLI's `optimize` makes it: through its stage
/// (`catflip::pipeline::stage`: sampled, flown, judged), with its JSON.
type Staged = (
    Plan,
    Schedule,
    serde_json::Value,
    catflip::verdict::Status,
    Option<String>,
    f64,
    [f64; 3],
);

fn staged(
    spec: &catflip::design::spec::DesignSpec,
    design: catflip::pipeline::Design,
) -> PyResult<Staged> {
    use catflip::pipeline::Design as D;
    let j = catflip::pipeline::stage(spec, design, 0.0);
    let json = j.design_json(spec).map_err(err)?;
    let (status, reason, peak) = (
        j.design.status(),
        j.verdict.reason(),
        j.design.peak_torque_nm(),
    );
    let (_, _, durations) = j.design.path_numbers();
    let plan: Plan = match j.design {
        D::Free(r) => std::sync::Arc::new(r.plan),
        D::Phased(r) => std::sync::Arc::new(r.plan),
        D::Analytic(a) => std::sync::Arc::new(a.plan),
        D::LeastHeight(l) => std::sync::Arc::new(l.schedule),
    };
    Ok((plan, j.schedule, json, status, reason, peak, durations))
}

/// The library's design for `method`, judged and sampled as the CLI does.
fn run_design(
    cfg: Cfg,
    source: Source,
    method: &'static str,
    seed: Option<&str>,
) -> PyResult<Design> {
    use catflip::verdict::Status;
    let no_seed = |what: &str| {
        ConfigError::new_err(format!(
            "seed applies to method=\"free\" ({what} has no seed); leave seed out or use method=\"free\""
        ))
    };
    let spec = cfg.design_spec();
    let (plan, schedule, json, status, reason, peak, durations): (Plan, _, _, Status, _, _, _) =
        match method {
            "free" => {
                use catflip::design::free::Seed;
                let seed = match seed {
                    None => None,
                    Some("phased") => Some(Seed::Phased),
                    Some("analytic") => Some(Seed::Analytic),
                    Some(other) => {
                        return Err(ConfigError::new_err(format!(
                            "unknown seed `{other}`; use \"phased\" or \"analytic\""
                        )));
                    }
                };
                // without a seed, the start `run` takes
                let r = catflip::pipeline::free_design(
                    &spec,
                    seed,
                    |_| {},
                    &mut |_: &catflip::design::scp::ScpIteration| {},
                    "catflip.least_height(config) gives it",
                );
                staged(&spec, catflip::pipeline::Design::Free(r.map_err(err)?))?
            }
            "phased" => {
                if seed.is_some() {
                    return Err(no_seed("the phased design"));
                }
                let r = catflip::design::phased::optimize(&spec, |_| {}).map_err(err)?;
                staged(&spec, catflip::pipeline::Design::Phased(r))?
            }
            _ => {
                if seed.is_some() {
                    return Err(no_seed("the analytic schedule"));
                }
                // the CLI's `analyze`: a miss is flagged in the analysis
                let a = catflip::verify::analyze::analyze(&spec, &cfg.name).map_err(err)?;
                let (sched, verdict) = catflip::pipeline::judge_analysis(&spec, &a);
                let (status, reason) = (Status::ClosedForm, verdict.reason());
                let json = serde_json::to_value(&a).expect("serialises");
                catflip::output::ensure_finite(&json, &[]).map_err(err)?;
                (
                    std::sync::Arc::new(a.plan),
                    sched,
                    json,
                    status,
                    reason,
                    a.peak_torque_nm,
                    a.closed.phase_durations_s,
                )
            }
        };
    Ok(Design {
        method,
        source,
        cfg,
        plan,
        schedule,
        json: with_verdict(json, &reason),
        status: status.name().into(),
        reason,
        peak,
        durations,
    })
}

/// Designs a torque schedule, as the CLI's `optimize --mode METHOD [--seed SEED]`
/// (`analyze` for `method="analytic"`), with the GIL released.
///
/// `objective` (`"peak-torque"`, `"time"`, `"energy"`) overrides `design.objective`;
/// `seed` (`"phased"`, `"analytic"`; None: the phased design, or where no phased one fits
/// the motors in this fall, and always for the `"time"` objective, the least-height
/// answer's shortest manoeuvre, as `run` and `optimize`) applies to `method="free"` only.
/// Raises ConfigError, ImpossibleError (the motors cannot flip the cat from
/// `fall.height`) or DesignError, with the CLI's messages.
#[pyfunction]
#[pyo3(signature = (config, method = "free", objective = None, seed = None))]
fn design(
    py: Python<'_>,
    config: &Config,
    method: &str,
    objective: Option<&str>,
    seed: Option<&str>,
) -> PyResult<Design> {
    let (mut source, mut cfg) = config.snapshot();
    if let Some(o) = objective
        && !["peak-torque", "time", "energy"].contains(&o)
    {
        return Err(ConfigError::new_err(format!(
            "unknown objective `{o}`; use \"peak-torque\", \"time\" or \"energy\" (or None: design.objective)"
        )));
    }
    let method = match method {
        "free" => "free",
        "phased" => "phased",
        "analytic" => "analytic",
        other => {
            return Err(ConfigError::new_err(format!(
                "unknown method `{other}`; use \"free\", \"phased\" or \"analytic\""
            )));
        }
    };
    if method == "analytic"
        && let Some(o) = objective
    {
        // (as a seed for the phased design: refused, not ignored)
        return Err(ConfigError::new_err(format!(
            "objective=\"{o}\" applies to the phased and free designs: the analytic schedule is the seed's closed form and optimises nothing; leave objective out or use method=\"phased\" or \"free\""
        )));
    }
    if let Some(o) = objective {
        let arg = format!(
            "design.objective={}",
            serde_json::to_string(o).expect("serialises")
        );
        cfg = source.load(Some(&arg)).map_err(err)?;
        source.overrides.push(arg);
    }
    let seed = seed.map(String::from);
    interruptible(
        py,
        || {},
        move || run_design(cfg, source, method, seed.as_deref()),
    )
}

#[pymethods]
impl Design {
    #[getter]
    /// `free`, `phased` or `analytic`.
    fn method(&self) -> &'static str {
        self.method
    }
    /// Solver status: `converged`, `iteration-limit`, `stalled` (free), `solved` (phased), `closed-form` (analytic).
    #[getter]
    fn status(&self) -> &str {
        &self.status
    }
    /// `flagged` when the design misses a target (solver status, flip or tilt, a limit), else `ok`.
    #[getter]
    fn verdict(&self) -> &'static str {
        if self.reason.is_some() {
            "flagged"
        } else {
            "ok"
        }
    }
    /// Why it is flagged, in the CLI's words; None when ok.
    #[getter]
    fn reason(&self) -> Option<String> {
        self.reason.clone()
    }
    /// Peak joint torque of the schedule (inverse dynamics, sampled densely), N m.
    #[getter]
    fn peak(&self) -> f64 {
        self.peak
    }
    /// `integral |tau|^2 dt` over the rows, N^2 m^2 s.
    #[getter]
    fn energy(&self) -> f64 {
        self.schedule.torque_squared_integral()
    }
    /// Phase durations (fold, twist, unfold), s.
    #[getter]
    fn durations(&self) -> (f64, f64, f64) {
        let d = self.durations;
        (d[0], d[1], d[2])
    }
    /// Manoeuvre time, s.
    #[getter]
    fn duration(&self) -> f64 {
        self.plan.duration()
    }
    /// The free-form optimiser's stopping certificate (step, constraint_violation, criticality, radius, weight, rule); None for the other methods.
    #[getter]
    fn certificate<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match self.json.get("certificate") {
            Some(c) => Ok(Some(json_loads(py, c)?)),
            None => Ok(None),
        }
    }
    /// Flip of the design's flight, deg (dynamic for free and phased, as `optimize` flies it; kinematic for analytic).
    #[getter]
    fn flip_deg(&self) -> f64 {
        self.json["flip_deg"].as_f64().unwrap_or(f64::NAN)
    }
    /// The config the design was made with (with `objective` applied).
    #[getter]
    fn config(&self) -> Config {
        Config {
            inner: Mutex::new(Snapshot {
                source: self.source.clone(),
                cfg: self.cfg.clone(),
            }),
        }
    }
    /// Sample times, s: float64, shape (N,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.schedule.rows.iter().map(|r| r.t).collect())
    }
    /// Phase of each row, 0 fold, 1 twist, 2 unfold: int64, shape (N,).
    #[getter]
    fn phase<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let p = |r: &catflip::design::plan::Row| {
            catflip::design::plan::Phase::ALL
                .iter()
                .position(|x| *x == r.phase)
                .unwrap() as i64
        };
        PyArray1::from_vec(py, self.schedule.rows.iter().map(p).collect())
    }
    /// Joint angles q1, q2, rad: float64, shape (N, 2).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(
            py,
            &self.schedule.rows.iter().map(|r| r.q).collect::<Vec<_>>(),
        )
    }
    /// Joint rates, rad/s: float64, shape (N, 2).
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(
            py,
            &self.schedule.rows.iter().map(|r| r.qd).collect::<Vec<_>>(),
        )
    }
    /// Joint accelerations, rad/s^2: float64, shape (N, 2).
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(
            py,
            &self.schedule.rows.iter().map(|r| r.qdd).collect::<Vec<_>>(),
        )
    }
    /// Joint torques tau1, tau2, N m: float64, shape (N, 2).
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(
            py,
            &self.schedule.rows.iter().map(|r| r.tau).collect::<Vec<_>>(),
        )
    }
    /// The summary `to_json()` gives, as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_loads(py, &self.json)
    }
    /// The CLI's `free.json` / `phased.json` / `analyze.json`, with `verdict` and `reason`.
    fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.json).expect("serialises")
    }
    /// The CLI's `<method>.csv` schedule.
    fn to_csv(&self) -> String {
        self.schedule.to_csv()
    }
    /// The CLI's `<method>.schedule.json`.
    fn schedule_json(&self) -> String {
        self.schedule.to_json()
    }
    /// Immutable: a copy is the same object.
    fn __copy__(slf: Py<Self>) -> Py<Self> {
        slf
    }
    fn __deepcopy__(slf: Py<Self>, _memo: &Bound<'_, PyAny>) -> Py<Self> {
        slf
    }
    fn __repr__(&self) -> String {
        format!(
            "Design(method={:?}, status={:?}, verdict={:?}, peak={:.6} N m, {} rows)",
            self.method,
            self.status,
            self.verdict(),
            self.peak,
            self.schedule.rows.len()
        )
    }
}

// --- Simulation -------------------------------------------------------------

/// A forward simulation in the full free-floating model (feed-forward, PD if `simulate.pd`,
/// the motor envelope), as `catflip simulate`. Trace arrays have one row per integrator step (M rows).
#[pyclass(frozen, module = "catflip")]
struct Simulation {
    report: SimReport,
    source: String,
    reason: Option<String>,
}

/// A design's torques are the joint's: a design made for the other joint
/// (rotation-vector torques against two hinges) cannot be flown on `cfg`'s body.
fn same_joint(cfg: &Cfg, d: &Design) -> PyResult<()> {
    let (want, made) = (cfg.cat().joint, d.cfg.cat().joint);
    if want != made {
        return Err(ConfigError::new_err(format!(
            "the {} design was made for the {} joint, but config `{}` has the {} joint; design one for this body",
            d.method,
            made.name(),
            cfg.name,
            want.name()
        )));
    }
    Ok(())
}

/// What `simulate` runs: a design's plan, a schedule file, or the analytic plan.
enum Subject {
    Design(Py<Design>),
    File(PathBuf, String),
    Analytic,
}

/// Simulates `design` (a Design, a schedule CSV path, or None for the analytic
/// schedule) on `config`'s cat, as `catflip simulate [--schedule FILE]`, with the GIL released.
/// `config` may differ from the design's (model error), but not in its joint, and its fall
/// must leave a Design its manoeuvre's time (a shorter one, as a least-time design's,
/// flies); `start` sets its `[start]` keys
/// (`{"angular_velocity": [0, 0, 0.5], "rotation_deg": [0, 30, 0]}`) for this simulation,
/// with the CLI's checks. Raises ConfigError, DesignError.
#[pyfunction]
#[pyo3(signature = (config, design = None, start = None))]
fn simulate(
    py: Python<'_>,
    config: &Config,
    design: Option<&Bound<'_, PyAny>>,
    start: Option<&Bound<'_, PyDict>>,
) -> PyResult<Simulation> {
    let (mut source, mut cfg) = config.snapshot();
    if let Some(start) = start {
        // each `[start]` key as `--set start.KEY=VALUE`, the CLI's checks
        for (k, v) in start.iter() {
            let key = format!("start.{}", k.extract::<String>()?);
            let value = toml_text(&v, &key)?;
            source.overrides.push(format!("{key}={value}"));
        }
        cfg = source.load(None).map_err(err)?;
    }
    let subject = match design {
        None => Subject::Analytic,
        Some(d) => match d.cast::<Design>() {
            Ok(d) => Subject::Design(d.clone().unbind()),
            Err(_) => {
                let p: PathBuf = d.extract().map_err(|_| {
                    PyTypeError::new_err(
                        "design must be a catflip.Design, a schedule CSV path or None",
                    )
                })?;
                let text = std::fs::read_to_string(&p).map_err(|e| {
                    err(catflip::Error::Usage(format!(
                        "cannot read schedule {}: {e}",
                        p.display()
                    )))
                })?;
                Subject::File(p, text)
            }
        },
    };
    if let Subject::Design(d) = &subject {
        let d = d.get();
        same_joint(&cfg, d)?;
        // as the controllers fly it: a manoeuvre longer than this fall
        // cannot be flown in it (a shorter one, as a least-time design, can)
        catflip::control::online::check_fits(&cfg, d.plan.as_ref()).map_err(err)?;
    }
    py.detach(move || {
        let (source, report) = match &subject {
            Subject::Design(d) => {
                let d = d.get();
                (
                    format!("{} design", d.method),
                    catflip::verify::analyze::verify(&cfg.design_spec(), d.plan.as_ref()),
                )
            }
            Subject::File(p, text) => {
                let origin = p.display().to_string();
                let s = catflip::verify::simulate::read_schedule(
                    &cfg.design_spec(),
                    &cfg.name,
                    text,
                    &origin,
                )
                .map_err(err)?;
                (
                    origin,
                    catflip::verify::analyze::verify(&cfg.design_spec(), &s),
                )
            }
            Subject::Analytic => {
                let plan = catflip::design::analytic::analytic_plan(&cfg.design_spec());
                (
                    "analytic schedule".into(),
                    catflip::verify::analyze::verify(&cfg.design_spec(), &plan),
                )
            }
        };
        let report = report.map_err(err)?;
        // as the CLI's `simulate`
        catflip::output::ensure_finite(&serde_json::to_value(&report).expect("serialises"), &[])
            .map_err(err)?;
        let reason = catflip::verdict::flight_reason(
            &catflip::verdict::Targets::of(&cfg.design_spec()),
            &catflip::verdict::Simulated::of(Ok(&report)),
        );
        Ok(Simulation {
            report,
            source,
            reason,
        })
    })
}

#[pymethods]
impl Simulation {
    /// Final rotation about the initial spine, unwrapped, deg.
    #[getter]
    fn flip_deg(&self) -> f64 {
        self.report.flip_deg
    }
    /// `pi - |flip|`, rad.
    #[getter]
    fn flip_error_rad(&self) -> f64 {
        self.report.flip_error_rad
    }
    /// Angle between the final and the initial spine, deg.
    #[getter]
    fn tilt_deg(&self) -> f64 {
        self.report.tilt_deg
    }
    /// `|q(T)|`: how far from straight the cat ends, rad.
    #[getter]
    fn final_shape_error_rad(&self) -> f64 {
        self.report.final_shape_error_rad
    }
    /// Largest angular momentum recomputed from the bodies' velocities, N m s.
    #[getter]
    fn momentum_drift_nms(&self) -> f64 {
        self.report.momentum_drift_nms
    }
    /// Largest joint torque applied, N m (config's norm).
    #[getter]
    fn peak_torque_nm(&self) -> f64 {
        self.report.peak_torque_nm
    }
    /// `flagged` when the flip or tilt misses `simulate.flip_tolerance`, else `ok`.
    #[getter]
    fn verdict(&self) -> &'static str {
        if self.reason.is_some() {
            "flagged"
        } else {
            "ok"
        }
    }
    /// Why it is flagged; None when ok.
    #[getter]
    fn reason(&self) -> Option<String> {
        self.reason.clone()
    }
    /// Step times, s: float64, shape (M,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.report.trace.iter().map(|p| p.t).collect())
    }
    /// Flip at each step, rad: float64, shape (M,).
    #[getter]
    fn flip<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.report.trace.iter().map(|p| p.flip).collect())
    }
    /// Tilt at each step, rad: float64, shape (M,).
    #[getter]
    fn tilt<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.report.trace.iter().map(|p| p.tilt).collect())
    }
    /// Joint angles, rad: float64, shape (M, 2).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(
            py,
            &self.report.trace.iter().map(|p| p.q).collect::<Vec<_>>(),
        )
    }
    /// Applied joint torques, N m: float64, shape (M, 2).
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(
            py,
            &self.report.trace.iter().map(|p| p.tau).collect::<Vec<_>>(),
        )
    }
    /// Rear half's attitude quaternion (w, x, y, z): float64, shape (M, 4).
    #[getter]
    fn attitude<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(
            py,
            &self
                .report
                .trace
                .iter()
                .map(|p| p.attitude)
                .collect::<Vec<_>>(),
        )
    }
    /// The CLI's `simulate --json`.
    fn to_json(&self) -> String {
        let mut v = serde_json::to_value(&self.report).expect("serialises");
        v["source"] = self.source.clone().into();
        serde_json::to_string_pretty(&with_verdict(v, &self.reason)).expect("serialises")
    }
    /// `to_json()` as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (self.to_json(),))
    }
    /// The CLI's `simulation.csv`.
    fn to_csv(&self) -> String {
        let mut s = String::from("t_s,flip_rad,tilt_rad,q1_rad,q2_rad,tau1_nm,tau2_nm\n");
        for p in &self.report.trace {
            s.push_str(&format!(
                "{:.9},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e}\n",
                p.t, p.flip, p.tilt, p.q[0], p.q[1], p.tau[0], p.tau[1]
            ));
        }
        s
    }
    /// Immutable: a copy is the same object.
    fn __copy__(slf: Py<Self>) -> Py<Self> {
        slf
    }
    fn __deepcopy__(slf: Py<Self>, _memo: &Bound<'_, PyAny>) -> Py<Self> {
        slf
    }
    fn __repr__(&self) -> String {
        format!(
            "Simulation(source={:?}, flip_deg={:.6}, tilt_deg={:.3e}, verdict={:?})",
            self.source,
            self.report.flip_deg,
            self.report.tilt_deg,
            self.verdict()
        )
    }
}

// --- least height, sweep, run -----------------------------------------------

/// The robot builder's answer: can the motors flip the cat from `fall.height`, and the least drop height
/// found (`run`'s least-height stage).
#[pyclass(frozen, module = "catflip")]
struct LeastHeight {
    answer: catflip::design::least_height::HeightAnswer,
    phased_m: f64,
}

#[pymethods]
impl LeastHeight {
    /// Whether the least height found is within `fall.height`.
    #[getter]
    fn possible(&self) -> bool {
        self.answer.possible
    }
    /// The configured drop height, m.
    #[getter]
    fn height_m(&self) -> f64 {
        self.answer.height_m
    }
    /// The least drop height found, m (an upper bound on the true one).
    #[getter]
    fn least_height_m(&self) -> f64 {
        self.answer.least_height_m
    }
    /// A lower bound on the least drop height, m, or None (the answer's
    /// `least_height_lower_bound_m`: the best stall-only design's, a local
    /// optimum, so an estimate; given only below the answer).
    #[getter]
    fn least_height_lower_bound_m(&self) -> Option<f64> {
        self.answer.least_height_lower_bound_m
    }
    /// Whether the motors need a fall longer than any catflip designs (30 s):
    /// then not possible from any height, and no schedule.
    #[getter]
    fn beyond_longest_fall(&self) -> bool {
        self.answer.beyond_longest_fall
    }
    /// The phased time design's least height, m.
    #[getter]
    fn phased_least_height_m(&self) -> f64 {
        self.phased_m
    }
    /// The shortest manoeuvre found inside the motor envelope, s.
    #[getter]
    fn least_time_s(&self) -> f64 {
        self.answer.least_time_s
    }
    /// Which design settles the answer: `phased` or `free` (`analytic` when the
    /// motors are far beyond the longest fall and no design was made).
    #[getter]
    fn method(&self) -> &'static str {
        self.answer.method
    }
    /// That design's solver status.
    #[getter]
    fn status(&self) -> String {
        self.answer.status.name().into()
    }
    /// Times of the least-height schedule, s: float64, shape (N,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.answer.schedule.rows.iter().map(|r| r.t).collect())
    }
    /// Its joint angles, rad: float64, shape (N, 2).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(
            py,
            &self
                .answer
                .schedule
                .rows
                .iter()
                .map(|r| r.q)
                .collect::<Vec<_>>(),
        )
    }
    /// Its joint torques, N m: float64, shape (N, 2).
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(
            py,
            &self
                .answer
                .schedule
                .rows
                .iter()
                .map(|r| r.tau)
                .collect::<Vec<_>>(),
        )
    }
    /// The answer in one sentence, as the CLI's table prints it.
    fn sentence(&self) -> String {
        pythonic(self.answer.sentence())
    }
    /// The `answer` object of `summary.json`.
    fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.answer).expect("serialises")
    }
    /// The schedule at the least height, as `least-height.csv`.
    fn to_csv(&self) -> String {
        self.answer.schedule.to_csv()
    }
    fn __repr__(&self) -> String {
        format!("LeastHeight({})", self.sentence())
    }
}

/// The least drop height at which the config's motors flip the cat (the phased and
/// free-form `time` designs inside the motor envelope), or None when the config sets no
/// motor limit. GIL released.
#[pyfunction]
fn least_height(py: Python<'_>, config: &Config) -> PyResult<Option<LeastHeight>> {
    let (_, cfg) = config.snapshot();
    interruptible(
        py,
        || {},
        move || {
            let h = catflip::design::least_height::heights(
                &cfg.design_spec(),
                catflip::design::least_height::Families::Both,
                |_| {},
            )
            .map_err(err)?;
            Ok(h.map(|h| LeastHeight {
                answer: h.answer,
                phased_m: h.phased_m,
            }))
        },
    )
}

/// The motors that would flip the cat from `height`, m: `catflip size CONFIG --height H
/// [--points P] [--gear-evaluations G] --json` in memory (nothing written), with the GIL
/// released: the CLI's `size.json` as a dict (`curve`, the stall torque against no-load
/// speed that just makes it; `gear`, the best gear ratio for the config's motor and the
/// least height it gives; the asymptotes). The config needs `limits.max_torque` and
/// `limits.no_load_speed`; `height` replaces its `fall.height`; its `design.objective` is
/// not used (the curve is of least-time designs). A point whose design failed is left out
/// of `curve` and named in `failed` (the CLI warns and exits 3 then).
#[pyfunction]
#[pyo3(signature = (config, height, points = 8, gear_evaluations = 6))]
fn size<'py>(
    py: Python<'py>,
    config: &Config,
    height: f64,
    points: i64,
    gear_evaluations: i64,
) -> PyResult<Bound<'py, PyAny>> {
    // the CLI's options, as this function names them
    let in_call_names = |e: catflip::Error| match e {
        catflip::Error::Usage(m) => err(catflip::Error::Usage(
            m.replace("--height ", "height=")
                .replace("--points ", "points=")
                .replace("--gear-evaluations ", "gear_evaluations="),
        )),
        e => err(e),
    };
    let count = |name: &str, n: i64| {
        usize::try_from(n).map_err(|_| {
            ConfigError::new_err(format!(
                "{name}={n}: give a count (points: 2 to 40, gear_evaluations: 0 to 20)"
            ))
        })
    };
    let settings = catflip::size::SizeSettings {
        points: count("points", points)?,
        gear_evaluations: count("gear_evaluations", gear_evaluations)?,
    };
    settings.validate().map_err(in_call_names)?;
    let (source, _) = config.snapshot();
    let cfg = source
        .load(Some(&format!("fall.height={height}")))
        .map_err(|e| in_call_names(catflip::size::height_error(height, e)))?;
    let q = catflip::size::question(&cfg, height).map_err(in_call_names)?;
    let json = interruptible(
        py,
        || {},
        move || {
            let a = catflip::size::size(&q, &settings, |_, _| {}).map_err(err)?;
            Ok(serde_json::to_value(&a).expect("serialises"))
        },
    )?;
    json_loads(py, &json)
}

/// Columns of a sweep: floats (NaN where a method gave none) and texts.
/// The columns of `catflip.sweep` (use that).
#[pyfunction]
#[pyo3(signature = (config, key, values, methods, threads = None, least_height_only = false))]
fn sweep_columns<'py>(
    py: Python<'py>,
    config: &Config,
    key: String,
    values: Vec<f64>,
    methods: Vec<String>,
    threads: Option<i64>,
    least_height_only: bool,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let (source, _) = config.snapshot();
    let mut m = catflip::sweep::Methods {
        analytic: false,
        phased: false,
        free: false,
        peaks: !least_height_only,
    };
    if methods.is_empty() {
        return Err(ConfigError::new_err(
            "methods is empty: give one or more of analytic, phased and free",
        ));
    }
    for name in &methods {
        match name.as_str() {
            "analytic" => m.analytic = true,
            "phased" => m.phased = true,
            "free" => m.free = true,
            other => {
                return Err(ConfigError::new_err(format!(
                    "unknown method `{other}` in methods; use analytic, phased and/or free"
                )));
            }
        }
    }
    if let Some(t) = threads
        && t < 1
    {
        return Err(ConfigError::new_err(format!(
            "threads={t}: at least one point must be computed at a time; give 1 or more, or None for one per core"
        )));
    }
    if values.is_empty() {
        return Err(ConfigError::new_err(
            "values is empty: give at least one value to sweep",
        ));
    }
    let threads = threads.map(|t| t as usize);
    let threads =
        threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let asked = stop.clone();
    let (points, csv) = interruptible(
        py,
        move || asked.store(true, std::sync::atomic::Ordering::SeqCst),
        move || {
            let points: Vec<_> = catflip::sweep::sweep_values(
                &key,
                &values,
                |v| source.load(Some(&format!("{key}={v}"))),
                m,
                threads,
                &stop,
                |_, _| {},
            )
            .map_err(|e| match e {
                // the values named as given, not as a `--set-range`
                catflip::Error::Range { arg, message } => {
                    ConfigError::new_err(pythonic(format!("{arg}: {message}")))
                }
                e => err(e),
            })?
            .into_iter()
            .flatten()
            .collect();
            let csv = catflip::sweep::to_csv(&key, &points);
            Ok((points, csv))
        },
    )?;
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(&catflip::sweep::SweepPoint) -> Option<f64>| {
        points
            .iter()
            .map(|p| f(p).unwrap_or(f64::NAN))
            .collect::<Vec<f64>>()
    };
    d.set_item(
        "value",
        vector(py, points.iter().map(|p| p.value).collect()),
    )?;
    d.set_item("analytic_peak_nm", vector(py, col(&|p| p.analytic_peak_nm)))?;
    d.set_item("phased_peak_nm", vector(py, col(&|p| p.phased_peak_nm)))?;
    d.set_item("free_peak_nm", vector(py, col(&|p| p.free_peak_nm)))?;
    d.set_item("phased_bend_deg", vector(py, col(&|p| p.phased_bend_deg)))?;
    d.set_item("free_bend_deg", vector(py, col(&|p| p.free_bend_deg)))?;
    d.set_item(
        "least_height_phased_m",
        vector(py, col(&|p| p.least_height_phased_m)),
    )?;
    d.set_item(
        "least_height_free_m",
        vector(py, col(&|p| p.least_height_free_m)),
    )?;
    d.set_item(
        "free_status",
        points
            .iter()
            .map(|p| p.free_status.map(|s| s.name()))
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "error",
        points.iter().map(|p| p.error.clone()).collect::<Vec<_>>(),
    )?;
    Ok((d, csv))
}

/// The Monte Carlo study of `catflip robustness CONFIG --trials N --seed S [--threads T]
/// --json`, in memory (nothing written), with the GIL released: the CLI's `robustness.json`
/// as a dict (`trials`, `controllers` with each one's `name`, `success_rate` and `ci95`,
/// ...) and `"csv"`, the text of its `robustness.csv`. Ctrl-C stops it after the trials in
/// flight. A RuntimeWarning (the CLI's `warning:` line) when the replans' p99 wall time on
/// this machine is over the control period.
#[pyfunction]
#[pyo3(signature = (config, trials = 1000, seed = 1, threads = None))]
fn robustness<'py>(
    py: Python<'py>,
    config: &Config,
    trials: i64,
    seed: i128,
    threads: Option<i64>,
) -> PyResult<Bound<'py, PyAny>> {
    use catflip::control::robustness::{Study, replan_timing, summarise, to_csv};
    use std::sync::atomic::{AtomicBool, Ordering};
    let (_, cfg) = config.snapshot();
    let max = catflip::config::MAX_TRIALS;
    let trials = usize::try_from(trials)
        .ok()
        .filter(|t| (1..=max).contains(t))
        .ok_or_else(|| ConfigError::new_err(format!("trials = {trials}: give 1 to {max}")))?;
    // the CLI's `--seed`: any 64-bit unsigned value
    let seed = u64::try_from(seed)
        .map_err(|_| ConfigError::new_err(format!("seed = {seed}: give 0 to 2**64 - 1")))?;
    let threads = match threads {
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
        Some(t) if t >= 1 => t as usize,
        Some(t) => {
            return Err(ConfigError::new_err(format!(
                "threads={t}: at least one trial must be flown at a time; give 1 or more, or None for one per core"
            )));
        }
    };
    let stop = std::sync::Arc::new(AtomicBool::new(false));
    let asked = stop.clone();
    let (json, late) = interruptible(
        py,
        move || asked.store(true, Ordering::SeqCst),
        move || {
            let design = catflip::control::robustness::design(&cfg).map_err(err)?;
            let study = Study::new(&cfg, std::sync::Arc::new(design.plan), seed).map_err(err)?;
            // a few trials a thread at a time, so that a stop leaves little in flight
            let mut results = Vec::with_capacity(trials);
            let chunk = 4 * threads;
            let mut from = 0;
            while from < trials && !stop.load(Ordering::SeqCst) {
                let to = (from + chunk).min(trials);
                results.extend(study.run(from..to, threads, |_, _| {}));
                from = to;
            }
            let summary = summarise(
                &results,
                seed,
                study.max_tilt_deg(),
                cfg.robustness.worst_kept,
            );
            let mut json = serde_json::to_value(catflip::control::resume::Published {
                status: catflip::sweep::resume::SweepStatus::Complete,
                summary: &summary,
            })
            .expect("serialises");
            json["csv"] = to_csv(&results, true).into();
            // (the CLI's warning: there is no budget here)
            let timing = replan_timing(&results, cfg.control.period());
            let late = catflip::console::robustness::late_replans(&timing, None);
            Ok((json, late))
        },
    )?;
    if let Some(text) = late {
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyRuntimeWarning>(),
            &std::ffi::CString::new(text).expect("no NUL"),
            1,
        )?;
    }
    json_loads(py, &json)
}

/// A whole `catflip run`, kept in memory: the summary and every file it would write.
#[pyclass(frozen, module = "catflip")]
struct Run {
    summary: serde_json::Value,
    files: Vec<(String, Vec<u8>)>,
    partial: bool,
    impossible: bool,
}

/// The CLI's main job, `catflip run`, in memory (nothing written), with the GIL released.
/// Raises DesignError when every method fails.
#[pyfunction]
fn run(py: Python<'_>, config: &Config) -> PyResult<Run> {
    let (_, cfg) = config.snapshot();
    interruptible(
        py,
        || {},
        move || {
            let r = catflip::run::run(&cfg, |_| {}).map_err(err)?;
            Ok(Run {
                summary: serde_json::to_value(&r.summary).expect("serialises"),
                files: r
                    .output
                    .files()
                    .map(|(n, c)| (n.to_string(), c.to_vec()))
                    .collect(),
                partial: r.is_partial(),
                impossible: r.is_impossible(),
            })
        },
    )
}

#[pymethods]
impl Run {
    /// `summary.json` as a dict.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_loads(py, &self.summary)
    }
    /// `ok`, `partial` (some method flagged or failed: exit 3) or `impossible` (exit 4).
    #[getter]
    fn outcome(&self) -> String {
        self.summary["outcome"].as_str().unwrap_or("").into()
    }
    /// Whether the run is partial (`outcome == "partial"`, the CLI's exit 3): some design is
    /// flagged or failed in a fall the motors can do; False when the flip is impossible.
    #[getter]
    fn partial(&self) -> bool {
        self.partial
    }
    /// Whether the motors cannot flip the cat from `fall.height`.
    #[getter]
    fn impossible(&self) -> bool {
        self.impossible
    }
    /// Names of the files `catflip run` writes.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.files.iter().map(|f| f.0.clone()).collect()
    }
    /// One of the files `catflip run` writes, as text.
    fn file(&self, name: &str) -> PyResult<String> {
        let f = self.files.iter().find(|f| f.0 == name).ok_or_else(|| {
            pyo3::exceptions::PyKeyError::new_err(format!(
                "{name}: not a file of this run; see Run.names"
            ))
        })?;
        Ok(String::from_utf8_lossy(&f.1).into_owned())
    }
    fn __repr__(&self) -> String {
        format!(
            "Run(outcome={:?}, {} files)",
            self.outcome(),
            self.files.len()
        )
    }
}

// --- simulators -------------------------------------------------------------

/// The cat as MuJoCo MJCF text (`catflip export mjcf`).
#[pyfunction]
fn export_mjcf(config: &Config) -> String {
    catflip::export::mjcf(&config.snapshot().1)
}

/// The cat as URDF text (`catflip export urdf`).
#[pyfunction]
fn export_urdf(config: &Config) -> String {
    catflip::export::urdf(&config.snapshot().1)
}

/// A design's controls at a simulator's time step: what `<method>.mujoco.csv` /
/// `<method>.pybullet.csv` hold (n steps, n + 1 rows: the last is the final planned state).
#[pyclass(frozen, module = "catflip")]
struct Controls {
    controls: catflip::export::controls::Controls,
    cfg: Cfg,
    method: &'static str,
}

/// A design's controls for `simulator` (`"mujoco"` or `"pybullet"`), in its joint
/// coordinates and actuators, as `catflip run` writes them.
#[pyfunction]
#[pyo3(signature = (design, simulator = "mujoco"))]
fn controls(py: Python<'_>, design: Py<Design>, simulator: &str) -> PyResult<Controls> {
    use catflip::export::controls::Simulator;
    let sim = match simulator {
        "mujoco" => Simulator::Mujoco,
        "pybullet" => Simulator::Pybullet,
        other => {
            return Err(ConfigError::new_err(format!(
                "unknown simulator `{other}`; use \"mujoco\" or \"pybullet\""
            )));
        }
    };
    py.detach(move || {
        let d = design.get();
        Ok(Controls {
            controls: catflip::export::controls::Controls::sample(&d.cfg, d.plan.as_ref(), sim),
            cfg: d.cfg.clone(),
            method: d.method,
        })
    })
}

#[pymethods]
impl Controls {
    /// `mujoco` or `pybullet`.
    #[getter]
    fn simulator(&self) -> &'static str {
        self.controls.simulator.name()
    }
    /// Time step, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.controls.dt
    }
    /// Number of steps n.
    #[getter]
    fn steps(&self) -> usize {
        self.controls.rows.len() - 1
    }
    /// `k` of MuJoCo's DC-motor actuators (the torque columns are then the command `tau + k qd`); 0 otherwise.
    #[getter]
    fn slope(&self) -> f64 {
        self.controls.slope
    }
    /// The CSV's column names (`t_s`, then position, velocity, torque columns).
    #[getter]
    fn columns(&self) -> Vec<String> {
        self.controls
            .simulator
            .columns(self.controls.joint, self.controls.slope > 0.0)
            .split(',')
            .map(String::from)
            .collect()
    }
    /// catflip's PD stiffness, N m/rad.
    #[getter]
    fn kp(&self) -> f64 {
        catflip::verify::simulate::Controller::from_spec(&self.cfg.design_spec()).kp
    }
    /// catflip's PD damping, N m s/rad.
    #[getter]
    fn kd(&self) -> f64 {
        catflip::verify::simulate::Controller::from_spec(&self.cfg.design_spec()).kd
    }
    /// `limits.max_torque`, N m, or None.
    #[getter]
    fn max_torque(&self) -> Option<f64> {
        self.cfg.limits.max_torque
    }
    /// Peak norm: `euclidean` or `per-motor`.
    #[getter]
    fn norm(&self) -> String {
        match self.cfg.norm() {
            catflip::model::TorqueNorm::Euclidean => "euclidean",
            catflip::model::TorqueNorm::PerMotor => "per-motor",
        }
        .into()
    }
    /// Step start times, s: float64, shape (n + 1,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.controls.rows.iter().map(|r| r.t).collect())
    }
    /// Planned joint position at each row: float64, shape (n + 1, 4) (ball: quaternion, MuJoCo w x y z, pyBullet x y z w) or (n + 1, 2) (universal).
    #[getter]
    fn pos<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix_vec(
            py,
            &self
                .controls
                .rows
                .iter()
                .map(|r| r.pos.clone())
                .collect::<Vec<_>>(),
        )
    }
    /// Planned joint velocity: float64, shape (n + 1, 3) (ball) or (n + 1, 2).
    #[getter]
    fn vel<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix_vec(
            py,
            &self
                .controls
                .rows
                .iter()
                .map(|r| r.vel.clone())
                .collect::<Vec<_>>(),
        )
    }
    /// Torque (or DC command) held over each step, N m: float64, shape (n + 1, 3) or (n + 1, 2); 0 on the last row.
    #[getter]
    fn torque<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix_vec(
            py,
            &self
                .controls
                .rows
                .iter()
                .map(|r| r.torque.clone())
                .collect::<Vec<_>>(),
        )
    }
    /// The CLI's `<method>.<simulator>.csv`.
    #[pyo3(signature = (method = None))]
    fn to_csv(&self, method: Option<&str>) -> String {
        self.controls
            .to_csv(&self.cfg, method.unwrap_or(self.method))
    }
    fn __repr__(&self) -> String {
        format!(
            "Controls(simulator={:?}, dt={:.6e} s, steps={})",
            self.simulator(),
            self.controls.dt,
            self.steps()
        )
    }
}

// --- closed loop ------------------------------------------------------------

use catflip::control::online::{Kind, Online, SimState, from_sim, to_sim};

/// A state argument: 11 floats in the `<stem>.tvlqr.csv` order.
fn sim_state(state: Vec<f64>) -> PyResult<SimState> {
    state.try_into().map_err(|v: Vec<f64>| {
        ConfigError::new_err(format!(
            "state has {} values; give 11: the rear half's attitude w, x, y, z (simulator's world), lambda (3), q (2), q_dot (2), as Controller.sensed builds it",
            v.len()
        ))
    })
}

/// An attitude quaternion `w x y z` must be a rotation: of unit norm (to 1 %;
/// a simulator's is to rounding), not zero or a raw sum of noise.
fn unit_attitude(a: &[f64]) -> PyResult<()> {
    let norm = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > 1e-2 {
        return Err(ConfigError::new_err(format!(
            "the attitude quaternion {a:?} has norm {norm:.6}; give the rear half's attitude as a unit quaternion w, x, y, z"
        )));
    }
    Ok(())
}

fn pair(v: Vec<f64>, what: &str) -> PyResult<[f64; 2]> {
    v.try_into().map_err(|v: Vec<f64>| {
        ConfigError::new_err(format!("{what} has {} values; give 2", v.len()))
    })
}

/// One of `catflip robustness`'s controllers along a design, for a simulation loop run
/// outside catflip (MuJoCo, pyBullet, a robot): `torque(t, state)` is the correction
/// catflip's own closed loop sends from that measurement (docs/control.md).
///
/// The state (11 floats) is the `<stem>.tvlqr.csv` convention: the rear half's attitude
/// `W R` as a unit quaternion `w, x, y, z` in the simulators' world (gravity `-z`),
/// `lambda` (3: the angular momentum about the common centre of mass in the rear half's
/// frame, N m s), `q` (2) and `q_dot` (2): the hinge angles for the universal joint, the
/// ball's rotation vector `(v1, v2)` and its rate for the no-twist joint. `sensed` builds
/// it from a gyro. Torques are catflip's joint torques (hinge torques; rotation-vector
/// torques for the no-twist joint).
///
/// The TVLQR predicts over its delay under the corrections it already sent, so the
/// controller remembers them: a command at control step `k` forgets those from `k` on,
/// and one at `t = 0` starts a new flight. Safe to share between threads (a lock).
#[pyclass(frozen, module = "catflip")]
struct Controller {
    online: Mutex<Online>,
    cfg: Cfg,
    plan: ControllerPlan,
}

/// The design a controller follows: a Python `Design`'s, or the study's own.
enum ControllerPlan {
    Design(Py<Design>),
    Study(std::sync::Arc<dyn ShapePlan + Send + Sync>),
}

impl ControllerPlan {
    fn plan(&self) -> &dyn ShapePlan {
        match self {
            ControllerPlan::Design(d) => d.get().plan.as_ref(),
            ControllerPlan::Study(p) => p.as_ref(),
        }
    }
    fn shared(&self) -> Plan {
        match self {
            ControllerPlan::Design(d) => d.get().plan.clone(),
            ControllerPlan::Study(p) => p.clone(),
        }
    }
}

/// A controller kind by its name.
fn controller_kind(kind: &str) -> PyResult<Kind> {
    match kind {
        "tvlqr" => Ok(Kind::Tvlqr),
        "open-loop" => Ok(Kind::OpenLoop),
        "replan" => Ok(Kind::Replan),
        other => Err(ConfigError::new_err(format!(
            "unknown controller kind `{other}`; use \"tvlqr\", \"replan\" or \"open-loop\""
        ))),
    }
}

/// A flight of catflip's closed-loop simulator, with every command the controller sent.
#[pyclass(frozen, module = "catflip")]
struct Flight {
    landing_error_deg: f64,
    max_correction_nm: f64,
    times: Vec<f64>,
    measured: Vec<SimState>,
    correction: Vec<[f64; 2]>,
    draw: Option<serde_json::Value>,
}

#[pymethods]
impl Controller {
    /// The controller `kind` (`"tvlqr"`, `"replan"` or `"open-loop"`) along `design`
    /// (None: the study's design, what `catflip robustness` flies) on `config`'s model
    /// and `[control]` keys. `budget_s`: the replanning controller drops a replan that
    /// takes longer (wall clock; None: none is dropped, as in catflip's study). GIL released.
    #[new]
    #[pyo3(signature = (config, design = None, kind = "tvlqr", budget_s = None))]
    fn new(
        py: Python<'_>,
        config: &Config,
        design: Option<Py<Design>>,
        kind: &str,
        budget_s: Option<f64>,
    ) -> PyResult<Controller> {
        let kind = controller_kind(kind)?;
        if budget_s.is_some() && kind != Kind::Replan {
            return Err(ConfigError::new_err(format!(
                "budget_s applies to kind=\"replan\" (a replan's wall-clock budget); leave it out for kind=\"{}\"",
                kind.name()
            )));
        }
        if let Some(b) = budget_s
            && !(b.is_finite() && b >= 0.0)
        {
            return Err(ConfigError::new_err(format!(
                "budget_s = {b}: a replan's wall-clock budget, s, is finite and not negative (None: no budget)"
            )));
        }
        let (_, cfg) = config.snapshot();
        if let Some(d) = &design {
            same_joint(&cfg, d.get())?;
        }
        interruptible(
            py,
            || {},
            move || {
                let plan = match design {
                    Some(d) => ControllerPlan::Design(d),
                    None => ControllerPlan::Study(std::sync::Arc::new(
                        catflip::control::robustness::design(&cfg)
                            .map_err(err)?
                            .plan,
                    )),
                };
                catflip::control::online::check_fits(&cfg, plan.plan()).map_err(err)?;
                let mut online = Online::new(&cfg, plan.shared(), kind).map_err(err)?;
                online.replanning.budget_s = budget_s;
                Ok(Controller {
                    online: Mutex::new(online),
                    cfg,
                    plan,
                })
            },
        )
    }

    /// `tvlqr`, `replan` or `open-loop`.
    #[getter]
    fn kind(&self) -> &'static str {
        self.lock().kind.name()
    }

    /// The correction, N m: shape (2,) (catflip's joint torques: hinge torques for the
    /// universal joint, rotation-vector torques for the no-twist joint), on top of the
    /// feed-forward, from the measured `state` at time `t`, s: catflip's closed-loop command
    /// of the control step `floor(t / period)`. It acts from `t + delay` to the next
    /// command. After the last control step (touchdown) the last correction holds; a
    /// command at an earlier step forgets the later ones. GIL released; ConfigError for a
    /// bad `t` or state (not finite, an attitude that is not a unit quaternion to 1 %);
    /// DesignError when the prediction over the delay diverges from a state far outside
    /// the model (the flight is then reset).
    fn torque<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        state: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        // (numpy's own error for a 2-D array named neither the argument nor its shape)
        let state: Vec<f64> = state.extract().map_err(|e| {
            ConfigError::new_err(format!(
                "state: give 11 numbers, a flat sequence or an array of shape (11,) ({e})"
            ))
        })?;
        if !(t.is_finite() && t >= 0.0) {
            return Err(ConfigError::new_err(format!(
                "t = {t}: the time since release, s, is finite and not negative"
            )));
        }
        let s = sim_state(state)?;
        if s.iter().any(|v| !v.is_finite()) {
            return Err(ConfigError::new_err(format!(
                "state {s:?} has a value that is not finite"
            )));
        }
        unit_attitude(&s[..4])?;
        let u = py.detach(|| {
            let mut o = self.lock();
            let k = o.step_at(t);
            let u = o.correction(k, &from_sim(&s));
            if !u.iter().all(|x| x.is_finite()) {
                o.reset();
            }
            u
        });
        if !u.iter().all(|x| x.is_finite()) {
            return Err(DesignError::new_err(format!(
                "the correction at t = {t} s is not finite ({u:?}): the controller's prediction over the actuator delay diverged from the state {s:?}, far outside its model (check the state's units: lambda in N m s, qd in rad/s); the controller's flight was reset"
            )));
        }
        Ok(vector(py, u.to_vec()))
    }

    /// Forgets the corrections sent (a new flight; a command at t = 0 does it too).
    fn reset(&self) {
        self.lock().reset();
    }

    /// The state `torque` takes, from a rear-half attitude `[w, x, y, z]` in the
    /// simulator's world, the joint angles `q` and rates `qd` (2 each) and the rear
    /// half's gyro (3, rad/s, its own frame); `lambda` from the model's inertias.
    fn sensed<'py>(
        &self,
        py: Python<'py>,
        attitude: Vec<f64>,
        q: Vec<f64>,
        qd: Vec<f64>,
        gyro: Vec<f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let a: [f64; 4] = attitude
            .try_into()
            .map_err(|_| ConfigError::new_err("attitude: give 4 values, w x y z"))?;
        let g: [f64; 3] = gyro
            .try_into()
            .map_err(|_| ConfigError::new_err("gyro: give 3 values, rad/s"))?;
        let (q, qd) = (pair(q, "q")?, pair(qd, "qd")?);
        if a.iter()
            .chain(&g)
            .chain(&q)
            .chain(&qd)
            .any(|v| !v.is_finite())
        {
            return Err(ConfigError::new_err(format!(
                "a measurement is not finite: attitude {a:?}, q {q:?}, qd {qd:?}, gyro {g:?}"
            )));
        }
        unit_attitude(&a)?;
        let s = self.lock().sensed(a, q, qd, g);
        Ok(vector(py, s.to_vec()))
    }

    /// The motor envelope (saturation and the back-EMF line of `[limits]`) on joint
    /// torques `tau` at joint speed `qd`, as catflip's plant applies it; a speed that is
    /// not a number gives NaN under a torque-speed line.
    fn clip<'py>(
        &self,
        py: Python<'py>,
        tau: Vec<f64>,
        qd: Vec<f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        // (NaN in, NaN out: a simulation that diverged between two steps
        // calls this inside its own step)
        let c = self.lock().motor.clip(pair(tau, "tau")?, pair(qd, "qd")?);
        Ok(vector(py, c.to_vec()))
    }

    /// Simulator step h, s (touchdown at `steps * h`).
    #[getter]
    fn step(&self) -> f64 {
        self.lock().reference.h
    }
    /// Simulator steps to touchdown.
    #[getter]
    fn steps(&self) -> usize {
        self.lock().reference.steps
    }
    /// Release to touchdown, s.
    #[getter]
    fn duration(&self) -> f64 {
        self.lock().reference.duration()
    }
    /// Time between two commands, s (`open-loop`: one simulator step).
    #[getter]
    fn period(&self) -> f64 {
        let o = self.lock();
        o.period_steps() as f64 * o.reference.h
    }
    /// Simulator steps between two commands.
    #[getter]
    fn period_steps(&self) -> usize {
        self.lock().period_steps()
    }
    /// The delay the controller predicts over, s (`open-loop`: 0).
    #[getter]
    fn delay(&self) -> f64 {
        let o = self.lock();
        o.delay_steps() as f64 * o.reference.h
    }
    /// Control steps with a command of their own.
    #[getter]
    fn control_steps(&self) -> usize {
        self.lock().control_steps()
    }
    /// Largest feed-forward torque, N m (the config's norm).
    #[getter]
    fn peak_torque(&self) -> f64 {
        self.lock().reference.peak_torque
    }
    /// The feed-forward of the plan in use at every half step, `tau(j h / 2)` (a replan
    /// changes it from the instant its plan acts on): float64, shape (2 steps + 1, 2).
    #[getter]
    fn feedforward<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(py, &self.lock().reference.completed().ff)
    }
    /// The planned shape `(q1, q2, qd1, qd2)` at every step (the PD's reference): shape (steps + 1, 4).
    #[getter]
    fn shape<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<[f64; 4]> = self
            .lock()
            .reference
            .completed()
            .shape
            .iter()
            .map(|(q, qd)| [q[0], q[1], qd[0], qd[1]])
            .collect();
        matrix(py, &rows)
    }
    /// The model's state under the feed-forward alone at every step, in `torque`'s
    /// convention: float64, shape (steps + 1, 11).
    #[getter]
    fn nominal<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<SimState> = self
            .lock()
            .reference
            .completed()
            .nominal
            .iter()
            .map(to_sim)
            .collect();
        matrix(py, &rows)
    }
    /// The TVLQR gains `K_k` (u = -K x): float64, shape (control steps, 2, 10).
    #[getter]
    fn gains<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray3<f64>> {
        let o = self.lock();
        let flat: Vec<f64> = o
            .tvlqr
            .gains
            .iter()
            .flat_map(|g| (0..2).flat_map(move |i| (0..10).map(move |j| g[(i, j)])))
            .collect();
        numpy::ndarray::Array3::from_shape_vec((o.tvlqr.gains.len(), 2, 10), flat)
            .expect("2 x 10 gains")
            .into_pyarray(py)
    }
    /// When each TVLQR correction starts to act, s: shape (control steps,).
    #[getter]
    fn t_apply<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let o = self.lock();
        let h = o.reference.h;
        vector(py, o.tvlqr.starts.iter().map(|&s| s as f64 * h).collect())
    }
    /// Corrections sent since the last reset, by control step: shape (k, 2).
    #[getter]
    fn issued<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(py, self.lock().issued())
    }
    /// The gains as the `<stem>.tvlqr.csv` text (`catflip export mjcf CONFIG --schedule S.csv`
    /// writes it for the schedule read back from its CSV). GIL released.
    fn gains_csv(&self, py: Python<'_>) -> PyResult<String> {
        py.detach(|| catflip::control::export::gains_csv(&self.cfg, self.plan.plan()))
            .map_err(err)
    }

    /// The same design's controller of another `kind`, its gains reused (no new design). GIL released.
    fn with_kind(&self, py: Python<'_>, kind: &str) -> PyResult<Controller> {
        let kind = controller_kind(kind)?;
        let plan = match &self.plan {
            ControllerPlan::Design(d) => ControllerPlan::Design(d.clone_ref(py)),
            ControllerPlan::Study(p) => ControllerPlan::Study(p.clone()),
        };
        let mut online = self.lock().clone();
        Ok(py.detach(move || {
            online.kind = kind;
            online.reset();
            Controller {
                online: Mutex::new(online),
                cfg: self.cfg.clone(),
                plan,
            }
        }))
    }

    /// A flight of catflip's closed-loop simulator under this controller: the nominal
    /// (`trial=None`: the model, the config's start, no delay or noise), or trial `trial`
    /// of `catflip robustness --seed SEED` (its draws, delay and noises). GIL released.
    #[pyo3(signature = (trial = None, seed = 1))]
    fn fly(&self, py: Python<'_>, trial: Option<i64>, seed: i128) -> PyResult<Flight> {
        let trial = trial.map(|t| count(t, "trial")).transpose()?;
        // the CLI's `--seed`: any 64-bit unsigned value
        let seed = u64::try_from(seed)
            .map_err(|_| ConfigError::new_err(format!("seed = {seed}: give 0 to 2**64 - 1")))?;
        Ok(py.detach(|| {
            let o = self.lock().clone();
            let r = o.flight_reference();
            let (draw, flight) = match trial {
                None => (None, catflip::control::closed_loop::Flight::nominal(r)),
                Some(i) => {
                    let (d, f) = catflip::control::robustness::trial_flight(
                        &self.cfg, &o.design, &o.tvlqr, seed, i,
                    );
                    (Some(d), f)
                }
            };
            let fb = match o.kind {
                Kind::Tvlqr => catflip::control::closed_loop::Feedback::Tvlqr(&o.tvlqr),
                Kind::Replan => {
                    catflip::control::closed_loop::Feedback::Replan(&o.tvlqr, &o.replanning)
                }
                Kind::OpenLoop => match &draw {
                    Some(d) => catflip::control::robustness::open_loop(&o.pd, d),
                    None => catflip::control::closed_loop::Feedback::JointPd {
                        kp: o.pd.kp,
                        kd: o.pd.kd,
                    },
                },
            };
            let mut log = catflip::control::closed_loop::Log::default();
            let landing =
                catflip::control::closed_loop::fly_logged(r, fb, &o.motor, flight, Some(&mut log));
            let log = log.commands;
            Flight {
                landing_error_deg: landing.error_deg,
                max_correction_nm: landing.max_correction_nm,
                times: log.iter().map(|c| c.step as f64 * r.h).collect(),
                measured: log.iter().map(|c| to_sim(&c.measured)).collect(),
                correction: log.iter().map(|c| c.correction).collect(),
                draw: draw.map(|d| serde_json::to_value(d).expect("serialises")),
            }
        }))
    }

    fn __repr__(&self) -> String {
        let o = self.lock();
        format!(
            "Controller(kind={:?}, period={:.6e} s, delay={:.6e} s, {} control steps)",
            o.kind.name(),
            o.period_steps() as f64 * o.reference.h,
            o.delay_steps() as f64 * o.reference.h,
            o.control_steps()
        )
    }
}

impl Controller {
    fn lock(&self) -> std::sync::MutexGuard<'_, Online> {
        self.online.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[pymethods]
impl Flight {
    /// The belly's angle from straight down at touchdown, deg (NaN: the flight diverged).
    #[getter]
    fn landing_error_deg(&self) -> f64 {
        self.landing_error_deg
    }
    /// Largest correction sent, N m (the motor norm).
    #[getter]
    fn max_correction_nm(&self) -> f64 {
        self.max_correction_nm
    }
    /// Measurement time of each command, s: shape (K,).
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector(py, self.times.clone())
    }
    /// What the controller measured (sensor noise included), `torque`'s convention: shape (K, 11).
    #[getter]
    fn measured<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(py, &self.measured)
    }
    /// The correction sent from each measurement, N m: shape (K, 2).
    #[getter]
    fn correction<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(py, &self.correction)
    }
    /// The trial's draws as a dict (`robustness.csv`'s draw columns grouped: `spin_rad_s`,
    /// `mass_error`, ... as pairs and triples); None for the nominal.
    #[getter]
    fn draw<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.draw.as_ref().map(|d| json_loads(py, d)).transpose()
    }
    fn __repr__(&self) -> String {
        format!(
            "Flight(landing_error_deg={:.6}, {} commands)",
            self.landing_error_deg,
            self.times.len()
        )
    }
}

#[pymodule]
fn _catflip(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("CatflipError", py.get_type::<CatflipError>())?;
    m.add("ConfigError", py.get_type::<ConfigError>())?;
    m.add("DesignError", py.get_type::<DesignError>())?;
    m.add("ImpossibleError", py.get_type::<ImpossibleError>())?;
    m.add("UnitSlipWarning", py.get_type::<UnitSlipWarning>())?;
    m.add_class::<Config>()?;
    m.add_class::<Design>()?;
    m.add_class::<Simulation>()?;
    m.add_class::<LeastHeight>()?;
    m.add_class::<Run>()?;
    m.add_class::<Controls>()?;
    m.add_class::<Controller>()?;
    m.add_class::<Flight>()?;
    m.add_function(wrap_pyfunction!(design, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(least_height, m)?)?;
    m.add_function(wrap_pyfunction!(size, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_columns, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(robustness, m)?)?;
    m.add_function(wrap_pyfunction!(export_mjcf, m)?)?;
    m.add_function(wrap_pyfunction!(export_urdf, m)?)?;
    m.add_function(wrap_pyfunction!(controls, m)?)?;
    Ok(())
}
