//! `docs/configuration.md` against the code: every key the config accepts has
//! a row, every row names a key the config accepts, and every documented
//! default is the code's default. Either side changing alone fails here.

use crate::util;

use catflip::Config;
use std::collections::BTreeMap;

/// The least config the code accepts: the keys documented as `required`.
const MINIMAL: &str =
    "name = \"doc\"\n[cat]\nmass = 1.0\nlength = 1.0\nradius = 0.1\n[fall]\nheight = 10.0\n";

/// A documented key's row: its default, unit and allowed cells.
struct Row {
    default: String,
    unit: String,
    allowed: String,
}

/// The rows of the document's key tables: `| `key` | default | unit | allowed | ... |`.
fn documented() -> BTreeMap<String, Row> {
    let text = std::fs::read_to_string(util::repo().join("docs/configuration.md"))
        .expect("docs/configuration.md exists");
    let mut rows = BTreeMap::new();
    for line in text.lines() {
        let cells = cells(line);
        let Some(key) = cells.first().and_then(|c| backticked(c)) else {
            continue;
        };
        assert!(
            cells.len() >= 4,
            "docs/configuration.md: the row of `{key}` needs key, default, unit and allowed cells: {line}"
        );
        let row = Row {
            default: cells[1].clone(),
            unit: cells[2].clone(),
            allowed: cells[3].clone(),
        };
        assert!(
            rows.insert(key.to_string(), row).is_none(),
            "docs/configuration.md documents `{key}` twice"
        );
    }
    assert!(
        !rows.is_empty(),
        "no key rows found in docs/configuration.md"
    );
    rows
}

/// A markdown table row's cells, `\|` kept inside a cell; empty for other lines.
fn cells(line: &str) -> Vec<String> {
    let line = line.trim();
    if !line.starts_with('|') || !line.ends_with('|') {
        return Vec::new();
    }
    let inner = &line[1..line.len() - 1];
    let mut out = vec![String::new()];
    let mut chars = inner.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek() == Some(&'|') => {
                out.last_mut().unwrap().push('|');
                chars.next();
            }
            '|' => out.push(String::new()),
            c => out.last_mut().unwrap().push(c),
        }
    }
    out.iter().map(|c| c.trim().to_string()).collect()
}

/// `x` of a cell that is exactly `` `x` ``.
fn backticked(cell: &str) -> Option<&str> {
    cell.strip_prefix('`')
        .and_then(|c| c.strip_suffix('`'))
        .filter(|c| !c.contains('`'))
}

/// The config with `overrides` on the minimal one, as the command line gives them.
fn parse(overrides: &[String]) -> catflip::Result<Config> {
    Config::from_toml(MINIMAL, "minimal config", overrides)
}

/// The field names a section accepts, from the parser's own refusal of an
/// unknown one (`unknown field `zz`, expected one of `a`, `b``); `None` when
/// `section` is not a table of fields (a number, a word, a list).
fn fields_of(section: &str) -> Option<Vec<String>> {
    const PROBE: &str = "zz_not_a_key";
    let key = if section.is_empty() {
        PROBE.to_string()
    } else {
        format!("{section}.{PROBE}")
    };
    let message = parse(&[format!("{key}=1")]).err()?.to_string();
    let listed = message.split_once(&format!("unknown field `{PROBE}`"))?.1;
    let listed = listed.split_once("expected").map_or("", |(_, l)| l);
    Some(
        listed
            .split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_string)
            .collect(),
    )
}

/// Every key the code accepts, sections walked by asking the parser.
fn accepted(section: &str, out: &mut Vec<String>) {
    for field in fields_of(section).unwrap_or_default() {
        let key = if section.is_empty() {
            field
        } else {
            format!("{section}.{field}")
        };
        if fields_of(&key).is_some() {
            accepted(&key, out);
        } else {
            out.push(key);
        }
    }
}

/// The default config's value at a dotted key, if it has one.
fn value_at<'a>(table: &'a toml::Table, key: &str) -> Option<&'a toml::Value> {
    let (head, rest) = match key.split_once('.') {
        Some((h, r)) => (h, Some(r)),
        None => (key, None),
    };
    let v = table.get(head)?;
    match rest {
        None => Some(v),
        Some(r) => value_at(v.as_table()?, r),
    }
}

#[test]
fn every_key_the_code_accepts_is_documented_and_no_other() {
    let docs = documented();
    let mut code = Vec::new();
    accepted("", &mut code);
    // the walk itself found the sections, including the optional ones
    for key in ["name", "cat.front.mass", "limits.max_torque", "free.nodes"] {
        assert!(
            code.iter().any(|k| k == key),
            "the walk missed {key}: {code:?}"
        );
    }
    let missing: Vec<_> = code.iter().filter(|k| !docs.contains_key(*k)).collect();
    assert!(
        missing.is_empty(),
        "keys the code accepts but docs/configuration.md does not document: {missing:?}"
    );
    let unknown: Vec<_> = docs.keys().filter(|k| !code.contains(k)).collect();
    assert!(
        unknown.is_empty(),
        "keys docs/configuration.md documents but the code does not accept: {unknown:?}"
    );
}

#[test]
fn every_documented_default_is_the_codes_default() {
    let default = parse(&[]).expect("the minimal config parses");
    let table = toml::Table::try_from(&default).expect("a config serialises");
    for (key, row) in documented() {
        match row.default.as_str() {
            "required" => {
                // leaving it out of the minimal config is refused
                let mut t: toml::Table = toml::from_str(MINIMAL).unwrap();
                let (section, leaf) = key.rsplit_once('.').unwrap_or(("", &key));
                let holder = if section.is_empty() {
                    &mut t
                } else {
                    t.get_mut(section)
                        .and_then(|s| s.as_table_mut())
                        .unwrap_or_else(|| panic!("{key}: required, but not in the minimal config"))
                };
                assert!(
                    holder.remove(leaf).is_some(),
                    "{key} is documented as required but the minimal config lacks it"
                );
                let text = toml::to_string(&t).unwrap();
                let e = Config::from_toml(&text, "t", &[])
                    .expect_err(&format!(
                        "{key} is documented as required, but a config without it parses"
                    ))
                    .to_string();
                assert!(e.contains(leaf), "{key}: the refusal should name it: {e}");
            }
            "none" => assert!(
                value_at(&table, &key).is_none(),
                "{key} is documented with default none, but the code's default is {:?}",
                value_at(&table, &key)
            ),
            cell => {
                let literal = backticked(cell).unwrap_or_else(|| {
                    panic!("{key}: the default cell must be `value`, required or none, not {cell}")
                });
                assert!(
                    value_at(&table, &key).is_some(),
                    "{key}: the code has no default value, the document says {literal}"
                );
                // the documented value, given as a user would, changes nothing
                let set = parse(&[format!("{key}={literal}")]).unwrap_or_else(|e| {
                    panic!("{key}={literal} from the document is refused: {e}")
                });
                assert!(
                    set == default,
                    "{key}: the documented default {literal} is not the code's {:?}",
                    value_at(&table, &key)
                );
            }
        }
    }
}

#[test]
fn documented_units_are_the_units_sweeps_label_axes_with() {
    for (key, row) in documented() {
        if let Some((_, unit)) = catflip::config::UNITS.iter().find(|(k, _)| *k == key) {
            assert_eq!(row.unit, *unit, "{key}: unit in docs/configuration.md");
        }
    }
}

/// One end of a documented range: the bound and whether it is allowed.
type End = Option<(f64, bool)>;

/// The simple forms of an allowed cell: `> a`, `>= a`, `(a, b)` with `[`/`]`
/// for included ends, `a to b` (whole numbers, both ends included); `None`
/// for the others (they involve other keys and are checked elsewhere).
fn range(cell: &str) -> Option<(End, End)> {
    let num = |s: &str| match s.trim() {
        "pi" => Some(std::f64::consts::PI),
        s => s.parse::<f64>().ok(),
    };
    if let Some(a) = cell.strip_prefix(">= ") {
        return Some((Some((num(a)?, true)), None));
    }
    if let Some(a) = cell.strip_prefix("> ") {
        return Some((Some((num(a)?, false)), None));
    }
    if let Some((a, b)) = cell.split_once(" to ") {
        return Some((Some((num(a)?, true)), Some((num(b)?, true))));
    }
    let open = cell.chars().next()?;
    let close = cell.chars().last()?;
    if "([".contains(open) && ")]".contains(close) {
        let (a, b) = cell[1..cell.len() - 1].split_once(", ")?;
        return Some((Some((num(a)?, open == '[')), Some((num(b)?, close == ']'))));
    }
    None
}

/// The words of an allowed cell that lists names: `` `a`, `b` ``.
fn words(cell: &str) -> Option<Vec<&str>> {
    cell.split(", ").map(backticked).collect()
}

/// Each documented range holds at its ends: an included end is accepted,
/// an excluded one (or one step past an included one) is refused, naming
/// the key; each listed word is accepted and another refused.
#[test]
fn documented_ranges_and_words_are_the_ones_the_code_checks() {
    let refused = |key: &str, value: &str| match parse(&[format!("{key}={value}")]) {
        Ok(_) => {
            panic!("docs/configuration.md: {key}={value} should be refused, the code accepts it")
        }
        Err(e) => assert!(
            e.to_string().contains(key),
            "{key}={value} is refused without naming the key: {e}"
        ),
    };
    let accepted = |key: &str, value: &str| {
        let mut sets = vec![format!("{key}={value}")];
        if key == "design.objective" && value == "time" {
            // (the least time needs a limit to be finite: the docs say so)
            sets.push("limits.max_torque=1".into());
        }
        if let Err(e) = parse(&sets) {
            panic!("docs/configuration.md allows {key}={value}, the code refuses it: {e}")
        }
    };
    let mut checked = 0;
    for (key, row) in documented() {
        if let Some((lo, hi)) = range(&row.allowed) {
            // whole numbers as TOML integers, which every numeric key takes
            let show = |x: f64| {
                if x.fract() == 0.0 {
                    format!("{}", x as i64)
                } else {
                    format!("{x:?}")
                }
            };
            for (end, step) in [(lo, -1.0), (hi, 1.0)] {
                match end {
                    Some((x, true)) => {
                        accepted(&key, &show(x));
                        refused(&key, &show(x + step));
                    }
                    Some((x, false)) => refused(&key, &show(x)),
                    None => {}
                }
            }
            checked += 1;
        } else if let Some(words) = words(&row.allowed) {
            for w in &words {
                accepted(&key, w);
            }
            refused(&key, "not-a-listed-word");
            checked += 1;
        }
    }
    assert!(
        checked >= 20,
        "only {checked} allowed cells were in a form this test reads"
    );
}
