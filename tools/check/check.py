#!/usr/bin/env python3
"""Check `tcb sample` against an independent implementation of spec/math.md.

    python3 tools/check/check.py [--tcb "cargo run --release -q -p tcb-cli --"]
    python3 tools/check/check.py --write-golden   # regenerate tools/check/golden/

For every clip under examples/clips/ and tools/check/clips/, samples at the
key times, inbetweens, and times before, after, far after (1e6 s) and far
before the keys, with --velocity, by both the runtime and --scalar paths,
and compares every value and velocity to 1e-5 relative (absolute below 1).
Quaternions are compared up to sign. Standard library only.
"""

import argparse
import json
import math
import os
import shlex
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tcbref  # noqa: E402

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
CLIP_DIRS = ["examples/clips", "tools/check/clips"]
GOLDEN = os.path.join(ROOT, "tools", "check", "golden")
TOL = 1e-5


def clips():
    for d in CLIP_DIRS:
        for name in sorted(os.listdir(os.path.join(ROOT, d))):
            if name.endswith(".json"):
                yield os.path.join(d, name)


def sample_times(clip):
    keys = sorted({t for _, _, tr in clip.tracks for t in tr.times})
    times = []
    for i, t in enumerate(keys):
        if i:
            a = keys[i - 1]
            times += [a + (t - a) * j / 4 for j in (1, 2, 3)]
        times.append(t)
    t0, tn = keys[0], keys[-1]
    span = tn - t0
    times += [t0 - 0.37 * span, t0 - 1.61 * span, t0 - 2.5, tn + 0.43 * span, tn + 1.77 * span,
              tn + 3.2, 1e6 + 0.37, -1e6 - 0.11]
    return times


def expected_rows(clip, times):
    rows = []
    for t in times:
        vals, vels = clip.row(t)
        rows.append((t, vals, vels))
    return rows


def quat_columns(clip):
    """Start index (in the value columns) of each quaternion track."""
    out, at = [], 0
    for _, kind, tr in clip.tracks:
        if kind == "quat":
            out.append(at)
        at += tr.dim
    return out


def compare(name, clip, times, header, got_rows, exp_rows):
    cols = clip.columns()
    want = ["time"] + cols + [c + ".d" for c in cols]
    if header != want:
        return [f"{name}: header {header} != {want}"]
    n = len(cols)
    quats = quat_columns(clip)
    errors = []
    for t, got, (et, ev, ed) in zip(times, got_rows, exp_rows):
        gv, gd = got[1 : 1 + n], got[1 + n :]
        ev, ed = list(ev), list(ed)
        for q in quats:  # compare rotations up to sign
            if sum(a * b for a, b in zip(gv[q : q + 4], ev[q : q + 4])) < 0:
                ev[q : q + 4] = [-x for x in ev[q : q + 4]]
                ed[q : q + 4] = [-x for x in ed[q : q + 4]]
        for label, g, e in [("", gv, ev), (".d", gd, ed)]:
            for c, a, b in zip(cols, g, e):
                if not (abs(a - b) <= TOL * max(1.0, abs(b))):
                    errors.append(f"{name}: t={t!r} {c}{label}: tcb {a!r}, reference {b!r}")
    return errors


def run_tcb(tcb, path, times, scalar):
    cmd = shlex.split(tcb) + ["sample", path, "--at", ",".join(repr(t) for t in times), "--velocity"]
    if scalar:
        cmd.append("--scalar")
    out = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed: {out.stderr}")
    lines = out.stdout.strip().split("\n")
    return lines[0].split(","), [[float(x) for x in l.split(",")] for l in lines[1:]]


def write_golden():
    os.makedirs(GOLDEN, exist_ok=True)
    for path in clips():
        with open(os.path.join(ROOT, path)) as f:
            clip = tcbref.SourceClip(json.load(f))
        times = sample_times(clip)
        cols = clip.columns()
        stem = os.path.splitext(os.path.basename(path))[0]
        with open(os.path.join(GOLDEN, stem + ".csv"), "w") as out:
            out.write(f"# clip: {path}\n")
            out.write("# expected values from tools/check/tcbref.py (independent of the Rust code); compare to 1e-5\n")
            out.write("# quat columns: " + " ".join(str(1 + q) for q in quat_columns(clip)) + "\n")
            out.write(",".join(["time"] + cols + [c + ".d" for c in cols]) + "\n")
            for t, vals, vels in expected_rows(clip, times):
                out.write(",".join(repr(float(x)) for x in [t] + vals + vels) + "\n")
        print(f"wrote {stem}.csv ({len(times)} rows, {len(cols)} columns)")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tcb", default="cargo run --release -q -p tcb-cli --")
    ap.add_argument("--write-golden", action="store_true")
    args = ap.parse_args()
    if args.write_golden:
        write_golden()
        return
    errors, checked = [], 0
    for path in clips():
        with open(os.path.join(ROOT, path)) as f:
            clip = tcbref.SourceClip(json.load(f))
        times = sample_times(clip)
        exp = expected_rows(clip, times)
        for scalar in (False, True):
            header, rows = run_tcb(args.tcb, path, times, scalar)
            e = compare(path + (" --scalar" if scalar else ""), clip, times, header, rows, exp)
            errors += e
            checked += len(rows) * (len(header) - 1)
    for e in errors[:40]:
        print(e)
    failed = len(errors)
    print(f"check: {checked - failed} passed, {failed} failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
