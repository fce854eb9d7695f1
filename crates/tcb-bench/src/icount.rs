//! Instruction counts: the regression gate that holds on noisy machines.
//!
//! `tcb-bench --icount` runs each scenario's runtime pass once under
//! valgrind's callgrind (`--toggle-collect` on [`pass`], so only sampling
//! counts, not building the scenario) and reads the instructions executed,
//! with callgrind's cache simulation for L1 and last-level miss estimates.
//! The same binary gives the same counts whatever else the machine does;
//! `--icount-check FILE` fails when a scenario executes more than
//! `--icount-max-growth` percent (default 2) more instructions than the
//! saved counts, or when a scenario's compiled clip holds more bytes
//! ([`tcb_runtime::Clip::memory_bytes`], deterministic too), and
//! `--icount-save FILE` writes them.

use crate::scenarios::Scenario;
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::Path;
use std::process::Command;
use tcb_runtime::Instance;

/// Counted passes that are not timing scenarios: `blend` (cross-fading
/// two poses of the CMU rig, the poses sampled before counting) and `batch`
/// (`crowd` through `tcb_runtime::batch::sample_all`, in a one-thread rayon
/// pool so that the count repeats).
pub const EXTRA: [&str; 2] = ["blend", "batch"];

/// The passes counted: every one of [`crate::scenarios::NAMES`] (the
/// reduced character's clip is reduced by the parent process and handed to
/// the counted one as a file: `tcb reduce` itself takes over 15 minutes
/// under valgrind) and [`EXTRA`].
pub fn names() -> Vec<&'static str> {
    crate::scenarios::NAMES.into_iter().chain(EXTRA).collect()
}

/// The function whose calls callgrind counts for pass `name`.
pub fn toggle(name: &str) -> &'static str {
    match name {
        "blend" => "tcb_bench::icount::blend_frames",
        "batch" => "tcb_bench::icount::batch_frames",
        _ => "tcb_bench::icount::pass",
    }
}

/// Blend `pairs` (cycled) into `out`, `frames` times: the `blend` pass.
#[inline(never)]
pub fn blend_frames(
    pairs: &[(tcb_runtime::Pose, tcb_runtime::Pose)],
    out: &mut tcb_runtime::Pose,
    frames: usize,
) {
    for f in 0..frames {
        let (a, b) = &pairs[f % pairs.len()];
        let w = (f % 17) as f32 / 16.0;
        tcb_runtime::blend(out, &[(a, 1.0 - w), (b, w)], None).expect("one rig");
        black_box(&*out);
    }
}

/// Every frame of `s` through `batch::sample_all`: the `batch` pass, run
/// on the pool's one worker thread.
#[inline(never)]
pub fn batch_frames(s: &Scenario, instances: &mut [Instance]) {
    let mut times = vec![0.0; instances.len()];
    for &t in &s.times {
        for (x, p) in times.iter_mut().zip(&s.phases) {
            *x = t + p;
        }
        tcb_runtime::batch::sample_all(instances, &times).expect("a time per instance");
        black_box(&instances[0]);
    }
}

/// Run the counted part of `blend` or `batch` once (under valgrind), and
/// print the bytes of the clips involved.
pub fn run_extra(name: &str, bvh: &Path) -> Result<(), Box<dyn std::error::Error>> {
    use std::sync::Arc;
    match name {
        "blend" => {
            let load = |mode| {
                let options = tcb_io::ImportOptions::default().rotation(mode);
                tcb_io::load_with(bvh, &options)
            };
            let a = load(tcb_core::RotationMode::Hermite)?;
            let b = load(tcb_core::RotationMode::Squad)?;
            let skeleton = a.skeleton.clone().ok_or("the BVH has no skeleton")?;
            let rig = Arc::new(tcb_runtime::Rig::from_skeleton(&skeleton)?);
            let (ca, cb) = (
                Arc::new(tcb_runtime::Clip::compile(&a.clip)),
                Arc::new(tcb_runtime::Clip::compile(&b.clip)),
            );
            println!("bytes: {}", ca.memory_bytes() + cb.memory_bytes());
            let mut ia = Instance::with_rig(ca, &rig)?;
            let mut ib = Instance::with_rig(cb, &rig)?;
            let pairs: Vec<_> = (0..16)
                .map(|i| {
                    let t = f64::from(i) * 1.3;
                    (ia.sample(t).clone(), ib.sample(t + 0.7).clone())
                })
                .collect();
            let mut out = rig.rest_pose();
            blend_frames(&pairs, &mut out, 1376);
        }
        _ => {
            let s = crate::scenarios::crowd(bvh)?;
            println!("bytes: {}", s.clip.memory_bytes());
            let mut instances = s.instances();
            let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
            pool.install(|| batch_frames(&s, &mut instances));
        }
    }
    Ok(())
}

/// One pass of a scenario's runtime (every time, every instance), the code
/// callgrind counts. Never inlined: its name is the toggle.
#[inline(never)]
pub fn pass(s: &Scenario, instances: &mut [Instance]) {
    for &t in &s.times {
        for (inst, &p) in instances.iter_mut().zip(&s.phases) {
            black_box(inst.sample(t + p));
        }
    }
}

/// Run [`pass`] once for `s` (what `--icount-pass NAME` does, under
/// valgrind), and print the compiled clip's bytes for [`count`] to read.
pub fn run_pass(s: &Scenario) {
    println!("bytes: {}", s.clip.memory_bytes());
    pass(s, &mut s.instances());
}

/// Counts of one scenario.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Counts {
    /// Instructions executed.
    pub instructions: u64,
    /// L1 misses, instruction and data (callgrind's estimate).
    pub l1_misses: u64,
    /// Last-level misses, instruction and data (callgrind's estimate).
    pub ll_misses: u64,
    /// The compiled clip's heap bytes.
    pub bytes: u64,
}

/// Count scenario `name` by running `exe --icount-pass NAME --bvh BVH`
/// under callgrind, or with `clip` the pass over that file
/// (`--icount-pass NAME --clip FILE`, as `--clip` times it); the AVX2
/// instance with `avx2` (`--icount-avx2`), else the baseline.
pub fn count(
    exe: &Path,
    name: &str,
    bvh: &Path,
    clip: Option<&Path>,
    avx2: bool,
) -> Result<Counts, String> {
    let toggle = format!("--toggle-collect={}", toggle(name));
    let out = std::env::temp_dir().join(format!(
        "tcb-icount-{}-{name}.callgrind",
        std::process::id()
    ));
    let status = Command::new("valgrind")
        .arg("--tool=callgrind")
        .arg("--cache-sim=yes")
        .arg(format!("--callgrind-out-file={}", out.display()))
        .arg(&toggle)
        .arg(exe)
        .args(["--icount-pass", name, "--bvh"])
        .arg(bvh)
        .args(avx2.then_some("--icount-avx2"))
        .args(
            clip.map(|c| [std::ffi::OsStr::new("--clip"), c.as_os_str()])
                .into_iter()
                .flatten(),
        )
        .output()
        .map_err(|e| {
            format!("cannot run valgrind ({e}); install it (apt-get install -y valgrind)")
        })?;
    if !status.status.success() {
        return Err(failure(name, &String::from_utf8_lossy(&status.stderr)));
    }
    let text = std::fs::read_to_string(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let _ = std::fs::remove_file(&out);
    let mut counts =
        parse(&text).ok_or_else(|| format!("no totals in callgrind's output for {name}"))?;
    counts.bytes = String::from_utf8_lossy(&status.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("bytes: "))
        .and_then(|b| b.trim().parse().ok())
        .ok_or_else(|| format!("the pass of {name} printed no bytes"))?;
    Ok(counts)
}

/// What to say when valgrind fails on scenario `name` with `stderr`: one
/// line where valgrind met an instruction it cannot decode (AVX-512, which
/// a `-C target-cpu=native` build uses on CPUs that have it), else all of
/// valgrind's output.
pub fn failure(name: &str, stderr: &str) -> String {
    if stderr.contains("unhandled instruction bytes") {
        let why = if cfg!(target_feature = "avx512f") {
            "; valgrind does not decode AVX-512"
        } else {
            ""
        };
        format!(
            "valgrind cannot run the pass of {name}: it stops at an instruction it does not \
             decode (this build: {}{why}). Count the default build, or one built with \
             RUSTFLAGS=\"-C target-cpu=x86-64-v3\" (AVX2 and FMA)",
            crate::report::flags()
        )
    } else {
        format!("valgrind on {name} failed: {stderr}")
    }
}

/// Totals from a callgrind output file (its `events:` and `summary:` lines).
pub fn parse(text: &str) -> Option<Counts> {
    let line = |key: &str| text.lines().find_map(|l| l.strip_prefix(key));
    let events: Vec<&str> = line("events:")?.split_whitespace().collect();
    let totals: Vec<u64> = line("summary:")?
        .split_whitespace()
        .map(|x| x.parse().ok())
        .collect::<Option<_>>()?;
    let get = |e: &str| {
        events
            .iter()
            .position(|x| *x == e)
            .and_then(|i| totals.get(i))
            .copied()
            .unwrap_or(0)
    };
    Some(Counts {
        instructions: get("Ir"),
        l1_misses: get("I1mr") + get("D1mr") + get("D1mw"),
        ll_misses: get("ILmr") + get("DLmr") + get("DLmw"),
        bytes: 0,
    })
}

/// Counts as the saved JSON.
pub fn to_json(counts: &BTreeMap<String, Counts>, note: &str) -> String {
    let scenarios: serde_json::Map<String, serde_json::Value> = counts
        .iter()
        .map(|(k, c)| {
            (
                k.clone(),
                serde_json::json!({
                    "instructions": c.instructions,
                    "l1_misses": c.l1_misses,
                    "ll_misses": c.ll_misses,
                    "bytes": c.bytes,
                }),
            )
        })
        .collect();
    let doc = serde_json::json!({ "note": note, "scenarios": scenarios });
    serde_json::to_string_pretty(&doc).expect("plain JSON") + "\n"
}

/// Compare with saved counts: a line per scenario, and whether every
/// scenario's instructions grew by at most `max_growth` percent and its
/// bytes not at all. A saved scenario that was not counted is a failure; a
/// new one is reported.
pub fn check(
    counts: &BTreeMap<String, Counts>,
    saved: &serde_json::Value,
    max_growth: f64,
) -> (Vec<String>, bool) {
    let mut lines = Vec::new();
    let mut ok = true;
    let saved = saved.get("scenarios").and_then(|s| s.as_object());
    for (name, c) in counts {
        let entry = saved.and_then(|s| s.get(name));
        let Some(before) = entry
            .and_then(|s| s.get("instructions"))
            .and_then(|x| x.as_u64())
        else {
            lines.push(format!("  new {name}: {} instructions", c.instructions));
            continue;
        };
        let growth = 100.0 * (c.instructions as f64 / before as f64 - 1.0);
        let fine = growth <= max_growth;
        ok &= fine;
        lines.push(format!(
            "  {} {name}: {before} -> {} instructions ({growth:+.2}%, allowed +{max_growth}%), L1 misses {}, LL misses {}",
            if fine { "ok" } else { "REGRESSION" },
            c.instructions,
            c.l1_misses,
            c.ll_misses
        ));
        if let Some(then) = entry.and_then(|s| s.get("bytes")).and_then(|x| x.as_u64()) {
            let fine = c.bytes <= then;
            ok &= fine;
            lines.push(format!(
                "  {} {name}: {then} -> {} bytes compiled",
                if fine { "ok" } else { "REGRESSION" },
                c.bytes
            ));
        }
    }
    if let Some(s) = saved {
        for name in s.keys().filter(|n| !counts.contains_key(*n)) {
            lines.push(format!("  MISSING {name}: saved but not counted"));
            ok = false;
        }
    }
    (lines, ok)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undecodable_instructions_are_explained_in_one_line() {
        let stderr = "==1== Callgrind\nvex amd64->IR: unhandled instruction bytes: 0x62 0xD1\n\
                      ==1== valgrind: Unrecognised instruction at address 0x33d790.\n";
        let m = failure("wide", stderr);
        assert!(
            m.contains("cannot run the pass of wide") && m.contains("x86-64-v3"),
            "{m}"
        );
        assert_eq!(m.lines().count(), 1);
        let other = failure("wide", "==1== some other failure\n");
        assert!(other.contains("some other failure"), "{other}");
    }

    #[test]
    fn parses_callgrind_totals() {
        let text = "version: 1\nevents: Ir Dr Dw I1mr D1mr D1mw ILmr DLmr DLmw\nsummary: 1000 10 20 1 2 3 0 1 1\n";
        let c = parse(text).unwrap();
        assert_eq!(
            c,
            Counts {
                instructions: 1000,
                l1_misses: 6,
                ll_misses: 2,
                bytes: 0,
            }
        );
    }

    #[test]
    fn five_percent_more_work_fails_two_percent_passes() {
        let c = |i| Counts {
            instructions: i,
            l1_misses: 0,
            ll_misses: 0,
            bytes: 1000,
        };
        let saved: serde_json::Value = serde_json::from_str(&to_json(
            &BTreeMap::from([("wide".to_string(), c(100_000))]),
            "",
        ))
        .unwrap();
        let now = |i| BTreeMap::from([("wide".to_string(), c(i))]);
        assert!(check(&now(100_000), &saved, 2.0).1);
        assert!(check(&now(101_900), &saved, 2.0).1);
        assert!(!check(&now(105_000), &saved, 2.0).1);
        // A scenario that disappeared fails too.
        assert!(!check(&BTreeMap::new(), &saved, 2.0).1);
        // So does one byte more.
        let mut bigger = now(100_000);
        bigger.get_mut("wide").unwrap().bytes = 1001;
        assert!(!check(&bigger, &saved, 2.0).1);
    }
}
