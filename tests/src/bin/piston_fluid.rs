//! `piston-fluid`: the analytic acoustic-column fluid participant, F = -A (p0 + ρ0 c0 v).

fn main() {
    eprintln!("piston-fluid: no command is available in this build yet");
    std::process::exit(2);
}
