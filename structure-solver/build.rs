//! Builds the C reference of the explicit BT4 step (`bench/bt4.c`) as a separate program for
//! `structure-solver bench` (gcc -O3 -march=native -ffp-contract=off: a measurement on this
//! machine; the solver itself is built for the baseline target and picks its vector width at
//! run time). Without a C compiler the bench reports the reference as unavailable.

use std::path::PathBuf;
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=bench/bt4.c");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=CC");
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("bt4-c");
    let cc = std::env::var("CC").unwrap_or_else(|_| "gcc".into());
    let status = Command::new(&cc)
        .args(["-O3", "-march=native", "-ffp-contract=off", "-fno-math-errno", "-std=c11"])
        .arg("bench/bt4.c")
        .arg("-o")
        .arg(&out)
        .arg("-lm")
        .status();
    match status {
        Ok(s) if s.success() => println!("cargo:rustc-env=BT4_C_REFERENCE={}", out.display()),
        other => {
            println!("cargo:warning=the C reference bench/bt4.c was not built ({cc}: {other:?})");
            println!("cargo:rustc-env=BT4_C_REFERENCE=");
        }
    }
}
