//! The case file: one TOML file parsed once into typed sections with defaults (DESIGN §7).
//!
//! Unknown keys are errors, and every error names the file, the line and column, the field and
//! what was expected. Each executable reads its own section: `fluid.rs`, `structure.rs`,
//! `coupling.rs`, `output.rs` (and `rigid.rs`, `piston.rs` for the light participants), so the
//! solvers' authors do not edit one file.
//!
//! Command-line overrides (`--set coupling.dt=1e-4`) are applied to the parsed document before
//! the typed sections are built; the case hash covers the effective document, so two peers started
//! with different overrides refuse to couple.

mod coupling;
mod embedded;
mod fluid;
mod level_set;
mod locate;
mod mesh;
mod output;
mod piston;
mod region;
mod rigid;
mod structure;

pub use coupling::*;
pub use embedded::*;
pub use fluid::*;
pub use level_set::*;
pub use mesh::*;
pub use output::*;
pub use piston::*;
pub use region::*;
pub use rigid::*;
pub use structure::*;

use serde::Deserialize;
use std::fmt;
use std::path::{Path, PathBuf};

/// A parsed case.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    #[serde(default)]
    pub case: CaseMeta,
    #[serde(default)]
    pub fluid: Option<FluidSection>,
    #[serde(default)]
    pub structure: Option<StructureSection>,
    #[serde(default)]
    pub coupling: CouplingSection,
    #[serde(default)]
    pub output: OutputSection,
    /// Where the case came from; not a TOML key.
    #[serde(skip)]
    pub source: CaseSource,
}

/// `[case]`: what the case is.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseMeta {
    /// Short name; defaults to the case file's folder name.
    #[serde(default)]
    pub name: String,
    #[serde(default)]
    pub description: String,
}

/// The file a case was read from and the hash of its effective content.
#[derive(Debug, Clone, Default)]
pub struct CaseSource {
    pub path: PathBuf,
    /// 64-bit FNV-1a of the effective document (after overrides), in canonical TOML form.
    pub hash: u64,
    /// The file's text as read (before overrides), to locate fields in errors.
    pub text: String,
    /// The dotted keys given by `--set`, whose values are not in `text`.
    pub overridden: Vec<String>,
}

impl Case {
    /// Reads and parses a case file, then applies `key=value` overrides.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Case, CaseError> {
        let text = std::fs::read_to_string(path).map_err(|e| CaseError {
            file: path.display().to_string(),
            location: None,
            field: None,
            message: format!("cannot read the case file: {e}"),
        })?;
        Case::parse(&text, path, overrides)
    }

    /// Parses case text; `path` names the file in errors and resolves relative paths.
    pub fn parse(text: &str, path: &Path, overrides: &[String]) -> Result<Case, CaseError> {
        let file = path.display().to_string();
        // First the text itself, so errors carry its line and column.
        let mut case: Case =
            toml::from_str(text).map_err(|e| CaseError::from_toml(&file, text, &e))?;
        let mut doc: toml::Table =
            toml::from_str(text).map_err(|e| CaseError::from_toml(&file, text, &e))?;
        if !overrides.is_empty() {
            let before = doc.clone();
            for o in overrides {
                apply_override(&mut doc, o).map_err(|message| CaseError {
                    file: file.clone(),
                    location: None,
                    field: Some(override_field(o)),
                    message: format!("in --set {o}: {message}"),
                })?;
            }
            case = Case::deserialize(toml::Value::Table(doc.clone())).map_err(|e| CaseError {
                file: file.clone(),
                location: None,
                field: Some(first_bad_override(before, overrides)),
                message: format!("after --set overrides: {}", e.message()),
            })?;
        }
        if case.case.name.is_empty() {
            case.case.name = path
                .canonicalize()
                .ok()
                .and_then(|p| {
                    p.parent().and_then(|d| d.file_name()).map(|n| n.to_string_lossy().into_owned())
                })
                .unwrap_or_else(|| "case".to_string());
        }
        let canonical = toml::to_string(&doc).unwrap_or_default();
        case.source = CaseSource {
            path: path.to_path_buf(),
            hash: fnv1a64(canonical.as_bytes()),
            text: text.to_string(),
            overridden: overrides.iter().map(|o| override_field(o)).collect(),
        };
        case.validate().map_err(|(field, message)| case.field_error(&field, message))?;
        Ok(case)
    }

    /// The folder of the case file; relative paths in the case are relative to it.
    pub fn dir(&self) -> PathBuf {
        self.source.path.parent().map(Path::to_path_buf).unwrap_or_default()
    }

    /// An error about `field` (dotted, e.g. `fluid.eos.gamma` or `fluid.probes[2].point`) found
    /// after parsing, by validation or by a solver's own setup: it names the file, the line and
    /// column where the field (or its nearest written ancestor) is written, and the field. A field
    /// given by `--set` is named as such instead of pointing into the file.
    pub fn field_error(&self, field: &str, message: impl Into<String>) -> CaseError {
        let mut message = message.into();
        let overridden = self.source.overridden.iter().find(|key| {
            field == key.as_str()
                || field.strip_prefix(key.as_str()).is_some_and(|r| r.starts_with(['.', '[']))
        });
        let location = match overridden {
            Some(key) => {
                message.push_str(&format!(" (value given by --set {key}=...)"));
                None
            }
            None => locate::locate_offset(&self.source.text, field)
                .map(|offset| line_col(&self.source.text, offset)),
        };
        CaseError {
            file: self.source.path.display().to_string(),
            location,
            field: Some(field.to_string()),
            message,
        }
    }

    /// The case hash exchanged in the handshake.
    pub fn hash(&self) -> u64 {
        self.source.hash
    }

    /// Checks the rules serde cannot express; returns the dotted field and what was expected.
    fn validate(&self) -> Result<(), (String, String)> {
        self.coupling.validate()?;
        if let Some(f) = &self.fluid {
            f.validate()?;
        }
        if let Some(s) = &self.structure {
            s.validate()?;
        }
        self.output.validate()
    }
}

/// A user error in a case file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CaseError {
    pub file: String,
    /// 1-based line and column, when known.
    pub location: Option<(usize, usize)>,
    /// Dotted name of the offending field, when known.
    pub field: Option<String>,
    pub message: String,
}

impl fmt::Display for CaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some((line, col)) = self.location {
            write!(f, ":{line}:{col}")?;
        }
        write!(f, ": ")?;
        if let Some(field) = &self.field {
            write!(f, "field `{field}`: ")?;
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for CaseError {}

impl CaseError {
    fn from_toml(file: &str, text: &str, e: &toml::de::Error) -> CaseError {
        let offset = e.span().map(|s| left_open_above(text, s.start, e.message()));
        let location = offset.map(|o| line_col(text, o));
        let field = offset
            .map(|o| locate::path_at(text, o).unwrap_or_else(|| field_at(text, o)))
            .filter(|f| !f.is_empty());
        CaseError {
            file: file.to_string(),
            location,
            field,
            message: e.message().trim().to_string(),
        }
    }
}

/// Where to report a syntax error the parser found at `offset`: an array or inline table left
/// open is only noticed at the start of the next line (a missing `,` or closing bracket), so such
/// an error is reported at the end of the previous non-blank line, where the open value is.
fn left_open_above(text: &str, offset: usize, message: &str) -> usize {
    let offset = offset.min(text.len());
    let at_line_start = text[..offset].trim_end_matches([' ', '\t']).ends_with('\n');
    let open = ["missing comma", "expected `]`", "expected `}`", "expected `,`"];
    if !at_line_start || !open.iter().any(|m| message.contains(m)) {
        return offset;
    }
    let above = text[..offset].trim_end();
    let line_start = above.rfind('\n').map_or(0, |i| i + 1);
    let line = &above[line_start..];
    line_start + (line.len() - line.trim_start().len())
}

/// 1-based line and column of a byte offset.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Dotted field name at a byte offset: the enclosing `[table]` header and the key on that line.
fn field_at(text: &str, offset: usize) -> String {
    let offset = offset.min(text.len());
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next().unwrap_or("").trim();
    let mut table = String::new();
    for l in text[..line_start].lines() {
        let l = l.trim();
        if l.starts_with('[') {
            table = l.trim_matches(|c| c == '[' || c == ']').trim().to_string();
        }
    }
    if line.starts_with('[') {
        return line.trim_matches(|c| c == '[' || c == ']').trim().to_string();
    }
    let key = line.split('=').next().unwrap_or("").trim().trim_matches('"');
    match (table.is_empty(), key.is_empty()) {
        (_, true) => table,
        (true, false) => key.to_string(),
        (false, false) => format!("{table}.{key}"),
    }
}

/// The field an override names: its key, else the whole assignment, else `--set` itself.
fn override_field(assignment: &str) -> String {
    match assignment.split('=').next().map(str::trim) {
        Some(key) if !key.is_empty() => key.to_string(),
        _ if !assignment.trim().is_empty() => assignment.to_string(),
        _ => "--set".to_string(),
    }
}

/// The key of the first override after which `doc` no longer makes a case (the last one if none
/// does alone): the field to name when the overridden document is refused.
fn first_bad_override(mut doc: toml::Table, overrides: &[String]) -> String {
    for o in overrides {
        if apply_override(&mut doc, o).is_err()
            || Case::deserialize(toml::Value::Table(doc.clone())).is_err()
        {
            return override_field(o);
        }
    }
    overrides.last().map(|o| override_field(o)).unwrap_or_default()
}

/// Sets `a.b.c=value` in a document; the value is parsed as TOML, or taken as a string.
fn apply_override(doc: &mut toml::Table, assignment: &str) -> Result<(), String> {
    let (key, raw) = assignment
        .split_once('=')
        .ok_or_else(|| "expected key=value, e.g. coupling.dt=1e-4".to_string())?;
    let value: toml::Value = toml::from_str::<toml::Table>(&format!("v = {}", raw.trim()))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(raw.trim().to_string()));
    let parts: Vec<&str> = key.trim().split('.').map(str::trim).collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err("expected key=value with a dotted key, e.g. coupling.dt=1e-4".to_string());
    }
    let (last, tables) = parts.split_last().ok_or("empty key")?;
    let mut table = doc;
    for p in tables {
        table = table
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .ok_or_else(|| format!("`{p}` is not a table"))?;
    }
    table.insert(last.to_string(), value);
    Ok(())
}

/// 64-bit FNV-1a.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

/// A helper for `validate`: `Err((field, message))` unless `value` is finite and positive.
pub(crate) fn require_positive(field: &str, value: f64) -> Result<(), (String, String)> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err((field.to_string(), format!("expected a finite number > 0, got {value}")))
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod override_tests {
    use super::*;

    fn err(overrides: &[&str]) -> CaseError {
        let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        Case::parse("[coupling]\ndt = 1e-3\n", Path::new("c.toml"), &o).unwrap_err()
    }

    #[test]
    fn a_refused_override_names_its_key() {
        let e = err(&["coupling.dt=2e-3", "coupling.dtt=1"]);
        assert_eq!(e.field.as_deref(), Some("coupling.dtt"), "{e}");
        assert!(e.to_string().contains("unknown field `dtt`"), "{e}");
        let e = err(&["nosuch=1"]);
        assert_eq!(e.field.as_deref(), Some("nosuch"), "{e}");
        for bad in ["=", "=1", "coupling..dt=1", ".dt=1"] {
            let e = err(&[bad]);
            assert!(e.field.as_deref().is_some_and(|f| !f.is_empty()), "{bad}: {e}");
            assert!(e.to_string().contains("dotted key"), "{bad}: {e}");
        }
        assert_eq!(err(&[""]).field.as_deref(), Some("--set"));
    }
}
