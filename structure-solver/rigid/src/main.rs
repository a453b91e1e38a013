//! `rigid-structure`: a rigid body on springs and dampers that speaks the coupling protocol.

fn main() {
    eprintln!("rigid-structure: no command is available in this build yet");
    std::process::exit(2);
}
