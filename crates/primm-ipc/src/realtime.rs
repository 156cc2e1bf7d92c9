//! Real-time settings of a primm program: CPU affinity and `SCHED_FIFO` priority of its
//! latency-critical threads, and locked memory.
//!
//! * **CPU affinity** (`sched_setaffinity` through `pthread_setaffinity_np`) keeps a thread on
//!   the CPUs given, so it does not migrate (cold caches) and, with the CPUs isolated from the
//!   scheduler (`isolcpus`, docs/realtime-tuning.md), does not share them with other work.
//! * **Real-time priority** (`SCHED_FIFO`, 1 to 99, through `pthread_setschedparam`) lets the
//!   thread preempt every normal thread on its CPU as soon as it becomes runnable.
//! * **Locked memory** (`mlockall(MCL_CURRENT | MCL_FUTURE)`) keeps every page of the process
//!   resident, so no page fault or swap-in lands in a frame. It is applied after the warm-up
//!   allocations (tracker, buffers, shared memory), so it locks what the loop will touch.
//!
//! A setting the process may not apply (no `CAP_SYS_NICE` and an `RLIMIT_RTPRIO` below the
//! priority, no `CAP_IPC_LOCK` and an `RLIMIT_MEMLOCK` below the process's size, a CPU outside
//! the process's allowed set) is a [`RealtimeError`] naming the setting, the OS error and what
//! to do. A [`RealtimeReport`] collects what was applied and what failed; at
//! [`finish`](RealtimeReport::finish) the program either logs each failure as a warning and
//! starts anyway, or, with [`RealtimeSettings::require_realtime`], refuses to start
//! ([`RealtimeRefused`]).
//!
//! `primm serve` applies [`RealtimeSettings`] to its tracking thread and
//! [`RealtimeSettings::inference_cpu_affinity`] to its inference threads; `primm-publisher` and
//! `primm-subscriber` apply them to their loop's thread. The `clap` feature adds
//! [`RealtimeArgs`] and [`TrackerRealtimeArgs`], the command-line options they flatten.

use std::fmt;
use std::str::FromStr;

/// Largest CPU index a [`CpuList`] accepts (the size of the kernel's `cpu_set_t`, less one).
pub const MAX_CPU_INDEX: usize = libc::CPU_SETSIZE as usize - 1;

/// Highest `SCHED_FIFO` priority Linux offers.
pub const MAX_REALTIME_PRIORITY: i32 = 99;

/// A list of CPU indices as written on the command line: `2`, `3,4`, `0-3` or `0,2-3`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CpuList(Vec<usize>);

impl CpuList {
    /// The CPUs in the order written (duplicates removed).
    pub fn cpus(&self) -> &[usize] {
        &self.0
    }

    /// The CPU for the `index`-th of several threads: the list is dealt out in order and starts
    /// over when it runs out.
    pub fn for_thread(&self, index: usize) -> usize {
        self.0[index % self.0.len()]
    }
}

impl fmt::Display for CpuList {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, cpu) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str(",")?;
            }
            write!(f, "{cpu}")?;
        }
        Ok(())
    }
}

/// A CPU list that could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CpuListError {
    /// The list names no CPU.
    #[error("the CPU list is empty (expected e.g. 2, 3,4 or 0-3)")]
    Empty,
    /// An entry is not a CPU index or a range `FIRST-LAST` of them.
    #[error("'{entry}' is not a CPU index or a range FIRST-LAST (expected e.g. 2, 3,4 or 0-3)")]
    Malformed {
        /// The entry.
        entry: String,
    },
    /// A range whose last CPU comes before its first.
    #[error("the CPU range '{entry}' is reversed")]
    Reversed {
        /// The entry.
        entry: String,
    },
    /// A CPU index beyond [`MAX_CPU_INDEX`].
    #[error("CPU {cpu} is beyond the largest index a CPU set holds ({MAX_CPU_INDEX})")]
    TooLarge {
        /// The index.
        cpu: usize,
    },
}

impl FromStr for CpuList {
    type Err = CpuListError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let mut cpus = Vec::new();
        for entry in text.split(',').map(str::trim) {
            if entry.is_empty() {
                continue;
            }
            let malformed = || CpuListError::Malformed { entry: entry.to_string() };
            let (first, last) = match entry.split_once('-') {
                Some((first, last)) => (
                    first.trim().parse::<usize>().map_err(|_| malformed())?,
                    last.trim().parse::<usize>().map_err(|_| malformed())?,
                ),
                None => {
                    let cpu = entry.parse::<usize>().map_err(|_| malformed())?;
                    (cpu, cpu)
                }
            };
            if last < first {
                return Err(CpuListError::Reversed { entry: entry.to_string() });
            }
            if last > MAX_CPU_INDEX {
                return Err(CpuListError::TooLarge { cpu: last });
            }
            for cpu in first..=last {
                if !cpus.contains(&cpu) {
                    cpus.push(cpu);
                }
            }
        }
        if cpus.is_empty() {
            return Err(CpuListError::Empty);
        }
        Ok(CpuList(cpus))
    }
}

/// The real-time settings of one program. The default applies nothing.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RealtimeSettings {
    /// CPUs the program's latency-critical thread (the tracking, replay or receive loop) may
    /// run on; `None`: wherever the scheduler likes.
    pub cpu_affinity: Option<CpuList>,
    /// CPUs of the inference threads (`primm serve` with PR): the `i`-th thread is pinned to
    /// the `i`-th CPU of the list, starting over when the list runs out; `None`: unpinned.
    pub inference_cpu_affinity: Option<CpuList>,
    /// `SCHED_FIFO` priority (1 to 99) of the latency-critical thread and of the inference
    /// threads; `None`: the normal time-sharing policy.
    pub realtime_priority: Option<i32>,
    /// Lock every page of the process in memory after the warm-up allocations.
    pub lock_memory: bool,
    /// Refuse to start when a setting cannot be applied, instead of warning.
    pub require_realtime: bool,
}

impl RealtimeSettings {
    /// Whether any setting is asked for.
    pub fn is_empty(&self) -> bool {
        self.cpu_affinity.is_none()
            && self.inference_cpu_affinity.is_none()
            && self.realtime_priority.is_none()
            && !self.lock_memory
    }

    /// Pins the calling thread to [`cpu_affinity`](Self::cpu_affinity) and gives it
    /// [`realtime_priority`](Self::realtime_priority), recording the outcome in `report`;
    /// `role` names the thread in messages (e.g. "tracking thread").
    pub fn apply_to_current_thread(&self, role: &str, report: &mut RealtimeReport) {
        // SAFETY: pthread_self has no preconditions.
        let thread = unsafe { libc::pthread_self() };
        if let Some(cpus) = &self.cpu_affinity {
            report.record(set_affinity(thread, role, cpus.cpus()));
        }
        if let Some(priority) = self.realtime_priority {
            report.record(set_fifo_priority(thread, role, priority));
        }
    }

    /// Pins the `index`-th inference thread, `thread`, to its CPU of
    /// [`inference_cpu_affinity`](Self::inference_cpu_affinity) and gives it
    /// [`realtime_priority`](Self::realtime_priority). `thread` must be a live or not yet joined
    /// thread of this process (as a `JoinHandle` keeps it).
    pub fn apply_to_inference_thread(
        &self,
        thread: libc::pthread_t,
        index: usize,
        report: &mut RealtimeReport,
    ) {
        let role = format!("inference thread {index}");
        if let Some(cpus) = &self.inference_cpu_affinity {
            report.record(set_affinity(thread, &role, &[cpus.for_thread(index)]));
        }
        if let Some(priority) = self.realtime_priority {
            report.record(set_fifo_priority(thread, &role, priority));
        }
    }

    /// Locks the process's memory if [`lock_memory`](Self::lock_memory) asks for it. Call it
    /// once the program has made its warm-up allocations.
    pub fn lock_memory_now(&self, report: &mut RealtimeReport) {
        if self.lock_memory {
            report.record(lock_all_memory());
        }
    }
}

/// A real-time setting that could not be applied, with the OS error and what to do.
#[derive(Debug, thiserror::Error)]
pub enum RealtimeError {
    /// The thread could not be pinned to its CPUs.
    #[error(
        "cannot pin the {role} to CPU(s) {cpus}: {source}; the process may run on CPU(s) {allowed} \
         (see `taskset -p`, the container's or cgroup's cpuset, and `nproc`)"
    )]
    Affinity {
        /// The thread.
        role: String,
        /// The CPUs asked for.
        cpus: String,
        /// The CPUs the process may use, as the kernel reports them.
        allowed: String,
        /// The OS error (`EINVAL`: none of the CPUs is available to the process).
        source: std::io::Error,
    },
    /// The thread could not get its `SCHED_FIFO` priority.
    #[error(
        "cannot give the {role} SCHED_FIFO priority {priority}: {source}; this needs CAP_SYS_NICE \
         or an RLIMIT_RTPRIO of at least {priority} (now {rtprio_limit}): run as root, grant the \
         capability (`setcap cap_sys_nice+ep BINARY`), or raise `rtprio` in \
         /etc/security/limits.conf (`ulimit -r`); in a container also allow SYS_NICE"
    )]
    Priority {
        /// The thread.
        role: String,
        /// The priority asked for.
        priority: i32,
        /// The soft RLIMIT_RTPRIO, as text ("unlimited" or a number).
        rtprio_limit: String,
        /// The OS error (`EPERM`: not permitted).
        source: std::io::Error,
    },
    /// The process's memory could not be locked.
    #[error(
        "cannot lock the process's memory (mlockall): {source}; this needs CAP_IPC_LOCK or an \
         RLIMIT_MEMLOCK above the process's size ({resident_kib} KiB resident; limit now \
         {memlock_limit}): run as root, raise `memlock` in /etc/security/limits.conf \
         (`ulimit -l`), or set LimitMEMLOCK=infinity in a systemd unit"
    )]
    LockMemory {
        /// The soft RLIMIT_MEMLOCK, as text ("unlimited" or bytes).
        memlock_limit: String,
        /// The process's resident size, KiB (0 if unknown).
        resident_kib: u64,
        /// The OS error (`ENOMEM`: over the limit; `EPERM`: not permitted).
        source: std::io::Error,
    },
}

/// Settings that could not be applied while [`RealtimeSettings::require_realtime`] was set.
#[derive(Debug, thiserror::Error)]
#[error("real-time settings required (--require-realtime) but not applied:\n  {}",
    .failures.iter().map(ToString::to_string).collect::<Vec<_>>().join("\n  "))]
pub struct RealtimeRefused {
    /// Every setting that failed.
    pub failures: Vec<RealtimeError>,
}

/// What applying the real-time settings did: the settings applied, as lines for the log, and
/// the failures.
#[derive(Debug, Default)]
pub struct RealtimeReport {
    applied: Vec<String>,
    failures: Vec<RealtimeError>,
}

impl RealtimeReport {
    fn record(&mut self, outcome: Result<String, RealtimeError>) {
        match outcome {
            Ok(line) => self.applied.push(line),
            Err(error) => self.failures.push(error),
        }
    }

    /// The settings applied, one line each.
    pub fn applied(&self) -> &[String] {
        &self.applied
    }

    /// The settings that failed.
    pub fn failures(&self) -> &[RealtimeError] {
        &self.failures
    }

    /// Logs what was applied; with `require_realtime` any failure refuses the start, else each
    /// is logged as a warning and the program goes on without that setting.
    pub fn finish(self, require_realtime: bool) -> Result<(), RealtimeRefused> {
        for line in &self.applied {
            tracing::info!("real-time setting applied: {line}");
        }
        if self.failures.is_empty() {
            return Ok(());
        }
        if require_realtime {
            return Err(RealtimeRefused { failures: self.failures });
        }
        for failure in &self.failures {
            tracing::warn!("{failure}; starting without it (--require-realtime refuses instead)");
        }
        Ok(())
    }
}

fn set_affinity(thread: libc::pthread_t, role: &str, cpus: &[usize]) -> Result<String, RealtimeError> {
    let list = CpuList(cpus.to_vec()).to_string();
    // SAFETY: cpu_set_t is plain data, valid as zero; CPU_SET is given indices below
    // CPU_SETSIZE (CpuList checks them); `thread` is a thread of this process that has not been
    // joined (the callers' contract), for which pthread_setaffinity_np reports ESRCH at worst.
    let code = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        for &cpu in cpus {
            libc::CPU_SET(cpu, &mut set);
        }
        libc::pthread_setaffinity_np(thread, std::mem::size_of::<libc::cpu_set_t>(), &set)
    };
    if code == 0 {
        Ok(format!("{role} pinned to CPU(s) {list}"))
    } else {
        Err(RealtimeError::Affinity {
            role: role.to_string(),
            cpus: list,
            allowed: allowed_cpus(),
            source: std::io::Error::from_raw_os_error(code),
        })
    }
}

fn set_fifo_priority(thread: libc::pthread_t, role: &str, priority: i32) -> Result<String, RealtimeError> {
    let param = libc::sched_param { sched_priority: priority };
    // SAFETY: `param` is a valid sched_param; `thread` as in `set_affinity`.
    let code = unsafe { libc::pthread_setschedparam(thread, libc::SCHED_FIFO, &param) };
    if code == 0 {
        Ok(format!("{role} runs SCHED_FIFO at priority {priority}"))
    } else {
        Err(RealtimeError::Priority {
            role: role.to_string(),
            priority,
            rtprio_limit: soft_limit(libc::RLIMIT_RTPRIO, ""),
            source: std::io::Error::from_raw_os_error(code),
        })
    }
}

fn lock_all_memory() -> Result<String, RealtimeError> {
    // SAFETY: mlockall takes flags only.
    if unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } == 0 {
        Ok(format!("process memory locked ({} KiB now)", status_kib("VmLck:")))
    } else {
        let source = std::io::Error::last_os_error();
        Err(RealtimeError::LockMemory {
            memlock_limit: soft_limit(libc::RLIMIT_MEMLOCK, " bytes"),
            resident_kib: status_kib("VmRSS:"),
            source,
        })
    }
}

/// The soft limit `resource`, as "unlimited" or the number and `unit`.
fn soft_limit(resource: libc::__rlimit_resource_t, unit: &str) -> String {
    let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: `limit` is a valid rlimit to write into.
    if unsafe { libc::getrlimit(resource, &mut limit) } != 0 {
        return "unknown".to_string();
    }
    if limit.rlim_cur == libc::RLIM_INFINITY {
        "unlimited".to_string()
    } else {
        format!("{}{unit}", limit.rlim_cur)
    }
}

/// A `/proc/self/status` field in KiB (`VmRSS:`, `VmLck:`); 0 if it cannot be read.
fn status_kib(field: &str) -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| {
            status.lines().find_map(|line| {
                line.strip_prefix(field)
                    .and_then(|rest| rest.trim().trim_end_matches("kB").trim().parse().ok())
            })
        })
        .unwrap_or(0)
}

/// The CPUs the process may run on, as a list ("unknown" if the kernel does not say).
pub fn allowed_cpus() -> String {
    // SAFETY: cpu_set_t is plain data, valid as zero; sched_getaffinity writes at most its size.
    let cpus: Vec<usize> = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return "unknown".to_string();
        }
        (0..=MAX_CPU_INDEX).filter(|&cpu| libc::CPU_ISSET(cpu, &set)).collect()
    };
    if cpus.is_empty() {
        "unknown".to_string()
    } else {
        CpuList(cpus).to_string()
    }
}

/// The real-time options of `primm-publisher` and `primm-subscriber` (flatten into their
/// arguments); [`TrackerRealtimeArgs`] adds the inference threads for `primm serve`.
#[cfg(feature = "clap")]
#[derive(Debug, Clone, Default, clap::Args)]
pub struct RealtimeArgs {
    /// Pin the loop's thread to these CPUs (e.g. 2, 2,3 or 2-3); see docs/realtime-tuning.md.
    #[arg(long, value_name = "CPUS")]
    pub cpu_affinity: Option<CpuList>,
    /// Run the loop's thread (and `primm serve`'s inference threads) under SCHED_FIFO at this
    /// priority (1 to 99); needs CAP_SYS_NICE or a large enough RLIMIT_RTPRIO.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(i32).range(1..=99))]
    pub realtime_priority: Option<i32>,
    /// Lock the process's memory (mlockall) after the warm-up allocations; needs CAP_IPC_LOCK
    /// or a large enough RLIMIT_MEMLOCK.
    #[arg(long)]
    pub lock_memory: bool,
    /// Refuse to start when a real-time setting cannot be applied (default: warn and start).
    #[arg(long)]
    pub require_realtime: bool,
}

#[cfg(feature = "clap")]
impl RealtimeArgs {
    /// The settings these options ask for.
    pub fn settings(&self) -> RealtimeSettings {
        RealtimeSettings {
            cpu_affinity: self.cpu_affinity.clone(),
            inference_cpu_affinity: None,
            realtime_priority: self.realtime_priority,
            lock_memory: self.lock_memory,
            require_realtime: self.require_realtime,
        }
    }
}

/// `primm serve`'s real-time options: [`RealtimeArgs`] for the tracking thread plus the
/// inference threads' CPUs.
#[cfg(feature = "clap")]
#[derive(Debug, Clone, Default, clap::Args)]
pub struct TrackerRealtimeArgs {
    #[command(flatten)]
    pub thread: RealtimeArgs,
    /// Pin the inference threads (methods pr and pr-imm): the i-th thread to the i-th CPU of
    /// this list (e.g. 3,4), starting over when the list runs out.
    #[arg(long, value_name = "CPUS")]
    pub inference_cpu_affinity: Option<CpuList>,
}

#[cfg(feature = "clap")]
impl TrackerRealtimeArgs {
    /// The settings these options ask for.
    pub fn settings(&self) -> RealtimeSettings {
        RealtimeSettings {
            inference_cpu_affinity: self.inference_cpu_affinity.clone(),
            ..self.thread.settings()
        }
    }

    /// The same options as command-line arguments (for starting a `primm serve` with them).
    pub fn to_arguments(&self) -> Vec<String> {
        let mut arguments = Vec::new();
        if let Some(cpus) = &self.thread.cpu_affinity {
            arguments.extend(["--cpu-affinity".to_string(), cpus.to_string()]);
        }
        if let Some(cpus) = &self.inference_cpu_affinity {
            arguments.extend(["--inference-cpu-affinity".to_string(), cpus.to_string()]);
        }
        if let Some(priority) = self.thread.realtime_priority {
            arguments.extend(["--realtime-priority".to_string(), priority.to_string()]);
        }
        if self.thread.lock_memory {
            arguments.push("--lock-memory".to_string());
        }
        if self.thread.require_realtime {
            arguments.push("--require-realtime".to_string());
        }
        arguments
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_lists_read_single_cpus_lists_and_ranges() {
        assert_eq!("2".parse::<CpuList>().unwrap().cpus(), &[2]);
        assert_eq!("3,4".parse::<CpuList>().unwrap().cpus(), &[3, 4]);
        assert_eq!(" 0-2, 5 ,1".parse::<CpuList>().unwrap().cpus(), &[0, 1, 2, 5]);
        assert_eq!("0,2-3".parse::<CpuList>().unwrap().to_string(), "0,2,3");
        let list: CpuList = "3,4".parse().unwrap();
        assert_eq!([0, 1, 2].map(|i| list.for_thread(i)), [3, 4, 3]);
    }

    #[test]
    fn bad_cpu_lists_are_named() {
        assert_eq!("".parse::<CpuList>(), Err(CpuListError::Empty));
        assert_eq!(",".parse::<CpuList>(), Err(CpuListError::Empty));
        assert_eq!("a".parse::<CpuList>(), Err(CpuListError::Malformed { entry: "a".into() }));
        assert_eq!("1-".parse::<CpuList>(), Err(CpuListError::Malformed { entry: "1-".into() }));
        assert_eq!("-1".parse::<CpuList>(), Err(CpuListError::Malformed { entry: "-1".into() }));
        assert_eq!("3-1".parse::<CpuList>(), Err(CpuListError::Reversed { entry: "3-1".into() }));
        assert_eq!("5000".parse::<CpuList>(), Err(CpuListError::TooLarge { cpu: 5000 }));
    }

    /// Runs `body` on a thread of its own, so that its settings leave the test harness alone.
    fn on_own_thread<T: Send + 'static>(body: impl FnOnce() -> T + Send + 'static) -> T {
        std::thread::spawn(body).join().unwrap()
    }

    #[test]
    fn pinning_to_an_allowed_cpu_takes_effect_and_to_an_absent_cpu_fails_with_einval() {
        let allowed: CpuList = allowed_cpus().parse().unwrap();
        let cpu = *allowed.cpus().last().unwrap();
        let (applied, now) = on_own_thread(move || {
            let settings = RealtimeSettings { cpu_affinity: Some(CpuList(vec![cpu])), ..Default::default() };
            let mut report = RealtimeReport::default();
            settings.apply_to_current_thread("test thread", &mut report);
            assert!(report.failures().is_empty(), "{:?}", report.failures());
            // SAFETY: as in `allowed_cpus`, for the calling thread.
            let now: Vec<usize> = unsafe {
                let mut set: libc::cpu_set_t = std::mem::zeroed();
                assert_eq!(libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set), 0);
                (0..=MAX_CPU_INDEX).filter(|&c| libc::CPU_ISSET(c, &set)).collect()
            };
            (report.applied().to_vec(), now)
        });
        assert_eq!(now, vec![cpu]);
        assert!(applied[0].contains(&format!("CPU(s) {cpu}")), "{applied:?}");

        let absent = MAX_CPU_INDEX;
        let failures = on_own_thread(move || {
            let settings =
                RealtimeSettings { cpu_affinity: Some(CpuList(vec![absent])), ..Default::default() };
            let mut report = RealtimeReport::default();
            settings.apply_to_current_thread("test thread", &mut report);
            report.failures.into_iter().map(|f| f.to_string()).collect::<Vec<_>>()
        });
        assert_eq!(failures.len(), 1);
        assert!(
            failures[0].contains("Invalid argument") && failures[0].contains("may run on"),
            "{failures:?}"
        );
    }

    #[test]
    fn a_failure_refuses_the_start_only_when_required() {
        let failure = || RealtimeError::Priority {
            role: "tracking thread".into(),
            priority: 50,
            rtprio_limit: "0".into(),
            source: std::io::Error::from_raw_os_error(libc::EPERM),
        };
        let mut report = RealtimeReport::default();
        report.record(Err(failure()));
        assert!(report.finish(false).is_ok());
        let mut report = RealtimeReport::default();
        report.record(Ok("applied".into()));
        report.record(Err(failure()));
        let refused = report.finish(true).unwrap_err();
        let text = refused.to_string();
        assert!(text.contains("--require-realtime") && text.contains("CAP_SYS_NICE"), "{text}");
        assert!(text.contains("priority 50") && text.contains("now 0"), "{text}");
        assert!(RealtimeReport::default().finish(true).is_ok());
    }
}
