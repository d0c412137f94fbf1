//! The mountings file (the `[[sensors]]` tables `examples/laser_mounting.rs` prints): reading
//! it, with errors naming the file and line, and matching its lasers to a recording's topics.
//!
//! Not for: estimating the mountings ([`crate::laser2d::mounting`]).

use super::*;

/// One `[[sensors]]` table of a mountings file ([`parse_mountings`]).
#[derive(Clone, Debug, PartialEq)]
pub struct NamedMounting {
    /// The laser's name (its topic without the leading `/`).
    pub name: String,
    /// Its pose on the robot.
    pub mounting: Pose2,
    /// The file's line of its `[[sensors]]` header.
    pub line: usize,
}

/// Reads the `[[sensors]]` tables that `examples/laser_mounting.rs` prints (`text`, from the
/// file `path`): each with `name = "…"` and `mounting = [x, y, heading]`; comments (`#`) and
/// blank lines are skipped. Any other line, key or table, a value that does not parse, a
/// table without `name` or `mounting`, a name given twice or no table at all is an error
/// naming the file and the line.
pub fn parse_mountings(text: &str, path: &std::path::Path) -> Result<Vec<NamedMounting>> {
    let err = |line: usize, field: &str, reason: String| Error::parse(path, line, field, reason);
    let mut out: Vec<(usize, Option<String>, Option<Pose2>)> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        let line = match raw.find('#') {
            // a `#` outside quotes starts a comment (the first `#` is taken)
            Some(c) if raw[..c].matches('"').count() % 2 == 0 => &raw[..c],
            _ => raw,
        }
        .trim();
        if line.is_empty() {
            continue;
        }
        if line == "[[sensors]]" {
            out.push((n, None, None));
            continue;
        }
        if line.starts_with('[') {
            return Err(err(n, line, "only [[sensors]] tables are read".into()));
        }
        let Some((key, value)) = line.split_once('=') else {
            return Err(err(n, line, "expected `key = value`".into()));
        };
        let (key, value) = (key.trim(), value.trim());
        let Some(table) = out.last_mut() else {
            return Err(err(
                n,
                key,
                "a key before the first [[sensors]] table".into(),
            ));
        };
        match key {
            "name" => {
                let name = value
                    .strip_prefix('"')
                    .and_then(|v| v.strip_suffix('"'))
                    .filter(|v| !v.is_empty() && !v.contains('"'))
                    .ok_or_else(|| err(n, key, format!("{value} is not a quoted name")))?;
                if table.1.replace(name.to_string()).is_some() {
                    return Err(err(n, key, "given twice in one table".into()));
                }
            }
            "mounting" => {
                let inner = value
                    .strip_prefix('[')
                    .and_then(|v| v.strip_suffix(']'))
                    .ok_or_else(|| err(n, key, format!("{value} is not [x, y, heading]")))?;
                let v: Vec<f64> = inner
                    .split(',')
                    .map(|s| s.trim().parse::<f64>())
                    .collect::<std::result::Result<_, _>>()
                    .map_err(|e| err(n, key, format!("{value}: {e}")))?;
                let [x, y, theta] = v[..] else {
                    return Err(err(
                        n,
                        key,
                        format!("{value} has {} values, [x, y, heading] expected", v.len()),
                    ));
                };
                if !(x.is_finite() && y.is_finite() && theta.is_finite()) {
                    return Err(err(n, key, format!("{value} is not finite")));
                }
                if table.2.replace(Pose2::new(x, y, theta)).is_some() {
                    return Err(err(n, key, "given twice in one table".into()));
                }
            }
            other => {
                return Err(err(
                    n,
                    other,
                    "unknown key (a [[sensors]] table has `name` and `mounting`)".into(),
                ))
            }
        }
    }
    if out.is_empty() {
        return Err(err(0, "[[sensors]]", "no [[sensors]] table".into()));
    }
    let mut tables = Vec::with_capacity(out.len());
    for (line, name, mounting) in out {
        let name = name.ok_or_else(|| err(line, "name", "missing in this table".into()))?;
        let mounting =
            mounting.ok_or_else(|| err(line, "mounting", "missing in this table".into()))?;
        if let Some(first) = tables.iter().find(|t: &&NamedMounting| t.name == name) {
            return Err(err(
                line,
                "name",
                format!("{name:?} is named twice (first on line {})", first.line),
            ));
        }
        tables.push(NamedMounting {
            name,
            mounting,
            line,
        });
    }
    Ok(tables)
}

/// [`parse_mountings`] of the file at `path`.
pub fn read_mountings(path: &std::path::Path) -> Result<Vec<NamedMounting>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse_mountings(&text, path)
}

/// For each of `topics`, its mounting in `mountings` (by the topic without its leading `/`);
/// an error naming the file (`path`) and the topic when one has none.
pub fn mountings_for_topics(
    mountings: &[NamedMounting],
    topics: &[String],
    path: &std::path::Path,
) -> Result<Vec<Pose2>> {
    topics
        .iter()
        .map(|t| {
            let name = t.trim_start_matches('/');
            mountings
                .iter()
                .find(|m| m.name == name)
                .map(|m| m.mounting)
                .ok_or_else(|| {
                    let known: Vec<&str> = mountings.iter().map(|m| m.name.as_str()).collect();
                    Error::parse(
                        path,
                        0,
                        "name",
                        format!(
                            "no [[sensors]] table for topic {t} (expected name {name:?}; the \
                             file names {})",
                            known.join(", ")
                        ),
                    )
                })
        })
        .collect()
}
