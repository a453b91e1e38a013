//! The staggered coupling schemes as a pure state machine: which participant gets which command
//! next, and whether its reply lets the run go on (DESIGN §4, the agreed command sequence).
//!
//! No IO here: the driver sends what [`Sequencer::next_command`] yields and hands the reply to
//! [`Sequencer::accept`]. The sequence, for Δt = `coupling.dt`, t^n = n Δt (the last step
//! shortened to end at `t_end`), roles S (structure) and F (fluid):
//!
//! ```text
//! S Init;  F Init;  S Advance START [0, 0];  (C0) F Advance START [0, Δt_0/2]
//! for n in 0..N:  S Advance PREDICT [t^n, t^{n+1}];  F Advance NONE [fluid interval n];
//!                 S Advance CORRECT [t^n, t^{n+1}];
//!                 if checkpoint_every > 0 and (n+1) % checkpoint_every == 0:
//!                     S Checkpoint tag;  F Checkpoint tag   (tag = tag_for_step(n+1))
//! S Finish;  F Finish
//! ```
//!
//! A restart from the checkpoint after k steps ([`Sequencer::resume`], `fsi run --restart`)
//! replays neither START nor the steps before k: each participant was started with `--restart`
//! naming the checkpoint folder and holds the state it wrote there, history included (C0's
//! start-up half step is part of it, never redone). Init publishes that state instead of the
//! initial one (the structure its topology and kinematics at t^k; the fluid publishes no loads,
//! the structure reads the next ones at CORRECT of step k):
//!
//! ```text
//! S Init;  F Init;  for n in k..N: (as above);  S Finish;  F Finish
//! ```
//!
//! The checkpoint tag is [`checkpoint::tag_for_step`] (`step_0000000100`), the folder name a
//! solver run alone writes too, so coupled and lone runs name checkpoints one way.
//!
//! The fluid interval of step n ends where the structure predicted the wall for, with the step's
//! own Δt_n: CSS t^{n+1}; C0 t^{n+1} + Δt_n/2 (fluid half a step ahead); A6 t^n + Δt_n/2. It starts
//! where the previous one ended (CSS t^n, C0 Δt_0/2 after the start-up half step, A6 0).

use interface_protocol::case::{Case, Scheme};
use interface_protocol::io::checkpoint;
use interface_protocol::messages::{command_kind, reply_kind, scheme_phase, Command, Reply, Role};

/// A reply that stops the run, or a reply that does not fit the command it answers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SchemeError {
    #[error("{role} failed at {command} (code {code}): {message}")]
    Failed { role: &'static str, command: String, code: u32, message: String },
    #[error("{role} answered {command} with reply kind {kind}, expected {expected}")]
    Unexpected { role: &'static str, command: String, kind: u32, expected: &'static str },
    #[error("coupling.t_end: with C0 the fluid runs half a step ahead, and a last step of {last:e} s (< dt/3 = {third:e} s) would move it backwards; choose t_end closer to a multiple of dt")]
    ShortLastStep { last: f64, third: f64 },
    #[error("a reply arrived from {role} while {expected} was awaited")]
    WrongRole { role: &'static str, expected: String },
    #[error("the checkpoint after step {step} (t = {t:e}) is the end of a run to coupling.t_end = {t_end:e} ({n_steps} steps): there is nothing to continue; raise coupling.t_end")]
    NothingToContinue { step: u64, t: f64, t_end: f64, n_steps: u64 },
}

/// What the scheme needs from the case.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SchemeSettings {
    pub scheme: Scheme,
    pub dt: f64,
    pub t_end: f64,
    pub n_steps: u64,
    /// 0: no checkpoint commands.
    pub checkpoint_every: u64,
}

/// Where the run stands: one position per command of the sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    InitStructure,
    InitFluid,
    StartStructure,
    StartFluid,
    Predict(u64),
    Fluid(u64),
    Correct(u64),
    CheckpointStructure(u64),
    CheckpointFluid(u64),
    FinishStructure,
    FinishFluid,
    Over,
}

/// What an accepted reply means for the run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Progress {
    /// The sequence goes on.
    Continue,
    /// The structure completed coupling step `step` (0-based), reaching time `t`.
    StepDone { step: u64, t: f64 },
    /// Both participants acknowledged `Finish`.
    Finished,
}

/// The command sequence of one run.
#[derive(Debug, Clone)]
pub struct Sequencer {
    s: SchemeSettings,
    stage: Stage,
    /// The command sent and not yet answered.
    pending: Option<(Role, Command)>,
    /// A restart: the steps completed before it (no START, the first step is this one).
    resume_at: Option<u64>,
}

/// The scheme's name as the case file spells it.
pub fn scheme_name(scheme: Scheme) -> &'static str {
    match scheme {
        Scheme::Css => "CSS",
        Scheme::C0 => "C0",
        Scheme::A6 => "A6",
    }
}

impl SchemeSettings {
    /// The settings of a case's `[coupling]` and `[output]` sections.
    pub fn of_case(case: &Case) -> Self {
        SchemeSettings {
            scheme: case.coupling.scheme,
            dt: case.coupling.dt,
            t_end: case.coupling.t_end,
            n_steps: case.coupling.n_steps(),
            checkpoint_every: case.output.checkpoint_every,
        }
    }
}

impl Sequencer {
    pub fn new(s: SchemeSettings) -> Result<Self, SchemeError> {
        let seq = Sequencer { s, stage: Stage::InitStructure, pending: None, resume_at: None };
        if s.scheme == Scheme::C0 && s.n_steps > 1 {
            // Fluid step N-1 runs from t^{N-1} + Δt/2 to t_end + Δt_last/2.
            let last = seq.step_dt(s.n_steps - 1);
            if 1.5 * last <= 0.5 * s.dt {
                return Err(SchemeError::ShortLastStep { last, third: s.dt / 3.0 });
            }
        }
        Ok(seq)
    }

    /// The sequence of a restart from the checkpoint after `step` completed steps (see the
    /// module doc): Init to both, then step `step`. A checkpoint at or past the last step has
    /// nothing to continue.
    pub fn resume(s: SchemeSettings, step: u64) -> Result<Self, SchemeError> {
        let mut seq = Sequencer::new(s)?;
        if step >= s.n_steps {
            let t = step as f64 * s.dt;
            return Err(SchemeError::NothingToContinue {
                step,
                t,
                t_end: s.t_end,
                n_steps: s.n_steps,
            });
        }
        seq.resume_at = Some(step);
        Ok(seq)
    }

    /// t^n: n Δt, and `t_end` for n = N.
    pub fn time(&self, n: u64) -> f64 {
        if n >= self.s.n_steps {
            self.s.t_end
        } else {
            n as f64 * self.s.dt
        }
    }

    /// Δt_n = t^{n+1} - t^n.
    pub fn step_dt(&self, n: u64) -> f64 {
        self.time(n + 1) - self.time(n)
    }

    /// Where the fluid's advance of coupling step n ends (see the module doc).
    fn fluid_end(&self, n: u64) -> f64 {
        match self.s.scheme {
            Scheme::Css => self.time(n + 1),
            Scheme::C0 => self.time(n + 1) + 0.5 * self.step_dt(n),
            Scheme::A6 => self.time(n) + 0.5 * self.step_dt(n),
        }
    }

    /// The fluid interval of coupling step n.
    pub fn fluid_interval(&self, n: u64) -> (f64, f64) {
        let start = match (self.s.scheme, n) {
            (Scheme::Css, _) => self.time(n),
            (Scheme::C0, 0) => 0.5 * self.step_dt(0),
            (Scheme::A6, 0) => 0.0,
            _ => self.fluid_end(n - 1),
        };
        (start, self.fluid_end(n))
    }

    /// The settings this sequence was built from.
    pub fn settings(&self) -> &SchemeSettings {
        &self.s
    }

    /// The next command and its addressee, `None` once the run is over. Call `accept` with the
    /// reply before asking again; asking again without it yields the same command.
    pub fn next_command(&mut self) -> Option<(Role, Command)> {
        if let Some(p) = self.pending {
            return Some(p);
        }
        use scheme_phase::{CORRECT, PREDICT, START};
        let (n_steps, t_end) = (self.s.n_steps, self.s.t_end);
        let finish = Command { step: n_steps, t_from: t_end, t_to: t_end, ..Command::finish() };
        let (role, cmd) = match self.stage {
            Stage::InitStructure => (Role::Structure, Command::init()),
            Stage::InitFluid => (Role::Fluid, Command::init()),
            Stage::StartStructure => (Role::Structure, Command::advance(0, 0.0, 0.0, START)),
            Stage::StartFluid => {
                (Role::Fluid, Command::advance(0, 0.0, 0.5 * self.step_dt(0), START))
            }
            Stage::Predict(n) => {
                (Role::Structure, Command::advance(n, self.time(n), self.time(n + 1), PREDICT))
            }
            Stage::Fluid(n) => {
                let (a, b) = self.fluid_interval(n);
                (Role::Fluid, Command::advance(n, a, b, scheme_phase::NONE))
            }
            Stage::Correct(n) => {
                (Role::Structure, Command::advance(n, self.time(n), self.time(n + 1), CORRECT))
            }
            Stage::CheckpointStructure(k) => (Role::Structure, checkpoint_command(k, self.time(k))),
            Stage::CheckpointFluid(k) => (Role::Fluid, checkpoint_command(k, self.time(k))),
            Stage::FinishStructure => (Role::Structure, finish),
            Stage::FinishFluid => (Role::Fluid, finish),
            Stage::Over => return None,
        };
        self.pending = Some((role, cmd));
        self.pending
    }

    /// Takes the reply to the pending command and moves on. A `Failed` reply or a reply of the
    /// wrong kind is an error and leaves the sequence where it was.
    pub fn accept(&mut self, from: Role, reply: &Reply) -> Result<Progress, SchemeError> {
        let Some((role, cmd)) = self.pending else {
            return Err(SchemeError::WrongRole { role: from.name(), expected: "nothing".into() });
        };
        if from != role {
            return Err(SchemeError::WrongRole {
                role: from.name(),
                expected: format!("{} from {}", cmd.describe(), role.name()),
            });
        }
        let expected =
            if cmd.kind == command_kind::INIT { reply_kind::READY } else { reply_kind::DONE };
        if reply.kind == reply_kind::FAILED {
            return Err(SchemeError::Failed {
                role: role.name(),
                command: cmd.describe(),
                code: reply.code,
                message: reply.message_str(),
            });
        }
        if reply.kind != expected {
            return Err(SchemeError::Unexpected {
                role: role.name(),
                command: cmd.describe(),
                kind: reply.kind,
                expected: if expected == reply_kind::READY { "Ready" } else { "Done" },
            });
        }
        self.pending = None;
        let (next, progress) = self.after(self.stage);
        self.stage = next;
        Ok(progress)
    }

    /// The stage after `stage` and what completing `stage` means.
    fn after(&self, stage: Stage) -> (Stage, Progress) {
        let n_steps = self.s.n_steps;
        let every = self.s.checkpoint_every;
        let first_step = if n_steps == 0 { Stage::FinishStructure } else { Stage::Predict(0) };
        let next = match stage {
            Stage::InitStructure => Stage::InitFluid,
            Stage::InitFluid => match self.resume_at {
                Some(k) => Stage::Predict(k),
                None => Stage::StartStructure,
            },
            Stage::StartStructure if self.s.scheme == Scheme::C0 => Stage::StartFluid,
            Stage::StartStructure | Stage::StartFluid => first_step,
            Stage::Predict(n) => Stage::Fluid(n),
            Stage::Fluid(n) => Stage::Correct(n),
            Stage::Correct(n) => {
                let next = if every > 0 && (n + 1) % every == 0 {
                    Stage::CheckpointStructure(n + 1)
                } else if n + 1 < n_steps {
                    Stage::Predict(n + 1)
                } else {
                    Stage::FinishStructure
                };
                return (next, Progress::StepDone { step: n, t: self.time(n + 1) });
            }
            Stage::CheckpointStructure(k) => Stage::CheckpointFluid(k),
            Stage::CheckpointFluid(k) if k < n_steps => Stage::Predict(k),
            Stage::CheckpointFluid(_) => Stage::FinishStructure,
            Stage::FinishStructure => Stage::FinishFluid,
            Stage::FinishFluid => return (Stage::Over, Progress::Finished),
            Stage::Over => Stage::Over,
        };
        (next, Progress::Continue)
    }
}

/// `Checkpoint { tag: tag_for_step(k) }` after k completed steps, at t^k.
fn checkpoint_command(k: u64, t: f64) -> Command {
    let tag = checkpoint::tag_for_step(k);
    Command { step: k, t_from: t, t_to: t, ..Command::checkpoint(&tag) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use interface_protocol::case::CouplingSection;

    fn settings(scheme: Scheme, dt: f64, t_end: f64, checkpoint_every: u64) -> SchemeSettings {
        let coupling = CouplingSection { scheme, dt, t_end, ..CouplingSection::default() };
        SchemeSettings { scheme, dt, t_end, n_steps: coupling.n_steps(), checkpoint_every }
    }

    fn reply(kind: u32) -> Reply {
        Reply { kind, ..Reply::default() }
    }

    /// Runs a sequence to its end, every participant answering as it should.
    fn run(s: SchemeSettings) -> Vec<(Role, Command)> {
        let mut seq = Sequencer::new(s).unwrap();
        let mut out = Vec::new();
        while let Some((role, cmd)) = seq.next_command() {
            out.push((role, cmd));
            let kind =
                if cmd.kind == command_kind::INIT { reply_kind::READY } else { reply_kind::DONE };
            seq.accept(role, &reply(kind)).unwrap();
            assert!(out.len() < 10_000, "the sequence does not end");
        }
        out
    }

    fn kind_code(name: &str) -> u32 {
        match name {
            "Init" => command_kind::INIT,
            "Advance" => command_kind::ADVANCE,
            "Checkpoint" => command_kind::CHECKPOINT,
            "Finish" => command_kind::FINISH,
            _ => panic!("unknown command kind `{name}` in a golden trace"),
        }
    }

    fn phase_code(name: &str) -> u32 {
        match name {
            "NONE" => scheme_phase::NONE,
            "START" => scheme_phase::START,
            "PREDICT" => scheme_phase::PREDICT,
            "CORRECT" => scheme_phase::CORRECT,
            _ => panic!("unknown phase `{name}` in a golden trace"),
        }
    }

    /// Compares a sequence with a hand-written golden trace, line by line.
    fn check_golden(name: &str, text: &str, s: SchemeSettings) {
        let expected: Vec<&str> =
            text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')).collect();
        let got = run(s);
        for (i, ((role, c), line)) in got.iter().zip(&expected).enumerate() {
            let f: Vec<&str> = line.split_whitespace().collect();
            let here = format!(
                "{name} command {} (`{line}`), got {} {}",
                i + 1,
                role.name(),
                c.describe()
            );
            assert!(f.len() == 6 || f.len() == 7, "{here}: malformed line");
            let role_code = if *role == Role::Structure { "S" } else { "F" };
            assert_eq!(role_code, f[0], "{here}: role");
            assert_eq!(c.kind, kind_code(f[1]), "{here}: kind");
            assert_eq!(c.scheme_phase, phase_code(f[2]), "{here}: phase");
            assert_eq!(c.step, f[3].parse::<u64>().unwrap(), "{here}: step");
            for (value, field) in [(c.t_from, f[4]), (c.t_to, f[5])] {
                let want: f64 = field.parse().unwrap();
                assert!((value - want).abs() <= 1e-12, "{here}: time {value} != {want}");
            }
            assert_eq!(c.tag_str(), f.get(6).copied().unwrap_or(""), "{here}: tag");
        }
        assert_eq!(got.len(), expected.len(), "{name}: number of commands");
    }

    macro_rules! golden {
        ($test:ident, $file:literal, $scheme:expr, $dt:expr, $t_end:expr, $every:expr) => {
            #[test]
            fn $test() {
                let text = include_str!(concat!("../tests/golden/", $file));
                check_golden($file, text, settings($scheme, $dt, $t_end, $every));
            }
        };
    }

    golden!(css_three_steps_match_golden_trace, "css_3steps.trace", Scheme::Css, 0.1, 0.3, 2);
    golden!(c0_three_steps_match_golden_trace, "c0_3steps.trace", Scheme::C0, 0.1, 0.3, 2);
    golden!(a6_three_steps_match_golden_trace, "a6_3steps.trace", Scheme::A6, 0.1, 0.3, 2);
    golden!(css_short_last_step_matches_golden, "css_short_last.trace", Scheme::Css, 0.1, 0.25, 3);
    golden!(c0_short_last_step_matches_golden, "c0_short_last.trace", Scheme::C0, 0.1, 0.25, 3);
    golden!(a6_short_last_step_matches_golden, "a6_short_last.trace", Scheme::A6, 0.1, 0.25, 3);

    /// The commands of a run restarted after `k` steps are those of the whole run from step k
    /// on, after the two Inits: no START, C0's start-up half step not redone.
    #[test]
    fn a_resumed_sequence_is_the_tail_of_the_whole_one() {
        for scheme in [Scheme::Css, Scheme::C0, Scheme::A6] {
            let s = settings(scheme, 0.1, 0.5, 2);
            let whole = run(s);
            for k in [2, 4] {
                let mut seq = Sequencer::resume(s, k).unwrap();
                let mut got = Vec::new();
                while let Some((role, cmd)) = seq.next_command() {
                    got.push((role, cmd));
                    let kind = if cmd.kind == command_kind::INIT {
                        reply_kind::READY
                    } else {
                        reply_kind::DONE
                    };
                    seq.accept(role, &reply(kind)).unwrap();
                }
                let first = whole
                    .iter()
                    .position(|(r, c)| {
                        *r == Role::Structure
                            && c.scheme_phase == scheme_phase::PREDICT
                            && c.step == k
                    })
                    .unwrap();
                assert_eq!(got[..2], whole[..2], "{scheme:?} from {k}: the Inits");
                assert_eq!(got[2..], whole[first..], "{scheme:?} from {k}");
                assert!(got.iter().all(|(_, c)| c.scheme_phase != scheme_phase::START));
            }
            let e = Sequencer::resume(s, 5).unwrap_err().to_string();
            assert!(e.contains("nothing to continue") && e.contains("coupling.t_end"), "{e}");
        }
    }

    #[test]
    fn steps_are_reported_once_each_with_their_end_time() {
        let mut seq = Sequencer::new(settings(Scheme::A6, 0.1, 0.25, 0)).unwrap();
        let mut done = Vec::new();
        while let Some((role, cmd)) = seq.next_command() {
            let kind =
                if cmd.kind == command_kind::INIT { reply_kind::READY } else { reply_kind::DONE };
            match seq.accept(role, &reply(kind)).unwrap() {
                Progress::StepDone { step, t } => done.push((step, t)),
                Progress::Finished => done.push((99, -1.0)),
                Progress::Continue => {}
            }
        }
        assert_eq!(done.len(), 4);
        for (got, want) in done.iter().zip([(0, 0.1), (1, 0.2), (2, 0.25), (99, -1.0)]) {
            assert_eq!(got.0, want.0);
            assert!((got.1 - want.1).abs() < 1e-12, "{got:?} vs {want:?}");
        }
    }

    #[test]
    fn a_failed_reply_stops_the_sequence_with_its_message() {
        let mut seq = Sequencer::new(settings(Scheme::C0, 0.1, 0.3, 0)).unwrap();
        let (role, _) = seq.next_command().unwrap();
        let failed = Reply::failed(7, "mesh file missing");
        let e = seq.accept(role, &failed).unwrap_err().to_string();
        assert!(
            e.contains("structure") && e.contains("Init") && e.contains("mesh file missing"),
            "{e}"
        );
        assert!(e.contains("code 7"), "{e}");
        // The same command is still pending.
        assert_eq!(seq.next_command().unwrap().1.kind, command_kind::INIT);
        assert_eq!(seq.next_command().unwrap().0, Role::Structure);
    }

    #[test]
    fn replies_of_the_wrong_kind_or_role_are_errors() {
        let mut seq = Sequencer::new(settings(Scheme::Css, 0.1, 0.3, 0)).unwrap();
        seq.next_command();
        let e = seq.accept(Role::Structure, &reply(reply_kind::DONE)).unwrap_err();
        assert!(matches!(e, SchemeError::Unexpected { expected: "Ready", .. }), "{e}");
        let e = seq.accept(Role::Fluid, &reply(reply_kind::READY)).unwrap_err();
        assert!(matches!(e, SchemeError::WrongRole { .. }), "{e}");
        assert_eq!(seq.accept(Role::Structure, &reply(reply_kind::READY)), Ok(Progress::Continue));
        let mut fresh = Sequencer::new(settings(Scheme::Css, 0.1, 0.3, 0)).unwrap();
        assert!(fresh.accept(Role::Structure, &reply(reply_kind::READY)).is_err());
    }

    #[test]
    fn c0_refuses_a_last_step_that_would_move_the_fluid_backwards() {
        let e = Sequencer::new(settings(Scheme::C0, 0.1, 0.23, 0)).unwrap_err();
        assert!(e.to_string().contains("coupling.t_end"), "{e}");
        assert!(Sequencer::new(settings(Scheme::C0, 0.1, 0.24, 0)).is_ok());
        assert!(Sequencer::new(settings(Scheme::A6, 0.1, 0.23, 0)).is_ok());
    }

    #[test]
    fn fluid_intervals_tile_time_without_gaps() {
        for scheme in [Scheme::Css, Scheme::C0, Scheme::A6] {
            let seq = Sequencer::new(settings(scheme, 0.1, 1.05, 0)).unwrap();
            for n in 1..seq.settings().n_steps {
                let (a, b) = seq.fluid_interval(n);
                assert_eq!(a, seq.fluid_interval(n - 1).1, "{scheme:?} step {n}");
                assert!(b > a, "{scheme:?} step {n}: [{a}, {b}]");
            }
        }
    }
}
