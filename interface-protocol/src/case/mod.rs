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
mod fluid;
mod output;
mod piston;
mod rigid;
mod structure;

pub use coupling::*;
pub use fluid::*;
pub use output::*;
pub use piston::*;
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
            for o in overrides {
                apply_override(&mut doc, o).map_err(|message| CaseError {
                    file: file.clone(),
                    location: None,
                    field: Some(o.split('=').next().unwrap_or("").trim().to_string()),
                    message: format!("in --set {o}: {message}"),
                })?;
            }
            case = Case::deserialize(toml::Value::Table(doc.clone())).map_err(|e| CaseError {
                file: file.clone(),
                location: None,
                field: None,
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
        case.source = CaseSource { path: path.to_path_buf(), hash: fnv1a64(canonical.as_bytes()) };
        case.validate().map_err(|(field, message)| CaseError {
            file,
            location: locate_key(text, &field),
            field: Some(field),
            message,
        })?;
        Ok(case)
    }

    /// The folder of the case file; relative paths in the case are relative to it.
    pub fn dir(&self) -> PathBuf {
        self.source.path.parent().map(Path::to_path_buf).unwrap_or_default()
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
        let location = e.span().map(|s| line_col(text, s.start));
        let field = e.span().map(|s| field_at(text, s.start)).filter(|f| !f.is_empty());
        CaseError {
            file: file.to_string(),
            location,
            field,
            message: e.message().trim().to_string(),
        }
    }
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

/// Line and column of a dotted key's definition, if it can be found in the text.
fn locate_key(text: &str, dotted: &str) -> Option<(usize, usize)> {
    if let Some((table, rest)) = dotted.split_once('[') {
        return locate_entry_key(text, table, rest);
    }
    let (table, key) = dotted.rsplit_once('.').unwrap_or(("", dotted));
    let mut current = String::new();
    let mut offset = 0;
    for l in text.split_inclusive('\n') {
        let t = l.trim();
        if t.starts_with('[') {
            current = t.trim_matches(|c| c == '[' || c == ']').trim().to_string();
        } else if current == table && t.split('=').next().map(str::trim) == Some(key) {
            return Some(line_col(text, offset + (l.len() - l.trim_start().len())));
        }
        offset += l.len();
    }
    None
}

/// `table[k].key...` (`rest` = `k].key...`): the line of `key` in the `k`-th `[[table]]`
/// entry, else the entry's header.
fn locate_entry_key(text: &str, table: &str, rest: &str) -> Option<(usize, usize)> {
    let (index, key) = rest.split_once(']')?;
    let index: usize = index.parse().ok()?;
    let key = key.trim_start_matches('.').split(['.', '[']).next().unwrap_or("");
    let (mut seen, mut header, mut offset) = (0, None, 0);
    for l in text.split_inclusive('\n') {
        let t = l.trim();
        let here = line_col(text, offset + (l.len() - l.trim_start().len()));
        if t.starts_with('[') {
            if header.is_some() {
                break;
            }
            if t.starts_with("[[") && t.trim_matches(|c| c == '[' || c == ']').trim() == table {
                seen += 1;
                if seen == index + 1 {
                    header = Some(here);
                }
            }
        } else if header.is_some()
            && !key.is_empty()
            && t.split('=').next().map(str::trim) == Some(key)
        {
            return Some(here);
        }
        offset += l.len();
    }
    header
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
    let parts: Vec<&str> = key.trim().split('.').collect();
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
