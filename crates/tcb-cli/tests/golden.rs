//! `tcb sample` against values computed independently of this code base:
//! `tools/check/tcbref.py`, a plain-Python reading of `docs/math.md`, wrote
//! `tools/check/golden/*.csv` (regenerate with
//! `python3 tools/check/check.py --write-golden`). Tolerance 1e-5 relative
//! (absolute below 1); quaternions up to sign.

mod common;

use common::{assert_success, command, root};
use std::path::{Path, PathBuf};

const TOL: f64 = 1e-5;

struct Golden {
    clip: String,
    /// Column of the `.x` of each quaternion track (compared up to sign).
    quats: Vec<usize>,
    header: Vec<String>,
    rows: Vec<Vec<f64>>,
}

fn read_golden(path: &Path) -> Golden {
    let text = std::fs::read_to_string(path).unwrap();
    let first = text.lines().next().unwrap();
    let clip = first.strip_prefix("# clip: ").unwrap().to_owned();
    let quats = text
        .lines()
        .find_map(|l| l.strip_prefix("# quat columns:"))
        .unwrap()
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    let (header, rows) = parse_csv(&text);
    Golden {
        clip,
        quats,
        header,
        rows,
    }
}

fn sample(clip: &str, times: &[f64], scalar: bool) -> (Vec<String>, Vec<Vec<f64>>) {
    let at: Vec<String> = times.iter().map(|t| format!("{t:?}")).collect();
    let mut cmd = command();
    cmd.current_dir(root())
        .args(["sample", clip, "--velocity", "--at"])
        .arg(at.join(","));
    if scalar {
        cmd.arg("--scalar");
    }
    let out = cmd.output().unwrap();
    assert_success(&out);
    parse_csv(&common::stdout(&out))
}

/// Header and numeric rows of a CSV, skipping `#` comment lines.
fn parse_csv(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn sample_matches_the_independent_reference() {
    let dir = root().join("tools/check/golden");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .collect();
    files.sort();
    assert!(
        files.len() >= 5,
        "golden files missing from {}",
        dir.display()
    );
    let mut checked = 0;
    let mut failures = Vec::new();
    for file in &files {
        let g = read_golden(file);
        let times: Vec<f64> = g.rows.iter().map(|r| r[0]).collect();
        for scalar in [false, true] {
            let (header, rows) = sample(&g.clip, &times, scalar);
            assert_eq!(header, g.header, "{}", g.clip);
            let n = (header.len() - 1) / 2;
            for (got, want) in rows.iter().zip(&g.rows) {
                let mut want = want.clone();
                for &q in &g.quats {
                    let dot: f64 = (0..4).map(|j| got[q + j] * want[q + j]).sum();
                    if dot < 0.0 {
                        for j in 0..4 {
                            want[q + j] = -want[q + j];
                            want[q + n + j] = -want[q + n + j];
                        }
                    }
                }
                for c in 1..header.len() {
                    checked += 1;
                    if (got[c] - want[c]).abs() > TOL * want[c].abs().max(1.0) {
                        failures.push(format!(
                            "{} t={} {}: got {}, want {}",
                            g.clip, want[0], header[c], got[c], want[c]
                        ));
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {checked} values differ:\n{}",
        failures.len(),
        failures[..failures.len().min(20)].join("\n")
    );
    assert!(checked > 10_000);
}
