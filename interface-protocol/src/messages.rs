//! Every type that crosses shared memory (DESIGN §3). All are `#[repr(C)]`, contain only
//! fixed-width integers and `f64`, carry a stable iceoryx2 type name, and have their byte layout
//! written next to them so a C, C++ or Python peer can declare the same struct. All integers and
//! floats are little-endian (the host order of every supported platform); no `usize` crosses.
//!
//! A layout line reads `offset:type name`; sizes and alignments are asserted at compile time.

use iceoryx2::prelude::ZeroCopySend;

/// Version of the wire protocol; bumped on any change of a type below or of the command sequence.
pub const PROTOCOL_VERSION: u32 = 1;

/// Which side of the coupling a participant plays.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum Role {
    Fluid = 1,
    Structure = 2,
}

impl Role {
    /// The wire value of the role.
    pub fn code(self) -> u32 {
        self as u32
    }

    /// The role of a wire value, `None` if it names no role.
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            1 => Some(Role::Fluid),
            2 => Some(Role::Structure),
            _ => None,
        }
    }

    /// Lower-case name used in service names and messages.
    pub fn name(self) -> &'static str {
        match self {
            Role::Fluid => "fluid",
            Role::Structure => "structure",
        }
    }
}

/// Unit system code carried by `Hello::units`: SI (m, kg, s, Pa, N) is the only one so far.
pub const UNITS_SI: u32 = 0;

/// Handshake sent once by each participant on `fsi/<run_id>/hello`.
///
/// Layout (48 bytes, align 8): `0:u32 protocol_version, 4:u32 role (1 fluid, 2 structure),
/// 8:u32 pid, 12:u32 units, 16:u64 n_surface_nodes, 24:u64 n_surface_elements, 32:u64 case_hash,
/// 40:u64 capabilities` (bits of [`capability`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ZeroCopySend)]
#[type_name("fsi::Hello::v1")]
#[repr(C)]
pub struct Hello {
    pub protocol_version: u32,
    pub role: u32,
    pub pid: u32,
    pub units: u32,
    /// Wet-surface nodes, phantom nodes included (the structure's count; the fluid echoes what it
    /// expects, 0 if it accepts any).
    pub n_surface_nodes: u64,
    pub n_surface_elements: u64,
    /// 64-bit FNV-1a hash of the effective case (see `case::Case::hash`).
    pub case_hash: u64,
    /// What the participant supports beyond the base sequence: bits of [`capability`].
    pub capabilities: u64,
}

/// Bits of `Hello::capabilities`.
pub mod capability {
    /// The participant continues a run from a checkpoint (`run --restart DIR`, the restart
    /// sequence of PROTOCOL.md §4): a launcher refuses a restart with a participant without it.
    pub const RESTART: u64 = 1;
    /// The participant reports `Reply::interface_work`: the launcher keeps the energy ledger
    /// of the interface (`run.json`'s `interface_energy`) when both do.
    pub const INTERFACE_WORK: u64 = 2;
}

/// Kinds of `Command::kind`.
pub mod command_kind {
    pub const INIT: u32 = 1;
    pub const ADVANCE: u32 = 2;
    pub const CHECKPOINT: u32 = 3;
    pub const FINISH: u32 = 4;
}

/// Launcher -> participant request on `fsi/<run_id>/control/<role>`.
///
/// Layout (96 bytes, align 8): `0:u32 kind, 4:u32 scheme_phase, 8:u64 step, 16:f64 t_from,
/// 24:f64 t_to, 32:[u8;64] tag (NUL-padded UTF-8, checkpoint name)`.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("fsi::Command::v1")]
#[repr(C)]
pub struct Command {
    pub kind: u32,
    /// Scheme-specific phase of an `Advance` (see the coupling module); 0 otherwise.
    pub scheme_phase: u32,
    pub step: u64,
    pub t_from: f64,
    pub t_to: f64,
    pub tag: [u8; 64],
}

impl Default for Command {
    fn default() -> Self {
        Self { kind: 0, scheme_phase: 0, step: 0, t_from: 0.0, t_to: 0.0, tag: [0; 64] }
    }
}

/// Values of `Command::scheme_phase` for an `Advance` (the sequence is in `coupling`).
pub mod scheme_phase {
    /// Fluid advances, and any command that is not an `Advance`.
    pub const NONE: u32 = 0;
    /// Structure: take the loads `F^0` the fluid computed at `Init`, start the scheme (C0:
    /// publish the kinematics predicted for `t^{1/2}`). Fluid (C0 only): the start-up half step.
    pub const START: u32 = 1;
    /// Structure: advance what can be advanced without the new load and publish the kinematics the
    /// fluid's next `Advance` needs.
    pub const PREDICT: u32 = 2;
    /// Structure: take the load the fluid just returned and complete the step.
    pub const CORRECT: u32 = 3;
}

/// Kinds of `Reply::kind`.
pub mod reply_kind {
    pub const READY: u32 = 1;
    pub const DONE: u32 = 2;
    pub const FAILED: u32 = 3;
}

/// Participant -> launcher response to a `Command`.
///
/// Layout (312 bytes, align 8): `0:u32 kind, 4:u32 code, 8:u64 step, 16:f64 t, 24:f64 dt_stable,
/// 32:f64 work_s, 40:f64 wait_s, 48:[u8;256] message (NUL-padded UTF-8), 304:f64 interface_work`.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("fsi::Reply::v1")]
#[repr(C)]
pub struct Reply {
    pub kind: u32,
    /// Error code of a `Failed` reply, 0 otherwise.
    pub code: u32,
    pub step: u64,
    pub t: f64,
    /// Largest step the participant can take stably from now (`inf` if unlimited).
    pub dt_stable: f64,
    /// Seconds of solver work and of waiting for the peer since the previous reply.
    pub work_s: f64,
    pub wait_s: f64,
    pub message: [u8; 256],
    /// The work the interface loads did on the wet surface from the start of the run to `t`
    /// (joules; cumulative, so a restart continues it), along the participant's own motion of
    /// the surface: the fluid's along its Hermite path, the structure's along its displacement.
    /// Read only from a participant that announces [`capability::INTERFACE_WORK`].
    pub interface_work: f64,
}

impl Default for Reply {
    fn default() -> Self {
        Self {
            kind: 0,
            code: 0,
            step: 0,
            t: 0.0,
            dt_stable: f64::INFINITY,
            work_s: 0.0,
            wait_s: 0.0,
            message: [0; 256],
            interface_work: 0.0,
        }
    }
}

/// User header of the `surface/topology`, `surface/kinematics` and `surface/loads` samples: one
/// header type for the three services, so every exchanged slice says which step it belongs to.
///
/// Layout (40 bytes, align 8): `0:u64 step, 8:f64 time, 16:f64 dt, 24:u64 topology_version,
/// 32:u64 count (elements in the slice)`.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("fsi::StepHeader::v1")]
#[repr(C)]
pub struct StepHeader {
    pub step: u64,
    pub time: f64,
    pub dt: f64,
    pub topology_version: u64,
    pub count: u64,
}

/// Position and velocity of one wet-surface node, structure numbering, phantom nodes after real
/// ones. Layout (48 bytes, align 8): `0:[f64;3] x, 24:[f64;3] v`.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("fsi::NodeState::v1")]
#[repr(C)]
pub struct NodeState {
    pub x: [f64; 3],
    pub v: [f64; 3],
}

/// Force on one wet-surface node, in the order of the kinematics slice.
/// Layout (24 bytes, align 8): `0:[f64;3] f`.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("fsi::NodeLoad::v1")]
#[repr(C)]
pub struct NodeLoad {
    pub f: [f64; 3],
}

/// Bits of `SurfaceElement::flags`.
pub mod element_flags {
    /// The element is a phantom element of a cracked one (thesis §4.3).
    pub const PHANTOM: u8 = 1;
}

/// A triangle (`n_nodes = 3`, `nodes[3]` ignored) or quad of the wet surface. `phi` is the signed
/// distance of the phantom element at its nodes: the fluid accepts an intersection only where the
/// interpolated `phi >= 0` (thesis Eq. 3.24-3.26). Uncracked elements carry `phi = 1.0`.
///
/// Layout (56 bytes, align 8): `0:[u32;4] nodes, 16:u8 n_nodes, 17:u8 flags, 18:[u8;6] padding,
/// 24:[f64;4] phi`.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("fsi::SurfaceElement::v1")]
#[repr(C)]
pub struct SurfaceElement {
    pub nodes: [u32; 4],
    pub n_nodes: u8,
    pub flags: u8,
    pub padding: [u8; 6],
    pub phi: [f64; 4],
}

impl Default for SurfaceElement {
    fn default() -> Self {
        Self { nodes: [0; 4], n_nodes: 3, flags: 0, padding: [0; 6], phi: [1.0; 4] }
    }
}

/// Copies `text` into a NUL-padded fixed buffer, truncating at a UTF-8 boundary.
pub fn write_fixed_str<const N: usize>(text: &str, out: &mut [u8; N]) {
    out.fill(0);
    let mut end = text.len().min(N);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    out[..end].copy_from_slice(&text.as_bytes()[..end]);
}

/// Reads a NUL-padded fixed buffer written by `write_fixed_str` (lossy on invalid UTF-8).
pub fn read_fixed_str(buf: &[u8]) -> String {
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    String::from_utf8_lossy(&buf[..end]).into_owned()
}

const _: () = {
    use core::mem::{align_of, size_of};
    assert!(size_of::<Hello>() == 48 && align_of::<Hello>() == 8);
    assert!(size_of::<Command>() == 96 && align_of::<Command>() == 8);
    assert!(size_of::<Reply>() == 312 && align_of::<Reply>() == 8);
    assert!(size_of::<StepHeader>() == 40 && align_of::<StepHeader>() == 8);
    assert!(size_of::<NodeState>() == 48 && align_of::<NodeState>() == 8);
    assert!(size_of::<NodeLoad>() == 24 && align_of::<NodeLoad>() == 8);
    assert!(size_of::<SurfaceElement>() == 56 && align_of::<SurfaceElement>() == 8);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_strings_round_trip_and_truncate_on_char_boundary() {
        let mut buf = [0u8; 8];
        write_fixed_str("abc", &mut buf);
        assert_eq!(read_fixed_str(&buf), "abc");
        write_fixed_str("ééééé", &mut buf); // 10 bytes, cut to 8 = 4 chars
        assert_eq!(read_fixed_str(&buf), "éééé");
    }

    #[test]
    fn type_names_are_stable() {
        // SAFETY: `type_name` only returns the string given in the derive attribute.
        let names =
            unsafe { [NodeState::type_name(), NodeLoad::type_name(), StepHeader::type_name()] };
        assert_eq!(names, ["fsi::NodeState::v1", "fsi::NodeLoad::v1", "fsi::StepHeader::v1"]);
    }
}
