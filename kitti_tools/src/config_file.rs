//! Reading the commands' TOML or JSON configuration files, with errors that name the file and
//! the line of the problem.
//!
//! Not for: what a configuration means — each command validates its own.

use anyhow::{bail, Context, Result};
use serde::de::DeserializeOwned;
use std::path::Path;

/// Reads `path` as TOML (`.toml`) or JSON (`.json`) into `T`.
pub fn read_config<T: DeserializeOwned>(path: &Path) -> Result<T> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "toml" => toml::from_str(&text).map_err(|e| {
            let line = e.span().map(|s| line_of(&text, s.start)).unwrap_or(0);
            anyhow::anyhow!("{}:{line}: {}", path.display(), e.message())
        }),
        "json" => serde_json::from_str(&text)
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
