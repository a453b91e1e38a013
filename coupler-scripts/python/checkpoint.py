"""Checkpoint part files `checkpoints/<tag>/<part>.ckpt` of the FSI protocol (PROTOCOL §4,
restart) in Python: the format of `interface_protocol::io::checkpoint`, written atomically and
read back with every field checked, so a Python participant's checkpoint is one the launcher and
the Rust readers accept.
"""

import os
import struct

import numpy as np

from fsi_peer import _FNV_BASIS, _FNV_PRIME, _U64

# ---- checkpoint parts `checkpoints/<tag>/<part>.ckpt` (PROTOCOL §4, `io::checkpoint`) ----
#
# The format of `interface_protocol::io::checkpoint`, version 1, all integers little-endian:
# magic `FSICKPT\0`, u32 version, u32 array count, u64 step, f64 time, u64 metadata length m and
# m bytes of metadata (postcard), then per array u16 name length, the UTF-8 name, u8 type (1 f64,
# 2 u64, 3 u32, 4 u8), u64 element count and the elements; last the u64 checksum of every byte
# before it (`checkpoint::checksum`).

CKPT_MAGIC = b"FSICKPT\0"
CKPT_VERSION = 1
CKPT_EXTENSION = "ckpt"
_CKPT_TYPES = {1: ("f64", "<f8"), 2: ("u64", "<u8"), 3: ("u32", "<u4"), 4: ("u8", "u1")}


class CheckpointError(Exception):
    """A checkpoint part that cannot be written or read; the message names the file."""


def ckpt_checksum(data):
    """FNV-1a over the little-endian u64 words of `data` (the last one zero-padded), then the
    byte length folded in the same way."""
    h = _FNV_BASIS
    for (w,) in struct.iter_unpack("<Q", data + b"\0" * (-len(data) % 8)):
        h = ((h ^ w) * _FNV_PRIME) & _U64
    return ((h ^ len(data)) * _FNV_PRIME) & _U64


def _varint(n):
    out = bytearray()
    while True:
        byte, n = n & 0x7F, n >> 7
        out.append(byte | (0x80 if n else 0))
        if not n:
            return bytes(out)


def postcard_strings(names):
    """A `Vec<String>` as postcard encodes it: varint count, then varint length and UTF-8 each."""
    out = bytearray(_varint(len(names)))
    for name in names:
        data = name.encode("utf-8")
        out += _varint(len(data)) + data
    return bytes(out)


def postcard_strings_decode(data):
    """The `Vec<String>` of `postcard_strings`; ValueError if `data` is not exactly one."""
    pos = 0

    def varint():
        nonlocal pos
        n, shift = 0, 0
        while True:
            if pos >= len(data) or shift > 63:
                raise ValueError("truncated varint")
            byte = data[pos]
            pos += 1
            n |= (byte & 0x7F) << shift
            shift += 7
            if not byte & 0x80:
                return n

    names = []
    for _ in range(varint()):
        n = varint()
        if pos + n > len(data):
            raise ValueError("truncated string")
        names.append(data[pos:pos + n].decode("utf-8"))
        pos += n
    if pos != len(data):
        raise ValueError(f"{len(data) - pos} bytes after the list")
    return names


def write_atomic(path, data):
    """Writes `path` as `io::atomic` does: `<name>.tmp.<pid>` beside it, fsync, rename over it,
    fsync the folder; readers see the old file or the new one, never a part."""
    tmp = f"{path}.tmp.{os.getpid()}"
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
        fd = os.open(os.path.dirname(os.path.abspath(path)), os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError as e:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise CheckpointError(f"checkpoint `{path}`: writing {path}: {e.strerror}") from None


def write_checkpoint(path, step, time_, meta, arrays):
    """Writes the part `path` atomically: `step`, `time_`, the metadata bytes `meta` and
    `arrays`, a list of (name, float64 values)."""
    b = bytearray(CKPT_MAGIC)
    b += struct.pack("<IIQdQ", CKPT_VERSION, len(arrays), step, time_, len(meta)) + meta
    for name, values in arrays:
        data = np.ascontiguousarray(values, dtype="<f8")
        raw = name.encode("utf-8")
        b += struct.pack("<H", len(raw)) + raw + struct.pack("<BQ", 1, data.size) + data.tobytes()
    b += struct.pack("<Q", ckpt_checksum(bytes(b)))
    write_atomic(path, bytes(b))


class Checkpoint:
    """A part read back by `read_checkpoint`: `step`, `time`, `meta` (bytes), `arrays` by name
    (numpy arrays), `path`."""

    def __init__(self, path, step, time_, meta, arrays):
        self.path, self.step, self.time, self.meta, self.arrays = path, step, time_, meta, arrays

    def f64(self, name, n=None):
        """The f64 array `name`, of `n` values if given; the error names file and array."""
        if name not in self.arrays:
            raise CheckpointError(f"checkpoint `{self.path}` has no array `{name}` (it holds: "
                                  f"{', '.join(self.arrays)})")
        a = self.arrays[name]
        if a.dtype != np.float64:
            raise CheckpointError(f"checkpoint `{self.path}`: array `{name}` holds {a.dtype}, "
                                  "not f64")
        if n is not None and a.size != n:
            raise CheckpointError(f"checkpoint `{self.path}`: `{name}` holds {a.size} values, "
                                  f"expected {n}")
        return a.astype(np.float64)


def read_checkpoint(path):
    """Reads and verifies the part `path`; a `CheckpointError` names the file and what is wrong
    (missing, truncated, not a checkpoint, another version, a damaged checksum)."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise CheckpointError(f"checkpoint `{path}`: {e.strerror}") from None
    pos = 0

    def take(n, what):
        nonlocal pos
        if pos + n > len(data):
            raise CheckpointError(f"checkpoint `{path}` is truncated: {what} needs bytes up to "
                                  f"{pos + n}, the file has {len(data)}")
        pos += n
        return data[pos - n:pos]

    def corrupt(reason):
        return CheckpointError(f"checkpoint `{path}` is corrupt: {reason}")

    if take(8, "the header") != CKPT_MAGIC:
        raise corrupt("not a checkpoint file (bad magic bytes)")
    version, count, step, time_, meta_len = struct.unpack("<IIQdQ", take(32, "the header"))
    if version != CKPT_VERSION:
        raise corrupt(f"format version {version}, this reader reads {CKPT_VERSION}")
    meta = take(meta_len, "the metadata")
    arrays = {}
    for i in range(count):
        (name_len,) = struct.unpack("<H", take(2, f"array {i}"))
        try:
            name = take(name_len, f"array {i}").decode("utf-8")
        except UnicodeDecodeError:
            raise corrupt(f"array {i} has a name that is not UTF-8") from None
        code, n = struct.unpack("<BQ", take(9, f"array `{name}`"))
        if code not in _CKPT_TYPES:
            raise corrupt(f"array `{name}` has unknown type code {code}")
        dtype = np.dtype(_CKPT_TYPES[code][1])
        arrays[name] = np.frombuffer(take(n * dtype.itemsize, f"array `{name}`"), dtype=dtype)
    body_end = pos
    (stored,) = struct.unpack("<Q", take(8, "the checksum"))
    if pos != len(data):
        raise corrupt(f"{len(data) - pos} unexpected bytes after the checksum")
    computed = ckpt_checksum(data[:body_end])
    if stored != computed:
        raise corrupt(f"checksum mismatch (stored {stored:016x}, computed {computed:016x}): the "
                      "file was damaged")
    return Checkpoint(path, step, time_, meta, arrays)
