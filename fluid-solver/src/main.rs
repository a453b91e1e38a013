//! `fluid-solver`: runs a case alone or as a coupled participant.

fn main() {
    eprintln!("fluid-solver: no command is available in this build yet");
    std::process::exit(2);
}
