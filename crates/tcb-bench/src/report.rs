//! The comparison report: measurement, table, JSON, targets and the
//! regression check.

use crate::measure::{Subject, median_seconds};
use crate::scenarios::Scenario;
use serde_json::{Map, Value, json};
use std::fmt::Write as _;
use std::time::Duration;

/// The compile flags in effect: RUSTFLAGS as cargo passed them, the
/// profile, and the SIMD target features the code was compiled for (what
/// `wide` chooses its instructions by).
pub fn flags() -> String {
    let mut features = Vec::new();
    for (on, name) in [
        (cfg!(target_feature = "sse2"), "sse2"),
        (cfg!(target_feature = "sse4.1"), "sse4.1"),
        (cfg!(target_feature = "avx"), "avx"),
        (cfg!(target_feature = "avx2"), "avx2"),
        (cfg!(target_feature = "fma"), "fma"),
        (cfg!(target_feature = "avx512f"), "avx512f"),
        (cfg!(target_feature = "neon"), "neon"),
    ] {
        if on {
            features.push(name);
        }
    }
    let rustflags = env!("TCB_BENCH_RUSTFLAGS");
    format!(
        "RUSTFLAGS=\"{rustflags}\" profile={} target-features={}",
        env!("TCB_BENCH_PROFILE"),
        features.join(",")
    )
}

/// The CPU model and the number of threads rayon uses.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    format!("{cpu}, {} threads", rayon::current_num_threads())
}

/// One scenario's numbers.
#[derive(Clone, Debug, Default)]
pub struct Row {
    /// Scenario name.
    pub name: String,
    /// Values per sample.
    pub channels: usize,
    /// ns per channel-sample: baseline, runtime, runtime_parallel, splines.
    pub ns: Vec<(&'static str, f64)>,
    /// Runtime vs baseline, per channel (both one thread).
    pub speedup_vs_baseline: f64,
    /// Runtime vs splines.
    pub speedup_vs_splines: Option<f64>,
    /// Read limit time / runtime time.
    pub read_limit_fraction: Option<f64>,
    /// Runtime ns per joint per frame.
    pub ns_per_joint: Option<f64>,
    /// Runtime one thread / runtime with rayon.
    pub parallel_speedup: Option<f64>,
    /// Largest difference between splines and the reference before timing.
    pub splines_agreement: Option<f64>,
    /// The compiled clip's memory ([`tcb_runtime::Clip::memory_bytes`]).
    pub bytes: usize,
    /// `character-reduced`: the dense `character-hermite` runtime time over
    /// this one (both measured in this run, so it holds across machines).
    pub speedup_vs_dense: Option<f64>,
}

impl Row {
    /// ns per channel-sample of one column.
    pub fn ns_of(&self, name: &str) -> Option<f64> {
        self.ns.iter().find(|(n, _)| *n == name).map(|p| p.1)
    }
}

/// Time every implementation of `s`.
pub fn measure(s: &Scenario, rounds: usize, slice: Duration) -> Row {
    let mut row = Row {
        name: s.name.to_string(),
        channels: s.channels(),
        bytes: s.clip.memory_bytes(),
        ..Row::default()
    };
    if let Some(peer) = &s.peer {
        let worst = peer.agreement(&s.source, 500);
        row.splines_agreement = Some(worst);
        assert!(
            worst < 1e-4,
            "{}: the splines crate and tcb disagree by {worst} on even keys with tcb 0; not timing it",
            s.name
        );
    }
    let mut subjects = vec![
        Subject {
            name: "baseline",
            run: Box::new(s.baseline_pass()),
        },
        Subject {
            name: "runtime",
            run: Box::new(s.runtime_pass()),
        },
    ];
    if s.parallel {
        subjects.push(Subject {
            name: "runtime_parallel",
            run: Box::new(s.parallel_pass()),
        });
    }
    if let Some(pass) = s.peer_pass() {
        subjects.push(Subject {
            name: "splines",
            run: Box::new(pass),
        });
    }
    if s.read_limit {
        subjects.push(Subject {
            name: "read_limit",
            run: Box::new(s.read_pass()),
        });
    }
    let secs = median_seconds(&mut subjects, rounds, slice);
    let per = s.channel_samples();
    for (sub, t) in subjects.iter().zip(&secs) {
        row.ns.push((sub.name, t * 1e9 / per));
    }
    let rt = row.ns_of("runtime").expect("always timed");
    row.speedup_vs_baseline = row.ns_of("baseline").expect("always timed") / rt;
    row.speedup_vs_splines = row.ns_of("splines").map(|x| x / rt);
    row.read_limit_fraction = row.ns_of("read_limit").map(|x| x / rt);
    row.parallel_speedup = row.ns_of("runtime_parallel").map(|x| rt / x);
    row.ns_per_joint = s.joints.map(|j| rt * s.channels() as f64 / j as f64);
    row.ns.retain(|(n, _)| *n != "read_limit");
    row
}

/// Ratios between rows: `character-reduced` against `character-hermite`.
pub fn relate(rows: &mut [Row]) {
    let dense = rows
        .iter()
        .find(|r| r.name == "character-hermite")
        .and_then(|r| r.ns_of("runtime"));
    for r in rows.iter_mut().filter(|r| r.name == "character-reduced") {
        r.speedup_vs_dense = dense.zip(r.ns_of("runtime")).map(|(d, x)| d / x);
    }
}

/// The JSON document.
pub fn to_json(rows: &[Row], flags: &str, machine: &str) -> Value {
    let scenarios: Vec<Value> = rows
        .iter()
        .map(|r| {
            let mut m = Map::new();
            m.insert("name".into(), json!(r.name));
            m.insert("channels".into(), json!(r.channels));
            let ns: Map<String, Value> =
                r.ns.iter()
                    .map(|(n, v)| (n.to_string(), json!(v)))
                    .collect();
            m.insert("ns_per_channel".into(), Value::Object(ns));
            m.insert("speedup_vs_baseline".into(), json!(r.speedup_vs_baseline));
            m.insert("bytes".into(), json!(r.bytes));
            let optional = [
                ("speedup_vs_splines", r.speedup_vs_splines),
                ("read_limit_fraction", r.read_limit_fraction),
                ("ns_per_joint", r.ns_per_joint),
                ("parallel_speedup", r.parallel_speedup),
                ("splines_agreement", r.splines_agreement),
                ("speedup_vs_dense", r.speedup_vs_dense),
            ];
            for (k, v) in optional {
                if let Some(v) = v {
                    m.insert(k.into(), json!(v));
                }
            }
            Value::Object(m)
        })
        .collect();
    json!({"flags": flags, "machine": machine, "scenarios": scenarios})
}

fn fmt(v: Option<f64>, unit: &str) -> String {
    match v {
        Some(v) if v >= 100.0 => format!("{v:.0}{unit}"),
        Some(v) if v >= 10.0 => format!("{v:.1}{unit}"),
        Some(v) => format!("{v:.3}{unit}"),
        None => "-".into(),
    }
}

/// The table.
pub fn table(rows: &[Row], flags: &str, machine: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "tcb-bench: ns per channel-sample (median), ratios measured in this run"
    );
    let _ = writeln!(out, "flags:   {flags}");
    let _ = writeln!(out, "machine: {machine}\n");
    let _ = writeln!(
        out,
        "{:<18} {:>8} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>10} {:>10} {:>9}",
        "scenario",
        "channels",
        "baseline",
        "runtime",
        "rt+rayon",
        "splines",
        "x base",
        "x splines",
        "read lim",
        "ns/joint",
        "MB"
    );
    for r in rows {
        let _ = writeln!(
            out,
            "{:<18} {:>8} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>10} {:>10} {:>9.3}",
            r.name,
            r.channels,
            fmt(r.ns_of("baseline"), ""),
            fmt(r.ns_of("runtime"), ""),
            fmt(r.ns_of("runtime_parallel"), ""),
            fmt(r.ns_of("splines"), ""),
            fmt(Some(r.speedup_vs_baseline), "x"),
            fmt(r.speedup_vs_splines, "x"),
            fmt(r.read_limit_fraction.map(|f| f * 100.0), "%"),
            fmt(r.ns_per_joint, ""),
            r.bytes as f64 / 1e6,
        );
    }
    out
}

/// The targets, each with what was measured.
pub fn targets(rows: &[Row]) -> Vec<(String, bool)> {
    let get = |n: &str| rows.iter().find(|r| r.name == n);
    let mut out = Vec::new();
    let native = cfg!(target_feature = "avx2");
    if let Some(w) = get("wide") {
        let need = if native { 8.0 } else { 4.0 };
        out.push((
            format!(
                "wide: runtime {:.2}x the baseline (target {need}x for this build)",
                w.speedup_vs_baseline
            ),
            w.speedup_vs_baseline >= need,
        ));
        if let Some(f) = w.read_limit_fraction {
            out.push((
                format!("wide: {:.1}% of the read limit (target 60%)", f * 100.0),
                f >= 0.6,
            ));
        }
    }
    for (n, limit) in [("character-hermite", 2.5), ("character-squad", 3.0)] {
        if let Some(j) = get(n).and_then(|r| r.ns_per_joint) {
            out.push((
                format!("{n}: {j:.2} ns per joint per frame (target < {limit})"),
                j < limit,
            ));
        }
    }
    if let (Some(r), Some(c)) = (get("character-reduced"), get("character-hermite"))
        && let Some(j) = r.ns_per_joint
    {
        out.push((
            format!(
                "character-reduced: {j:.2} ns per joint per frame (target <= 1.5), {:.3} MB against {:.3} MB dense ({:.2}x smaller)",
                r.bytes as f64 / 1e6,
                c.bytes as f64 / 1e6,
                c.bytes as f64 / r.bytes as f64
            ),
            j <= 1.5,
        ));
    }
    if let (Some(s), Some(c)) = (get("seek"), get("character-hermite")) {
        let (a, b) = (
            s.ns_of("runtime").unwrap_or(f64::NAN),
            c.ns_of("runtime").unwrap_or(f64::NAN),
        );
        out.push((
            format!(
                "seek: {:.2}x the cost of forward playback (target <= 1.2x)",
                a / b
            ),
            a / b <= 1.2,
        ));
    }
    if let Some(p) = get("crowd").and_then(|r| r.parallel_speedup) {
        out.push((
            format!("crowd: rayon {p:.2}x one thread (target >= 1.8x on 2 cores)"),
            p >= 1.8,
        ));
    }
    for name in ["sparse", "sparse-rotations"] {
        if let (Some(s), Some(w)) = (get(name), get("wide")) {
            let (a, b) = (
                s.ns_of("runtime").unwrap_or(f64::NAN),
                w.ns_of("runtime").unwrap_or(f64::NAN),
            );
            out.push((
                format!(
                    "{name}: {:.1}x the per-channel cost of wide (target <= 1.5x)",
                    a / b
                ),
                a / b <= 1.5,
            ));
        }
    }
    for r in rows {
        if let Some(x) = r.speedup_vs_splines {
            out.push((
                format!("{}: {x:.1}x the splines crate (target >= 20x)", r.name),
                x >= 20.0,
            ));
        }
    }
    out
}

/// Compare this run's ratios with a saved report: each scenario's
/// `speedup_vs_baseline` and `read_limit_fraction` may fall by at most
/// `max_regression` percent. (`parallel_speedup` depends on the core count,
/// so it is reported but not checked.) Returns the lines to print
/// and whether everything held.
pub fn check(rows: &[Row], saved: &Value, max_regression: f64) -> (Vec<String>, bool) {
    let mut lines = Vec::new();
    let mut ok = true;
    let Some(scenarios) = saved.get("scenarios").and_then(Value::as_array) else {
        return (
            vec!["the baseline file has no \"scenarios\" array".into()],
            false,
        );
    };
    for s in scenarios {
        let Some(name) = s.get("name").and_then(Value::as_str) else {
            continue;
        };
        let Some(row) = rows.iter().find(|r| r.name == name) else {
            lines.push(format!("{name}: in the baseline file but not measured"));
            ok = false;
            continue;
        };
        for (key, now) in [
            ("speedup_vs_baseline", Some(row.speedup_vs_baseline)),
            ("read_limit_fraction", row.read_limit_fraction),
            ("speedup_vs_dense", row.speedup_vs_dense),
        ] {
            let (Some(then), Some(now)) = (s.get(key).and_then(Value::as_f64), now) else {
                continue;
            };
            let change = (now / then - 1.0) * 100.0;
            let bad = change < -max_regression;
            ok &= !bad;
            lines.push(format!(
                "{} {name} {key}: {then:.3} -> {now:.3} ({change:+.1}%, allowed -{max_regression}%)",
                if bad { "REGRESSION" } else { "ok" }
            ));
        }
        // Memory is deterministic: any growth is a change to look at.
        if let Some(then) = s.get("bytes").and_then(Value::as_u64) {
            let now = row.bytes as u64;
            let bad = now > then;
            ok &= !bad;
            lines.push(format!(
                "{} {name} bytes: {then} -> {now}",
                if bad { "REGRESSION" } else { "ok" }
            ));
        }
    }
    (lines, ok)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(name: &str, speedup: f64) -> Row {
        Row {
            name: name.into(),
            speedup_vs_baseline: speedup,
            ..Row::default()
        }
    }

    #[test]
    fn check_flags_a_fall_beyond_the_allowance_only() {
        let saved = to_json(&[row("wide", 100.0), row("sparse", 4.0)], "", "");
        let (_, ok) = check(&[row("wide", 91.0), row("sparse", 4.5)], &saved, 10.0);
        assert!(ok);
        let (lines, ok) = check(&[row("wide", 89.0), row("sparse", 4.5)], &saved, 10.0);
        assert!(!ok);
        assert!(
            lines[0].starts_with("REGRESSION wide speedup_vs_baseline"),
            "{lines:?}"
        );
        // A scenario that disappeared is a failure too.
        let (_, ok) = check(&[row("wide", 100.0)], &saved, 10.0);
        assert!(!ok);
        let (_, ok) = check(&[], &serde_json::json!({}), 10.0);
        assert!(!ok);
    }
}
