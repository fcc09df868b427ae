//! The machine's memory limit, read from the process's limits, the cgroup
//! and `/proc/meminfo`, and the engine's budget ([`fvr_engine::memory`])
//! that every job is checked against.

pub use fvr_engine::memory::*;

/// Make the engine read this machine's limits ([`detect`]); called once by
/// the program before any work.
pub fn install() {
    set_machine_probe(|| detect(None));
}

/// The smallest of `flag` and the limits this machine and process impose.
pub fn detect(flag: Option<u64>) -> MemoryLimit {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let candidates = [
        flag.map(|b| (b, LimitSource::Flag)),
        read("/proc/self/limits")
            .and_then(|s| address_space_limit(&s))
            .map(|b| {
                (
                    b.saturating_sub(PROCESS_OVERHEAD),
                    LimitSource::AddressSpace,
                )
            }),
        cgroup_limit().map(|b| (b, LimitSource::Cgroup)),
        read("/proc/meminfo")
            .and_then(|s| mem_available(&s))
            .map(|b| (b, LimitSource::Available)),
    ];
    let (bytes, source) = candidates
        .into_iter()
        .flatten()
        .min_by_key(|&(b, _)| b)
        .unwrap_or((FALLBACK_LIMIT, LimitSource::Fallback));
    MemoryLimit { bytes, source }
}

/// The soft "Max address space" of `/proc/self/limits`, if not unlimited.
pub fn address_space_limit(limits: &str) -> Option<u64> {
    let rest = limits
        .lines()
        .find_map(|l| l.strip_prefix("Max address space"))?;
    rest.split_whitespace().next()?.parse().ok()
}

/// `MemAvailable` in bytes from the text of `/proc/meminfo`.
pub fn mem_available(meminfo: &str) -> Option<u64> {
    let rest = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?;
    let mut words = rest.split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        _ => None,
    }
}

/// The tightest cgroup memory limit on the path from this process's cgroup
/// to the root, v2 or v1.
fn cgroup_limit() -> Option<u64> {
    let cgroups = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let mut best: Option<u64> = None;
    for (root, file, path) in cgroup_files(&cgroups) {
        let mut dir = std::path::PathBuf::from(root).join(path.trim_start_matches('/'));
        loop {
            if let Some(b) = std::fs::read_to_string(dir.join(file))
                .ok()
                .and_then(|s| parse_cgroup_value(&s))
            {
                best = Some(best.map_or(b, |x| x.min(b)));
            }
            if !dir.pop() || !dir.starts_with(root) {
                break;
            }
        }
    }
    best
}

/// The (mount root, limit file, cgroup path) of each memory controller named
/// in `/proc/self/cgroup`.
fn cgroup_files(cgroups: &str) -> Vec<(&'static str, &'static str, &str)> {
    cgroups
        .lines()
        .filter_map(|line| {
            let mut parts = line.splitn(3, ':');
            let (id, controllers, path) = (parts.next()?, parts.next()?, parts.next()?);
            if id == "0" && controllers.is_empty() {
                Some(("/sys/fs/cgroup", "memory.max", path))
            } else if controllers.split(',').any(|c| c == "memory") {
                Some(("/sys/fs/cgroup/memory", "memory.limit_in_bytes", path))
            } else {
                None
            }
        })
        .collect()
}

/// A cgroup limit file's value: bytes, or `None` for "max" and the v1
/// "no limit" values near `i64::MAX`.
pub fn parse_cgroup_value(text: &str) -> Option<u64> {
    let b: u64 = text.trim().parse().ok()?;
    (b < 1 << 62).then_some(b)
}

/// A byte count given as `flag`: a whole number, optionally with K, M or G
/// (powers of 1024).
///
/// # Errors
/// A one-line message naming the flag and (the start of) the value.
pub fn parse_bytes(flag: &str, s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (digits, shift) = match t.char_indices().last() {
        Some((i, 'K' | 'k')) => (&t[..i], 10),
        Some((i, 'M' | 'm')) => (&t[..i], 20),
        Some((i, 'G' | 'g')) => (&t[..i], 30),
        _ => (t, 0),
    };
    digits
        .parse::<u64>()
        .ok()
        .and_then(|v| v.checked_mul(1u64 << shift))
        .ok_or_else(|| {
            let shown: String = s.chars().take(40).collect();
            let more = if s.chars().nth(40).is_some() {
                "…"
            } else {
                ""
            };
            format!("{flag} `{shown}{more}`: expected a number of bytes, optionally with K, M or G")
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_text_is_read_soft_column() {
        let text = "Limit                     Soft Limit           Hard Limit           Units\n\
                    Max address space         3221225472           unlimited            bytes\n";
        assert_eq!(address_space_limit(text), Some(3 << 30));
        let unlimited =
            "Max address space         unlimited            unlimited            bytes\n";
        assert_eq!(address_space_limit(unlimited), None);
    }

    #[test]
    fn cgroup_values() {
        assert_eq!(parse_cgroup_value("max\n"), None);
        assert_eq!(parse_cgroup_value("9223372036854771712\n"), None);
        assert_eq!(parse_cgroup_value("1073741824\n"), Some(1 << 30));
        let files = cgroup_files("4:memory:/a/b\n0::/c\n3:cpu:/\n");
        assert_eq!(
            files,
            vec![
                ("/sys/fs/cgroup/memory", "memory.limit_in_bytes", "/a/b"),
                ("/sys/fs/cgroup", "memory.max", "/c"),
            ]
        );
    }

    #[test]
    fn byte_counts() {
        assert_eq!(parse_bytes("--f", "1024"), Ok(1024));
        assert_eq!(parse_bytes("--f", "3K"), Ok(3072));
        assert_eq!(parse_bytes("--f", "2M"), Ok(2 << 20));
        assert_eq!(parse_bytes("--f", "3G"), Ok(3 << 30));
        assert!(parse_bytes("--f", "x").unwrap_err().starts_with("--f `x`"));
        assert!(parse_bytes("--f", "99999999999G").is_err());
        assert!(parse_bytes("--f", &"9".repeat(500)).unwrap_err().len() < 120);
        assert_eq!(human_bytes(1536 << 20), "1.5 GiB");
        assert_eq!(human_bytes(12), "12 B");
    }

    #[test]
    fn the_flag_wins_when_smallest_and_budgets_saturate() {
        let limit = detect(Some(1 << 20));
        assert_eq!(
            limit,
            MemoryLimit {
                bytes: 1 << 20,
                source: LimitSource::Flag
            }
        );
        let mut b = Budget::new();
        b.hold("spectrum", 1 << 20, 2).hold("volume", 1, 10);
        let e = b.check(limit, "use --resample").unwrap_err();
        assert_eq!(e.needed, (2 << 20) + 10);
        let text = e.to_string();
        assert!(
            text.contains("2.0 MiB") && text.contains("--max-memory"),
            "{text}"
        );
        let mut huge = Budget::new();
        huge.hold("frames", u64::MAX, 8);
        assert!(huge
            .check(
                MemoryLimit {
                    bytes: u64::MAX,
                    source: LimitSource::Flag
                },
                ""
            )
            .is_err());
    }
}
