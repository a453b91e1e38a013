//! The gmsh `.msh` 4.1 format, ASCII and binary (little-endian, as gmsh writes on every common
//! machine), read into a neutral description both solvers map onto their own meshes: node
//! coordinates with their tags, element blocks (entity dimension and tag, gmsh element type,
//! connectivity as node indices), the entities with their physical groups and the names of
//! `$PhysicalNames`. Every item keeps its [`Position`] in the file, so a solver refusing it
//! names the file and the line (and the byte offset inside binary data), as the parser does.
//!
//! Format: gmsh reference manual, §10.1 "MSH file format" (version 4.1). Sections other than
//! `$MeshFormat`, `$PhysicalNames`, `$Entities`, `$Nodes` and `$Elements` are skipped, except
//! `$PartitionedEntities`, which is refused (partitioned meshes are not read). Element types are
//! those of [`element_type`]; what a solver accepts of them is its own business.

use std::collections::HashMap;
use std::fmt;
use std::path::Path;

/// Where something is in the file: its byte offset and 1-based line (in binary data, the number
/// of newline bytes before it, plus one).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Position {
    pub byte: usize,
    pub line: usize,
}

/// An error naming the file and, when it has one, the place in it: `file:line: message` in
/// ASCII, `file: byte N (line L): message` inside binary data.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {message}", self.location())]
pub struct GmshError {
    pub file: String,
    pub at: Option<Position>,
    /// Whether `at` is in a binary file (then the byte offset is named).
    pub binary: bool,
    pub message: String,
}

impl GmshError {
    /// `file:line`, `file: byte N (line L)` or `file`.
    pub fn location(&self) -> String {
        match self.at {
            None => self.file.clone(),
            Some(p) if self.binary => format!("{}: byte {} (line {})", self.file, p.byte, p.line),
            Some(p) => format!("{}:{}", self.file, p.line),
        }
    }
}

/// The shape of a gmsh element type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    Point,
    Line,
    Triangle,
    Quadrangle,
    Tetrahedron,
    Hexahedron,
    Prism,
    Pyramid,
}

impl Shape {
    pub fn dim(self) -> i32 {
        match self {
            Shape::Point => 0,
            Shape::Line => 1,
            Shape::Triangle | Shape::Quadrangle => 2,
            _ => 3,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Shape::Point => "point",
            Shape::Line => "line",
            Shape::Triangle => "triangle",
            Shape::Quadrangle => "quadrangle",
            Shape::Tetrahedron => "tetrahedron",
            Shape::Hexahedron => "hexahedron",
            Shape::Prism => "prism",
            Shape::Pyramid => "pyramid",
        }
    }
}

/// A gmsh element type: its code in the file, shape, polynomial order and number of nodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ElementType {
    pub code: i32,
    pub shape: Shape,
    pub order: u8,
    pub n_nodes: usize,
}

/// The element types of gmsh's fixed-size families (manual §10.2, "Node ordering"; the node
/// counts agree with `gmsh.model.mesh.getElementProperties`), or `None` for any other code.
pub fn element_type(code: i32) -> Option<ElementType> {
    use Shape::*;
    let (shape, order, n_nodes) = match code {
        15 => (Point, 1, 1),
        1 => (Line, 1, 2),
        8 => (Line, 2, 3),
        26 => (Line, 3, 4),
        27 => (Line, 4, 5),
        28 => (Line, 5, 6),
        2 => (Triangle, 1, 3),
        9 => (Triangle, 2, 6),
        20 => (Triangle, 3, 9),
        21 => (Triangle, 3, 10),
        22 => (Triangle, 4, 12),
        23 => (Triangle, 4, 15),
        24 => (Triangle, 5, 15),
        25 => (Triangle, 5, 21),
        3 => (Quadrangle, 1, 4),
        16 => (Quadrangle, 2, 8),
        10 => (Quadrangle, 2, 9),
        4 => (Tetrahedron, 1, 4),
        11 => (Tetrahedron, 2, 10),
        29 => (Tetrahedron, 3, 20),
        30 => (Tetrahedron, 4, 35),
        31 => (Tetrahedron, 5, 56),
        5 => (Hexahedron, 1, 8),
        17 => (Hexahedron, 2, 20),
        12 => (Hexahedron, 2, 27),
        92 => (Hexahedron, 3, 64),
        93 => (Hexahedron, 4, 125),
        6 => (Prism, 1, 6),
        18 => (Prism, 2, 15),
        13 => (Prism, 2, 18),
        7 => (Pyramid, 1, 5),
        19 => (Pyramid, 2, 13),
        14 => (Pyramid, 2, 14),
        _ => return None,
    };
    Some(ElementType { code, shape, order, n_nodes })
}

impl fmt::Display for ElementType {
    /// `tetrahedron`, `second-order hexahedron (27 nodes)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let order = ["", "", "second", "third", "fourth", "fifth"];
        match self.order {
            1 => f.write_str(self.shape.name()),
            o => write!(
                f,
                "{}-order {} ({} nodes)",
                order[o as usize],
                self.shape.name(),
                self.n_nodes
            ),
        }
    }
}

/// A geometric entity of `$Entities`: its physical group tags and where it is declared.
#[derive(Debug, Clone, PartialEq)]
pub struct Entity {
    pub dim: i32,
    pub tag: i32,
    pub physical: Vec<i32>,
    pub at: Position,
}

/// One block of `$Elements`: elements of one type on one entity.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementBlock {
    pub dim: i32,
    pub entity: i32,
    pub kind: ElementType,
    /// Where the block header is.
    pub at: Position,
    /// The element tags, one per element.
    pub tags: Vec<u64>,
    /// Where each element is.
    pub positions: Vec<Position>,
    /// `kind.n_nodes` node indices (into [`Msh::coords`]) per element, in gmsh's node order.
    pub connectivity: Vec<u32>,
}

impl ElementBlock {
    pub fn len(&self) -> usize {
        self.tags.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tags.is_empty()
    }

    /// The node indices of each element.
    pub fn elements(&self) -> std::slice::ChunksExact<'_, u32> {
        self.connectivity.chunks_exact(self.kind.n_nodes)
    }
}

/// The contents of a `.msh` 4.1 file.
#[derive(Debug, Clone, PartialEq)]
pub struct Msh {
    /// The file name, for messages.
    pub origin: String,
    pub binary: bool,
    pub coords: Vec<[f64; 3]>,
    /// The gmsh tag of each node of [`Msh::coords`].
    pub node_tags: Vec<u64>,
    /// `(dim, tag) -> name`, or `None` if the file has no `$PhysicalNames`.
    pub physical_names: Option<HashMap<(i32, i32), String>>,
    /// `(dim, tag) -> entity`, or `None` if the file has no `$Entities`.
    pub entities: Option<HashMap<(i32, i32), Entity>>,
    pub blocks: Vec<ElementBlock>,
    /// The end of the file.
    pub end: Position,
}

impl Msh {
    /// An error at `at` in this file.
    pub fn error(&self, at: Position, message: impl fmt::Display) -> GmshError {
        GmshError {
            file: self.origin.clone(),
            at: Some(at),
            binary: self.binary,
            message: message.to_string(),
        }
    }

    /// The name `$PhysicalNames` gives physical group `tag` of dimension `dim` (the sign of a
    /// tag, an orientation, is ignored).
    pub fn physical_name(&self, dim: i32, tag: i32) -> Option<&str> {
        self.physical_names.as_ref()?.get(&(dim, tag.abs())).map(String::as_str)
    }

    /// The physical group tags of entity `(dim, tag)`: none if the entity or `$Entities` is
    /// missing.
    pub fn physical_groups(&self, dim: i32, tag: i32) -> &[i32] {
        self.entities
            .as_ref()
            .and_then(|e| e.get(&(dim, tag)))
            .map(|e| e.physical.as_slice())
            .unwrap_or(&[])
    }
}

/// Reads a gmsh 4.1 file. `accept` says whether the caller reads a type of element: it is
/// asked at each block header, before the block's data, and its `Err(message)` is the error
/// there (a type miswritten in a header would otherwise be reported wherever its wrong node
/// count runs the data off its lines).
pub fn read(
    path: &Path,
    accept: impl Fn(ElementType) -> Result<(), String>,
) -> Result<Msh, GmshError> {
    let origin = path.display().to_string();
    match std::fs::read(path) {
        Ok(bytes) => parse(&bytes, origin, accept),
        Err(e) => Err(GmshError {
            file: origin,
            at: None,
            binary: false,
            message: format!("cannot read the mesh file: {e}"),
        }),
    }
}

/// Parses the bytes of a gmsh 4.1 file named `origin` (for messages); `accept` as in [`read`].
pub fn parse(
    bytes: &[u8],
    origin: impl Into<String>,
    accept: impl Fn(ElementType) -> Result<(), String>,
) -> Result<Msh, GmshError> {
    let mut r = Reader {
        bytes,
        pos: 0,
        origin: origin.into(),
        binary: false,
        size_t: 8,
        line: 1,
        counted: 0,
    };
    let mut format_seen = false;
    let mut physical_names = None;
    let mut entities = None;
    let mut nodes: Option<Nodes> = None;
    let mut blocks: Option<Vec<ElementBlock>> = None;
    while let Some(name) = r.section()? {
        let header = r.pos;
        if !format_seen && name != "MeshFormat" {
            return Err(r.error("not a gmsh .msh file: it must start with `$MeshFormat`"));
        }
        match name {
            "MeshFormat" => {
                mesh_format(&mut r)?;
                format_seen = true;
            }
            "PhysicalNames" => physical_names = Some(read_physical_names(&mut r)?),
            "Entities" => entities = Some(read_entities(&mut r)?),
            "PartitionedEntities" => {
                return Err(r.error("partitioned meshes are not read: save the mesh unpartitioned"))
            }
            "Nodes" => nodes = Some(read_nodes(&mut r)?),
            "Elements" => {
                let Some(Nodes { index, .. }) = &nodes else {
                    return Err(r.error_at(header, "`$Elements` comes before `$Nodes`"));
                };
                blocks = Some(read_elements(&mut r, index, &accept)?);
            }
            other => {
                r.skip_section(other)?;
                continue;
            }
        }
        r.end(name)?;
    }
    if !format_seen {
        return Err(r.error_at(0, "empty file: expected `$MeshFormat`"));
    }
    let (Some(Nodes { coords, tags: node_tags, .. }), Some(blocks)) = (nodes, blocks) else {
        return Err(r.error("the file has no `$Nodes` or no `$Elements` section (truncated?)"));
    };
    let end = r.position();
    Ok(Msh {
        origin: r.origin,
        binary: r.binary,
        coords,
        node_tags,
        physical_names,
        entities,
        blocks,
        end,
    })
}

/// A position in the file and the typed reading of its tokens (ASCII) or values (binary).
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    origin: String,
    binary: bool,
    /// Size of `size_t` in binary files (the third number of `$MeshFormat`).
    size_t: usize,
    /// The line at byte `counted` (kept up to date by [`Reader::position`]).
    line: usize,
    counted: usize,
}

impl<'a> Reader<'a> {
    /// `file:line: message` (`file: byte N (line L): message` inside binary data) at byte `pos`.
    fn error_at(&self, pos: usize, message: impl fmt::Display) -> GmshError {
        let pos = pos.min(self.bytes.len());
        let line = 1 + self.bytes[..pos].iter().filter(|&&b| b == b'\n').count();
        GmshError {
            file: self.origin.clone(),
            at: Some(Position { byte: pos, line }),
            binary: self.binary,
            message: message.to_string(),
        }
    }

    fn error(&self, message: impl fmt::Display) -> GmshError {
        self.error_at(self.pos, message)
    }

    /// The position of the next token or value, its line counted from the last one asked for.
    fn position(&mut self) -> Position {
        if !self.binary {
            self.skip_space();
        }
        let newlines = |s: &[u8]| s.iter().filter(|&&b| b == b'\n').count();
        if self.pos >= self.counted {
            self.line += newlines(&self.bytes[self.counted..self.pos]);
        } else {
            self.line -= newlines(&self.bytes[self.pos..self.counted]);
        }
        self.counted = self.pos;
        Position { byte: self.pos, line: self.line }
    }

    fn skip_space(&mut self) {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// Steps over the newline after a header line, where binary data starts.
    fn skip_newline(&mut self) {
        if self.bytes.get(self.pos) == Some(&b'\r') {
            self.pos += 1;
        }
        if self.pos < self.bytes.len() {
            self.pos += 1;
        }
    }

    /// The next whitespace-separated ASCII token; `what` names it in the error at the end of
    /// the file.
    fn token(&mut self, what: &str) -> Result<&'a str, GmshError> {
        self.skip_space();
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.error(format!("the file ends where {what} was expected (truncated?)")));
        }
        std::str::from_utf8(&self.bytes[start..self.pos])
            .map_err(|_| self.error_at(start, format!("{what}: not text")))
    }

    fn parse_token<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, GmshError> {
        let t = self.token(what)?;
        t.parse().map_err(|_| self.error(format!("{what}: expected a number, found `{t}`")))
    }

    /// `N` raw bytes of binary data.
    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N], GmshError> {
        let Some(s) = self.bytes.get(self.pos..self.pos + N) else {
            return Err(self.error(format!("the file ends inside {what} (truncated?)")));
        };
        self.pos += N;
        Ok(s.try_into().expect("a slice of N bytes"))
    }

    /// A C `int`.
    fn int(&mut self, what: &str) -> Result<i32, GmshError> {
        if self.binary {
            Ok(i32::from_le_bytes(self.take(what)?))
        } else {
            self.parse_token(what)
        }
    }

    /// A `size_t` (a count or a node/element tag), checked non-negative in ASCII.
    fn size(&mut self, what: &str) -> Result<u64, GmshError> {
        if !self.binary {
            self.skip_space();
            let start = self.pos;
            let t = self.token(what)?;
            return t.parse().map_err(|_| match t.parse::<i64>() {
                Ok(v) => self.error_at(start, format!("{what}: {v} is negative")),
                Err(_) => self.error(format!("{what}: expected a number, found `{t}`")),
            });
        }
        Ok(match self.size_t {
            4 => u32::from_le_bytes(self.take(what)?) as u64,
            _ => u64::from_le_bytes(self.take(what)?),
        })
    }

    fn double(&mut self, what: &str) -> Result<f64, GmshError> {
        if self.binary {
            Ok(f64::from_le_bytes(self.take(what)?))
        } else {
            self.parse_token(what)
        }
    }

    /// A count used to size an allocation: at most the bytes left (each item takes at least one).
    fn count(&mut self, what: &str) -> Result<usize, GmshError> {
        if !self.binary {
            self.skip_space();
        }
        let start = self.pos;
        let n = self.size(what)?;
        match usize::try_from(n) {
            Ok(n) if n <= self.bytes.len() - self.pos => Ok(n),
            _ => Err(self
                .error_at(start, format!("{what}: {n} is more than the file holds (truncated?)"))),
        }
    }

    /// The next section header `$Name`, or `None` at the end of the file.
    fn section(&mut self) -> Result<Option<&'a str>, GmshError> {
        self.skip_space();
        if self.pos == self.bytes.len() {
            return Ok(None);
        }
        let start = self.pos;
        let t = self.token("a section")?;
        match t.strip_prefix('$') {
            Some(name) if !name.starts_with("End") => {
                if self.binary {
                    self.skip_newline();
                }
                Ok(Some(name))
            }
            _ => {
                Err(self.error_at(start, format!("expected a section header `$Name`, found `{t}`")))
            }
        }
    }

    /// Expects `$End<name>` next.
    fn end(&mut self, name: &str) -> Result<(), GmshError> {
        self.skip_space();
        let start = self.pos;
        let want = format!("$End{name}");
        let got = self.token(&want)?;
        if got != want {
            return Err(self.error_at(start, format!("expected `{want}`, found `{got}`")));
        }
        Ok(())
    }

    /// Skips to just after `$End<name>`.
    fn skip_section(&mut self, name: &str) -> Result<(), GmshError> {
        let start = self.pos;
        let want = format!("$End{name}");
        let found = self.bytes[self.pos..].windows(want.len()).position(|w| w == want.as_bytes());
        match found {
            Some(k) => {
                self.pos += k + want.len();
                Ok(())
            }
            None => {
                Err(self.error_at(start, format!("section `${name}` has no `{want}` (truncated?)")))
            }
        }
    }
}

/// `$MeshFormat`: version 4.1, ASCII or little-endian binary.
fn mesh_format(r: &mut Reader) -> Result<(), GmshError> {
    let version = r.token("the format version")?;
    if version != "4.1" {
        return Err(r.error(format!(
            "MSH format version {version}; only 4.1 is read (gmsh: -format msh41, or Mesh.MshFileVersion = 4.1)"
        )));
    }
    let file_type: i64 = r.parse_token("the file type")?;
    r.size_t = r.parse_token("the data size")?;
    match file_type {
        0 => Ok(()),
        1 => {
            if r.size_t != 4 && r.size_t != 8 {
                return Err(r.error(format!("data size {}: expected 4 or 8", r.size_t)));
            }
            // One newline, then the integer 1 in the writer's byte order.
            r.skip_newline();
            match r.take::<4>("the byte-order mark")? {
                [1, 0, 0, 0] => {}
                [0, 0, 0, 1] => {
                    return Err(r.error("big-endian binary files are not read: write the mesh as ASCII or on a little-endian machine"))
                }
                _ => return Err(r.error("binary file: the byte-order integer is not 1")),
            }
            r.binary = true;
            Ok(())
        }
        _ => Err(r.error(format!("file type {file_type}: expected 0 (ASCII) or 1 (binary)"))),
    }
}

/// `$PhysicalNames` (ASCII in binary files too): `(dim, tag) -> name`.
fn read_physical_names(r: &mut Reader) -> Result<HashMap<(i32, i32), String>, GmshError> {
    let mut names = HashMap::new();
    let n: usize = r.parse_token("the number of physical names")?;
    for _ in 0..n {
        let dim = r.parse_token("a physical group dimension")?;
        let tag = r.parse_token("a physical group tag")?;
        r.skip_space();
        let start = r.pos;
        if r.bytes.get(r.pos) != Some(&b'"') {
            return Err(r.error("expected a quoted physical group name"));
        }
        let len = r.bytes[start + 1..].iter().position(|&b| b == b'"' || b == b'\n');
        let Some(len) = len.filter(|&l| r.bytes[start + 1 + l] == b'"') else {
            return Err(r.error("unterminated physical group name"));
        };
        let name = String::from_utf8_lossy(&r.bytes[start + 1..start + 1 + len]).into_owned();
        r.pos = start + len + 2;
        names.insert((dim, tag), name);
    }
    Ok(names)
}

/// `$Entities`: points, curves, surfaces and volumes with their physical tags (bounding boxes
/// and bounding entities are read and dropped).
fn read_entities(r: &mut Reader) -> Result<HashMap<(i32, i32), Entity>, GmshError> {
    let mut counts = [0usize; 4];
    for (d, c) in counts.iter_mut().enumerate() {
        *c = r.count(&format!("the number of {d}-dimensional entities"))?;
    }
    let mut entities = HashMap::new();
    for (dim, &count) in (0..).zip(&counts) {
        for _ in 0..count {
            let at = r.position();
            let tag = r.int("an entity tag")?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                r.double("an entity bounding box")?;
            }
            let n = r.count("the number of physical tags")?;
            let physical =
                (0..n).map(|_| r.int("a physical tag")).collect::<Result<Vec<_>, _>>()?;
            if dim > 0 {
                let n = r.count("the number of bounding entities")?;
                for _ in 0..n {
                    r.int("a bounding entity tag")?;
                }
            }
            if entities.insert((dim, tag), Entity { dim, tag, physical, at }).is_some() {
                return Err(
                    r.error_at(at.byte, format!("{dim}-dimensional entity {tag} appears twice"))
                );
            }
        }
    }
    Ok(entities)
}

/// Node tag -> index into the coordinates: a table over the tag range when it is dense enough,
/// else a hash map.
enum NodeIndex {
    Dense { min: u64, index: Vec<u32> },
    Sparse(HashMap<u64, u32>),
}

impl NodeIndex {
    fn get(&self, tag: u64) -> Option<u32> {
        match self {
            NodeIndex::Dense { min, index } => tag
                .checked_sub(*min)
                .and_then(|k| index.get(usize::try_from(k).ok()?))
                .copied()
                .filter(|&i| i != u32::MAX),
            NodeIndex::Sparse(map) => map.get(&tag).copied(),
        }
    }

    /// Records `tag -> i`; `false` if the tag was there already.
    fn insert(&mut self, tag: u64, i: u32) -> bool {
        match self {
            NodeIndex::Dense { min, index } => {
                std::mem::replace(&mut index[(tag - *min) as usize], i) == u32::MAX
            }
            NodeIndex::Sparse(map) => map.insert(tag, i).is_none(),
        }
    }
}

/// `$Nodes`: coordinates, tags and the tag -> index map.
/// What `$Nodes` holds.
struct Nodes {
    coords: Vec<[f64; 3]>,
    tags: Vec<u64>,
    index: NodeIndex,
}

fn read_nodes(r: &mut Reader) -> Result<Nodes, GmshError> {
    let blocks = r.count("the number of node blocks")?;
    let n = r.count("the number of nodes")?;
    let min = r.size("the minimum node tag")?;
    let max = r.size("the maximum node tag")?;
    if n > u32::MAX as usize - 1 {
        return Err(r.error(format!("{n} nodes: more than this reader indexes")));
    }
    let dense = max >= min && max - min < 4 * n as u64 + 1024;
    let mut index = if dense {
        NodeIndex::Dense { min, index: vec![u32::MAX; (max - min + 1) as usize] }
    } else {
        NodeIndex::Sparse(HashMap::with_capacity(n))
    };
    let mut coords = Vec::with_capacity(n);
    let mut tags = Vec::with_capacity(n);
    for _ in 0..blocks {
        let dim = r.int("a node block's entity dimension")?;
        r.int("a node block's entity tag")?;
        let parametric = r.int("a node block's parametric flag")?;
        let count = r.count("the number of nodes in a block")?;
        let first = coords.len();
        if first + count > n {
            return Err(r.error(format!("the node blocks hold more than the {n} nodes announced")));
        }
        for k in 0..count {
            let at = r.position();
            let tag = r.size("a node tag")?;
            if tag < min || tag > max {
                return Err(r.error_at(
                    at.byte,
                    format!("node tag {tag} outside the announced range {min}..={max}"),
                ));
            }
            if !index.insert(tag, (first + k) as u32) {
                return Err(r.error_at(at.byte, format!("node tag {tag} appears twice")));
            }
            tags.push(tag);
        }
        let params = if parametric == 1 { dim.clamp(0, 3) as usize } else { 0 };
        for _ in 0..count {
            let at = r.position();
            let p = [r.double("a node x")?, r.double("a node y")?, r.double("a node z")?];
            if !p.iter().all(|v| v.is_finite()) {
                return Err(r.error_at(at.byte, format!("non-finite node coordinates {p:?}")));
            }
            for _ in 0..params {
                r.double("a node's parametric coordinate")?;
            }
            coords.push(p);
        }
    }
    if coords.len() != n {
        return Err(r.error(format!("the node blocks hold {} nodes, {n} announced", coords.len())));
    }
    Ok(Nodes { coords, tags, index })
}

/// `$Elements`: the blocks, node tags resolved to indices.
fn read_elements(
    r: &mut Reader,
    index: &NodeIndex,
    accept: &impl Fn(ElementType) -> Result<(), String>,
) -> Result<Vec<ElementBlock>, GmshError> {
    let n_blocks = r.count("the number of element blocks")?;
    let total = r.position();
    let n = r.size("the number of elements")?;
    r.size("the minimum element tag")?;
    r.size("the maximum element tag")?;
    let mut blocks = Vec::with_capacity(n_blocks);
    let mut seen = 0u64;
    for _ in 0..n_blocks {
        let at = r.position();
        let dim = r.int("an element block's entity dimension")?;
        let entity = r.int("an element block's entity tag")?;
        let code = r.int("an element type")?;
        let count = r.count("the number of elements in a block")?;
        let kind = element_type(code).ok_or_else(|| {
            r.error_at(at.byte, format!("element type {code} is not a gmsh element type this reader knows (fixed-size lines, triangles, quadrangles, tetrahedra, hexahedra, prisms, pyramids, points)"))
        })?;
        if dim != kind.shape.dim() {
            return Err(
                r.error_at(at.byte, format!("a {kind} block on a {dim}-dimensional entity"))
            );
        }
        accept(kind).map_err(|message| r.error_at(at.byte, message))?;
        let mut block = ElementBlock {
            dim,
            entity,
            kind,
            at,
            tags: Vec::with_capacity(count),
            positions: Vec::with_capacity(count),
            connectivity: Vec::with_capacity(count * kind.n_nodes),
        };
        for _ in 0..count {
            block.positions.push(r.position());
            let tag = r.size("an element tag")?;
            block.tags.push(tag);
            for _ in 0..kind.n_nodes {
                if !r.binary {
                    r.skip_space();
                }
                let pos = r.pos;
                let t = r.size("an element's node tag")?;
                let i = index.get(t).ok_or_else(|| {
                    r.error_at(
                        pos,
                        format!("element {tag} refers to node {t}, which is not in `$Nodes`"),
                    )
                })?;
                block.connectivity.push(i);
            }
        }
        seen += count as u64;
        blocks.push(block);
    }
    if seen != n {
        return Err(
            r.error_at(total.byte, format!("{n} elements announced, the blocks hold {seen}"))
        );
    }
    Ok(blocks)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in the x-y plane: curve 1 (physical 1 "clamped") from node 10 to node 20,
    /// two triangles on surface 1 (physical 2 "plate", physical 7 unnamed), node tags sparse.
    const SQUARE: &str = r#"$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
1 1 "clamped"
2 2 "plate"
$EndPhysicalNames
$Entities
0 1 1 0
1 0 0 0 0 1 0 1 1 0
1 0 0 0 1 1 0 2 2 -7 0
$EndEntities
$Nodes
2 4 10 40
1 1 0 2
10
20
0 0 0
0 1 0
2 1 0 2
30
40
1 0 0
1 1 0
$EndNodes
$Elements
2 3 1 3
1 1 1 1
1 10 20
2 1 2 2
2 10 30 40
3 10 40 20
$EndElements
"#;

    fn all(_: ElementType) -> Result<(), String> {
        Ok(())
    }

    fn err(text: &str) -> String {
        parse(text.as_bytes(), "t.msh", all).map(|_| ()).unwrap_err().to_string()
    }

    /// `SQUARE` with its line `n` (1-based) replaced.
    fn with_line(n: usize, line: &str) -> String {
        let mut lines: Vec<&str> = SQUARE.lines().collect();
        lines[n - 1] = line;
        lines.join("\n") + "\n"
    }

    #[test]
    fn ascii_file_gives_nodes_blocks_and_groups() {
        let m = parse(SQUARE.as_bytes(), "square.msh", all).unwrap();
        assert!(!m.binary);
        assert_eq!(m.node_tags, vec![10, 20, 30, 40]);
        assert_eq!(m.coords[2], [1.0, 0.0, 0.0]);
        assert_eq!(m.blocks.len(), 2);
        let (line, tri) = (&m.blocks[0], &m.blocks[1]);
        assert_eq!(
            (line.dim, line.entity, line.kind.code, line.kind.shape),
            (1, 1, 1, Shape::Line)
        );
        assert_eq!(line.connectivity, vec![0, 1]);
        assert_eq!((tri.dim, tri.entity, tri.kind.n_nodes, tri.len()), (2, 1, 3, 2));
        assert_eq!(tri.elements().collect::<Vec<_>>(), vec![&[0, 2, 3][..], &[0, 3, 1][..]]);
        assert_eq!(tri.tags, vec![2, 3]);
        assert_eq!(tri.at.line, 31);
        assert_eq!(tri.positions.iter().map(|p| p.line).collect::<Vec<_>>(), vec![32, 33]);
        assert_eq!(m.physical_groups(1, 1), &[1]);
        assert_eq!(m.physical_groups(2, 1), &[2, -7]);
        assert_eq!(m.physical_groups(3, 1), &[] as &[i32]);
        assert_eq!(m.physical_name(1, 1), Some("clamped"));
        assert_eq!(m.physical_name(2, 2), Some("plate"));
        assert_eq!(m.physical_name(2, -7), None);
        assert_eq!(m.entities.as_ref().unwrap()[&(2, 1)].at.line, 12);
        assert_eq!(m.end.line, SQUARE.lines().count() + 1);
        let e = m.error(tri.positions[1], "refused");
        assert_eq!(e.to_string(), "square.msh:33: refused");
    }

    /// The same mesh written in binary (size_t of 8 bytes, then of 4) reads alike, with the
    /// positions of its items as byte offsets.
    #[test]
    fn binary_file_reads_like_ascii() {
        for size_t in [8usize, 4] {
            let bytes = binary_square(size_t);
            let b = parse(&bytes, "b.msh", all).unwrap();
            let a = parse(SQUARE.as_bytes(), "a.msh", all).unwrap();
            assert!(b.binary);
            assert_eq!((&a.coords, &a.node_tags), (&b.coords, &b.node_tags));
            assert_eq!(a.physical_names, b.physical_names);
            for (x, y) in a.blocks.iter().zip(&b.blocks) {
                assert_eq!((x.dim, x.entity, x.kind), (y.dim, y.entity, y.kind));
                assert_eq!((&x.tags, &x.connectivity), (&y.tags, &y.connectivity));
            }
            for (k, e) in a.entities.as_ref().unwrap() {
                assert_eq!(e.physical, b.entities.as_ref().unwrap()[k].physical);
            }
            let tri = &b.blocks[1];
            assert_eq!(&bytes[tri.positions[1].byte..][..size_t], &3u64.to_le_bytes()[..size_t]);
            let e = b.error(tri.positions[1], "refused").to_string();
            assert!(e.starts_with(&format!("b.msh: byte {} (line ", tri.positions[1].byte)), "{e}");
            // Cut inside the element data: the byte offset of the end is named.
            let cut = &bytes[..tri.positions[1].byte + 3];
            let e = parse(cut, "cut.msh", all).unwrap_err().to_string();
            assert!(e.starts_with(&format!("cut.msh: byte {} ", cut.len() - 3)), "{e}");
            assert!(e.contains("truncated"), "{e}");
        }
    }

    /// `SQUARE` in binary MSH 4.1 with `size_t` of `s` bytes.
    fn binary_square(s: usize) -> Vec<u8> {
        let mut b: Vec<u8> = format!("$MeshFormat\n4.1 1 {s}\n").into_bytes();
        let int = |b: &mut Vec<u8>, v: i32| b.extend(v.to_le_bytes());
        let size = |b: &mut Vec<u8>, v: u64| b.extend(&v.to_le_bytes()[..s]);
        let dbl = |b: &mut Vec<u8>, v: f64| b.extend(v.to_le_bytes());
        int(&mut b, 1);
        b.extend(b"\n$EndMeshFormat\n$PhysicalNames\n2\n1 1 \"clamped\"\n2 2 \"plate\"\n");
        b.extend(b"$EndPhysicalNames\n$Entities\n");
        for c in [0, 1, 1, 0] {
            size(&mut b, c);
        }
        for (dim_tag, phys) in [(1, &[1][..]), (1, &[2, -7][..])] {
            int(&mut b, dim_tag);
            for v in [0.0, 0.0, 0.0, 1.0, 1.0, 0.0] {
                dbl(&mut b, v);
            }
            size(&mut b, phys.len() as u64);
            phys.iter().for_each(|&p| int(&mut b, p));
            size(&mut b, 0);
        }
        b.extend(b"\n$EndEntities\n$Nodes\n");
        for v in [2, 4, 10, 40] {
            size(&mut b, v);
        }
        for (dim, tags, xs) in [
            (1, [10, 20], [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
            (2, [30, 40], [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]),
        ] {
            for v in [dim, 1, 0] {
                int(&mut b, v);
            }
            size(&mut b, 2);
            tags.iter().for_each(|&t| size(&mut b, t));
            xs.iter().flatten().for_each(|&x| dbl(&mut b, x));
        }
        b.extend(b"\n$EndNodes\n$Elements\n");
        for v in [2, 3, 1, 3] {
            size(&mut b, v);
        }
        for (dim, code, elems) in
            [(1, 1, vec![vec![1, 10, 20]]), (2, 2, vec![vec![2, 10, 30, 40], vec![3, 10, 40, 20]])]
        {
            for v in [dim, 1, code] {
                int(&mut b, v);
            }
            size(&mut b, elems.len() as u64);
            elems.iter().flatten().for_each(|&t| size(&mut b, t));
        }
        b.extend(b"\n$EndElements\n");
        b
    }

    #[test]
    fn the_element_type_table_knows_node_counts_and_names() {
        let count = |c| element_type(c).unwrap().n_nodes;
        assert_eq!([1, 2, 3, 4, 5, 6, 7, 15].map(count), [2, 3, 4, 4, 8, 6, 5, 1]);
        assert_eq!(
            [8, 9, 10, 11, 12, 13, 14, 16, 17, 18, 19].map(count),
            [3, 6, 9, 10, 27, 18, 14, 8, 20, 15, 13]
        );
        assert_eq!(element_type(12).unwrap().to_string(), "second-order hexahedron (27 nodes)");
        assert_eq!(element_type(4).unwrap().to_string(), "tetrahedron");
        assert!(element_type(0).is_none() && element_type(99).is_none());
        for c in (1..32).chain([92, 93]) {
            let t = element_type(c).unwrap();
            assert!(t.n_nodes > t.shape.dim() as usize, "{c}: {t}");
        }
    }

    #[test]
    fn sections_it_does_not_read_are_skipped() {
        let text = SQUARE.replacen(
            "$EndMeshFormat\n",
            "$EndMeshFormat\n$Comments\n$Nodes 1 2 3\n$EndComments\n",
            1,
        );
        let m = parse(text.as_bytes(), "c.msh", all).unwrap();
        assert_eq!(m.blocks[1].positions[0].line, 35);
    }

    #[test]
    fn bad_files_give_errors_naming_file_and_line() {
        let cut = &SQUARE[..SQUARE.find("3 10 40 20").unwrap()];
        let open = &SQUARE[..SQUARE.find("$EndPhysicalNames").unwrap()];
        let cases: Vec<(String, &str)> = vec![
            (cut.to_string(), "t.msh:33: the file ends where an element tag was expected"),
            (SQUARE.replace("4.1 0 8", "2.2 0 8"), "t.msh:2: MSH format version 2.2; only 4.1"),
            (SQUARE.replace("4.1 0 8", "4.1 3 8"), "t.msh:2: file type 3"),
            (with_line(31, "2 1 99 2"), "t.msh:31: element type 99 is not a gmsh element type"),
            (with_line(31, "3 1 2 2"), "t.msh:31: a triangle block on a 3-dimensional entity"),
            (with_line(33, "3 10 40 21"), "t.msh:33: element 3 refers to node 21, which is not in"),
            (with_line(18, "10"), "t.msh:18: node tag 10 appears twice"),
            (with_line(18, "41"), "t.msh:18: node tag 41 outside the announced range 10..=40"),
            (with_line(24, "1 nan 0"), "t.msh:24: non-finite node coordinates"),
            (with_line(15, "2 5 10 40"), "t.msh:25: the node blocks hold 4 nodes, 5 announced"),
            (with_line(32, "2 10 x 40"), "t.msh:32: an element's node tag: expected a number"),
            (with_line(32, "2 10 -30 40"), "t.msh:32: an element's node tag: -30 is negative"),
            (with_line(28, "2 4 1 3"), "t.msh:28: 4 elements announced, the blocks hold 3"),
            (with_line(13, "$EndEntitie"), "t.msh:13: expected `$EndEntities`, found `$EndEnt"),
            (with_line(10, "0 1 1 x"), "t.msh:10: the number of 3-dimensional entities: expected"),
            (
                with_line(12, "1 0 0 0 1 1 0 99999 2"),
                "t.msh:12: the number of physical tags: 99999 is",
            ),
            (SQUARE.replace("\"plate\"", "\"plate"), "t.msh:7: unterminated physical group name"),
            (SQUARE.replace("$Entities", "$PartitionedEntities"), "t.msh:9: partitioned meshes"),
            (SQUARE.replacen("$MeshFormat", "$Comments", 1), "t.msh:1: not a gmsh .msh file"),
            (String::new(), "t.msh:1: empty file"),
            (SQUARE[..SQUARE.find("$Elements").unwrap()].to_string(), "no `$Elements`"),
            (open.to_string(), "t.msh:8: the file ends where $EndPhysicalNames was expected"),
            (
                SQUARE.replacen("$EndMeshFormat\n", "$EndMeshFormat\n$Comments\n", 1),
                "t.msh:4: section `$Comments` has no `$EndComments`",
            ),
        ];
        for (text, want) in cases {
            let e = err(&text);
            assert!(e.contains(want), "expected `{want}` in: {e}");
        }
        // A type the caller refuses is refused at its block header, before its data: here a
        // miswritten second-order header over linear lines.
        let lines_only = |t: ElementType| match t.shape {
            Shape::Line if t.order == 1 => Ok(()),
            _ => Err(format!("element type {} ({t}) is not read", t.code)),
        };
        let text = with_line(29, "1 1 8 1");
        let e = parse(text.as_bytes(), "t.msh", lines_only).unwrap_err().to_string();
        assert_eq!(e, "t.msh:29: element type 8 (second-order line (3 nodes)) is not read");
        let e = parse(SQUARE.as_bytes(), "t.msh", lines_only).unwrap_err().to_string();
        assert_eq!(e, "t.msh:31: element type 2 (triangle) is not read");
        // Elements before nodes.
        let nodes = SQUARE.find("$Nodes").unwrap();
        let elements = SQUARE.find("$Elements").unwrap();
        let swapped = format!("{}{}", &SQUARE[..nodes], &SQUARE[elements..]);
        assert!(
            err(&swapped).contains("t.msh:14: `$Elements` comes before `$Nodes`"),
            "{}",
            err(&swapped)
        );
        // Big-endian binary data is refused by name.
        let mut big = binary_square(8);
        let mark = big.windows(8).position(|w| w == b"4.1 1 8\n").unwrap() + 8;
        big[mark..mark + 4].copy_from_slice(&[0, 0, 0, 1]);
        let e = parse(&big, "big.msh", all).unwrap_err().to_string();
        assert!(e.starts_with("big.msh:3: big-endian"), "{e}");
        let e = read(Path::new("/nonexistent/m.msh"), all).unwrap_err();
        assert_eq!(e.location(), "/nonexistent/m.msh");
        assert!(e.to_string().contains("cannot read the mesh file"), "{e}");
    }
}
