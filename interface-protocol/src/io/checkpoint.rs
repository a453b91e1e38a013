//! Checkpoint folders `checkpoints/<tag>/<part>.ckpt`: named `f64`/`u64`/`u32`/`u8` arrays plus
//! a small serde metadata struct, written atomically and read back bitwise.
//!
//! Each process writes its own part (`fluid`, `structure`, `launcher`) into the tag folder, so
//! coupled solvers never write the same file; [`latest`] finds the newest tag whose parts are all
//! present and intact.
//!
//! File format (all integers little-endian):
//!
//! | bytes      | content                                                                   |
//! |------------|---------------------------------------------------------------------------|
//! | 8          | magic `FSICKPT\0`                                                        |
//! | 4          | format version, `u32` = 1                                                 |
//! | 4          | array count `u32`                                                         |
//! | 8          | step `u64`                                                                |
//! | 8          | time, `f64` bits                                                          |
//! | 8 + m      | metadata length `u64` m, then the metadata (postcard)                     |
//! | per array  | name length `u16` n, name (UTF-8, n bytes), type `u8` (1 f64, 2 u64, 3 u32,  |
//! |            | 4 u8), element count `u64` k, then the k elements                         |
//! | 8          | checksum `u64` of every preceding byte (see [`checksum`])                |

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::Serialize;

mod search;
pub use search::{latest, restart_point, search, Found, Search, Skipped};

const MAGIC: &[u8; 8] = b"FSICKPT\0";
const VERSION: u32 = 1;
/// File extension of a checkpoint part.
pub const EXTENSION: &str = "ckpt";

/// An array stored in a checkpoint.
#[derive(Debug, Clone, PartialEq)]
pub enum Array {
    F64(Vec<f64>),
    U64(Vec<u64>),
    U32(Vec<u32>),
    U8(Vec<u8>),
}

impl Array {
    fn code(&self) -> u8 {
        match self {
            Array::F64(_) => 1,
            Array::U64(_) => 2,
            Array::U32(_) => 3,
            Array::U8(_) => 4,
        }
    }
    fn type_name(&self) -> &'static str {
        match self {
            Array::F64(_) => "f64",
            Array::U64(_) => "u64",
            Array::U32(_) => "u32",
            Array::U8(_) => "u8",
        }
    }
    fn len(&self) -> usize {
        match self {
            Array::F64(v) => v.len(),
            Array::U64(v) => v.len(),
            Array::U32(v) => v.len(),
            Array::U8(v) => v.len(),
        }
    }
}

impl From<Vec<f64>> for Array {
    fn from(v: Vec<f64>) -> Self {
        Array::F64(v)
    }
}
impl From<Vec<u64>> for Array {
    fn from(v: Vec<u64>) -> Self {
        Array::U64(v)
    }
}
impl From<Vec<u32>> for Array {
    fn from(v: Vec<u32>) -> Self {
        Array::U32(v)
    }
}
impl From<Vec<u8>> for Array {
    fn from(v: Vec<u8>) -> Self {
        Array::U8(v)
    }
}

/// A checkpoint could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("checkpoint `{path}`: {source}")]
    Io { path: String, source: io::Error },
    #[error(
        "checkpoint `{path}` is truncated: {what} needs bytes up to {needed}, the file has {len}"
    )]
    Truncated { path: String, what: String, needed: u64, len: u64 },
    #[error("checkpoint `{path}` is corrupt: {reason}")]
    Corrupt { path: String, reason: String },
    #[error("checkpoint `{path}` has no array `{name}` (it holds: {})", .available.join(", "))]
    MissingArray { path: String, name: String, available: Vec<String> },
    #[error("checkpoint `{path}`: array `{name}` holds {found}, not {expected}")]
    WrongType { path: String, name: String, expected: &'static str, found: &'static str },
    #[error("checkpoint `{path}`: array `{name}` has {len} values, not a multiple of {width}")]
    Shape { path: String, name: String, len: usize, width: usize },
    #[error("checkpoint `{path}`: metadata: {source}")]
    Meta { path: String, source: postcard::Error },
    #[error("checkpoint array name `{0}` must be 1 to 65535 bytes long")]
    BadName(String),
    #[error(
        "checkpoint tag or part `{0}` must be non-empty, not start with `.`, and contain no `/` \
         or `\\`"
    )]
    BadTag(String),
}

/// The state of one process at one step.
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    pub step: u64,
    pub time: f64,
    meta: Vec<u8>,
    arrays: Vec<(String, Array)>,
    /// Where it was read from, for error messages.
    origin: String,
}

impl Checkpoint {
    /// An empty checkpoint for `step` at `time`.
    pub fn new(step: u64, time: f64) -> Self {
        Self { step, time, meta: Vec::new(), arrays: Vec::new(), origin: "(in memory)".into() }
    }

    /// Stores the metadata struct (postcard-encoded).
    pub fn set_meta<M: Serialize>(&mut self, meta: &M) -> Result<(), CheckpointError> {
        self.meta = postcard::to_stdvec(meta)
            .map_err(|source| CheckpointError::Meta { path: self.origin.clone(), source })?;
        Ok(())
    }

    /// Decodes the metadata struct.
    pub fn meta<M: DeserializeOwned>(&self) -> Result<M, CheckpointError> {
        postcard::from_bytes(&self.meta)
            .map_err(|source| CheckpointError::Meta { path: self.origin.clone(), source })
    }

    /// Stores `array` under `name`, replacing an array of the same name:
    /// `ck.put("rho", rho.to_vec())?`.
    pub fn put(&mut self, name: &str, array: impl Into<Array>) -> Result<(), CheckpointError> {
        let array = array.into();
        if name.is_empty() || name.len() > u16::MAX as usize {
            return Err(CheckpointError::BadName(name.to_string()));
        }
        match self.arrays.iter_mut().find(|(n, _)| n == name) {
            Some((_, a)) => *a = array,
            None => self.arrays.push((name.to_string(), array)),
        }
        Ok(())
    }

    /// Stores a field of `N`-vectors flattened (read it back with [`Checkpoint::f64_n`]).
    pub fn put_f64_n<const N: usize>(
        &mut self,
        name: &str,
        v: &[[f64; N]],
    ) -> Result<(), CheckpointError> {
        self.put(name, Array::F64(v.as_flattened().to_vec()))
    }

    /// Names of the stored arrays, in insertion order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.arrays.iter().map(|(n, _)| n.as_str())
    }

    /// The array `name`, or an error listing what the checkpoint holds.
    pub fn get(&self, name: &str) -> Result<&Array, CheckpointError> {
        self.arrays.iter().find(|(n, _)| n == name).map(|(_, a)| a).ok_or_else(|| {
            CheckpointError::MissingArray {
                path: self.origin.clone(),
                name: name.to_string(),
                available: self.names().map(str::to_string).collect(),
            }
        })
    }

    fn wrong_type(&self, name: &str, expected: &'static str, a: &Array) -> CheckpointError {
        CheckpointError::WrongType {
            path: self.origin.clone(),
            name: name.to_string(),
            expected,
            found: a.type_name(),
        }
    }

    pub fn f64(&self, name: &str) -> Result<&[f64], CheckpointError> {
        match self.get(name)? {
            Array::F64(v) => Ok(v),
            a => Err(self.wrong_type(name, "f64", a)),
        }
    }

    /// An `f64` array regrouped into `N`-vectors.
    pub fn f64_n<const N: usize>(&self, name: &str) -> Result<Vec<[f64; N]>, CheckpointError> {
        let flat = self.f64(name)?;
        if N == 0 || flat.len() % N != 0 {
            let path = self.origin.clone();
            return Err(CheckpointError::Shape {
                path,
                name: name.into(),
                len: flat.len(),
                width: N,
            });
        }
        Ok(flat.chunks_exact(N).map(|c| c.try_into().expect("chunk of length N")).collect())
    }

    pub fn u64(&self, name: &str) -> Result<&[u64], CheckpointError> {
        match self.get(name)? {
            Array::U64(v) => Ok(v),
            a => Err(self.wrong_type(name, "u64", a)),
        }
    }

    pub fn u32(&self, name: &str) -> Result<&[u32], CheckpointError> {
        match self.get(name)? {
            Array::U32(v) => Ok(v),
            a => Err(self.wrong_type(name, "u32", a)),
        }
    }

    pub fn u8(&self, name: &str) -> Result<&[u8], CheckpointError> {
        match self.get(name)? {
            Array::U8(v) => Ok(v),
            a => Err(self.wrong_type(name, "u8", a)),
        }
    }

    /// Writes `checkpoints_dir/<tag>/<part>.ckpt` atomically; returns its path.
    pub fn write(
        &self,
        checkpoints_dir: &Path,
        tag: &str,
        part: &str,
    ) -> Result<PathBuf, CheckpointError> {
        check_tag(tag)?;
        check_tag(part)?;
        let dir = checkpoints_dir.join(tag);
        let path = part_path(&dir, part);
        fs::create_dir_all(&dir)
            .map_err(|source| CheckpointError::Io { path: dir.display().to_string(), source })?;
        self.write_file(&path)?;
        Ok(path)
    }

    /// Writes the checkpoint to `path` atomically.
    pub fn write_file(&self, path: &Path) -> Result<(), CheckpointError> {
        let bytes = self.encode();
        super::atomic::write_bytes_atomic(path, &bytes)
            .map_err(|source| CheckpointError::Io { path: path.display().to_string(), source })
    }

    /// Reads `checkpoints_dir/<tag>/<part>.ckpt`.
    pub fn read(checkpoints_dir: &Path, tag: &str, part: &str) -> Result<Self, CheckpointError> {
        Self::read_file(&part_path(&checkpoints_dir.join(tag), part))
    }

    /// Reads and verifies a checkpoint file.
    pub fn read_file(path: &Path) -> Result<Self, CheckpointError> {
        let origin = path.display().to_string();
        let bytes = fs::read(path)
            .map_err(|source| CheckpointError::Io { path: origin.clone(), source })?;
        decode(&bytes, origin)
    }

    fn encode(&self) -> Vec<u8> {
        let payload: usize = self.arrays.iter().map(|(n, a)| 11 + n.len() + 8 * a.len()).sum();
        let mut b = Vec::with_capacity(48 + self.meta.len() + payload);
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&VERSION.to_le_bytes());
        b.extend_from_slice(&(self.arrays.len() as u32).to_le_bytes());
        b.extend_from_slice(&self.step.to_le_bytes());
        b.extend_from_slice(&self.time.to_bits().to_le_bytes());
        b.extend_from_slice(&(self.meta.len() as u64).to_le_bytes());
        b.extend_from_slice(&self.meta);
        for (name, a) in &self.arrays {
            b.extend_from_slice(&(name.len() as u16).to_le_bytes());
            b.extend_from_slice(name.as_bytes());
            b.push(a.code());
            b.extend_from_slice(&(a.len() as u64).to_le_bytes());
            match a {
                Array::F64(v) => {
                    v.iter().for_each(|x| b.extend_from_slice(&x.to_bits().to_le_bytes()))
                }
                Array::U64(v) => v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes())),
                Array::U32(v) => v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes())),
                Array::U8(v) => b.extend_from_slice(v),
            }
        }
        let sum = checksum(&b);
        b.extend_from_slice(&sum.to_le_bytes());
        b
    }
}

/// A bounds-checked reader over the file bytes: running past the end is reported as truncation.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    origin: &'a str,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: u64, what: &str) -> Result<&'a [u8], CheckpointError> {
        let needed = (self.pos as u64).saturating_add(n);
        if needed > self.bytes.len() as u64 {
            return Err(CheckpointError::Truncated {
                path: self.origin.to_string(),
                what: what.to_string(),
                needed,
                len: self.bytes.len() as u64,
            });
        }
        let s = &self.bytes[self.pos..needed as usize];
        self.pos = needed as usize;
        Ok(s)
    }
    fn array<const K: usize>(&mut self, what: &str) -> Result<[u8; K], CheckpointError> {
        Ok(self.take(K as u64, what)?.try_into().expect("took K bytes"))
    }
    fn u64(&mut self, what: &str) -> Result<u64, CheckpointError> {
        Ok(u64::from_le_bytes(self.array(what)?))
    }
}

fn decode(bytes: &[u8], origin: String) -> Result<Checkpoint, CheckpointError> {
    let corrupt = |reason: String| CheckpointError::Corrupt { path: origin.clone(), reason };
    let mut c = Cursor { bytes, pos: 0, origin: &origin };
    if c.array::<8>("the header")? != *MAGIC {
        return Err(corrupt("not a checkpoint file (bad magic bytes)".into()));
    }
    let version = u32::from_le_bytes(c.array("the header")?);
    if version != VERSION {
        return Err(corrupt(format!("format version {version}, this build reads {VERSION}")));
    }
    let count = u32::from_le_bytes(c.array("the header")?);
    let step = c.u64("the header")?;
    let time = f64::from_bits(c.u64("the header")?);
    let meta_len = c.u64("the header")?;
    let meta = c.take(meta_len, "the metadata")?.to_vec();
    let mut arrays = Vec::with_capacity(count.min(1024) as usize);
    for i in 0..count {
        let what = format!("array {i}");
        let name_len = u16::from_le_bytes(c.array(&what)?);
        let name = std::str::from_utf8(c.take(name_len.into(), &what)?)
            .map_err(|_| corrupt(format!("array {i} has a name that is not UTF-8")))?
            .to_string();
        let what = format!("array `{name}`");
        let code = c.array::<1>(&what)?[0];
        let len = c.u64(&what)?;
        let size = match code {
            1 | 2 => 8,
            3 => 4,
            4 => 1,
            _ => return Err(corrupt(format!("array `{name}` has unknown type code {code}"))),
        };
        let data = c.take(len.saturating_mul(size), &what)?;
        let array = match code {
            1 => Array::F64(data.chunks_exact(8).map(|x| f64::from_bits(le8(x))).collect()),
            2 => Array::U64(data.chunks_exact(8).map(le8).collect()),
            3 => Array::U32(
                data.chunks_exact(4).map(|x| u32::from_le_bytes(x.try_into().unwrap())).collect(),
            ),
            _ => Array::U8(data.to_vec()),
        };
        arrays.push((name, array));
    }
    let body_end = c.pos;
    let stored = c.u64("the checksum")?;
    if c.pos != bytes.len() {
        return Err(corrupt(format!(
            "{} unexpected bytes after the checksum",
            bytes.len() - c.pos
        )));
    }
    let computed = checksum(&bytes[..body_end]);
    if stored != computed {
        return Err(corrupt(format!(
            "checksum mismatch (stored {stored:016x}, computed {computed:016x}): the file was \
             damaged"
        )));
    }
    Ok(Checkpoint { step, time, meta, arrays, origin })
}

fn le8(x: &[u8]) -> u64 {
    u64::from_le_bytes(x.try_into().expect("8-byte chunk"))
}

/// FNV-1a (64-bit offset basis and prime) over the little-endian 64-bit words of `bytes`, the
/// last partial word zero-padded, then the byte length folded in the same way. Not
/// cryptographic: it detects truncation and damage, which is all a checkpoint needs.
pub fn checksum(bytes: &[u8]) -> u64 {
    const BASIS: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h = BASIS;
    let mut words = bytes.chunks_exact(8);
    for w in &mut words {
        h = (h ^ le8(w)).wrapping_mul(PRIME);
    }
    let rest = words.remainder();
    if !rest.is_empty() {
        let mut pad = [0u8; 8];
        pad[..rest.len()].copy_from_slice(rest);
        h = (h ^ u64::from_le_bytes(pad)).wrapping_mul(PRIME);
    }
    (h ^ bytes.len() as u64).wrapping_mul(PRIME)
}

fn check_tag(tag: &str) -> Result<(), CheckpointError> {
    if tag.is_empty() || tag.starts_with('.') || tag.contains(['/', '\\']) {
        return Err(CheckpointError::BadTag(tag.to_string()));
    }
    Ok(())
}

fn part_path(tag_dir: &Path, part: &str) -> PathBuf {
    tag_dir.join(format!("{part}.{EXTENSION}"))
}

/// The conventional tag of the checkpoint at `step`: `step_0000000042` (sorts by step).
pub fn tag_for_step(step: u64) -> String {
    format!("step_{step:010}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    /// Replaces a file's bytes, to damage it on purpose.
    pub(super) fn overwrite(path: &Path, bytes: &[u8]) {
        fs::write(path, bytes).unwrap();
    }

    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    struct Meta {
        scheme: String,
        newton_iterations: u32,
        dt: f64,
    }

    pub(super) fn sample(step: u64) -> Checkpoint {
        let mut c = Checkpoint::new(step, step as f64 * 1e-3);
        let awkward = vec![
            0.0,
            -0.0,
            f64::MIN_POSITIVE / 4.0,               // subnormal
            f64::from_bits(0x7ff8_0000_dead_beef), // NaN with a payload
            f64::INFINITY,
            1.0 / 3.0,
            -1e308,
        ];
        c.put("rho", Array::F64(awkward)).unwrap();
        c.put_f64_n("velocity", &[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]).unwrap();
        c.put("global_id", Array::U64(vec![0, u64::MAX, 1 << 40])).unwrap();
        c.put("status", vec![7u32, u32::MAX]).unwrap();
        c.put("phase", Array::U8(vec![0, 1, 255])).unwrap();
        c.put("empty", Array::F64(vec![])).unwrap();
        c.set_meta(&Meta { scheme: "A6".into(), newton_iterations: 3, dt: 2.5e-4 }).unwrap();
        c
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    #[test]
    fn round_trip_is_bitwise() {
        let dir = tempfile::tempdir().unwrap();
        let c = sample(42);
        let path = c.write(dir.path(), &tag_for_step(42), "fluid").unwrap();
        assert_eq!(path, dir.path().join("step_0000000042/fluid.ckpt"));
        let back = Checkpoint::read(dir.path(), "step_0000000042", "fluid").unwrap();
        assert_eq!((back.step, back.time.to_bits()), (42, c.time.to_bits()));
        assert_eq!(bits(back.f64("rho").unwrap()), bits(c.f64("rho").unwrap()));
        assert_eq!(back.f64_n::<3>("velocity").unwrap(), vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert_eq!(back.u64("global_id").unwrap(), &[0, u64::MAX, 1 << 40]);
        assert_eq!(back.u32("status").unwrap(), &[7, u32::MAX]);
        assert_eq!(back.u8("phase").unwrap(), &[0, 1, 255]);
        assert!(back.f64("empty").unwrap().is_empty());
        assert_eq!(back.meta::<Meta>().unwrap(), c.meta::<Meta>().unwrap());
        assert_eq!(back.names().collect::<Vec<_>>(), c.names().collect::<Vec<_>>());
        // Same bytes again: the encoding is deterministic.
        assert_eq!(back.encode(), c.encode());
    }

    #[test]
    fn missing_or_mistyped_array_is_a_clear_error() {
        let c = sample(1);
        let err = c.f64("pressure").unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, CheckpointError::MissingArray { .. }));
        assert!(msg.contains("`pressure`") && msg.contains("rho, velocity"), "{msg}");
        let err = c.u32("rho").unwrap_err().to_string();
        assert!(err.contains("holds f64, not u32"), "{err}");
        assert!(matches!(
            c.f64_n::<4>("velocity"),
            Err(CheckpointError::Shape { len: 6, width: 4, .. })
        ));
    }

    #[test]
    fn truncated_file_is_reported_as_truncated() {
        let dir = tempfile::tempdir().unwrap();
        let path = sample(3).write(dir.path(), "t", "fluid").unwrap();
        let bytes = fs::read(&path).unwrap();
        for cut in [0, 5, 40, bytes.len() / 2, bytes.len() - 1] {
            overwrite(&path, &bytes[..cut]);
            let err = Checkpoint::read_file(&path).unwrap_err();
            assert!(matches!(err, CheckpointError::Truncated { .. }), "cut {cut}: {err}");
            assert!(
                err.to_string().contains("fluid.ckpt") && err.to_string().contains("truncated")
            );
        }
    }

    #[test]
    fn flipped_bit_is_reported_as_corrupt() {
        let dir = tempfile::tempdir().unwrap();
        let path = sample(3).write(dir.path(), "t", "fluid").unwrap();
        let good = fs::read(&path).unwrap();
        // A bit in the `rho` values, one in the step, one in the checksum itself.
        let rho = good.windows(3).position(|w| w == b"rho").unwrap() + 3 + 1 + 8;
        for at in [rho + 20, 17, good.len() - 3] {
            let mut bad = good.clone();
            bad[at] ^= 0x10;
            overwrite(&path, &bad);
            let err = Checkpoint::read_file(&path).unwrap_err();
            assert!(matches!(err, CheckpointError::Corrupt { .. }), "byte {at}: {err}");
            assert!(err.to_string().contains("checksum mismatch"), "{err}");
        }
        overwrite(&path, b"PK\x03\x04 something else entirely, long enough for a header");
        assert!(Checkpoint::read_file(&path).unwrap_err().to_string().contains("bad magic"));
    }

    #[test]
    fn bad_tags_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let c = Checkpoint::new(0, 0.0);
        assert!(matches!(c.write(dir.path(), "../x", "fluid"), Err(CheckpointError::BadTag(_))));
        assert!(matches!(c.write(dir.path(), "ok", ""), Err(CheckpointError::BadTag(_))));
    }
}
