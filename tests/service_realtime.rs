//! `primm serve`'s real-time settings, on both paths the machine allows: where the process may
//! set them (root, or CAP_SYS_NICE and CAP_IPC_LOCK), the tracking thread really runs SCHED_FIFO
//! on its CPU, each inference thread on its own, and the memory is locked, as the kernel reports
//! in /proc; where it may not (the capabilities dropped and RLIMIT_RTPRIO and RLIMIT_MEMLOCK
//! lowered in the child before it starts), the service warns and serves, or with
//! `--require-realtime` refuses to start and names each setting, its OS error and the remedy.

use crate::common::service::{unique_prefix, wait_until, ChildGuard, Iceoryx2Domain, TestClient};
use primm_service::catalog::ServiceNames;
use std::io::Read;
use std::os::unix::process::CommandExt;
use std::process::{Command, Stdio};
use std::time::Duration;

const CAP_IPC_LOCK: u32 = 14;
const CAP_SYS_NICE: u32 = 23;

/// Whether this process holds capability `cap` in its effective set.
fn has_capability(cap: u32) -> bool {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status.lines().find(|line| line.starts_with("CapEff:")).unwrap();
    let mask = u64::from_str_radix(line["CapEff:".len()..].trim(), 16).unwrap();
    mask & (1 << cap) != 0
}

/// The CPUs this process may run on.
fn allowed_cpus() -> Vec<usize> {
    primm_service::realtime::allowed_cpus()
        .parse::<primm_service::realtime::CpuList>()
        .unwrap()
        .cpus()
        .to_vec()
}

/// The CPUs task `tid` may run on.
fn affinity_of(tid: i32) -> Vec<usize> {
    // SAFETY: cpu_set_t is plain data, valid as zero; the kernel writes at most its size.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        assert_eq!(libc::sched_getaffinity(tid, std::mem::size_of::<libc::cpu_set_t>(), &mut set), 0);
        (0..libc::CPU_SETSIZE as usize).filter(|&cpu| libc::CPU_ISSET(cpu, &set)).collect()
    }
}

/// The scheduling policy and priority of task `tid`.
fn policy_of(tid: i32) -> (i32, i32) {
    let mut param = libc::sched_param { sched_priority: 0 };
    // SAFETY: `param` is a valid sched_param to write into.
    unsafe {
        let policy = libc::sched_getscheduler(tid);
        assert_eq!(libc::sched_getparam(tid, &mut param), 0);
        (policy, param.sched_priority)
    }
}

/// The ids of the inference threads of process `pid` (the thread name is cut to 15 bytes).
fn inference_threads(pid: i32) -> Vec<i32> {
    let mut tids: Vec<i32> = std::fs::read_dir(format!("/proc/{pid}/task"))
        .unwrap()
        .filter_map(|entry| {
            let tid: i32 = entry.ok()?.file_name().to_str()?.parse().ok()?;
            let comm = std::fs::read_to_string(format!("/proc/{pid}/task/{tid}/comm")).ok()?;
            comm.starts_with("primm-pr-infer").then_some(tid)
        })
        .collect();
    tids.sort_unstable();
    tids
}

/// `primm serve` in `domain`; `restricted`: the child drops CAP_SYS_NICE and CAP_IPC_LOCK from
/// its bounding set (so they are gone after exec, even for root) and lowers RLIMIT_RTPRIO to 0
/// and RLIMIT_MEMLOCK to 64 KiB before it starts.
fn serve(domain: &Iceoryx2Domain, prefix: &str, extra: &[&str], restricted: bool) -> ChildGuard {
    let mut command = Command::new(env!("CARGO_BIN_EXE_primm"));
    command
        .args(["serve", "--service-prefix", prefix, "--latency-every", "0"])
        .args(extra)
        .env("PRIMM_ICEORYX2_DOMAIN", domain.name())
        .env("RUST_LOG", "info")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if restricted {
        // SAFETY: only async-signal-safe calls (prctl, setrlimit) between fork and exec.
        unsafe {
            command.pre_exec(|| {
                for cap in [CAP_SYS_NICE, CAP_IPC_LOCK] {
                    // Fails (EPERM) without CAP_SETPCAP; the process then lacks the
                    // capabilities already, which `can_restrict` checks.
                    libc::prctl(libc::PR_CAPBSET_DROP, cap as libc::c_ulong, 0, 0, 0);
                }
                let rtprio = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
                let memlock = libc::rlimit { rlim_cur: 64 * 1024, rlim_max: 64 * 1024 };
                if libc::setrlimit(libc::RLIMIT_RTPRIO, &rtprio) != 0
                    || libc::setrlimit(libc::RLIMIT_MEMLOCK, &memlock) != 0
                {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    }
    ChildGuard(command.spawn().expect("primm serve starts"))
}

/// Whether a restricted child really loses the settings: it either can drop the capabilities
/// (CAP_SETPCAP) or never had them.
fn can_restrict() -> bool {
    has_capability(8) || !(has_capability(CAP_SYS_NICE) || has_capability(CAP_IPC_LOCK))
}

/// Stops the service with SIGTERM and returns its stderr.
fn stop(mut child: ChildGuard) -> String {
    child.signal(libc::SIGTERM);
    let mut stderr = child.0.stderr.take().unwrap();
    let (status, _) = child.wait(Duration::from_secs(30));
    let mut text = String::new();
    stderr.read_to_string(&mut text).unwrap();
    assert!(status.success(), "{status:?}\n{text}");
    text
}

#[test]
fn where_permitted_the_tracking_and_inference_threads_run_pinned_under_sched_fifo_with_memory_locked() {
    if !(has_capability(CAP_SYS_NICE) && has_capability(CAP_IPC_LOCK)) {
        println!(
            "skipped: this process may not set SCHED_FIFO or lock memory (no CAP_SYS_NICE / CAP_IPC_LOCK)"
        );
        return;
    }
    let cpus = allowed_cpus();
    let tracking_cpu = *cpus.last().unwrap();
    let inference_cpus = [cpus[0], *cpus.last().unwrap()];
    let prefix = unique_prefix("realtime-permitted");
    let domain = Iceoryx2Domain::new("realtime_permitted");
    let client = TestClient::in_domain(&ServiceNames::new(&prefix), domain.name());
    let tracking = tracking_cpu.to_string();
    let inference = format!("{},{}", inference_cpus[0], inference_cpus[1]);
    let child = serve(
        &domain,
        &prefix,
        &[
            "--method",
            "pr-imm",
            "--inference-threads",
            "2",
            "--cpu-affinity",
            &tracking,
            "--inference-cpu-affinity",
            &inference,
            "--realtime-priority",
            "7",
            "--lock-memory",
            "--require-realtime",
        ],
        false,
    );
    client.wait_for_tracker(Duration::from_secs(60));
    let pid = child.pid();
    // The tracking loop runs on the main thread, whose task id is the process id; its settings
    // follow right after the services open, so wait for them.
    wait_until("the tracking thread under SCHED_FIFO", Duration::from_secs(20), || {
        policy_of(pid).0 == libc::SCHED_FIFO
    });
    assert_eq!(affinity_of(pid), vec![tracking_cpu]);
    assert_eq!(policy_of(pid), (libc::SCHED_FIFO, 7));
    let threads = inference_threads(pid);
    assert_eq!(threads.len(), 2, "inference threads {threads:?}");
    for (index, &tid) in threads.iter().enumerate() {
        assert_eq!(affinity_of(tid), vec![inference_cpus[index]], "inference thread {index}");
        assert_eq!(policy_of(tid), (libc::SCHED_FIFO, 7), "inference thread {index}");
    }
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let locked_kib: u64 = status
        .lines()
        .find_map(|line| line.strip_prefix("VmLck:"))
        .map(|rest| rest.trim().trim_end_matches("kB").trim().parse().unwrap())
        .unwrap();
    assert!(locked_kib > 1024, "only {locked_kib} KiB locked");
    let stderr = stop(child);
    assert!(stderr.contains("tracking thread runs SCHED_FIFO at priority 7"), "{stderr}");
    assert!(stderr.contains("process memory locked"), "{stderr}");
    assert!(!stderr.contains("WARN"), "{stderr}");
}

#[test]
fn where_not_permitted_the_service_warns_and_serves_without_the_settings() {
    if !can_restrict() {
        println!("skipped: cannot take CAP_SYS_NICE / CAP_IPC_LOCK from a child");
        return;
    }
    let prefix = unique_prefix("realtime-warned");
    let domain = Iceoryx2Domain::new("realtime_warned");
    let client = TestClient::in_domain(&ServiceNames::new(&prefix), domain.name());
    let child = serve(&domain, &prefix, &["--realtime-priority", "7", "--lock-memory"], true);
    client.wait_for_tracker(Duration::from_secs(60));
    assert_eq!(policy_of(child.pid()).0, libc::SCHED_OTHER);
    let stderr = stop(child);
    assert!(stderr.contains("WARN"), "{stderr}");
    assert!(
        stderr.contains("SCHED_FIFO priority 7") && stderr.contains("Operation not permitted"),
        "{stderr}"
    );
    assert!(stderr.contains("RLIMIT_RTPRIO of at least 7 (now 0)"), "{stderr}");
    assert!(stderr.contains("mlockall") && stderr.contains("limit now 65536 bytes"), "{stderr}");
    assert!(stderr.contains("starting without it"), "{stderr}");
}

#[test]
fn where_not_permitted_require_realtime_refuses_to_start_and_names_each_setting() {
    if !can_restrict() {
        println!("skipped: cannot take CAP_SYS_NICE / CAP_IPC_LOCK from a child");
        return;
    }
    let prefix = unique_prefix("realtime-refused");
    let domain = Iceoryx2Domain::new("realtime_refused");
    let mut child = serve(
        &domain,
        &prefix,
        &["--realtime-priority", "7", "--lock-memory", "--cpu-affinity", "1023", "--require-realtime"],
        true,
    );
    let mut stderr = String::new();
    child.0.stderr.take().unwrap().read_to_string(&mut stderr).unwrap();
    let (status, _) = child.wait(Duration::from_secs(30));
    assert!(!status.success(), "started although required settings failed\n{stderr}");
    assert!(stderr.contains("real-time settings required (--require-realtime) but not applied"), "{stderr}");
    assert!(stderr.contains("cannot pin the tracking thread to CPU(s) 1023"), "{stderr}");
    assert!(stderr.contains("cannot give the tracking thread SCHED_FIFO priority 7"), "{stderr}");
    assert!(stderr.contains("cannot lock the process's memory (mlockall)"), "{stderr}");
    assert!(stderr.contains("CAP_SYS_NICE") && stderr.contains("CAP_IPC_LOCK"), "{stderr}");
}

#[test]
fn a_bad_cpu_list_or_priority_is_refused_by_the_command_line() {
    for (option, value, expected) in [
        ("--cpu-affinity", "2-a", "'2-a' is not a CPU index"),
        ("--inference-cpu-affinity", "4-1", "reversed"),
        ("--realtime-priority", "0", "0 is not in 1..=99"),
        ("--realtime-priority", "100", "100 is not in 1..=99"),
    ] {
        let output =
            Command::new(env!("CARGO_BIN_EXE_primm")).args(["serve", option, value]).output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success());
        assert!(stderr.contains(expected), "{option} {value}: {stderr}");
    }
}
