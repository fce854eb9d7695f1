//! `cargo run --release -p tcb-bench`: the comparison report on the bundled
//! real data; `--json PATH` writes it as JSON; `--check BASELINE.json`
//! exits non-zero when a ratio regressed by more than `--max-regression`
//! percent.

#![forbid(unsafe_code)]

use clap::Parser;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;
use tcb_bench::{icount, report, scenarios};

#[derive(Parser)]
#[command(
    name = "tcb-bench",
    about = "Runtime vs scalar baseline vs the splines crate, on real data"
)]
struct Args {
    /// Write the report as JSON here too.
    #[arg(long, value_name = "PATH")]
    json: Option<PathBuf>,
    /// Compare with a saved JSON report; exit 1 on a regression.
    #[arg(long, value_name = "BASELINE.json")]
    check: Option<PathBuf>,
    /// Largest allowed fall of a ratio, percent.
    #[arg(long, value_name = "PCT", default_value_t = 10.0)]
    max_regression: f64,
    /// The motion-capture file for character, crowd and seek.
    #[arg(long, value_name = "FILE.bvh", default_value_os_t = scenarios::default_bvh())]
    bvh: PathBuf,
    /// Only these scenarios (comma separated).
    #[arg(long, value_name = "NAMES")]
    only: Option<String>,
    /// Timing rounds per implementation (the median is reported).
    #[arg(long, default_value_t = 11)]
    rounds: usize,
    /// Milliseconds per timing.
    #[arg(long, default_value_t = 20)]
    slice_ms: u64,
    /// Time these clips (JSON, BVH, glTF) instead of the scenarios: 60 fps
    /// forward over each clip, as `character`.
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
    /// Run one scenario's pass and exit (what --icount runs under valgrind).
    #[arg(long, value_name = "NAME", hide = true)]
    icount_pass: Option<String>,
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

/// `--icount`: count each scenario under callgrind, then check or save.
fn run_icount(args: &Args) -> Result<bool, Box<dyn std::error::Error>> {
    if args.icount_max_growth.is_nan() || args.icount_max_growth < 0.0 {
        return Err("--icount-max-growth must be a number >= 0".into());
    }
    let saved = read_json(args.icount_check.as_deref())?;
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
    let exe = std::env::current_exe()?;
    let mut counts = std::collections::BTreeMap::new();
    println!("tcb-bench --icount: instructions of one runtime pass under callgrind");
    println!("flags: {}", report::flags());
    for name in names {
        let c = icount::count(&exe, name, &args.bvh)?;
        println!(
            "  {name:<18} {:>12} instructions  {:>9} L1 misses  {:>7} LL misses",
            c.instructions, c.l1_misses, c.ll_misses
        );
        counts.insert(name.to_string(), c);
    }
    if let Some(path) = &args.icount_save {
        let note = format!(
            "tcb-bench --icount ({}); regenerate with: cargo run --release -p tcb-bench -- --icount --icount-save {}",
            report::flags(),
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

fn run(args: &Args) -> Result<bool, Box<dyn std::error::Error>> {
    if let Some(name) = &args.icount_pass {
        let s = scenarios::named(&args.bvh, |n| n == name)?;
        let s = s.first().ok_or_else(|| format!("no scenario {name}"))?;
        icount::run_pass(s);
        return Ok(true);
    }
    if args.icount {
        return run_icount(args);
    }
    if args.max_regression.is_nan() || args.max_regression < 0.0 || args.rounds == 0 {
        return Err("--max-regression must be >= 0 and --rounds > 0".into());
    }
    // Read the baseline first: a bad file should fail before minutes of timing.
    let saved = read_json(args.check.as_deref())?;
    if cfg!(debug_assertions) {
        eprintln!("tcb-bench: warning: a debug build; numbers mean little (use --release)");
    }
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
    let all = if args.clip.is_empty() {
        scenarios::named(&args.bvh, |n| names.as_ref().is_none_or(|w| w.contains(&n)))?
    } else {
        args.clip
            .iter()
            .map(|p| scenarios::file(p))
            .collect::<Result<_, _>>()?
    };
    let slice = Duration::from_millis(args.slice_ms.max(1));
    let mut rows: Vec<_> = all
        .iter()
        .map(|s| report::measure(s, args.rounds, slice))
        .collect();
    report::relate(&mut rows);
    let (flags, machine) = (report::flags(), report::machine());
    print!("{}", report::table(&rows, &flags, &machine));
    println!("\ntargets:");
    for (line, met) in report::targets(&rows) {
        println!("  {} {line}", if met { "met " } else { "MISS" });
    }
    if let Some(path) = &args.json {
        let doc = report::to_json(&rows, &flags, &machine);
        let text = serde_json::to_string_pretty(&doc)? + "\n";
        tcb_io::write_atomically(path, text.as_bytes())?;
    }
    let mut ok = true;
    if let Some(saved) = &saved {
        let (lines, held) = report::check(&rows, saved, args.max_regression);
        println!(
            "\nregression check against {}:",
            args.check
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_default()
        );
        for l in lines {
            println!("  {l}");
        }
        ok = held;
    }
    Ok(ok)
}
