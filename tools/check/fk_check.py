#!/usr/bin/env python3
"""Check a compressed clip against the BVH it came from, by forward kinematics.

    python3 tools/check/fk_check.py --bvh data/cmu-01_01.bvh --tcbc cmu.tcbc \
        --tolerance E --shell R [--printed P] \
        [--tcb "cargo run --release -q -p tcb-cli --"]
    python3 tools/check/fk_check.py --bvh data/cmu-01_01.bvh \
        --clip data/cmu-01_01.bvh --tolerance 1e-4 --shell R   # sanity check

The BVH is read here (not by the project's code): Euler rotation channels in
degrees composed in the order listed (R = R_c1 R_c2 R_c3), position channels
replacing the OFFSET on their axis, End Sites as leaves `<parent>_end` with
identity rotation. The clip is sampled with `tcb sample --at` at every frame
time t_k = k * Frame Time, its tracks `<Joint>.translation` (vec3),
`<Joint>.rotation` (x, y, z, w) and, if any, `<Joint>.scale` are composed down
the BVH hierarchy (a joint without a translation track keeps its OFFSET, one
without a rotation track the identity) with M_j = M_parent T_j R_j S_j, in
float64. The error is docs/reduce.md's shell metric:

    e_j(t) = max over v in {0, R e_x, R e_y, R e_z} of |M_j(t) v - M'_j(t) v|

maximized over frames and joints (End Sites included). Exit 0 if it is at
most --tolerance and, with --printed (the error `tcb compress` printed, a max
over frames and inbetweens), if the same error measured against the BVH as
`tcb sample` plays it (float32 keys: the reference of docs/reduce.md, which
the tolerance is then held against too) is at most the printed one (to 1e-6
relative + 1e-9); 1 if not, 2 on any other error. The summary line goes to
stdout; with --printed, the played-reference numbers go to stderr.
Standard library only.
"""

import argparse
import math
import os
import shlex
import struct
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
TIME_TOL = 1e-6


class CheckError(Exception):
    """Anything that is not a measured error over the tolerance (exit 2)."""


# ---------------------------------------------------------------- BVH

class Bvh:
    def __init__(self):
        self.names = []      # joint and end-site names
        self.parents = []    # parent index or None
        self.offsets = []    # [x, y, z]
        self.channels = []   # per joint: list of (kind 'p'|'r', axis 0..2)
        self.is_end = []     # End Site?
        self.frame_time = None
        self.frames = []     # rows of floats


def parse_bvh(path):
    with open(path, "r", encoding="utf-8", errors="replace") as f:
        lines = f.read().splitlines()
    motion = None
    for i, line in enumerate(lines):
        words = line.split()
        if words and words[0] == "MOTION":
            motion = i
            break
    if motion is None:
        raise CheckError(f"{path}: no MOTION section")
    tokens = [(i + 1, w) for i, line in enumerate(lines[:motion]) for w in line.split()]
    bvh = Bvh()
    stack = []
    end_of = []  # (parent index, offset) of End Sites, named after the joints
    pos = 0

    def take(what):
        nonlocal pos
        if pos >= len(tokens):
            raise CheckError(f"{path}: the hierarchy ends where {what} was expected")
        tok = tokens[pos]
        pos += 1
        return tok

    def number(what):
        line, w = take(what)
        try:
            v = float(w)
        except ValueError:
            raise CheckError(f"{path}:{line}: '{w}' is not a number ({what})")
        if not math.isfinite(v):
            raise CheckError(f"{path}:{line}: '{w}' is not finite ({what})")
        return v

    def expect(word):
        line, w = take(repr(word))
        if w != word:
            raise CheckError(f"{path}:{line}: expected '{word}', found '{w}'")

    expect("HIERARCHY")
    while pos < len(tokens):
        line, w = take("a keyword")
        if w in ("ROOT", "JOINT"):
            if (w == "ROOT") != (not stack):
                raise CheckError(f"{path}:{line}: {w} in the wrong place")
            name = []
            while pos < len(tokens) and tokens[pos][0] == line and tokens[pos][1] != "{":
                name.append(tokens[pos][1])
                pos += 1
            name = " ".join(name)
            if not name or name in bvh.names:
                raise CheckError(f"{path}:{line}: missing or repeated joint name '{name}'")
            expect("{")
            bvh.names.append(name)
            bvh.parents.append(stack[-1] if stack else None)
            bvh.offsets.append([0.0, 0.0, 0.0])
            bvh.channels.append([])
            bvh.is_end.append(False)
            stack.append(len(bvh.names) - 1)
        elif w == "OFFSET":
            if not stack:
                raise CheckError(f"{path}:{line}: OFFSET outside a joint")
            bvh.offsets[stack[-1]] = [number("OFFSET x"), number("OFFSET y"), number("OFFSET z")]
        elif w == "CHANNELS":
            if not stack:
                raise CheckError(f"{path}:{line}: CHANNELS outside a joint")
            _, n = take("the channel count")
            try:
                n = int(n)
            except ValueError:
                raise CheckError(f"{path}:{line}: '{n}' is not a channel count")
            chans = []
            for _ in range(n):
                l2, c = take("a channel name")
                lc = c.lower()
                if len(lc) < 2 or lc[0] not in "xyz" or lc[1:] not in ("position", "rotation"):
                    raise CheckError(f"{path}:{l2}: unknown channel '{c}'")
                chans.append((lc[1], "xyz".index(lc[0])))
            bvh.channels[stack[-1]] = chans
        elif w == "End":
            if not stack:
                raise CheckError(f"{path}:{line}: End Site outside a joint")
            expect("Site")
            expect("{")
            expect("OFFSET")
            off = [number("OFFSET x"), number("OFFSET y"), number("OFFSET z")]
            expect("}")
            end_of.append((stack[-1], off))
        elif w == "}":
            if not stack:
                raise CheckError(f"{path}:{line}: '}}' without a joint")
            stack.pop()
        else:
            raise CheckError(f"{path}:{line}: unexpected '{w}' in the hierarchy")
    if stack or not bvh.names:
        raise CheckError(f"{path}: unbalanced hierarchy or no ROOT")

    # End Sites after all joints, named <parent>_end (then _end2, ...).
    taken = set(bvh.names)
    for parent, off in end_of:
        base = bvh.names[parent] + "_end"
        name, n = base, 1
        while name in taken:
            n += 1
            name = f"{base}{n}"
        taken.add(name)
        bvh.names.append(name)
        bvh.parents.append(parent)
        bvh.offsets.append(off)
        bvh.channels.append([])
        bvh.is_end.append(True)

    rest = [(i + 1, l.strip()) for i, l in enumerate(lines[motion + 1:], start=motion + 1)]
    rest = [(i, l) for i, l in rest if l]

    def header(key, k):
        if k >= len(rest) or ":" not in rest[k][1]:
            raise CheckError(f"{path}: '{key}:' missing after MOTION")
        head, value = rest[k][1].split(":", 1)
        if " ".join(head.split()) != key:
            raise CheckError(f"{path}:{rest[k][0]}: expected '{key}:', found '{rest[k][1]}'")
        return value.strip()

    claimed = int(header("Frames", 0))
    bvh.frame_time = float(header("Frame Time", 1))
    if not (bvh.frame_time > 0 and math.isfinite(bvh.frame_time)):
        raise CheckError(f"{path}: Frame Time must be a positive number")
    width = sum(len(c) for c in bvh.channels)
    for line, text in rest[2:]:
        row = [float(x) for x in text.split()]
        if len(row) != width:
            raise CheckError(f"{path}:{line}: {len(row)} values, expected {width}")
        bvh.frames.append(row)
    if claimed != len(bvh.frames):
        print(f"fk_check: warning: Frames: {claimed} but {len(bvh.frames)} rows; using the rows",
              file=sys.stderr)
    return bvh


# ---------------------------------------------------------------- math

IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def matmul(a, b):
    return tuple(
        tuple(a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] for j in range(3))
        for i in range(3)
    )


def matvec(a, v):
    return (
        a[0][0] * v[0] + a[0][1] * v[1] + a[0][2] * v[2],
        a[1][0] * v[0] + a[1][1] * v[1] + a[1][2] * v[2],
        a[2][0] * v[0] + a[2][1] * v[1] + a[2][2] * v[2],
    )


def axis_rotation(axis, degrees):
    r = math.radians(degrees)
    c, s = math.cos(r), math.sin(r)
    if axis == 0:
        return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))
    if axis == 1:
        return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))
    return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))


def quat_matrix(x, y, z, w):
    n = x * x + y * y + z * z + w * w
    if not (n > 0 and math.isfinite(n)):
        raise CheckError(f"quaternion ({x}, {y}, {z}, {w}) is not a rotation")
    s = 2.0 / n  # normalizes
    return (
        (1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)),
        (s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)),
        (s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)),
    )


def compose(bvh, locals_):
    """Model-space (linear part, position) per joint from local (T, L) pairs."""
    out = []
    for j, (t, lin) in enumerate(locals_):
        p = bvh.parents[j]
        if p is None:
            out.append((lin, tuple(t)))
        else:
            plin, ppos = out[p]
            d = matvec(plin, t)
            out.append((matmul(plin, lin), (ppos[0] + d[0], ppos[1] + d[1], ppos[2] + d[2])))
    return out


def bvh_locals(bvh, row):
    locals_ = []
    at = 0
    for j in range(len(bvh.names)):
        t = list(bvh.offsets[j])
        rot = IDENTITY
        for kind, axis in bvh.channels[j]:
            v = row[at]
            at += 1
            if kind == "p":
                t[axis] = v  # a position channel replaces the OFFSET on its axis
            else:
                rot = matmul(rot, axis_rotation(axis, v))
        locals_.append((t, rot))
    return locals_


def clip_locals(bvh, tracks, values):
    locals_ = []
    for j, name in enumerate(bvh.names):
        tr = tracks.get(name, {})
        t = list(bvh.offsets[j])
        if "translation" in tr:
            t = [values[c] for c in tr["translation"]]
        lin = IDENTITY
        if "rotation" in tr:
            lin = quat_matrix(*(values[c] for c in tr["rotation"]))
        if "scale" in tr:
            s = [values[c] for c in tr["scale"]]
            lin = matmul(lin, ((s[0], 0.0, 0.0), (0.0, s[1], 0.0), (0.0, 0.0, s[2])))
        locals_.append((t, lin))
    return locals_


def shell_error(a, b, radius):
    (la, pa), (lb, pb) = a, b
    e = math.dist(pa, pb)
    for i in range(3):
        qa = [pa[k] + radius * la[k][i] for k in range(3)]
        qb = [pb[k] + radius * lb[k][i] for k in range(3)]
        e = max(e, math.dist(qa, qb))
    return e


# ---------------------------------------------------------------- tcb sample

def tcb_command(spec):
    cmd = shlex.split(spec)
    if not cmd:
        raise CheckError("--tcb is empty")
    if os.sep in cmd[0] and not os.path.isabs(cmd[0]):
        cmd[0] = os.path.abspath(cmd[0])
    return cmd


_F32 = struct.Struct("<f")


def f32(x):
    """The float32 nearest to x (inf beyond its range)."""
    try:
        return _F32.unpack(_F32.pack(x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)


def sample(cmd, clip, times, chunk):
    """Rows of floats (time first) and the header, sampled at `times`."""
    header, rows = None, []
    for start in range(0, len(times), chunk):
        part = times[start:start + chunk]
        args = cmd + ["sample", clip, "--at=" + ",".join(repr(t) for t in part)]
        r = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
        if r.returncode != 0:
            msg = (r.stderr.strip() or r.stdout.strip()).splitlines()
            raise CheckError(f"{shlex.join(args[:3])} ... failed ({r.returncode}): "
                             f"{msg[-1] if msg else ''}")
        lines = [l for l in r.stdout.splitlines() if l.strip()]
        if not lines:
            raise CheckError("tcb sample printed nothing")
        h = lines[0].split(",")
        if header is None:
            header = h
        elif h != header:
            raise CheckError("tcb sample printed different columns for different times")
        for line in lines[1:]:
            # Values are float32 printed in shortest round-trip form: read
            # as float64 they are off by up to half a float32 ulp (about
            # 5e-7 of error at the end of an 18-unit chain), so round them
            # back to the float32 they were. The time column is float64.
            row = line.split(",")
            row = [float(row[0])] + [f32(float(x)) for x in row[1:]]
            if len(row) != len(header):
                raise CheckError(f"tcb sample: a row of {len(row)} values, header has {len(header)}")
            if not all(math.isfinite(x) for x in row):
                raise CheckError(f"tcb sample: non-finite value at time {row[0]}")
            rows.append(row)
    if header is None or header[0] != "time":
        raise CheckError("tcb sample: the first column is not 'time'")
    if len(rows) != len(times):
        raise CheckError(f"tcb sample gave {len(rows)} rows for {len(times)} times")
    for row, t in zip(rows, times):
        if abs(row[0] - t) > TIME_TOL:
            raise CheckError(f"tcb sample: time {row[0]} where {t} was asked")
    return header, rows


def group_tracks(header, bvh):
    """{joint: {'translation'|'rotation'|'scale': [column indices]}}."""
    comps = {"translation": "xyz", "rotation": "xyzw", "scale": "xyz"}
    cols = {}
    for i, name in enumerate(header[1:], start=1):
        track, _, comp = name.rpartition(".")
        joint, _, prop = track.rpartition(".")
        if prop not in comps or comp not in comps[prop]:
            raise CheckError(f"tcb sample: column '{name}' is not <joint>.<translation|rotation|scale>.<c>")
        if joint not in bvh.names:
            raise CheckError(f"tcb sample: column '{name}' names a joint the BVH does not have")
        cols.setdefault(joint, {}).setdefault(prop, {})[comp] = i
    tracks = {}
    for joint, props in cols.items():
        tracks[joint] = {}
        for prop, got in props.items():
            if set(got) != set(comps[prop]):
                raise CheckError(f"tcb sample: {joint}.{prop} has columns {sorted(got)}")
            tracks[joint][prop] = [got[c] for c in comps[prop]]
    return tracks


# ---------------------------------------------------------------- main

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bvh", required=True, help="the source BVH (the reference)")
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--tcbc", help="the compressed clip written by `tcb compress`")
    src.add_argument("--clip", help="any file `tcb sample` reads, instead of a .tcbc")
    ap.add_argument("--tolerance", type=float, required=True, help="the stated error E")
    ap.add_argument("--shell", type=float, required=True, help="the shell radius R")
    ap.add_argument("--printed", type=float, help="the max error `tcb compress` printed")
    ap.add_argument("--tcb", default="cargo run --release -q -p tcb-cli --",
                    help="the tcb command (run from the repository root)")
    ap.add_argument("--chunk", type=int, default=2000, help="times per `tcb sample` call")
    args = ap.parse_args()

    try:
        bvh = parse_bvh(args.bvh)
        clip = os.path.abspath(args.tcbc or args.clip)
        times = [k * bvh.frame_time for k in range(len(bvh.frames))]
        if not times:
            raise CheckError(f"{args.bvh}: no frames")
        header, rows = sample(tcb_command(args.tcb), clip, times, max(1, args.chunk))
        tracks = group_tracks(header, bvh)

        # The printed error is measured against the BVH as `tcb sample`
        # plays it (float32 keys, docs/reduce.md "What is compared"), which
        # differs from the float64 BVH text by about 1e-6 of the height; so
        # with --printed the BVH is also sampled through tcb, and the clip
        # is compared with that played reference too.
        played_rows = played_tracks = None
        if args.printed is not None:
            ph, played_rows = sample(tcb_command(args.tcb), os.path.abspath(args.bvh), times,
                                     max(1, args.chunk))
            played_tracks = group_tracks(ph, bvh)

        names = bvh.names
        worst = [-1.0, None, None]   # clip vs the float64 BVH (the tolerance)
        played = [-1.0, None, None]  # clip vs the BVH as tcb plays it (the printed error)
        floor = [-1.0, None, None]   # the played BVH vs the float64 BVH

        def take(w, a, b, t):
            for j in range(len(names)):
                e = shell_error(a[j], b[j], args.shell)
                if not math.isfinite(e):
                    raise CheckError(f"non-finite error at {names[j]} time {t}")
                if e > w[0]:
                    w[:] = [e, names[j], t]

        for k, (row, frame) in enumerate(zip(rows, bvh.frames)):
            ref = compose(bvh, bvh_locals(bvh, frame))
            got = compose(bvh, clip_locals(bvh, tracks, row))
            take(worst, ref, got, row[0])
            if played_rows is not None:
                pref = compose(bvh, clip_locals(bvh, played_tracks, played_rows[k]))
                take(played, pref, got, row[0])
                take(floor, ref, pref, row[0])
    except (CheckError, OSError, ValueError) as err:
        print(f"fk_check: error: {err}")
        return 2
    worst, worst_joint, worst_time = worst
    if played_rows is not None:
        print(f"fk_check: vs the BVH as tcb sample plays it: max {played[0]!r} at {played[1]} "
              f"time {played[2]!r}; the played BVH vs the float64 BVH: max {floor[0]!r} "
              f"at {floor[1]} time {floor[2]!r}", file=sys.stderr)

    printed = "none" if args.printed is None else repr(args.printed)
    summary = (f"max shell error {worst!r} at {worst_joint} time {worst_time!r} over "
               f"{len(rows)} frames and {len(bvh.names)} joints+end sites "
               f"(tolerance {args.tolerance!r}, printed {printed})")
    failures = []
    # The contract's reference is the input as `tcb sample` plays it; the
    # float64 BVH differs from it by the floor printed above (about 1e-6 of
    # the height), so the tolerance is held against the played BVH when it
    # was sampled, and against the float64 BVH otherwise.
    held = played[0] if played_rows is not None else worst
    if not held <= args.tolerance:
        failures.append("over the tolerance")
    if args.printed is not None and not played[0] <= args.printed * (1 + 1e-6) + 1e-9:
        failures.append(f"{played[0]!r} against the BVH as tcb plays it is over the printed "
                        "error (a max over frames and inbetweens)")
    if failures:
        print(f"fk_check: FAIL ({' and '.join(failures)}): {summary}")
        return 1
    print(f"fk_check: {summary}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
