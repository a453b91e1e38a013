//! What a run may ask of the machine: memory estimated before allocating and step counts capped,
//! so an input that cannot fit is refused with a number instead of aborting in the allocator or
//! running for ever.

/// The most time steps one run may take: far beyond any real run (10^9 explicit steps of a
/// thousand-node model already take days), and small enough that a count given by mistake
/// (`t_end / dt` of 2^64) is refused at once.
pub const MAX_STEPS: u64 = 1_000_000_000;

/// Why a run cannot be given what it asks for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResourceError {
    #[error(
        "{what} needs about {} but this machine has {} available; use a coarser mesh or a \
         machine with more memory",
        human_bytes(*.needed),
        human_bytes(*.available)
    )]
    Memory { what: String, needed: u64, available: u64 },
    #[error("{what}: about {count:.3e} steps is more than the {MAX_STEPS} one run may take; check the end time and step")]
    Steps { what: String, count: f64 },
}

/// Bytes of memory available to a new allocation: `MemAvailable` of `/proc/meminfo`, or `None`
/// where that file is missing or unreadable (the check is then skipped).
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    parse_mem_available(&text)
}

fn parse_mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Refuses an allocation of about `needed` bytes (`what` names it, e.g. "the fluid mesh of
/// `mesh.cells = [...]`") when the machine does not have it available.
pub fn ensure_memory(what: &str, needed: u64) -> Result<(), ResourceError> {
    match available_memory() {
        Some(available) if needed > available => {
            Err(ResourceError::Memory { what: what.to_string(), needed, available })
        }
        _ => Ok(()),
    }
}

/// Bytes for `count` items of `bytes_each`, saturating (a count of 1e14 must not wrap).
pub fn bytes_for(count: f64, bytes_each: u64) -> u64 {
    let b = count * bytes_each as f64;
    if b.is_finite() && b < u64::MAX as f64 {
        b as u64
    } else {
        u64::MAX
    }
}

/// The number of steps of length `dt` that reach `t_end`, refused past [`MAX_STEPS`] (`what`
/// names the keys, e.g. "coupling.t_end / coupling.dt").
pub fn step_count(what: &str, t_end: f64, dt: f64) -> Result<u64, ResourceError> {
    let count = (t_end / dt).ceil();
    if count.is_nan() || count > MAX_STEPS as f64 {
        return Err(ResourceError::Steps { what: what.to_string(), count });
    }
    Ok(count.max(0.0) as u64)
}

/// A byte count for people: `3.2 GiB`.
pub fn human_bytes(b: u64) -> String {
    const UNITS: [&str; 7] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = b as f64;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_mem_available() {
        let text = "MemTotal:       24000000 kB\nMemFree:  100 kB\nMemAvailable:   2048 kB\n";
        assert_eq!(parse_mem_available(text), Some(2048 * 1024));
        assert_eq!(parse_mem_available("MemTotal: 1 kB\n"), None);
    }

    #[test]
    fn refuses_what_cannot_fit_and_names_it() {
        let e = ensure_memory("the fluid mesh", u64::MAX).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("the fluid mesh") && msg.contains("EiB"), "{msg}");
        assert!(ensure_memory("a small buffer", 1024).is_ok());
        assert_eq!(bytes_for(1e14, 800), 80_000_000_000_000_000);
        assert_eq!(bytes_for(1e30, 800), u64::MAX);
    }

    #[test]
    fn caps_step_counts() {
        assert_eq!(step_count("t", 1.0, 0.25).unwrap(), 4);
        let e = step_count("coupling.t_end / coupling.dt", 1.0, 1e-300).unwrap_err();
        assert!(e.to_string().contains("coupling.t_end / coupling.dt"), "{e}");
        assert!(step_count("t", f64::INFINITY, 1.0).is_err());
        assert!(step_count("t", 1.0, 0.0).is_err());
        assert_eq!(human_bytes(512), "512 B");
        assert_eq!(human_bytes(3 * 1024 * 1024 * 1024), "3.0 GiB");
    }
}
