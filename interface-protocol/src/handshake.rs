//! The handshake (DESIGN §3): each participant publishes a `Hello`; the launcher checks both
//! before the first command and refuses a run whose sides disagree, naming both values. Also the
//! constructors of `Command` and `Reply`, so no side writes a kind code by hand.

use crate::endpoint::ProtocolError;
use crate::messages::{
    command_kind, read_fixed_str, reply_kind, scheme_phase, write_fixed_str, Command, Hello, Reply,
    Role, PROTOCOL_VERSION, UNITS_SI,
};

/// What a participant announces about itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct HelloInfo {
    /// Wet-surface nodes (phantoms included); the fluid sends 0 if it accepts any count.
    pub n_surface_nodes: u64,
    pub n_surface_elements: u64,
    /// `case::Case::hash()` of the case the participant loaded.
    pub case_hash: u64,
    /// Bits of `messages::capability` (0: the base sequence only).
    pub capabilities: u64,
}

impl HelloInfo {
    /// The `Hello` of this process in `role`.
    pub fn hello(&self, role: Role) -> Hello {
        Hello {
            protocol_version: PROTOCOL_VERSION,
            role: role.code(),
            pid: std::process::id(),
            units: UNITS_SI,
            n_surface_nodes: self.n_surface_nodes,
            n_surface_elements: self.n_surface_elements,
            case_hash: self.case_hash,
            capabilities: self.capabilities,
        }
    }
}

/// Checks the two `Hello`s against each other and against the launcher's case hash; the error
/// names every disagreeing value of both sides.
pub fn check(
    fluid: &Hello,
    structure: &Hello,
    expected_case_hash: u64,
) -> Result<(), ProtocolError> {
    let mut problems = Vec::new();
    for (hello, role) in [(fluid, Role::Fluid), (structure, Role::Structure)] {
        if hello.role != role.code() {
            problems.push(format!("the {} hello carries role code {}", role.name(), hello.role));
        }
    }
    if fluid.protocol_version != PROTOCOL_VERSION || structure.protocol_version != PROTOCOL_VERSION
    {
        problems.push(format!(
            "protocol version: fluid {} (pid {}), structure {} (pid {}), launcher {PROTOCOL_VERSION}",
            fluid.protocol_version, fluid.pid, structure.protocol_version, structure.pid
        ));
    }
    if fluid.case_hash != expected_case_hash || structure.case_hash != expected_case_hash {
        problems.push(format!(
            "case hash: fluid {:016x}, structure {:016x}, launcher {expected_case_hash:016x} (the \
             participants read a different case file or other --set overrides)",
            fluid.case_hash, structure.case_hash
        ));
    }
    if fluid.units != structure.units {
        problems.push(format!("units: fluid {}, structure {}", fluid.units, structure.units));
    }
    let counts_disagree = |f: u64, s: u64| f != 0 && f != s;
    if counts_disagree(fluid.n_surface_nodes, structure.n_surface_nodes) {
        problems.push(format!(
            "wet-surface nodes: fluid expects {}, structure has {}",
            fluid.n_surface_nodes, structure.n_surface_nodes
        ));
    }
    if counts_disagree(fluid.n_surface_elements, structure.n_surface_elements) {
        problems.push(format!(
            "wet-surface elements: fluid expects {}, structure has {}",
            fluid.n_surface_elements, structure.n_surface_elements
        ));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(ProtocolError::Mismatch(format!("handshake refused: {}", problems.join("; "))))
    }
}

impl Command {
    /// `Init`: publish the initial state (structure) or the initial loads (fluid).
    pub fn init() -> Command {
        Command { kind: command_kind::INIT, ..Command::default() }
    }

    /// `Advance` from `t_from` to `t_to` in coupling step `step`, `phase` one of `scheme_phase`.
    pub fn advance(step: u64, t_from: f64, t_to: f64, phase: u32) -> Command {
        Command {
            kind: command_kind::ADVANCE,
            scheme_phase: phase,
            step,
            t_from,
            t_to,
            ..Command::default()
        }
    }

    /// `Checkpoint` named `tag`.
    pub fn checkpoint(tag: &str) -> Command {
        let mut c = Command { kind: command_kind::CHECKPOINT, ..Command::default() };
        write_fixed_str(tag, &mut c.tag);
        c
    }

    /// `Finish`: flush output and exit.
    pub fn finish() -> Command {
        Command { kind: command_kind::FINISH, ..Command::default() }
    }

    /// The checkpoint tag as text.
    pub fn tag_str(&self) -> String {
        read_fixed_str(&self.tag)
    }

    /// One line for logs and golden traces, e.g. `Advance PREDICT step 3 [0.003, 0.004]`.
    pub fn describe(&self) -> String {
        match self.kind {
            command_kind::INIT => "Init".into(),
            command_kind::ADVANCE => {
                let phase = match self.scheme_phase {
                    scheme_phase::NONE => "NONE",
                    scheme_phase::START => "START",
                    scheme_phase::PREDICT => "PREDICT",
                    scheme_phase::CORRECT => "CORRECT",
                    _ => "?",
                };
                // Times to 12 significant digits: step 360 of 0.03 reads 10.8, not 10.799999999999999.
                let t = |v: f64| format!("{v:.11e}").parse().unwrap_or(v);
                format!("Advance {phase} step {} [{}, {}]", self.step, t(self.t_from), t(self.t_to))
            }
            command_kind::CHECKPOINT => format!("Checkpoint {}", self.tag_str()),
            command_kind::FINISH => "Finish".into(),
            k => format!("unknown command kind {k}"),
        }
    }
}

impl Reply {
    /// `Ready` after `Init`.
    pub fn ready(dt_stable: f64) -> Reply {
        Reply { kind: reply_kind::READY, dt_stable, ..Reply::default() }
    }

    /// `Done` after `Advance`, `Checkpoint` or `Finish`.
    pub fn done(step: u64, t: f64, dt_stable: f64, work_s: f64, wait_s: f64) -> Reply {
        Reply { kind: reply_kind::DONE, step, t, dt_stable, work_s, wait_s, ..Reply::default() }
    }

    /// `Failed` with an error `code` and a message (truncated to 255 bytes).
    pub fn failed(code: u32, message: &str) -> Reply {
        let mut r = Reply { kind: reply_kind::FAILED, code: code.max(1), ..Reply::default() };
        write_fixed_str(message, &mut r.message);
        r
    }

    /// The message of a `Failed` reply.
    pub fn message_str(&self) -> String {
        read_fixed_str(&self.message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hellos() -> (Hello, Hello) {
        let s =
            HelloInfo { n_surface_nodes: 4, n_surface_elements: 2, case_hash: 7, capabilities: 0 };
        let f = HelloInfo { n_surface_nodes: 0, ..s };
        (f.hello(Role::Fluid), s.hello(Role::Structure))
    }

    #[test]
    fn matching_hellos_pass_and_fluid_may_accept_any_count() {
        let (f, s) = hellos();
        check(&f, &s, 7).unwrap();
    }

    #[test]
    fn mismatches_name_both_sides() {
        let (mut f, s) = hellos();
        f.case_hash = 9;
        f.n_surface_nodes = 5;
        let e = check(&f, &s, 7).unwrap_err().to_string();
        assert!(e.contains("fluid 0000000000000009, structure 0000000000000007"), "{e}");
        assert!(e.contains("fluid expects 5, structure has 4"), "{e}");
        let (mut f, s) = hellos();
        f.protocol_version = 99;
        let e = check(&f, &s, 7).unwrap_err().to_string();
        assert!(e.contains("protocol version: fluid 99"), "{e}");
    }

    #[test]
    fn commands_and_replies_round_trip() {
        assert_eq!(Command::checkpoint("step_0000000010").tag_str(), "step_0000000010");
        assert_eq!(
            Command::advance(3, 0.5, 0.75, scheme_phase::PREDICT).describe(),
            "Advance PREDICT step 3 [0.5, 0.75]"
        );
        assert_eq!(
            Command::advance(360, 360.0 * 0.03, 10.83, scheme_phase::CORRECT).describe(),
            "Advance CORRECT step 360 [10.8, 10.83]"
        );
        let r = Reply::failed(0, "boom");
        assert_eq!((r.kind, r.code, r.message_str().as_str()), (reply_kind::FAILED, 1, "boom"));
    }
}
