//! `cargo run --release -p tcb-bench [-- --quick]`: the comparison report
//! on the bundled real data. `--json PATH` or `--save-baseline NAME` saves
//! it with the machine's fingerprint; `--check PATH` or `--baseline NAME`
//! compares with a saved one and exits 1 when bytes grew, or (same machine
//! and build only) the runtime got slower beyond the noise its rounds
//! measured and by more than `--max-regression` percent, in its own time
//! and against the scalar baseline's in the same rounds (`report::check`).
//! `--markdown FILE` writes this machine's table into a markdown document
//! (`docs/benchmarks.md`; [`tcb_bench::markdown`]).
//! `--icount` counts instructions under callgrind instead: the CI gate.

#![forbid(unsafe_code)]

use clap::Parser;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;
use tcb_bench::{icount, markdown, report, scenarios};

#[derive(Parser)]
#[command(
    name = "tcb-bench",
    about = "Runtime vs scalar baseline vs the splines crate, on real data"
)]
struct Args {
    /// A first look in under 10 s: 5 rounds of 8 ms, the slow baseline and
    /// splines crate timed on a subset of the frames. Without it, the full
    /// run: 11 rounds of 20 ms over every frame (about a minute).
    #[arg(long)]
    quick: bool,
    /// Write the report as JSON here too (with the machine fingerprint).
    #[arg(long, value_name = "PATH")]
    json: Option<PathBuf>,
    /// Put this machine's and build's table (dated, with the command) into
    /// this markdown file, between its "tcb-bench --markdown" comment
    /// lines, replacing the table of the same machine and build and
    /// keeping the others and the rest of the file (created if missing).
    #[arg(long, value_name = "FILE.md", conflicts_with = "icount")]
    markdown: Option<PathBuf>,
    /// Save the report as a named baseline of this machine
    /// (target/tcb-bench/NAME.json), to compare later runs with.
    #[arg(long, value_name = "NAME")]
    save_baseline: Option<String>,
    /// Compare with a named baseline saved by --save-baseline.
    #[arg(long, value_name = "NAME", conflicts_with = "check")]
    baseline: Option<String>,
    /// Compare with a saved JSON report (--json); exit 1 on a regression.
    #[arg(long, value_name = "BASELINE.json")]
    check: Option<PathBuf>,
    /// Against a same-machine baseline: the smallest slowdown of the
    /// runtime reported as a regression, percent (it must also exceed 3
    /// MADs of the rounds, in its own time and over the scalar baseline's).
    #[arg(long, value_name = "PCT", default_value_t = 10.0)]
    max_regression: f64,
    /// The motion-capture file for character, crowd and seek.
    #[arg(long, value_name = "FILE.bvh", default_value_os_t = scenarios::default_bvh())]
    bvh: PathBuf,
    /// Only these scenarios (comma separated).
    #[arg(long, value_name = "NAMES")]
    only: Option<String>,
    /// Timing rounds per implementation, the median is reported (default
    /// 11, or 5 with --quick).
    #[arg(long)]
    rounds: Option<usize>,
    /// Milliseconds per timing (default 20, or 8 with --quick).
    #[arg(long, value_name = "MS")]
    slice_ms: Option<u64>,
    /// Time these clips (JSON, BVH, glTF) instead of the scenarios: 60 fps
    /// forward over each clip, as `character`. With --icount, count them
    /// (named by file stem), to gate your own clips.
    #[arg(long, value_name = "FILE")]
    clip: Vec<PathBuf>,
    /// Count instructions instead of timing: each scenario's runtime pass
    /// once under valgrind's callgrind (repeatable on the same binary).
    #[arg(long)]
    icount: bool,
    /// With --icount: compare with saved counts; exit 1 when a scenario
    /// executes more than --icount-max-growth percent more instructions.
    #[arg(long, value_name = "ICOUNT.json", requires = "icount")]
    icount_check: Option<PathBuf>,
    /// With --icount: write the counts here (the baseline to commit).
    #[arg(long, value_name = "ICOUNT.json", requires = "icount")]
    icount_save: Option<PathBuf>,
    /// Largest allowed growth of a scenario's instruction count, percent.
    #[arg(long, value_name = "PCT", default_value_t = 2.0)]
    icount_max_growth: f64,
    /// Time the runtime's default-build kernels even where the CPU has
    /// AVX2 (`tcb_runtime::force_baseline_simd`), to compare with a run
    /// without it; the instruction counts (--icount) always do
    #[arg(long, conflicts_with = "icount")]
    baseline_simd: bool,
    /// Time the decoder's AVX2 instance even where the CPU has AVX-512
    /// (`tcb_runtime::force_no_avx512`), to compare with a run without it
    #[arg(long, conflicts_with = "icount")]
    no_avx512: bool,
    /// Run one scenario's pass and exit (what --icount runs under valgrind).
    #[arg(long, value_name = "NAME", hide = true)]
    icount_pass: Option<String>,
    /// With --icount: count the AVX2 instance of the kernels and the
    /// decoder (`tcb_runtime::simd`) instead of the baseline the gate's
    /// counts use everywhere; on a CPU without AVX2, say so and count
    /// nothing (exit 0). Its counts go in a file of their own
    /// (benches/icount-avx2.json)
    #[arg(long)]
    icount_avx2: bool,
}

fn main() -> ExitCode {
    let args = Args::parse();
    match run(&args) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("tcb-bench: error: {e}");
            ExitCode::from(2)
        }
    }
}

/// A saved JSON report or count file, if one is given.
fn read_json(path: Option<&std::path::Path>) -> Result<Option<serde_json::Value>, String> {
    let Some(p) = path else { return Ok(None) };
    let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|e| format!("{}: {e}", p.display()))
}

/// Where `--save-baseline NAME` keeps its reports: `TCB_BENCH_BASELINES`,
/// or `tcb-bench/` in cargo's target directory (beside `release/`, where
/// criterion keeps its own), so `cargo clean` removes them.
fn baseline_path(name: &str) -> Result<PathBuf, String> {
    if name.is_empty()
        || name.starts_with('.')
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
    {
        return Err(format!(
            "baseline name '{name}': use letters, digits, '-', '_' and '.' (not first)"
        ));
    }
    let dir = match std::env::var_os("TCB_BENCH_BASELINES") {
        Some(d) => PathBuf::from(d),
        None => {
            let exe = std::env::current_exe().map_err(|e| format!("baseline directory: {e}"))?;
            exe.parent()
                .and_then(|p| p.parent())
                .ok_or("baseline directory: the executable has no target directory")?
                .join("tcb-bench")
        }
    };
    Ok(dir.join(format!("{name}.json")))
}

/// `--icount`: count each scenario under callgrind, then check or save.
fn run_icount(args: &Args) -> Result<bool, Box<dyn std::error::Error>> {
    if args.icount_max_growth.is_nan() || args.icount_max_growth < 0.0 {
        return Err("--icount-max-growth must be a number >= 0".into());
    }
    if args.icount_avx2 && tcb_runtime::simd() == tcb_runtime::Simd::Baseline {
        println!(
            "tcb-bench --icount --icount-avx2: skipped, this CPU (or build) runs no AVX2 instance"
        );
        return Ok(true);
    }
    let saved = read_json(args.icount_check.as_deref())?;
    let scratch = std::env::temp_dir().join(format!("tcb-icount-{}", std::process::id()));
    let jobs = icount_jobs(args, &scratch)?;
    let exe = std::env::current_exe()?;
    let mut counts = std::collections::BTreeMap::new();
    println!("tcb-bench --icount: instructions of one runtime pass under callgrind");
    println!("flags: {}", report::flags());
    for (name, clip) in &jobs {
        let name = name.as_str();
        let c = icount::count(&exe, name, &args.bvh, clip.as_deref(), args.icount_avx2)?;
        println!(
            "  {name:<18} {:>12} instructions  {:>9} L1 misses  {:>7} LL misses  {:>9} bytes",
            c.instructions, c.l1_misses, c.ll_misses, c.bytes
        );
        counts.insert(name.to_string(), c);
    }
    let _ = std::fs::remove_dir_all(&scratch);
    if let Some(path) = &args.icount_save {
        let note = format!(
            "tcb-bench --icount ({}, {}{}); regenerate with: cargo run --release -p tcb-bench -- --icount{} --icount-save {}",
            report::flags(),
            env!("TCB_BENCH_RUSTC"),
            if args.icount_avx2 {
                ", the AVX2 instance"
            } else {
                ""
            },
            match (&args.only, args.icount_avx2) {
                (Some(only), true) => format!(" --icount-avx2 --only {only}"),
                (Some(only), false) => format!(" --only {only}"),
                (None, true) => " --icount-avx2".into(),
                (None, false) => String::new(),
            },
            path.display()
        );
        tcb_io::write_atomically(path, icount::to_json(&counts, &note).as_bytes())?;
    }
    let mut ok = true;
    if let Some(saved) = &saved {
        // With --only, scenarios left out are not missing.
        let mut saved = saved.clone();
        if args.only.is_some()
            && let Some(s) = saved.get_mut("scenarios").and_then(|s| s.as_object_mut())
        {
            s.retain(|k, _| counts.contains_key(k));
        }
        let (lines, held) = icount::check(&counts, &saved, args.icount_max_growth);
        println!(
            "
instruction counts against the saved ones:"
        );
        for l in lines {
            println!("{l}");
        }
        ok = held;
    }
    Ok(ok)
}

/// A scenario `--icount` counts, by name, and the clip file its pass
/// loads (none for the bundled scenarios built from the BVH).
type Job = (String, Option<PathBuf>);

/// What `--icount` counts: the bundled scenarios (`--only` of them), or
/// with `--clip` the user's files, each named by its file stem as the
/// report names it, with the clip file the counted process loads (the
/// reduced and compressed scenarios are made here, into `scratch`).
fn icount_jobs(
    args: &Args,
    scratch: &std::path::Path,
) -> Result<Vec<Job>, Box<dyn std::error::Error>> {
    if !args.clip.is_empty() {
        return Ok(args
            .clip
            .iter()
            .map(|p| Ok((scenarios::file(p)?.name, Some(p.clone()))))
            .collect::<Result<_, tcb_io::Error>>()?);
    }
    let names: Vec<&str> = match &args.only {
        Some(o) => o.split(',').map(str::trim).collect(),
        None => icount::names(),
    };
    if let Some(bad) = names.iter().find(|n| !icount::names().contains(n)) {
        return Err(format!(
            "--only {bad}: not counted (one of {})",
            icount::names().join(", ")
        )
        .into());
    }
    let mut jobs = Vec::new();
    for n in names {
        let clip = if n == "character-reduced" {
            // Reduced here, natively; counted from the written clip.
            let doc = scenarios::reduced_doc(&args.bvh)?;
            std::fs::create_dir_all(scratch)?;
            let path = scratch.join("character-reduced.json");
            tcb_io::write_clip_doc(&doc, &path)?;
            Some(path)
        } else if n.starts_with("character-compressed") {
            // Compressed here too (a search of clips measured); counted
            // from the written .tcbc, which the counted process loads.
            let packed = scenarios::compress_cmu(&args.bvh, n.ends_with("acl"))?;
            std::fs::create_dir_all(scratch)?;
            let path = scratch.join(format!("{n}.tcbc"));
            tcb_io::write_atomically(&path, &packed.to_bytes())?;
            Some(path)
        } else {
            None
        };
        jobs.push((n.to_string(), clip));
    }
    Ok(jobs)
}

/// `--icount-pass NAME` (hidden): the one runtime pass that `--icount`
/// counts, run inside callgrind.
fn run_pass(args: &Args, name: &str) -> Result<bool, Box<dyn std::error::Error>> {
    // The same instructions on every CPU: the gate's counts do not depend
    // on whether the runner has AVX2 (`tcb_runtime::simd`).
    tcb_runtime::force_baseline_simd(!args.icount_avx2);
    // The AVX2 gate counts the AVX2 instance, which valgrind decodes
    // (it does not decode AVX-512, and hides it from detection too).
    tcb_runtime::force_no_avx512(true);
    if icount::EXTRA.contains(&name) {
        icount::run_extra(name, &args.bvh)?;
        return Ok(true);
    }
    let s = match args.clip.first() {
        Some(p) => vec![scenarios::file(p)?],
        None => scenarios::named(&args.bvh, |n| n == name)?,
    };
    let s = s.first().ok_or_else(|| format!("no scenario {name}"))?;
    icount::run_pass(s);
    Ok(true)
}

fn run(args: &Args) -> Result<bool, Box<dyn std::error::Error>> {
    if let Some(name) = &args.icount_pass {
        return run_pass(args, name);
    }
    if args.icount {
        return run_icount(args);
    }
    tcb_runtime::force_baseline_simd(args.baseline_simd);
    tcb_runtime::force_no_avx512(args.no_avx512);
    let timing = timing(args)?;
    // Find and read the saved report first: a bad name or file should fail
    // before a minute of timing.
    let save = args
        .save_baseline
        .as_deref()
        .map(baseline_path)
        .transpose()?;
    let compare = compared_report(args)?;
    let saved = read_json(compare.as_deref())?;
    // And the markdown file, for the same reason.
    let markdown_doc = match &args.markdown {
        Some(p) if p.exists() => {
            let doc = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
            markdown::check(&doc, &p.display().to_string())?;
            Some(doc)
        }
        _ => None,
    };
    if cfg!(debug_assertions) {
        eprintln!("tcb-bench: warning: a debug build; numbers mean little (use --release)");
    }
    let load = markdown::load_average();
    let names = only_names(args)?;
    let all = if args.clip.is_empty() {
        scenarios::named(&args.bvh, |n| names.as_ref().is_none_or(|w| w.contains(&n)))?
    } else {
        args.clip
            .iter()
            .map(|p| scenarios::file(p))
            .collect::<Result<_, _>>()?
    };
    let mut rows: Vec<_> = all.iter().map(|s| report::measure(s, &timing)).collect();
    report::relate(&mut rows);
    let here = report::Fingerprint::here();
    print_report(args, &rows, &here, &timing, load);
    let doc = report::to_json(&rows, &here, &timing);
    let text = serde_json::to_string_pretty(&doc)? + "\n";
    for path in args.json.iter().chain(&save) {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        tcb_io::write_atomically(path, text.as_bytes())?;
    }
    if let Some(path) = &args.markdown {
        let table = markdown_table(&rows, &here, &timing, load);
        let doc = markdown::update(markdown_doc.as_deref(), &table, &path.display().to_string())?;
        tcb_io::write_atomically(path, doc.as_bytes())?;
        println!(
            "\nwrote \"{}\" into {}",
            markdown::heading(&here).trim_start_matches("### "),
            path.display()
        );
    }
    if let (Some(name), Some(path)) = (&args.save_baseline, &save) {
        println!("\nsaved as baseline '{name}' ({})", path.display());
    }
    let mut ok = true;
    if let (Some(saved), Some(path)) = (&saved, &compare) {
        ok = check_saved(args, saved, path, names.is_some(), &rows, &here, &timing);
    }
    Ok(ok)
}

/// This machine's table for `--markdown`, with the command that made it.
fn markdown_table(
    rows: &[report::Row],
    here: &report::Fingerprint,
    timing: &report::Timing,
    load: Option<f64>,
) -> String {
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let command = markdown::command(
        env!("TCB_BENCH_RUSTFLAGS"),
        env!("TCB_BENCH_PROFILE"),
        &argv,
    );
    markdown::table(rows, here, timing, &command, &report::today(), load)
}

/// `--check` or `--baseline`: this run against the `saved` report (read
/// from `path`; with `--only`, its other scenarios are not missing), the
/// lines printed; whether everything held.
fn check_saved(
    args: &Args,
    saved: &serde_json::Value,
    path: &std::path::Path,
    only: bool,
    rows: &[report::Row],
    here: &report::Fingerprint,
    timing: &report::Timing,
) -> bool {
    let mut saved = saved.clone();
    if only && let Some(s) = saved.get_mut("scenarios").and_then(|s| s.as_array_mut()) {
        s.retain(|x| {
            x.get("name")
                .and_then(|n| n.as_str())
                .is_some_and(|n| rows.iter().any(|r| r.name == n))
        });
    }
    let (lines, held) = report::check(rows, &saved, here, timing, args.max_regression);
    println!("\nagainst {}:", path.display());
    for l in lines {
        println!("  {l}");
    }
    held
}

/// The rounds and slices of timing: `--quick` or the full report, with
/// `--rounds` and `--slice-ms` over them.
fn timing(args: &Args) -> Result<report::Timing, Box<dyn std::error::Error>> {
    let mut timing = if args.quick {
        report::Timing::QUICK
    } else {
        report::Timing::FULL
    };
    if let Some(r) = args.rounds {
        timing.rounds = r;
    }
    if let Some(ms) = args.slice_ms {
        timing.slice = Duration::from_millis(ms.max(1));
    }
    if args.max_regression.is_nan() || args.max_regression < 0.0 || timing.rounds == 0 {
        return Err("--max-regression must be >= 0 and --rounds > 0".into());
    }
    Ok(timing)
}

/// The saved report to compare with: `--check PATH`, or `--baseline NAME`
/// (which must have been saved).
fn compared_report(args: &Args) -> Result<Option<PathBuf>, Box<dyn std::error::Error>> {
    Ok(match (&args.check, &args.baseline) {
        (Some(p), _) => Some(p.clone()),
        (None, Some(name)) => {
            let p = baseline_path(name)?;
            if !p.exists() {
                return Err(format!(
                    "no baseline '{name}' ({}): save one first with --save-baseline {name}",
                    p.display()
                )
                .into());
            }
            Some(p)
        }
        (None, None) => None,
    })
}

/// The scenarios `--only` names, each checked to be one.
fn only_names(args: &Args) -> Result<Option<Vec<&str>>, Box<dyn std::error::Error>> {
    let names: Option<Vec<&str>> = args
        .only
        .as_ref()
        .map(|o| o.split(',').map(str::trim).collect());
    if let Some(names) = &names
        && let Some(bad) = names.iter().find(|n| !scenarios::NAMES.contains(n))
    {
        return Err(format!(
            "--only {bad}: no such scenario (one of {})",
            scenarios::NAMES.join(", ")
        )
        .into());
    }
    Ok(names)
}

/// The report on stdout: the table, the README's goals met or not (after
/// what their figures depend on, with the load the run started under),
/// and a word after `--quick`.
fn print_report(
    args: &Args,
    rows: &[report::Row],
    here: &report::Fingerprint,
    timing: &report::Timing,
    load: Option<f64>,
) {
    print!("{}", report::table(rows, here, timing));
    let goals = report::goals(rows);
    if !goals.is_empty() {
        println!("\ngoals (the README's \"Goals\"):");
        println!("{}", goals_note(load, here.cores));
        for (line, met) in goals {
            println!("  {} {line}", if met { "met    " } else { "not yet" });
        }
    }
    if args.quick {
        println!(
            "\nThis was --quick; run without it for the full report (11 rounds of 20 ms, every frame)."
        );
    }
}

/// What the goals' figures depend on, said before them: the ns-per-joint
/// goals are absolute, so a slower CPU or a busy machine misses them; the
/// others are bytes or ratios timed in the same rounds; crowd's needs
/// idle cores. `load` is the one-minute load average when the run started.
fn goals_note(load: Option<f64>, cores: usize) -> String {
    let load = match load {
        Some(l) if l > 0.5 * cores as f64 => {
            format!("load average {l:.2} on {cores} cores at the start: busy, so these read slow")
        }
        Some(l) => format!("load average {l:.2} on {cores} cores at the start"),
        None => "load average unknown".to_string(),
    };
    format!(
        "  the ns-per-joint goals are absolute: they hold or not with the CPU, the build and\n  \
         what else runs; the rest are bytes, which no machine changes, or ratios timed in the\n  \
         same rounds (crowd's needs idle cores).\n  This run: {load}."
    )
}
