//! `fsi`: starts the two solvers of a case, supervises them and sequences the coupling scheme.

fn main() {
    eprintln!("fsi: no command is available in this build yet");
    std::process::exit(2);
}
