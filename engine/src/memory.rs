//! One memory budget for a whole job.
//!
//! Before any large allocation, a job adds up what it will hold at its
//! peak (decoded volume, spectra, slice grids, frames) and checks the sum
//! against one limit: the smallest of the job's own limit (`--max-memory`
//! in the `fvr` program, [`DEFAULT_CEILING`] without it) and the machine's,
//! which the program that embeds the engine reads ([`set_machine_probe`]:
//! `fvr-host` reads `ulimit -v`, the cgroup and `MemAvailable`). The error
//! names what would be needed, the limit and where it comes from, and how
//! to ask for less.

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

/// Reads the machine's and process's limit; set once by the program.
static PROBE: std::sync::OnceLock<fn() -> MemoryLimit> = std::sync::OnceLock::new();

/// Set how the machine's and process's memory limit is read (the first call
/// wins). Without a probe the machine's limit is [`FALLBACK_LIMIT`].
pub fn set_machine_probe(probe: fn() -> MemoryLimit) {
    let _ = PROBE.set(probe);
}

/// The machine's and process's limit, read once, when the job first asks
/// (before it allocates anything large), so that `MemAvailable` is not
/// lowered by the job's own buffers and then counted twice.
static DETECTED: std::sync::OnceLock<MemoryLimit> = std::sync::OnceLock::new();

/// The limit in force: the smallest of the machine's (its probe's) and
/// `--max-memory` (or [`DEFAULT_CEILING`] without it), less what the job
/// already [`hold`]s.
pub fn limit() -> MemoryLimit {
    let machine = *DETECTED.get_or_init(|| match PROBE.get() {
        Some(probe) => probe(),
        None => MemoryLimit {
            bytes: FALLBACK_LIMIT,
            source: LimitSource::Fallback,
        },
    });
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

/// A vector of `len` zeros written one by one, for accumulators whose
/// elements are read before they are written (`+=`).
///
/// `vec![0.0; len]` asks the allocator for zeroed memory, which the kernel
/// maps lazily to its shared zero page: the first `+=` on each page then
/// takes a copy-on-write fault that flushes the TLB of every CPU the
/// process runs threads on. Planning the CT head spent about 12% of a whole
/// `fvr render` in those faults (`perf record`). Writing the zeros first
/// maps each page once, without a flush. The `black_box` keeps the compiler
/// from turning the allocation and the writes back into a zeroed
/// allocation.
pub fn written_zeros<T: Copy + Default>(len: usize) -> Vec<T> {
    let mut v: Vec<T> = Vec::with_capacity(len);
    std::hint::black_box(v.as_mut_ptr());
    v.resize(len, T::default());
    v
}

/// [`limit`] in bytes.
pub fn limit_bytes() -> u64 {
    limit().bytes
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
