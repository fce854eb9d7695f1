"""An independent implementation of spec/math.md, in plain Python floats (f64).

Written from the spec's formulas as printed, sharing nothing with the Rust
code: the tangent rules use the spec's time-unit forms (v-, v+, TI, TO) where
the Rust code reduces every rule to chord coefficients. Used to check
`tcb sample` to 1e-5 and to write the golden files the Rust tests read.
"""

import math

RULES = ("uniform", "adjusted", "secant", "parabolic")


# ---------------------------------------------------------------- vectors

def add(a, b):
    return [x + y for x, y in zip(a, b)]


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def mul(a, f):
    return [x * f for x in a]


def norm(a):
    return math.sqrt(sum(x * x for x in a))


# ---------------------------------------------------------------- quaternions [x, y, z, w]

def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]


def qconj(q):
    return [-q[0], -q[1], -q[2], q[3]]


def qlog(q):
    v = q[:3]
    s = norm(v)
    if s == 0.0:
        return [0.0, 0.0, 0.0]
    return mul(v, math.atan2(s, q[3]) / s)


def qexp(v):
    th = norm(v)
    if th == 0.0:
        return [0.0, 0.0, 0.0, 1.0]
    return mul(v, math.sin(th) / th) + [math.cos(th)]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def slerp(p, q, s):
    c = max(-1.0, min(1.0, dot(p, q)))
    th = math.acos(c)
    if abs(math.sin(th)) < 1e-12:
        return add(mul(p, 1 - s), mul(q, s))
    return add(mul(p, math.sin((1 - s) * th) / math.sin(th)), mul(q, math.sin(s * th) / math.sin(th)))


def normalize(q):
    n = norm(q)
    return mul(q, 1.0 / n)


# ---------------------------------------------------------------- parameters

def weights(tcb):
    t, c, b = tcb
    return (
        (1 - t) * (1 - c) * (1 + b) / 2,  # wIA
        (1 - t) * (1 + c) * (1 - b) / 2,  # wIB
        (1 - t) * (1 + c) * (1 + b) / 2,  # wOA
        (1 - t) * (1 - c) * (1 - b) / 2,  # wOB
    )


def rule_tangents(rule, fade, tcb, A, B, dm, dp):
    """(DS, DD) in value per segment, literally as spec/math.md writes each rule."""
    wIA, wIB, wOA, wOB = weights(tcb)
    if rule == "uniform":
        return add(mul(A, wIA), mul(B, wIB)), add(mul(A, wOA), mul(B, wOB))
    if rule == "adjusted":
        fi = 2 * dm / (dm + dp)
        fo = 2 * dp / (dm + dp)
        if fade:
            c = abs(tcb[1])
            fi = fi + c * (1 - fi)
            fo = fo + c * (1 - fo)
        return mul(add(mul(A, wIA), mul(B, wIB)), fi), mul(add(mul(A, wOA), mul(B, wOB)), fo)
    vm = mul(A, 1 / dm)
    vp = mul(B, 1 / dp)
    if rule == "secant":
        TI = add(mul(vm, wIA), mul(vp, wIB))
        TO = add(mul(vm, wOA), mul(vp, wOB))
    elif rule == "parabolic":
        TI = mul(add(mul(vm, wIA * dp), mul(vp, wIB * dm)), 2 / (dm + dp))
        TO = mul(add(mul(vm, wOA * dp), mul(vp, wOB * dm)), 2 / (dm + dp))
    else:
        raise ValueError(rule)
    return mul(TI, dm), mul(TO, dp)


def matched(DS, DD, dm, dp):
    TI, TO = mul(DS, 1 / dm), mul(DD, 1 / dp)
    a, b = norm(TI), norm(TO)
    if a + b == 0:
        return DS, DD
    TI2 = mul(TI, 2 * b / (a + b))
    TO2 = mul(TO, 2 * a / (a + b))
    return mul(TI2, dm), mul(TO2, dp)


class Settings:
    def __init__(self, d):
        self.rule = d.get("tangent_rule", "adjusted")
        self.ends = d.get("ends", "copy")
        self.match_speed = d.get("match_speed", False)
        self.fade = d.get("continuity_fade", False)
        self.tcb = d.get("tcb", [0.0, 0.0, 0.0])
        self.pre = d.get("pre", "constant")
        self.post = d.get("post", "constant")
        self.rotation = d.get("rotation", "squad")
        self.hemisphere = d.get("hemisphere", "nearest")


def key_tangents(times, chords, keys, st, dim, wrap_sign=1.0):
    """DS_k, DD_k of every key (value per segment), per spec/math.md.

    wrap_sign: -1 for a cyclic hermite rotation whose last key is -q_0 (a
    full turn): each lap is the previous one negated, so key 0's source chord
    is -A and DS_{n-1}, in the last key's sign, is -DS.
    """
    n = len(times)
    D = [times[k + 1] - times[k] for k in range(n - 1)]
    DS, DD = [None] * n, [None] * n
    zero = [0.0] * dim
    for k in range(n):
        tcb = keys[k].get("tcb", st.tcb)
        if 0 < k < n - 1:
            A, B, dm, dp = chords[k - 1], chords[k], D[k - 1], D[k]
            ds, dd = rule_tangents(st.rule, st.fade, tcb, A, B, dm, dp)
            if st.match_speed:
                ds, dd = matched(ds, dd, dm, dp)
        elif st.ends == "cyclic":
            tcb = keys[0].get("tcb", st.tcb)
            A, B, dm, dp = mul(chords[n - 2], wrap_sign), chords[0], D[n - 2], D[0]
            ds, dd = rule_tangents(st.rule, st.fade, tcb, A, B, dm, dp)
            if st.match_speed:
                ds, dd = matched(ds, dd, dm, dp)
            if k == n - 1:
                ds = mul(ds, wrap_sign)
        else:
            if k == 0:
                B, dp = chords[0], D[0]
                A = B if st.ends != "zero" else zero
                dm = dp
            else:
                A, dm = chords[n - 2], D[n - 2]
                B = A if st.ends != "zero" else zero
                dp = dm
            ds, dd = rule_tangents(st.rule, st.fade, tcb, A, B, dm, dp)
        if "in" in keys[k]:
            ds = mul(as_list(keys[k]["in"]), dm)
        if "out" in keys[k]:
            dd = mul(as_list(keys[k]["out"]), dp)
        DS[k], DD[k] = ds, dd
    if st.ends == "natural":
        # In time units, as the spec writes it, then back to per-segment units.
        TI1 = mul(DS[1], 1 / D[0])
        TOn2 = mul(DD[n - 2], 1 / D[n - 2])
        free0 = "out" not in keys[0]
        free1 = "in" not in keys[n - 1]
        if n == 2 and free0 and free1:
            DD[0] = chords[0]
            DS[1] = chords[0]
        else:
            if free0:
                TO0 = sub(mul(chords[0], 3 / (2 * D[0])), mul(TI1, 0.5))
                DD[0] = mul(TO0, D[0])
            if free1:
                TIn = sub(mul(chords[n - 2], 3 / (2 * D[n - 2])), mul(TOn2, 0.5))
                DS[n - 1] = mul(TIn, D[n - 2])
    return DS, DD


def as_list(v):
    return list(v) if isinstance(v, list) else [v]


def ease_s(u, a, e):
    """(s, ds/du) for plain parameter u with ease-from a and ease-to e."""
    if a + e > 1:
        a, e = a / (a + e), e / (a + e)
    if a == 0 and e == 0:
        return u, 1.0
    K = 1 / (2 - a - e)
    if u < a:
        return K * u * u / a, 2 * K * u / a
    if e > 0 and u >= 1 - e:
        return 1 - K * (1 - u) ** 2 / e, 2 * K * (1 - u) / e
    return K * (2 * u - a), 2 * K


def h_row(s):
    return (2 * s**3 - 3 * s**2 + 1, -2 * s**3 + 3 * s**2, s**3 - 2 * s**2 + s, s**3 - s**2)


def dh_row(s):
    return (6 * s**2 - 6 * s, -6 * s**2 + 6 * s, 3 * s**2 - 4 * s + 1, 3 * s**2 - 2 * s)


# ---------------------------------------------------------------- tracks

class Track:
    def __init__(self, doc, defaults):
        merged = dict(defaults)
        for k in ("tangent_rule", "ends", "match_speed", "continuity_fade", "tcb", "pre", "post", "rotation", "hemisphere"):
            if k in doc:
                merged[k] = doc[k]
        self.st = Settings(merged)
        self.kind = doc["kind"]
        self.times = [float(t) for t in doc["times"]]
        self.keys = doc.get("keys") or [{} for _ in self.times]
        vals = [as_list(v) for v in doc["values"]]
        # The file's numbers are read as f32 by the project; do the same.
        vals = [[f32(x) for x in v] for v in vals]
        self.dim = len(vals[0])
        n = len(self.times)
        if self.kind == "quat":
            qs = []
            self.keys = [dict(k) for k in self.keys]
            for i, q in enumerate(vals):
                q = normalize(q)
                # hemisphere "keep": keys and tangents exactly as written.
                if self.st.hemisphere == "nearest" and qs and dot(qs[-1], q) < 0:
                    q = mul(q, -1)
                    for side in ("in", "out"):
                        if side in self.keys[i]:
                            self.keys[i][side] = [-x for x in self.keys[i][side]]
                qs.append(q)
            vals = qs
        self.values = vals
        self.D = [self.times[k + 1] - self.times[k] for k in range(n - 1)]
        self.interp = [k.get("interp", "curve") for k in self.keys]
        self.squad = self.kind == "quat" and self.st.rotation == "squad"
        if self.squad:
            self.chords = [qlog(qmul(qconj(vals[k]), vals[k + 1])) for k in range(n - 1)]
            self.DS, self.DD = key_tangents(self.times, self.chords, self.keys, self.st, 3)
            self.a, self.b = [None] * n, [None] * n
            for k in range(n):
                if k < n - 1:
                    self.a[k] = qmul(vals[k], qexp(mul(sub(self.DD[k], self.chords[k]), 0.5)))
                if k > 0:
                    self.b[k] = qmul(vals[k], qexp(mul(sub(self.chords[k - 1], self.DS[k]), 0.5)))
        else:
            self.chords = [sub(vals[k + 1], vals[k]) for k in range(n - 1)]
            wrap = -1.0 if self.kind == "quat" and self.st.ends == "cyclic" and dot(vals[0], vals[-1]) < 0 else 1.0
            self.DS, self.DD = key_tangents(self.times, self.chords, self.keys, self.st, self.dim, wrap)

    # value and d/dt inside [t0, tn]
    def inside(self, time):
        t, n = self.times, len(self.times)
        k = 0
        while k < n - 2 and time >= t[k + 1]:
            k += 1
        u = min(1.0, max(0.0, (time - t[k]) / self.D[k]))
        a = self.keys[k].get("ease", [0, 0])[1]
        e = self.keys[k + 1].get("ease", [0, 0])[0]
        s, dsdu = ease_s(u, a, e)
        rate = dsdu / self.D[k]
        P0, P1 = self.values[k], self.values[k + 1]
        shape = self.interp[k]
        last = k == n - 2 and u >= 1.0
        if shape == "step":
            return (P1 if last else P0), [0.0] * self.dim
        if self.kind == "quat" and shape == "linear":
            f = lambda x: slerp(P0, P1, x)
            return f(s), mul(numdiff(f, s), rate)
        if self.squad:
            f = lambda x: slerp(slerp(P0, P1, x), slerp(self.a[k], self.b[k + 1], x), 2 * x * (1 - x))
            return normalize(f(s)), mul(numdiff(f, s), rate)
        if shape == "linear":
            M0 = M1 = self.chords[k]
        else:
            M0, M1 = self.DD[k], self.DS[k + 1]
        h, dh = h_row(s), dh_row(s)
        P = [h[0] * p0 + h[1] * p1 + h[2] * m0 + h[3] * m1 for p0, p1, m0, m1 in zip(P0, P1, M0, M1)]
        dP = [(dh[0] * p0 + dh[1] * p1 + dh[2] * m0 + dh[3] * m1) * rate for p0, p1, m0, m1 in zip(P0, P1, M0, M1)]
        if self.kind == "quat":  # hermite rotation: normalize, and d/dt of p/|p|
            L = norm(P)
            q = mul(P, 1 / L)
            return q, mul(sub(dP, mul(q, dot(q, dP))), 1 / L)
        return P, dP

    def sample(self, time):
        t0, tn = self.times[0], self.times[-1]
        zero = [0.0] * self.dim
        if math.isnan(time):
            return self.values[0], zero
        if t0 <= time <= tn:
            return self.inside(time)
        after = time > tn
        mode = self.st.post if after else self.st.pre
        if math.isinf(time):
            if mode == "reset":
                return self.reset(), zero
            return self.values[-1 if after else 0], zero
        if mode == "constant":
            return self.values[-1 if after else 0], zero
        if mode == "reset":
            return self.reset(), zero
        if mode == "linear":
            if after:
                TI = mul(self.DS[-1], 1 / self.D[-1])
                return add(self.values[-1], mul(TI, time - tn)), TI
            TO = mul(self.DD[0], 1 / self.D[0])
            return add(self.values[0], mul(TO, time - t0)), TO
        L = tn - t0
        m = math.floor((time - t0) / L)
        r = min(L, max(0.0, (time - t0) - m * L))
        if mode == "repeat":
            return self.inside(t0 + r)
        if mode == "offset-repeat":
            v, d = self.inside(t0 + r)
            return add(v, mul(sub(self.values[-1], self.values[0]), m)), d
        if mode == "oscillate":
            if m % 2 == 0:
                return self.inside(t0 + r)
            v, d = self.inside(tn - r)
            return v, mul(d, -1)
        raise ValueError(mode)

    def reset(self):
        return [0.0, 0.0, 0.0, 1.0] if self.kind == "quat" else [0.0] * self.dim


def numdiff(f, s, h=1e-4):
    return mul(sub(f(s + h), f(s - h)), 1 / (2 * h))


def f32(x):
    import struct
    return struct.unpack("f", struct.pack("f", x))[0]


class SourceClip:
    def __init__(self, doc):
        defaults = doc.get("defaults", {})
        self.tracks = [(t["name"], t["kind"], Track(t, defaults)) for t in doc["tracks"]]

    def columns(self):
        out = []
        for name, kind, tr in self.tracks:
            if kind == "scalar":
                out.append(name)
            else:
                out += [name + "." + c for c in "xyzw"[: tr.dim]]
        return out

    def row(self, time):
        vals, vels = [], []
        for _, _, tr in self.tracks:
            v, d = tr.sample(time)
            vals += v
            vels += d
        return vals, vels
