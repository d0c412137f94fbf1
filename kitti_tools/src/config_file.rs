//! Reading the commands' TOML or JSON configuration files, with errors that name the file and
//! the line of the problem.
//!
//! Not for: what a configuration means — each command validates its own.

use anyhow::{bail, Context, Result};
use serde::de::DeserializeOwned;
use std::path::Path;

/// The tracking configuration of `track` and `batch`: the file's (default: the library's),
/// with `--particles` overriding its particles per track.
pub fn tracking_config(
    path: Option<&Path>,
    particles: Option<usize>,
) -> Result<smc_lmb::pipeline::drive_tracking::TrackingConfig> {
    let mut config: smc_lmb::pipeline::drive_tracking::TrackingConfig = match path {
        Some(p) => read_checked(
            p,
            |c: &smc_lmb::pipeline::drive_tracking::TrackingConfig| c.validate(),
        )?,
        None => Default::default(),
    };
    if let Some(n) = particles {
        config.filter.particles = n;
    }
    Ok(config)
}

/// [`read_config`], then `check` (the type's own validation), whose error names the file.
pub fn read_checked<T: DeserializeOwned>(
    path: &Path,
    check: impl FnOnce(&T) -> smc_lmb::Result<()>,
) -> Result<T> {
    let config = read_config(path)?;
    check(&config).with_context(|| format!("{}", path.display()))?;
    Ok(config)
}

/// Reads `path` over `base`: the fields the file sets replace `base`'s (tables field by field),
/// the others keep `base`'s values. The file's text is first parsed as a `T` of its own, so that
/// a misspelt field or a bad value is reported with its file and line.
pub fn read_config_over<T: DeserializeOwned + serde::Serialize>(
    path: &Path,
    base: &T,
) -> Result<T> {
    let text = read_text(path)?;
    parse_config::<T>(path, &text)?;
    let file: serde_json::Value = parse_config(path, &text)?;
    let mut merged = serde_json::to_value(base).context("configuration as a table")?;
    overlay(&mut merged, file);
    serde_json::from_value(merged).with_context(|| format!("{}", path.display()))
}

/// Puts `top` over `base`: tables merge key by key, anything else replaces.
fn overlay(base: &mut serde_json::Value, top: serde_json::Value) {
    match (base, top) {
        (serde_json::Value::Object(b), serde_json::Value::Object(t)) => {
            for (k, v) in t {
                match b.get_mut(&k) {
                    Some(slot) => overlay(slot, v),
                    None => {
                        b.insert(k, v);
                    }
                }
            }
        }
        (slot, v) => *slot = v,
    }
}

/// Reads `path` as TOML (`.toml`) or JSON (`.json`) into `T`.
pub fn read_config<T: DeserializeOwned>(path: &Path) -> Result<T> {
    parse_config(path, &read_text(path)?)
}

fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))
}

/// Parses `text`, the contents of `path`, as TOML or JSON by `path`'s extension; errors name
/// the file and line.
fn parse_config<T: DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "toml" => toml::from_str(text).map_err(|e| {
            let line = e.span().map(|s| line_of(text, s.start)).unwrap_or(0);
            anyhow::anyhow!("{}:{line}: {}", path.display(), e.message())
        }),
        "json" => serde_json::from_str(text)
            .map_err(|e| anyhow::anyhow!("{}:{}: {e}", path.display(), e.line())),
        other => bail!(
            "{}: unknown config extension `{other}` (expected .toml or .json)",
            path.display()
        ),
    }
}

/// One-based line number of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    1 + text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_over_a_base_replaces_only_what_it_sets() {
        #[derive(serde::Serialize, serde::Deserialize, Debug, PartialEq)]
        #[serde(default, deny_unknown_fields)]
        struct Inner {
            a: f64,
            b: Vec<u32>,
        }
        impl Default for Inner {
            fn default() -> Self {
                Inner { a: 1.0, b: vec![1] }
            }
        }
        #[derive(serde::Serialize, serde::Deserialize, Debug, PartialEq, Default)]
        #[serde(default, deny_unknown_fields)]
        struct Outer {
            n: u32,
            inner: Inner,
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.toml");
        std::fs::write(&path, "[inner]\nb = [7, 8]\n").unwrap();
        let base = Outer {
            n: 5,
            inner: Inner { a: 2.5, b: vec![] },
        };
        let read = read_config_over(&path, &base).unwrap();
        assert_eq!(
            read,
            Outer {
                n: 5,
                inner: Inner {
                    a: 2.5,
                    b: vec![7, 8]
                }
            }
        );
        std::fs::write(&path, "[inner]\nc = 1\n").unwrap();
        let err = format!("{:#}", read_config_over(&path, &base).unwrap_err());
        assert!(
            err.contains("c.toml:2") && err.contains("unknown field"),
            "{err}"
        );
    }

    #[test]
    fn line_numbers_count_from_one_and_include_the_offsets_own_line() {
        let text = "a = 1\nb = 2\nc = 3\n";
        assert_eq!(line_of(text, 0), 1);
        assert_eq!(line_of(text, 6), 2); // start of "b"
        assert_eq!(line_of(text, 12), 3); // start of "c"
        assert_eq!(line_of(text, 1000), 4);
    }

    #[test]
    fn a_bad_value_at_the_start_of_a_line_is_reported_on_that_line() {
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct C {
            a: u32,
            b: u32,
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.toml");
        std::fs::write(&path, "a = 1\nb = \"x\"\n").unwrap();
        let err = read_config::<C>(&path).unwrap_err().to_string();
        assert!(err.contains("c.toml:2:"), "{err}");
    }
}

/// Hostile configuration files: arbitrary bytes, the example configuration with a few bytes
/// changed or cut short, deep nesting and huge numbers. Each read (and the check or build that
/// follows it in the commands) must return, an error naming the file, never a panic.
#[cfg(test)]
mod hostile {
    use super::*;
    use proptest::prelude::*;
    use proptest::sample::Index;
    use smc_lmb::config::RunConfig;
    use smc_lmb::pipeline::drive_tracking::TrackingConfig;
    use smc_lmb::sim::street::StreetConfig;
    use std::path::PathBuf;

    fn example() -> Vec<u8> {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/data/config.toml");
        std::fs::read(p).unwrap()
    }

    fn example_json() -> Vec<u8> {
        let text = String::from_utf8(example()).unwrap();
        let config: RunConfig = toml::from_str(&text).unwrap();
        serde_json::to_vec_pretty(&config).unwrap()
    }

    /// Reads `bytes` as `name` for every configuration type the commands read, checks or
    /// builds what was read as the commands do, and returns whether the run configuration was
    /// read and built a filter. Every reading error must name the file.
    fn read_all(dir: &Path, name: &str, bytes: &[u8]) -> bool {
        let path: PathBuf = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let named = |e: &dyn std::fmt::Display| {
            let msg = e.to_string();
            assert!(msg.contains(&path.display().to_string()), "{msg}");
        };
        let run = read_config::<RunConfig>(&path);
        let accepted = match &run {
            // The detections command builds the filter right away.
            Ok(config) => config.build().is_ok(),
            Err(e) => {
                named(e);
                false
            }
        };
        match read_config::<StreetConfig>(&path) {
            Ok(config) => drop(config.validate()),
            Err(e) => named(&e),
        }
        if let Err(e) = read_config::<TrackingConfig>(&path) {
            named(&e);
        }
        accepted
    }

    fn mutate(valid: &[u8], edits: &[(Index, u8, u8)]) -> Vec<u8> {
        let mut v = valid.to_vec();
        for (at, byte, kind) in edits {
            if v.is_empty() {
                v.push(*byte);
                continue;
            }
            let i = at.index(v.len());
            match kind % 3 {
                0 => v[i] = *byte,
                1 => v.insert(i, *byte),
                _ => {
                    v.remove(i);
                }
            }
        }
        v
    }

    fn hostile(valid: Vec<u8>) -> impl Strategy<Value = Vec<u8>> {
        let edits = proptest::collection::vec((any::<Index>(), any::<u8>(), any::<u8>()), 1..8);
        prop_oneof![
            proptest::collection::vec(any::<u8>(), 0..1024),
            edits.prop_map(move |e| mutate(&valid, &e)),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]

        #[test]
        fn toml_hostile_bytes(bytes in hostile(example())) {
            let dir = tempfile::tempdir().unwrap();
            read_all(dir.path(), "c.toml", &bytes);
        }

        #[test]
        fn json_hostile_bytes(bytes in hostile(example_json())) {
            let dir = tempfile::tempdir().unwrap();
            read_all(dir.path(), "c.json", &bytes);
        }
    }

    #[test]
    fn every_truncation_returns_and_the_whole_file_is_accepted() {
        let dir = tempfile::tempdir().unwrap();
        for (name, valid) in [("c.toml", example()), ("c.json", example_json())] {
            for n in 0..valid.len() {
                read_all(dir.path(), name, &valid[..n]);
            }
            assert!(read_all(dir.path(), name, &valid), "{name}");
        }
    }

    #[test]
    fn deep_nesting_and_huge_numbers_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let deep = 100_000;
        for text in [
            format!("seed = {}{}", "[".repeat(deep), "]".repeat(deep)),
            format!("seed = {}1{}", "{a=".repeat(deep), "}".repeat(deep)),
            format!("{}seed = 1", "[a.".repeat(deep)),
            format!("[{}]", "a.".repeat(deep) + "b"),
        ] {
            assert!(!read_all(dir.path(), "deep.toml", text.as_bytes()));
        }
        let json = format!("{{\"seed\": {}{}}}", "[".repeat(deep), "]".repeat(deep));
        assert!(!read_all(dir.path(), "deep.json", json.as_bytes()));
        let text = String::from_utf8(example()).unwrap();
        for (from, to) in [
            (
                "particles = 500\n\n[transition]",
                "particles = 1000000000000\n\n[transition]",
            ),
            (
                "particles = 500\nposition_std",
                "particles = 1000000000000\nposition_std",
            ),
            (
                "particles = 500\n\n[transition]",
                "particles = 18446744073709551616\n\n[transition]",
            ),
            ("dims = 2", "dims = 1000000000000"),
            ("seed = 7", "seed = 1e400"),
        ] {
            assert!(text.contains(from), "{from}");
            let bad = text.replacen(from, to, 1);
            assert!(!read_all(dir.path(), "huge.toml", bad.as_bytes()), "{to}");
        }
    }
}

/// `--vehicle-param NAME=VALUE` flags as (name, value) pairs; a flag without `=` or with a
/// value that is not a number is an error naming it.
pub fn vehicle_params(flags: &[String]) -> anyhow::Result<Vec<(String, f64)>> {
    flags
        .iter()
        .map(|f| {
            let Some((name, value)) = f.split_once('=') else {
                anyhow::bail!("--vehicle-param `{f}`: expected NAME=VALUE, e.g. wheelbase=2.9");
            };
            let v: f64 = value
                .trim()
                .parse()
                .map_err(|_| anyhow::anyhow!("--vehicle-param `{f}`: `{value}` is not a number"))?;
            Ok((name.trim().to_string(), v))
        })
        .collect()
}
