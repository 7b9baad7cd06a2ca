//! `docs/configuration.md` against the code: every key the config accepts has
//! a row, every row names a key the config accepts, and every documented
//! default is the code's default. Either side changing alone fails here.

mod util;

use catflip::Config;
use std::collections::BTreeMap;

/// The least config the code accepts: the keys documented as `required`.
const MINIMAL: &str =
    "name = \"doc\"\n[cat]\nmass = 1.0\nlength = 1.0\nradius = 0.1\n[fall]\nheight = 10.0\n";

/// A documented key's row: its default and its unit cells.
struct Row {
    default: String,
    unit: String,
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
