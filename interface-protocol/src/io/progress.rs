//! The terminal progress bar of a run (DESIGN §7): step, time, dt, steps/s and ETA. Hidden with
//! `--quiet` or when stderr is not a terminal, so scripts and CI logs stay clean.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Bar resolution: the position is the fraction of simulated time done, in these units.
const TICKS: u64 = 10_000;

/// Progress of a run toward its end time.
pub struct Progress {
    bar: ProgressBar,
    end_time: f64,
    start: Instant,
    first_step: Option<u64>,
    quiet: bool,
}

impl Progress {
    /// A bar for a run up to simulated time `end_time`, drawn on stderr unless `quiet` or stderr
    /// is not a terminal.
    pub fn new(end_time: f64, quiet: bool) -> Self {
        let visible = !quiet && std::io::stderr().is_terminal();
        let target =
            if visible { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
        let bar = ProgressBar::with_draw_target(Some(TICKS), target);
        let style = ProgressStyle::with_template(
            "{elapsed_precise} [{wide_bar}] {percent:>3}% {msg} ETA {eta}",
        )
        .expect("the progress template is valid")
        .progress_chars("=> ");
        bar.set_style(style);
        Self { bar, end_time, start: Instant::now(), first_step: None, quiet }
    }

    /// Whether nothing is drawn.
    pub fn is_hidden(&self) -> bool {
        self.bar.is_hidden()
    }

    /// Records that step `step` reached `time` with time step `dt`.
    pub fn update(&mut self, step: u64, time: f64, dt: f64) {
        let first = *self.first_step.get_or_insert(step);
        self.bar.set_position(fraction_ticks(time, self.end_time));
        if self.bar.is_hidden() {
            return;
        }
        let rate = steps_per_second(step.saturating_sub(first), self.start.elapsed());
        self.bar.set_message(format!("step {step} t={time:.4e} dt={dt:.3e} {rate:.1} steps/s"));
    }

    /// Prints a line above the bar; to plain stderr when the bar is hidden, nothing when quiet.
    pub fn println(&self, line: &str) {
        if self.quiet {
            return;
        }
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    /// Removes the bar.
    pub fn finish(self) {
        self.bar.finish_and_clear();
    }
}

/// Bar position of `time` out of `end_time`, clamped to the bar and safe for NaN or a zero end.
fn fraction_ticks(time: f64, end_time: f64) -> u64 {
    let f = time / end_time;
    if f.is_finite() {
        (f.clamp(0.0, 1.0) * TICKS as f64).round() as u64
    } else if end_time <= 0.0 && time >= end_time {
        TICKS
    } else {
        0
    }
}

fn steps_per_second(steps: u64, elapsed: Duration) -> f64 {
    let s = elapsed.as_secs_f64();
    if s > 0.0 {
        steps as f64 / s
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quiet_bar_is_hidden_and_tracks_time_fraction() {
        let mut p = Progress::new(2.0, true);
        assert!(p.is_hidden());
        p.update(0, 0.0, 0.1);
        p.update(5, 0.5, 0.1);
        assert_eq!(p.bar.position(), TICKS / 4);
        p.update(99, 3.0, 0.1);
        assert_eq!(p.bar.position(), TICKS);
        p.finish();
    }

    #[test]
    fn odd_times_do_not_panic() {
        assert_eq!(fraction_ticks(f64::NAN, 1.0), 0);
        assert_eq!(fraction_ticks(0.0, 0.0), TICKS);
        assert_eq!(fraction_ticks(-1.0, 1.0), 0);
        assert_eq!(steps_per_second(10, Duration::ZERO), 0.0);
        assert_eq!(steps_per_second(10, Duration::from_secs(2)), 5.0);
    }
}
