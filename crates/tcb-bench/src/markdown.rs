//! `--markdown FILE`: the report as one table per machine and build in a
//! markdown document (`docs/benchmarks.md`), regenerated rather than
//! written by hand.
//!
//! The tables live between the lines [`BEGIN`] and [`END`]. Each starts
//! with a `### ` heading naming the machine and the build
//! ([`heading`]); a run replaces the table under its own heading, keeps
//! the other machines' and appends its own when it has none. Everything
//! outside the two lines (the history, the how-to) is left as it is.

use crate::noise;
use crate::report::{Fingerprint, Row, Timing};
use std::fmt::Write as _;

/// The line before the generated tables.
pub const BEGIN: &str = "<!-- tcb-bench --markdown: current tables from here -->";
/// The line after them.
pub const END: &str = "<!-- tcb-bench --markdown: to here -->";

/// The table's heading: the machine (CPU model, cores) and the build
/// (RUSTFLAGS or the default, and the SIMD target features), which is
/// what a run replaces.
pub fn heading(here: &Fingerprint) -> String {
    let rustflags = here
        .flags
        .split_once("RUSTFLAGS=\"")
        .and_then(|(_, r)| r.split_once('"'))
        .map_or("", |(r, _)| r.trim());
    let features = here
        .flags
        .split_once("target-features=")
        .map_or("", |(_, f)| f.trim());
    let build = if rustflags.is_empty() {
        "default build".to_string()
    } else {
        format!("`RUSTFLAGS=\"{rustflags}\"`")
    };
    let features = if features.is_empty() {
        String::new()
    } else {
        format!(" ({features})")
    };
    format!("### {}, {} cores: {build}{features}", here.cpu, here.cores)
}

/// The command that ran this binary, as it would be typed: cargo's
/// `run`, the profile, RUSTFLAGS when set, and the arguments (quoted for
/// a POSIX shell where they need it).
pub fn command(rustflags: &str, profile: &str, args: &[String]) -> String {
    let mut out = String::new();
    if !rustflags.trim().is_empty() {
        let _ = write!(out, "RUSTFLAGS=\"{}\" ", rustflags.trim());
    }
    out.push_str("cargo run ");
    if profile == "release" {
        out.push_str("--release ");
    }
    out.push_str("-p tcb-bench");
    if !args.is_empty() {
        out.push_str(" --");
        for a in args {
            out.push(' ');
            out.push_str(&quote(a));
        }
    }
    out
}

/// `a` as one shell word.
fn quote(a: &str) -> String {
    let plain = !a.is_empty()
        && a.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=,:+@%".contains(c));
    if plain {
        a.to_string()
    } else {
        format!("'{}'", a.replace('\'', "'\\''"))
    }
}

/// A median (about three significant digits) with its MAD (two).
fn with_spread(m: f64, spread: f64) -> String {
    let d = match m.abs() {
        v if v >= 100.0 => 0,
        v if v >= 10.0 => 1,
        v if v >= 1.0 => 2,
        _ => 3,
    };
    let spread = if spread > 0.0 && spread.is_finite() {
        let s = (1 - spread.log10().floor() as i32).clamp(0, 6) as usize;
        format!("{spread:.s$}")
    } else if spread == 0.0 {
        "0".to_string()
    } else {
        "?".to_string()
    };
    format!("{m:.d$} ± {spread}")
}

/// An integer with thousands separators.
fn thousands(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The one-minute load average (Linux's `/proc/loadavg`), read before
/// timing: numbers taken on a busy machine say so.
pub fn load_average() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

/// One machine's table: heading, date, compiler, flags, load, timing, the
/// command, then per scenario its bytes and the runtime's medians with
/// their MADs (per channel-sample, per pose, per joint).
pub fn table(
    rows: &[Row],
    here: &Fingerprint,
    timing: &Timing,
    command: &str,
    date: &str,
    load: Option<f64>,
) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "{}\n", heading(here));
    let load = load.map_or(String::new(), |l| {
        format!(", load average {l:.2} when it started")
    });
    let _ = writeln!(
        out,
        "{date}, {}; `{}`; {} rayon threads{load}. The median of {} rounds of about {} ms per \
         implementation{}, ± the rounds' MAD (median absolute deviation). Command:\n",
        here.rustc,
        here.flags,
        rayon::current_num_threads(),
        timing.rounds,
        timing.slice.as_millis(),
        if timing.reference_samples.is_some() {
            " (`--quick`: the baseline on a subset of the frames)"
        } else {
            ""
        }
    );
    let _ = writeln!(out, "```sh\n{command}\n```\n");
    out.push_str(
        "| scenario | channels | bytes | runtime ns per channel-sample | ns per pose | ns per joint | x baseline |\n",
    );
    out.push_str("|---|---:|---:|---:|---:|---:|---:|\n");
    for r in rows {
        let (rt, mad) = match (r.ns_of("runtime"), r.rounds_of("runtime")) {
            (Some(m), Some(rounds)) => (m, noise::mad(rounds)),
            (Some(m), None) => (m, f64::NAN),
            _ => continue,
        };
        let channels = r.channels as f64;
        let bytes = match r.file_bytes {
            Some(f) => format!("{} (file {})", thousands(r.bytes), thousands(f)),
            None => thousands(r.bytes),
        };
        let joint = r
            .ns_per_joint
            .map_or("-".to_string(), |j| with_spread(j, mad * j / rt));
        let _ = writeln!(
            out,
            "| `{}` | {} | {bytes} | {} | {} | {joint} | {:.1} |",
            r.name,
            r.channels,
            with_spread(rt, mad),
            with_spread(rt * channels, mad * channels),
            r.speedup_vs_baseline
        );
    }
    out.push_str(
        "\nA pose is one sample of every channel of one instance; bytes are the compiled \
         clip's heap (and a packed clip's `.tcbc` file); x baseline is the scalar baseline's \
         time over the runtime's in the same rounds.\n",
    );
    out
}

/// Where the generated part of `doc` starts (after [`BEGIN`]) and ends
/// (at [`END`]), or a one-line error naming the file `name`.
fn generated(doc: &str, name: &str) -> Result<(usize, usize), String> {
    let missing = || {
        format!(
            "{name}: no lines '{BEGIN}' and '{END}' (in that order) to put the current tables between"
        )
    };
    let inside_at = doc.find(BEGIN).ok_or_else(missing)? + BEGIN.len();
    let end = inside_at + doc[inside_at..].find(END).ok_or_else(missing)?;
    Ok((inside_at, end))
}

/// Whether [`update`] can put a table into `doc`: checked before the
/// timing, so a file without the markers fails at once.
pub fn check(doc: &str, name: &str) -> Result<(), String> {
    generated(doc, name).map(|_| ())
}

/// `doc` (or a new document when `None`) with `table` in place of the
/// table under the same heading between [`BEGIN`] and [`END`], or after
/// the last one. `name` is the file, for the error.
pub fn update(doc: Option<&str>, table: &str, name: &str) -> Result<String, String> {
    let Some(doc) = doc else {
        return Ok(format!("# Benchmarks\n\n{BEGIN}\n\n{table}\n{END}\n"));
    };
    let (inside_at, end) = generated(doc, name)?;
    let inside = &doc[inside_at..end];
    // Split what is inside into a preamble and the tables, each from its
    // "### " line.
    let mut starts: Vec<usize> = inside.match_indices("\n### ").map(|(i, _)| i + 1).collect();
    let preamble_end = starts.first().copied().unwrap_or(inside.len());
    starts.push(inside.len());
    let mut tables: Vec<String> = starts
        .windows(2)
        .map(|w| inside[w[0]..w[1]].trim_end().to_string())
        .collect();
    let mine = table.lines().next().unwrap_or("");
    match tables.iter_mut().find(|t| t.lines().next() == Some(mine)) {
        Some(t) => *t = table.trim_end().to_string(),
        None => tables.push(table.trim_end().to_string()),
    }
    let preamble = inside[..preamble_end].trim();
    let mut out = String::with_capacity(doc.len() + table.len());
    out.push_str(&doc[..inside_at]);
    out.push_str("\n\n");
    if !preamble.is_empty() {
        out.push_str(preamble);
        out.push_str("\n\n");
    }
    for t in &tables {
        out.push_str(t);
        out.push_str("\n\n");
    }
    out.push_str(&doc[end..]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fingerprint(cpu: &str, flags: &str) -> Fingerprint {
        Fingerprint {
            cpu: cpu.into(),
            cores: 2,
            flags: flags.into(),
            rustc: "rustc 1.95.0".into(),
        }
    }

    fn rows() -> Vec<Row> {
        let runtime = vec![1.0, 1.02, 0.98, 1.01, 0.99];
        vec![
            Row {
                name: "character-hermite".into(),
                channels: 100,
                ns: vec![("baseline", 40.0), ("runtime", 1.0)],
                rounds: vec![("baseline", vec![40.0; 5]), ("runtime", runtime)],
                speedup_vs_baseline: 40.0,
                ns_per_joint: Some(4.0),
                bytes: 3_047_890,
                ..Row::default()
            },
            Row {
                name: "character-compressed".into(),
                channels: 100,
                ns: vec![("baseline", 40.0), ("runtime", 5.0)],
                rounds: vec![("runtime", vec![5.0; 5])],
                speedup_vs_baseline: 8.0,
                bytes: 224_000,
                file_bytes: Some(195_182),
                ..Row::default()
            },
        ]
    }

    const DEFAULT: &str = "RUSTFLAGS=\"\" profile=release target-features=sse2";

    #[test]
    fn a_table_has_its_machine_date_command_and_medians_with_spread() {
        let here = fingerprint("AMD EPYC", DEFAULT);
        let cmd = command(
            "",
            "release",
            &["--markdown".into(), "docs/benchmarks.md".into()],
        );
        assert_eq!(
            cmd,
            "cargo run --release -p tcb-bench -- --markdown docs/benchmarks.md"
        );
        let t = table(&rows(), &here, &Timing::FULL, &cmd, "2026-12-04", Some(0.5));
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines[0], "### AMD EPYC, 2 cores: default build (sse2)");
        assert!(
            lines[2].starts_with("2026-12-04, rustc 1.95.0; `RUSTFLAGS=\"\""),
            "{t}"
        );
        assert!(
            lines[2].contains(
                "threads, load average 0.50 when it started. The median of 11 rounds of about 20 ms"
            ),
            "{t}"
        );
        assert!(t.contains(&format!("```sh\n{cmd}\n```\n")), "{t}");
        let header = lines
            .iter()
            .position(|l| l.starts_with("| scenario"))
            .unwrap();
        assert!(lines[header + 1].starts_with("|---|"), "{t}");
        // Median 1.0, MAD 0.01; per pose x100 channels; per joint x4.
        assert_eq!(
            lines[header + 2],
            "| `character-hermite` | 100 | 3,047,890 | 1.00 ± 0.010 | 100 ± 1.0 | 4.00 ± 0.040 | 40.0 |"
        );
        assert_eq!(
            lines[header + 3],
            "| `character-compressed` | 100 | 224,000 (file 195,182) | 5.00 ± 0 | 500 ± 0 | - | 8.0 |"
        );
        // Every table row has as many cells as the header.
        let cells = |l: &str| l.matches('|').count();
        for l in &lines[header..header + 4] {
            assert_eq!(cells(l), cells(lines[header]), "{l}");
        }
    }

    #[test]
    fn commands_quote_what_a_shell_would_split() {
        let cmd = command(
            "-C target-cpu=native",
            "release",
            &[
                "--clip".into(),
                "my clip.json".into(),
                "--only".into(),
                "a,b".into(),
            ],
        );
        assert_eq!(
            cmd,
            "RUSTFLAGS=\"-C target-cpu=native\" cargo run --release -p tcb-bench -- --clip 'my clip.json' --only a,b"
        );
        assert_eq!(command("", "debug", &[]), "cargo run -p tcb-bench");
        let native = fingerprint(
            "AMD EPYC",
            "RUSTFLAGS=\"-C target-cpu=native\" profile=release target-features=sse2,avx2",
        );
        assert_eq!(
            heading(&native),
            "### AMD EPYC, 2 cores: `RUSTFLAGS=\"-C target-cpu=native\"` (sse2,avx2)"
        );
    }

    #[test]
    fn update_replaces_this_machines_table_and_keeps_the_rest() {
        let here = fingerprint("AMD EPYC", DEFAULT);
        let other = fingerprint("Intel Xeon", DEFAULT);
        let t = |fp: &Fingerprint, date: &str| table(&rows(), fp, &Timing::FULL, "cmd", date, None);
        // A new file.
        let doc = update(None, &t(&here, "2026-12-01"), "b.md").unwrap();
        assert!(doc.starts_with("# Benchmarks\n") && doc.contains("2026-12-01"));
        // History around the markers stays; another machine is appended.
        let doc = doc.replace(END, &format!("{END}\n\n# History\n\nold numbers"));
        let doc = update(Some(&doc), &t(&other, "2026-12-02"), "b.md").unwrap();
        let doc = update(Some(&doc), &t(&here, "2026-12-03"), "b.md").unwrap();
        assert!(!doc.contains("2026-12-01"), "{doc}");
        assert_eq!(doc.matches("### AMD EPYC").count(), 1, "{doc}");
        assert_eq!(doc.matches("### Intel Xeon").count(), 1, "{doc}");
        let (amd, xeon) = (doc.find("### AMD").unwrap(), doc.find("### Intel").unwrap());
        assert!(
            amd < xeon && doc.find("2026-12-03").unwrap() < xeon,
            "{doc}"
        );
        assert!(
            doc.ends_with(&format!("{END}\n\n# History\n\nold numbers\n")),
            "{doc}"
        );
        // Regenerating the same table changes nothing.
        let again = update(Some(&doc), &t(&here, "2026-12-03"), "b.md").unwrap();
        assert_eq!(again, doc);
        // A document without the markers is refused, in one line.
        let e = update(Some("# Benchmarks\n"), &t(&here, "x"), "b.md").unwrap_err();
        assert!(e.starts_with("b.md: no lines") && !e.contains('\n'), "{e}");
        assert_eq!(check("# Benchmarks\n", "b.md"), Err(e));
        assert_eq!(check(&doc, "b.md"), Ok(()));
        // END before BEGIN is not a generated part either.
        assert!(check(&format!("{END}\n{BEGIN}\n"), "b.md").is_err());
    }
}
