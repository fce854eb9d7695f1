#!/usr/bin/env python3
"""The C and C++ examples print `Hips.translation,<t>,<x>,<y>,<z>`; check
that each is, as an f32, what `tcb sample FILE --at <t>` prints in its
Hips.translation columns. Usage: check_sample.py CLI.csv OUT...  (stdlib only)"""
import csv
import struct
import sys


def f32(text):
    return struct.unpack("<f", struct.pack("<f", float(text)))[0]


def main():
    cli_csv, outputs = sys.argv[1], sys.argv[2:]
    with open(cli_csv, newline="") as f:
        rows = list(csv.reader(f))
    header, values = rows[0], rows[1]
    want = [f32(values[header.index(f"Hips.translation.{c}")]) for c in "xyz"]
    time = float(values[header.index("time")])
    for path in outputs:
        lines = [l for l in open(path) if l.startswith("Hips.translation,")]
        if len(lines) != 1:
            sys.exit(f"{path}: expected one Hips.translation line, found {len(lines)}")
        fields = lines[0].strip().split(",")
        t, got = float(fields[1]), [f32(x) for x in fields[2:5]]
        if t != time or got != want:
            sys.exit(f"{path}: t={t} {got}, but tcb sample --at {time} gives {want}")
        print(f"{path}: Hips.translation at {t} s = {got}, as tcb sample prints")


main()
