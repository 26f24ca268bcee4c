//! How much memory this machine can give a run, so that a limit a user raises (`max_samples`,
//! `max_bytes`) is checked against what the machine can honour before anything is allocated:
//! an allocation the system cannot serve aborts the process ("memory allocation of N bytes
//! failed") instead of returning an error.
//!
//! The figure is the kernel's `MemAvailable` (Linux, `/proc/meminfo`), lowered to a control
//! group's memory limit where one is set; elsewhere it is unknown and nothing is refused.

/// Bytes of memory available to this process now, if the system says.
pub fn available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kb: u64 = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    let free = kb.saturating_mul(1024);
    Some(match cgroup_room() {
        Some(room) => free.min(room),
        None => free,
    })
}

/// What a cgroup v2 memory limit leaves (`memory.max` − `memory.current`), if one is set.
fn cgroup_room() -> Option<u64> {
    let read = |name: &str| std::fs::read_to_string(format!("/sys/fs/cgroup/{name}")).ok();
    let max: u64 = read("memory.max")?.trim().parse().ok()?;
    let current: u64 = read("memory.current")?.trim().parse().ok()?;
    Some(max.saturating_sub(current))
}

/// `Err` with a sentence when `bytes` (a float, so that a count too large for any integer is
/// still compared rightly) is more than `available` bytes; `None` available refuses nothing.
pub fn check(bytes: f64, available: Option<u64>) -> Result<(), String> {
    match available {
        Some(room) if !(bytes <= room as f64) => Err(format!(
            "needs about {}, more than the {} of memory this machine has available",
            gigabytes(bytes),
            gigabytes(room as f64)
        )),
        _ => Ok(()),
    }
}

/// Bytes as a size for messages: `1.4 GB`, `80000000.0 GB`.
pub fn gigabytes(bytes: f64) -> String {
    if bytes < 1e9 {
        format!("{:.0} MB", bytes / 1e6)
    } else if bytes < 1e15 {
        format!("{:.1} GB", bytes / 1e9)
    } else {
        format!("{:.1e} GB", bytes / 1e9)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn more_than_is_available_is_refused_with_both_sizes() {
        assert_eq!(check(1e9, Some(2_000_000_000)), Ok(()));
        assert_eq!(
            check(8e13, Some(2_000_000_000)).unwrap_err(),
            "needs about 80000.0 GB, more than the 2.0 GB of memory this machine has available"
        );
        assert!(check(f64::INFINITY, Some(1)).is_err());
        assert!(check(f64::NAN, Some(1)).is_err());
        assert_eq!(check(1e30, None), Ok(()));
        assert_eq!(gigabytes(1.4e18), "1.4e9 GB");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn linux_says_what_is_available() {
        let room = available().unwrap();
        assert!(room > 1_000_000, "{room}");
    }
}
