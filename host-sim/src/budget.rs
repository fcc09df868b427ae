//! One memory budget for a whole job.
//!
//! Before any large allocation or decompression, a job adds up what it will
//! hold at its peak (decoded volume, spectra, slice grids, frames) and checks
//! the sum against one limit: the smallest of `--max-memory`, the process's
//! address-space limit (`RLIMIT_AS`, as `ulimit -v` sets it), the cgroup's
//! memory limit, and `MemAvailable`. The error names what would be needed,
//! the limit and where it comes from, and how to ask for less.

use std::fmt;

/// Bytes the process holds beyond the budgeted buffers: code, allocator
/// arenas, thread stacks. Under an address-space limit this is subtracted
/// from the limit before the buffers are compared with it.
pub const PROCESS_OVERHEAD: u64 = 256 << 20;

/// Memory limit when nothing else can be read: 8 GiB.
pub const FALLBACK_LIMIT: u64 = 8 << 30;

/// What a job may hold without `--max-memory`: 2.75 GiB, so that with
/// [`PROCESS_OVERHEAD`] the program stays within 3 GiB whatever a file
/// claims, on any machine. `--max-memory` raises (or lowers) it, up to the
/// machine's and process's limits.
pub const DEFAULT_CEILING: u64 = (3 << 30) - PROCESS_OVERHEAD;

/// Where a memory limit comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LimitSource {
    /// `--max-memory`.
    Flag,
    /// The soft `RLIMIT_AS` (`ulimit -v`), less [`PROCESS_OVERHEAD`].
    AddressSpace,
    /// The cgroup's `memory.max` (v2) or `memory.limit_in_bytes` (v1).
    Cgroup,
    /// `MemAvailable` in `/proc/meminfo`.
    Available,
    /// None could be read: [`FALLBACK_LIMIT`].
    Fallback,
    /// [`DEFAULT_CEILING`], in force without `--max-memory`.
    Ceiling,
}

impl fmt::Display for LimitSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            LimitSource::Flag => "--max-memory",
            LimitSource::AddressSpace => "the address-space limit (ulimit -v)",
            LimitSource::Cgroup => "the cgroup memory limit",
            LimitSource::Available => "MemAvailable in /proc/meminfo",
            LimitSource::Fallback => "the default limit",
            LimitSource::Ceiling => "the default ceiling; raise it with --max-memory",
        })
    }
}

/// The bytes a job may hold, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryLimit {
    /// Bytes.
    pub bytes: u64,
    /// Which limit is the smallest.
    pub source: LimitSource,
}

/// `--max-memory`, set once by the program before any work.
static MAX_MEMORY: std::sync::OnceLock<u64> = std::sync::OnceLock::new();

/// Set the `--max-memory` limit for this process (the first call wins).
pub fn set_max_memory(bytes: u64) {
    let _ = MAX_MEMORY.set(bytes);
}

/// The machine's and process's limit, read once, when the job first asks
/// (before it allocates anything large), so that `MemAvailable` is not
/// lowered by the job's own buffers and then counted twice.
static DETECTED: std::sync::OnceLock<MemoryLimit> = std::sync::OnceLock::new();

/// The limit in force: the smallest of [`MemoryLimit::detect`] and
/// `--max-memory` (or [`DEFAULT_CEILING`] without it), less what the job
/// already [`hold`]s.
pub fn limit() -> MemoryLimit {
    let machine = *DETECTED.get_or_init(|| MemoryLimit::detect(None));
    let (job, source) = match MAX_MEMORY.get() {
        Some(&b) => (b, LimitSource::Flag),
        None => (DEFAULT_CEILING, LimitSource::Ceiling),
    };
    let mut l = if job <= machine.bytes {
        MemoryLimit { bytes: job, source }
    } else {
        machine
    };
    l.bytes = l.bytes.saturating_sub(held());
    l
}

/// [`limit`] in bytes.
pub fn limit_bytes() -> u64 {
    limit().bytes
}

impl MemoryLimit {
    /// The smallest of `flag` and the limits this machine and process impose.
    pub fn detect(flag: Option<u64>) -> Self {
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

/// Bytes in binary units, e.g. `1.5 GiB`.
pub fn human_bytes(b: u64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < units.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", units[u])
    }
}

/// What a job will hold at its peak, item by item.
#[derive(Clone, Debug, Default)]
pub struct Budget {
    items: Vec<(&'static str, u64)>,
    overflow: bool,
}

/// A job over its memory limit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OverBudget {
    /// Bytes needed (saturated at `u64::MAX`).
    pub needed: u64,
    /// The limit.
    pub limit: MemoryLimit,
    /// The items that are not empty, largest first.
    pub items: Vec<(&'static str, u64)>,
    /// How to ask for less.
    pub hint: &'static str,
}

impl fmt::Display for OverBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts: Vec<String> = self
            .items
            .iter()
            .take(3)
            .map(|(what, b)| format!("{what} {}", human_bytes(*b)))
            .collect();
        if self.items.len() > 3 {
            parts.push(format!("{} more", self.items.len() - 3));
        }
        write!(
            f,
            "this job needs about {} ({}) but the memory limit is {} ({}); {}",
            human_bytes(self.needed),
            parts.join(" + "),
            human_bytes(self.limit.bytes),
            self.limit.source,
            self.hint
        )
    }
}

impl std::error::Error for OverBudget {}

impl Budget {
    /// An empty budget.
    pub fn new() -> Self {
        Budget::default()
    }

    /// Add `count` elements of `size` bytes held as `what`.
    pub fn hold(&mut self, what: &'static str, count: u64, size: u64) -> &mut Self {
        match count.checked_mul(size) {
            Some(b) => self.items.push((what, b)),
            None => {
                self.items.push((what, u64::MAX));
                self.overflow = true;
            }
        }
        self
    }

    /// The total, saturating.
    pub fn total(&self) -> u64 {
        self.items
            .iter()
            .fold(0u64, |a, &(_, b)| a.saturating_add(b))
    }

    /// `Ok` if the total fits `limit`; otherwise the error, with `hint`.
    ///
    /// # Errors
    /// [`OverBudget`].
    pub fn check(&self, limit: MemoryLimit, hint: &'static str) -> Result<(), OverBudget> {
        let needed = self.total();
        if needed <= limit.bytes && !self.overflow {
            return Ok(());
        }
        let mut items: Vec<_> = self.items.iter().copied().filter(|&(_, b)| b > 0).collect();
        items.sort_by_key(|&(_, b)| std::cmp::Reverse(b));
        Err(OverBudget {
            needed,
            limit,
            items,
            hint,
        })
    }
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
        let limit = MemoryLimit::detect(Some(1 << 20));
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

/// What a job will build from the volume it loads, given the volume's dims:
/// set by the program before loading ([`set_plan`]), so that a reader can
/// refuse a volume before decoding or decompressing it.
type Plan = Box<dyn Fn([usize; 3]) -> Budget + Send + Sync>;

static PLAN: std::sync::Mutex<Option<(Plan, &'static str)>> = std::sync::Mutex::new(None);

/// Declare what this job builds from a volume of given dims (spectra, images,
/// frames), and how to ask for less; replaces any earlier plan.
pub fn set_plan(hint: &'static str, plan: impl Fn([usize; 3]) -> Budget + Send + Sync + 'static) {
    let mut slot = PLAN
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    *slot = Some((Box::new(plan), hint));
}

/// The plan's budget for `dims` (empty without a plan), and its hint.
fn planned(dims: [usize; 3]) -> (Budget, &'static str) {
    let slot = PLAN
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    match slot.as_ref() {
        Some((plan, hint)) => (plan(dims), *hint),
        None => (Budget::new(), "use a smaller volume or raise --max-memory"),
    }
}

/// Check, before decoding, a volume of `dims` whose decoding also holds
/// `transit` bytes of raw samples, together with what the job plans to
/// build from it ([`set_plan`]) and what it already holds ([`hold`]).
///
/// # Errors
/// [`OverBudget`], naming the largest items.
pub fn check_load(dims: [usize; 3], transit: u64) -> Result<(), OverBudget> {
    let count = dims.iter().fold(1u64, |a, &d| a.saturating_mul(d as u64));
    let (mut budget, hint) = planned(dims);
    budget.hold("decoded volume", count, 4);
    budget.hold("raw samples in transit", transit, 1);
    budget.check(limit(), hint)
}

/// Check what the job plans to build from a loaded volume of `dims`
/// ([`set_plan`]) against the limit, less what it holds (the volume, once
/// [`hold`] counts it). For volumes made in memory (phantoms) this is the
/// first check; for files it repeats [`check_load`]'s with the actual dims.
///
/// # Errors
/// [`OverBudget`].
pub fn check_plan(dims: [usize; 3]) -> Result<(), OverBudget> {
    let (budget, hint) = planned(dims);
    budget.check(limit(), hint)
}

/// Bytes held by live [`Held`] guards.
static HELD: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// A long-lived buffer counted against the limit while the guard lives:
/// [`limit`] is lowered by its size, so that every later check sees the
/// whole job (the volume while its spectrum is checked, the first image
/// while `compare` reads the second).
#[derive(Debug)]
#[must_use = "the bytes are counted only while the guard lives"]
pub struct Held(u64);

/// Count `bytes` as held until the returned guard drops.
pub fn hold(bytes: u64) -> Held {
    HELD.fetch_add(bytes, std::sync::atomic::Ordering::SeqCst);
    Held(bytes)
}

/// Bytes currently held through [`hold`].
pub fn held() -> u64 {
    HELD.load(std::sync::atomic::Ordering::SeqCst)
}

impl Drop for Held {
    fn drop(&mut self) {
        HELD.fetch_sub(self.0, std::sync::atomic::Ordering::SeqCst);
    }
}
