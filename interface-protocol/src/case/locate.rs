//! Where a dotted field (`fluid.mesh.box.cells`, `structure.bc[1].fixed[0]`) is written in a case
//! file, from the spans of the TOML parser itself: inline tables, arrays of tables and dotted keys
//! are found the same way as `[table]` keys, so an error raised after parsing (a validation rule,
//! or a solver's own check) still names the line and column.

use toml::de::{DeTable, DeValue};

/// One step of a dotted path: a key, or an index into an array.
#[derive(Debug, PartialEq)]
enum Segment<'a> {
    Key(&'a str),
    Index(usize),
}

/// `a.b[2].c` as `[Key(a), Key(b), Index(2), Key(c)]`; `None` if the path is malformed.
fn segments(dotted: &str) -> Option<Vec<Segment<'_>>> {
    let mut out = Vec::new();
    for part in dotted.split('.') {
        let (key, mut rest) = part.split_once('[').map_or((part, ""), |(k, r)| (k, r));
        if !key.is_empty() {
            out.push(Segment::Key(key.trim_matches('"')));
        }
        while !rest.is_empty() {
            let (index, tail) = rest.split_once(']')?;
            out.push(Segment::Index(index.parse().ok()?));
            rest = tail.strip_prefix('[').unwrap_or(tail);
        }
    }
    Some(out)
}

/// Byte offset of the deepest part of `dotted` present in `text`: the key of a table entry, the
/// value of an array element. A path only partly present gives its deepest present ancestor (the
/// enclosing key names the place to look); `None` when not even its first key is written (a
/// default, or a value given by `--set`).
pub(crate) fn locate_offset(text: &str, dotted: &str) -> Option<usize> {
    let segments = segments(dotted)?;
    let doc = DeTable::parse(text).ok()?;
    let mut value: Option<&DeValue<'_>> = None;
    let mut table: Option<&DeTable<'_>> = Some(doc.get_ref());
    let mut found = None;
    for segment in segments {
        match segment {
            Segment::Key(key) => {
                let Some((k, v)) = table.and_then(|t| t.iter().find(|(k, _)| k.get_ref() == key))
                else {
                    break;
                };
                found = Some(k.span().start);
                value = Some(v.get_ref());
            }
            Segment::Index(i) => {
                let Some(DeValue::Array(items)) = value else { break };
                let Some(item) = items.get(i) else { break };
                found = Some(item.span().start);
                value = Some(item.get_ref());
            }
        }
        table = match value {
            Some(DeValue::Table(t)) => Some(t),
            _ => None,
        };
    }
    found
}

/// The dotted field written at byte `offset` of `text` (`structure.bc[0].fixed[1]`), the
/// deepest key or array element whose key or value holds the offset; `None` when the text does
/// not parse or the offset lies in no entry.
pub(crate) fn path_at(text: &str, offset: usize) -> Option<String> {
    let doc = DeTable::parse(text).ok()?;
    let mut path = String::new();
    table_path(doc.get_ref(), offset, &mut path).then_some(path)
}

/// Appends to `path` the entry of `table` that holds `offset`; false if none does.
fn table_path(table: &DeTable<'_>, offset: usize, path: &mut String) -> bool {
    for (key, value) in table.iter() {
        let len = path.len();
        if !path.is_empty() {
            path.push('.');
        }
        path.push_str(key.get_ref());
        if value_path(value.get_ref(), offset, path)
            || key.span().contains(&offset)
            || value.span().contains(&offset)
        {
            return true;
        }
        path.truncate(len);
    }
    false
}

/// Appends the part of `value` below its own key that holds `offset`; false if none does.
fn value_path(value: &DeValue<'_>, offset: usize, path: &mut String) -> bool {
    match value {
        DeValue::Table(t) => table_path(t, offset, path),
        DeValue::Array(items) => items.iter().enumerate().any(|(i, item)| {
            let len = path.len();
            path.push_str(&format!("[{i}]"));
            if value_path(item.get_ref(), offset, path) || item.span().contains(&offset) {
                return true;
            }
            path.truncate(len);
            false
        }),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Line and column of `dotted` in `text`, 1-based.
    fn at(text: &str, dotted: &str) -> Option<(usize, usize)> {
        locate_offset(text, dotted).map(|o| super::super::line_col(text, o))
    }

    const TEXT: &str = "\
[fluid]
mesh = { box = { cells = [10, 1, 1], lo = [0, 0, 0] } }
eos = { kind = \"stiffened\", gamma = 0.5 }

[[fluid.probes]]
name = \"a\"
point = [0, 0, 0]

[[fluid.probes]]
name = \"b\"
point = [9, 0, 0]

[structure]
bc = [{ set = \"root\", fixed = [\"ux\", \"bad\"] }]
time.dt = 1e-3
";

    #[test]
    fn finds_keys_inside_inline_tables_and_arrays() {
        assert_eq!(at(TEXT, "fluid.mesh.box.cells"), Some((2, 18)));
        assert_eq!(at(TEXT, "fluid.eos.gamma"), Some((3, 29)));
        assert_eq!(at(TEXT, "fluid.probes[1].point"), Some((11, 1)));
        assert_eq!(at(TEXT, "fluid.probes[0].name"), Some((6, 1)));
        assert_eq!(at(TEXT, "structure.bc[0].fixed[1]"), Some((14, 38)));
        assert_eq!(at(TEXT, "structure.time.dt"), Some((15, 6)));
    }

    #[test]
    fn a_missing_leaf_gives_its_deepest_ancestor() {
        assert_eq!(at(TEXT, "fluid.mesh.box.hi"), Some((2, 10)));
        assert_eq!(at(TEXT, "fluid.probes[7].point"), Some((5, 9)));
        assert_eq!(at(TEXT, "coupling.dt"), None);
        assert_eq!(at("not = [toml", "not"), None);
    }

    #[test]
    fn names_the_field_at_an_offset() {
        let path = |needle: &str| path_at(TEXT, TEXT.find(needle).unwrap());
        assert_eq!(path("10, 1").as_deref(), Some("fluid.mesh.box.cells[0]"));
        assert_eq!(path("0.5").as_deref(), Some("fluid.eos.gamma"));
        assert_eq!(path("[9, 0").as_deref(), Some("fluid.probes[1].point"));
        assert_eq!(path("\"bad\"").as_deref(), Some("structure.bc[0].fixed[1]"));
        assert_eq!(path("1e-3").as_deref(), Some("structure.time.dt"));
        assert_eq!(path_at("a = [1,", 5), None);
    }

    #[test]
    fn parses_paths() {
        use Segment::*;
        assert_eq!(
            segments("a.b[2][3].c").unwrap(),
            vec![Key("a"), Key("b"), Index(2), Index(3), Key("c")]
        );
        assert!(segments("a[x]").is_none());
    }
}
