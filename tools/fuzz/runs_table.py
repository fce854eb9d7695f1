#!/usr/bin/env python3
"""The runs table of docs/fuzzing.md from libFuzzer's logs.

    python3 tools/fuzz/runs_table.py TARGET:COMMIT:LOG[:ARTIFACT_DIR] ...

One row per argument: seconds, runs and coverage (edges) from the log's
first and last status lines (`#N: cov: ...`, as `-fork=1` prints them),
and its findings (crashes, OOMs and timeouts, and any file left in the
artifact directory). A log without libFuzzer's `INFO: exiting` line is
refused: the run has not ended.
"""
import os
import re
import sys

STATUS = re.compile(
    r"#(\d+): cov: (\d+) .*oom/timeout/crash: (\d+)/(\d+)/(\d+) time: (\d+)s"
)

print("| target | commit | seconds | runs | coverage (edges, start -> end) | findings |")
print("|---|---|---:|---:|---|---|")
for arg in sys.argv[1:]:
    try:
        target, commit, log, *art = arg.split(":")
        lines = open(log, errors="replace").read().splitlines()
    except (ValueError, OSError) as e:
        sys.exit(f"runs_table: {arg}: {e} (expected TARGET:COMMIT:LOG[:ARTIFACT_DIR])")
    status = [m for m in map(STATUS.match, lines) if m]
    if not status or not any("INFO: exiting" in line for line in lines):
        sys.exit(f"{log}: not a finished libFuzzer run")
    runs, cov, oom, timeout, crash, secs = status[-1].groups()
    left = len(os.listdir(art[0])) if art else 0
    found = int(oom) + int(timeout) + int(crash) + left
    what = "none" if found == 0 else f"{crash} crashes, {oom} OOM, {timeout} timeouts"
    print(f"| `{target}` | `{commit}` | {secs} | {int(runs):,} | {status[0].group(2)} -> {cov} | {what} |")
