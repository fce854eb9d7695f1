//! Rotations as hermite controls, checked against squad in f64; the
//! segments the cubic misses, split or kept exact ([`exact_table`]).

use super::controls::{Controls, vector_controls};
use crate::exact::{Exact, ExactTable, SQ_STRIDE};
use crate::grid::{KeyTimes, TimeGrid};
use tcb_core::Interp;
use tcb_core::ease::SegmentEase;
use tcb_core::rotation::RotationTrack;
use wide::{f32x8, f64x4};

/// A rotation's hermite controls per component over the stored segments
/// `0..=n`, and per stored segment the exact squad controls where the cubic
/// misses the reference (`None` where it holds).
#[derive(Clone)]
pub(crate) struct RotationControls {
    pub comps: Vec<Controls>,
    pub exact: Vec<Option<[f64; SQ_STRIDE]>>,
    /// Per stored segment: its cubic holds the values, and misses only
    /// the velocities (meaningful where `exact` is set).
    pub velocity_only: Vec<bool>,
    /// Per stored segment `[a, w]`: it is `s` in `[a, a + w]` of the squad
    /// segment `exact` holds (`[0, 1]` but for pieces of a split segment).
    pub piece: Vec<[f64; 2]>,
}

/// Largest rotation component error the compiled cubic may have (the
/// runtime is held to 1e-6; this leaves room between check points).
const CUBIC_VALUE_TOL: f32 = 4e-7;
/// Largest velocity error of the cubic (per component), relative to
/// `max(1, |velocity|)` with `|velocity|` the rotation's largest component
/// velocity: half the 1e-4 of its speed the runtime is held to, leaving
/// room between check points. On the CMU capture (squad) it makes 457
/// segments exact for velocities only (3.783 MB); 2e-5 would make 1273
/// (4.351 MB) and 1e-5 6277 (8.242 MB), as f32 cancellation in
/// `6 (P1 - P0)` alone reaches about 1e-5 there; held per component instead
/// (relative to each component's own velocity, which crosses zero), 5e-5
/// doubled `sparse-rotations`' instructions and quadrupled its bytes.
const CUBIC_VELOCITY_TOL: f32 = 5e-5;

/// Every rotation as hermite controls (normalized after, like `hermite`
/// rotations): curve segments of a `hermite` track as they are; squad and
/// slerp segments as the cubic through their ends with their end
/// derivatives, checked at 17 points of the segment in the kernel's own f32
/// arithmetic against the f64 formula (value and velocity). Segments where
/// the cubic misses keep their squad controls, and the kernel evaluates
/// those lanes exactly ([`kernel::exact_quats`]).
pub(crate) fn rotation_controls(t: &RotationTrack, exact_velocities: bool) -> RotationControls {
    let keys = t.keys();
    let n = keys.len();
    let interps = t.interps();
    let mut comps = match t.hermite_track() {
        Some(h) => vector_controls(h),
        None => vec![vec![[0.0; 4]; n + 1]; 4],
    };
    let mut exact = vec![None; n + 1];
    let mut velocity_only = vec![false; n + 1];
    let squad = t.squad_segments();
    for k in 0..n - 1 {
        let c = match squad {
            Some(segs) => segs[k].controls(),
            None if interps[k] == Interp::Linear => {
                tcb_core::simd::squad::controls(keys[k], keys[k + 1], keys[k], keys[k + 1])
            }
            None => continue, // a hermite curve or step segment: exact as it is
        };
        // The ends are the keys themselves (stored once per key, see `per_key`).
        let (_, d0) = tcb_core::simd::squad::squad_with_derivative(&c, 0.0);
        let (_, d1) = tcb_core::simd::squad::squad_with_derivative(&c, 1.0);
        let next = if interps[k] == Interp::Step { k } else { k + 1 };
        let (q0, q1) = (keys[k].to_array(), keys[next].to_array());
        let mut ctl: [[f32; 4]; 4] =
            std::array::from_fn(|i| [q0[i], q1[i], d0[i], d1[i]].map(finite_f32));
        let max_rate = 2.0 / (t.times()[k + 1] - t.times()[k]);
        let mut holds = cubic_holds(&c, &ctl, max_rate, (0.0, 1.0));
        // Where the cubic through squad's end derivatives misses the values,
        // tangents fitted to the values may hold them (an instance without
        // velocities then plays the cubic; one with velocities plays squad
        // exactly). Not the last segment: the post sentinel's arriving
        // velocity is its M1.
        if !holds.values && k + 2 < n {
            let fitted = fitted_tangents(&c, &ctl);
            let h = cubic_holds(&c, &fitted, max_rate, (0.0, 1.0));
            if h.values {
                (ctl, holds) = (fitted, h);
            }
        }
        holds.velocities &= !exact_velocities;
        for (i, comp) in comps.iter_mut().enumerate() {
            comp[k + 1] = ctl[i];
        }
        if !holds.both() {
            exact[k + 1] = Some(c);
            velocity_only[k + 1] = holds.values;
        }
    }
    // Sentinels: hold the end keys; the post one carries the velocity
    // arriving at the last key (as `vector_controls` does).
    let (first, last) = (keys[0].to_array(), keys[n - 1].to_array());
    let d = t.times()[n - 1] - t.times()[n - 2];
    let end_rate = (t.eases()[n - 2].apply(1.0).1 / d) as f32;
    for (i, comp) in comps.iter_mut().enumerate() {
        comp[0] = [first[i] as f32, first[i] as f32, 0.0, 0.0];
        let arrive = finite_f32(f64::from(comp[n - 1][3]) * f64::from(end_rate));
        comp[n] = [last[i] as f32, last[i] as f32, 0.0, arrive];
    }
    RotationControls {
        comps,
        exact,
        velocity_only,
        piece: vec![[0.0, 1.0]; n + 1],
    }
}

/// Whether `rot` holds one value: every stored segment of every component
/// is `[q, q, 0, 0]` with the same `q` (bit for bit), and no segment is
/// played exactly.
pub(crate) fn is_constant(rot: &RotationControls) -> bool {
    rot.exact.iter().all(Option::is_none)
        && rot.comps.iter().all(|comp| {
            let q = comp.first().map_or(0.0, |c| c[0]);
            comp.iter().all(|c| {
                c[0].to_bits() == q.to_bits()
                    && c[1].to_bits() == q.to_bits()
                    && c[2] == 0.0
                    && c[3] == 0.0
            })
        })
}

/// A constant rotation ([`is_constant`]) over `segments` stored segments
/// (a grid of `segments - 1` keys).
pub(crate) fn held(rot: &RotationControls, segments: usize) -> RotationControls {
    RotationControls {
        comps: rot
            .comps
            .iter()
            .map(|comp| vec![[comp[0][0], comp[0][0], 0.0, 0.0]; segments])
            .collect(),
        exact: vec![None; segments],
        velocity_only: vec![false; segments],
        piece: vec![[0.0, 1.0]; segments],
    }
}

/// `ctl` with its tangents (`M0`, `M1` of each component) fitted to squad's
/// values over the segment in least squares, its ends kept: the cubic then
/// follows the curve more closely than the one through its end
/// derivatives, and its velocity less.
fn fitted_tangents(c: &[f64; SQ_STRIDE], ctl: &[[f32; 4]; 4]) -> [[f32; 4]; 4] {
    use tcb_core::simd::basis::hermite_basis;
    const POINTS: usize = 64;
    let (mut a11, mut a12, mut a22) = (0.0f64, 0.0f64, 0.0f64);
    let mut rhs = [[0.0f64; 2]; 4];
    for j in 1..POINTS {
        let s = j as f64 / POINTS as f64;
        let (q, _) = tcb_core::simd::squad::unit(c, s, false);
        let h = hermite_basis(s);
        a11 += h[2] * h[2];
        a12 += h[2] * h[3];
        a22 += h[3] * h[3];
        for (i, r) in rhs.iter_mut().enumerate() {
            let rest = q[i] - h[0] * f64::from(ctl[i][0]) - h[1] * f64::from(ctl[i][1]);
            r[0] += h[2] * rest;
            r[1] += h[3] * rest;
        }
    }
    let det = a11 * a22 - a12 * a12;
    std::array::from_fn(|i| {
        let [b1, b2] = rhs[i];
        let m0 = (a22 * b1 - a12 * b2) / det;
        let m1 = (a11 * b2 - a12 * b1) / det;
        [ctl[i][0], ctl[i][1], finite_f32(m0), finite_f32(m1)]
    })
}

/// How much normalizing can grow an error of a rotation's cubic:
/// `|d(p / |p|)| <= 2 |dp| / |p|`, so `2 / min(1, |p|)` with `|p|` the
/// smallest length of its cubic pieces (sampled at 33 points per segment,
/// with 5% to spare between them). Near 2 for curves close to unit length;
/// large where a curve between keys on opposite hemispheres, kept as
/// written, passes near zero.
pub(crate) fn normalize_gain(rot: &RotationControls) -> f32 {
    use tcb_core::simd::basis::{hermite, hermite_basis};
    let n = rot.comps[0].len();
    let mut least = 1.0f32;
    for s in 1..n - 1 {
        if rot.exact[s].is_some() && !rot.velocity_only[s] {
            continue; // evaluated exactly, not as this cubic
        }
        for j in 0..=32 {
            let h = hermite_basis(j as f32 / 32.0);
            let len2: f32 = (0..4)
                .map(|c| {
                    let k = rot.comps[c][s];
                    hermite(&h, k[0], k[1], k[2], k[3]).powi(2)
                })
                .sum();
            least = least.min(len2.sqrt());
        }
    }
    2.0 / (0.95 * least).max(1e-6)
}

/// `x` in f32, finite: beyond f32's range the largest finite f32 of its
/// sign, NaN as 0. Rotation controls come from f64 (squad's derivatives,
/// tangents of keys with huge parameters); an infinite one would turn the
/// zero of a hold row into NaN. Segments whose cubic this changes miss
/// [`cubic_holds`] and are evaluated exactly.
fn finite_f32(x: f64) -> f32 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32
    }
}

/// What [`cubic_holds`] found.
#[derive(Clone, Copy, Debug)]
struct Holds {
    values: bool,
    velocities: bool,
}

impl Holds {
    fn both(self) -> bool {
        self.values && self.velocities
    }
}

/// Whether the normalized cubic `ctl` (per component `[P0, P1, M0, M1]`,
/// evaluated as the kernel does, in f32) follows the squad `c` from `s = a`
/// to `b` within [`CUBIC_VALUE_TOL`] and [`CUBIC_VELOCITY_TOL`] at 17
/// points: values and velocities apart.
fn cubic_holds(
    c: &[f64; SQ_STRIDE],
    ctl: &[[f32; 4]; 4],
    max_rate: f64,
    (a, b): (f64, f64),
) -> Holds {
    use tcb_core::simd::basis::{hermite, hermite_basis, hermite_basis_derivative};
    let mut holds = Holds {
        values: true,
        velocities: true,
    };
    for j in 0..=16 {
        let s = j as f64 / 16.0;
        let (q, dq) = tcb_core::simd::squad::unit(c, a + (b - a) * s, true);
        let dq = dq.expect("asked for").map(|x| x * (b - a));
        let (h, dh) = (hermite_basis(s as f32), hermite_basis_derivative(s as f32));
        let p = ctl.map(|k| hermite(&h, k[0], k[1], k[2], k[3]));
        let dp = ctl.map(|k| hermite(&dh, k[0], k[1], k[2], k[3]));
        let (a, da) = tcb_core::quat::normalize(p, Some(dp));
        let da = da.expect("asked for");
        let rate = max_rate as f32;
        let speed = (0..4)
            .map(|i| (dq[i] as f32 * rate).abs())
            .fold(1.0f32, f32::max);
        holds.values &= (0..4).all(|i| (a[i] - q[i] as f32).abs() <= CUBIC_VALUE_TOL);
        holds.velocities &=
            (0..4).all(|i| ((da[i] - dq[i] as f32) * rate).abs() <= CUBIC_VELOCITY_TOL * speed);
        if !holds.values && !holds.velocities {
            break;
        }
    }
    holds
}

/// A rotation whose segments the cubic misses (`exact`), split: each such
/// segment becomes 2, 4, 8 or 16 pieces between evenly spaced times
/// (rounded to f64), each the cubic through squad's values and derivatives
/// at the parameters of its rounded ends, the fewest that pass
/// [`cubic_holds`]. The keys of the result are the track's own plus the
/// split points. Segments that cannot be split stay as they were, exact: an
/// eased or step segment, one too short to split, or one where 16 pieces
/// still miss.
///
/// For a loose lane (`on_group` false), pieces must hold values and
/// velocities, and a result with no exact segment left needs no f64 per
/// frame. On a group (`on_group` true), pieces need only hold the values:
/// they keep the segment's squad for velocities (`piece` says where they
/// lie in it), so an instance that samples velocities gets them in f64 as
/// before and one that does not plays cubics; segments whose cubic misses
/// only the velocities stay as they are.
pub(crate) fn split_rotation(
    grid: &TimeGrid,
    rot: &RotationControls,
    on_group: bool,
) -> (TimeGrid, RotationControls) {
    let n = grid.times.len();
    let mut times = vec![grid.times.at(0)];
    let (mut eases, mut steps) = (Vec::new(), Vec::new());
    let mut out = RotationControls {
        comps: rot.comps.iter().map(|c| vec![c[0]]).collect(),
        exact: vec![None],
        velocity_only: vec![false],
        piece: vec![[0.0, 1.0]],
    };
    let push = |out: &mut RotationControls, ctl: [[f32; 4]; 4], exact, velocity_only, piece| {
        for (c, ctl) in out.comps.iter_mut().zip(ctl) {
            c.push(ctl);
        }
        out.exact.push(exact);
        out.velocity_only.push(velocity_only);
        out.piece.push(piece);
    };
    for k in 0..n - 1 {
        let (t0, t1) = (grid.times.at(k), grid.times.at(k + 1));
        let pieces = split_pieces(grid, rot, k, on_group);
        let Some(pieces) = pieces else {
            times.push(t1);
            eases.push(grid.ease(k));
            steps.push(grid.is_step(k));
            let ctl = std::array::from_fn(|i| rot.comps[i][k + 1]);
            let (exact, vo) = (rot.exact[k + 1], rot.velocity_only[k + 1]);
            push(&mut out, ctl, exact, vo, rot.piece[k + 1]);
            continue;
        };
        let m = pieces.len();
        // On a group, squad gives the pieces' velocities, as it did for the
        // whole segment (the cubic's, within 5e-5 of the speed, may be 1e-5
        // off, which `tcb sample --velocity` is checked to); a loose lane's
        // pieces hold both.
        let exact = rot.exact[k + 1].filter(|_| on_group);
        for (j, (ctl, piece)) in pieces.into_iter().enumerate() {
            times.push(split_time(t0, t1, j + 1, m));
            eases.push(SegmentEase::default());
            steps.push(false);
            push(&mut out, ctl, exact, exact.is_some(), piece);
        }
    }
    let ctl = std::array::from_fn(|i| rot.comps[i][n]);
    push(&mut out, ctl, None, false, [0.0, 1.0]);
    let grid = TimeGrid {
        times: KeyTimes::Listed(times),
        eases,
        steps,
        pre: grid.pre,
        post: grid.post,
    };
    (grid.compact(), out)
}

/// A piece of a split segment: its controls per component, and `[a, w]`
/// (where it starts in the segment, and its width).
type Piece = ([[f32; 4]; 4], [f64; 2]);

/// Stored segment `k + 1` of `rot` (from key `k` of `grid`) as the fewest
/// equal pieces (2, 4, 8 or 16) whose cubics hold squad (values, and
/// velocities unless `on_group`): each piece's controls and `[a, w]`, where
/// it starts in the segment and its width. None where the segment is not
/// exact, eased, a step, too short to split, or 16 pieces still miss.
fn split_pieces(
    grid: &TimeGrid,
    rot: &RotationControls,
    k: usize,
    on_group: bool,
) -> Option<Vec<Piece>> {
    let (t0, t1) = (grid.times.at(k), grid.times.at(k + 1));
    let c = rot.exact[k + 1]
        .filter(|_| grid.ease(k).is_none() && !grid.is_step(k))
        .filter(|_| !(on_group && rot.velocity_only[k + 1]))?;
    [2usize, 4, 8, 16].into_iter().find_map(|m| {
        // Split times strictly increasing (not so in f64 on keys a few ulps
        // apart).
        let at = |j: usize| split_time(t0, t1, j, m);
        if (1..=m).any(|j| at(j) <= at(j - 1)) {
            return None;
        }
        // A piece is played between its split times as they are in f64,
        // rounded: it covers the segment's parameters from `param(j)` to
        // `param(j + 1)`, which on a segment a few ulps long are far from
        // `j / m` (issue 29 class 2: 17 ulps in 16 pieces, 0.02 off).
        let param = |j: usize| (at(j) - t0) / (t1 - t0);
        (0..m)
            .map(|j| {
                let (a, b) = (param(j), param(j + 1));
                let w = b - a;
                let (qa, da) = tcb_core::simd::squad::squad_with_derivative(&c, a);
                let (qb, db) = tcb_core::simd::squad::squad_with_derivative(&c, b);
                let ctl: [[f32; 4]; 4] = std::array::from_fn(|i| {
                    // The segment's own ends stay its keys.
                    let p0 = if j == 0 {
                        rot.comps[i][k + 1][0]
                    } else {
                        qa[i] as f32
                    };
                    let p1 = if j + 1 == m {
                        rot.comps[i][k + 1][1]
                    } else {
                        qb[i] as f32
                    };
                    [p0, p1, (w * da[i]) as f32, (w * db[i]) as f32]
                });
                let holds = cubic_holds(&c, &ctl, 2.0 / (w * (t1 - t0)), (a, b));
                let enough = if on_group { holds.values } else { holds.both() };
                enough.then_some((ctl, [a, w]))
            })
            .collect::<Option<Vec<_>>>()
    })
}

/// Time `j` of `m` (`t0` at 0, `t1` exactly at `m`) splitting `[t0, t1]`
/// into equal pieces.
fn split_time(t0: f64, t1: f64, j: usize, m: usize) -> f64 {
    if j == m {
        t1
    } else {
        t0 + (t1 - t0) * (j as f64 / m as f64)
    }
}

/// The exact entries of one group's rotations, per stored segment: offsets
/// per stored segment, the entries, and the squad controls they read.
pub(crate) fn exact_table(rows: &[&RotationControls], segments: usize) -> ExactTable {
    let identity = {
        let mut c = [0.0; SQ_STRIDE];
        c[3] = 1.0;
        c[11] = 1.0;
        c
    };
    let mut at = Vec::with_capacity(segments + 1);
    let mut out = Vec::new();
    let mut pool: Vec<[f64x4; 2 * SQ_STRIDE]> = Vec::new();
    for seg in 0..segments {
        at.push(out.len() as u32);
        for (b, block) in rows.chunks(8).enumerate() {
            if block.iter().all(|r| r.exact[seg].is_none()) {
                continue;
            }
            let lane = |l: usize| block.get(l).and_then(|r| r.exact[seg]);
            let values = |l: usize| lane(l).is_some() && !block[l].velocity_only[seg];
            let mask_of = |f: &dyn Fn(usize) -> bool| {
                f32x8::new(std::array::from_fn(|l| {
                    f32::from_bits(if f(l) { u32::MAX } else { 0 })
                }))
            };
            let mask = mask_of(&|l| lane(l).is_some());
            let value_mask = mask_of(&values);
            let controls: [f64x4; 2 * SQ_STRIDE] = std::array::from_fn(|k| {
                let (half, j) = (k / SQ_STRIDE, k % SQ_STRIDE);
                f64x4::new(std::array::from_fn(|l| {
                    lane(4 * half + l).unwrap_or(identity)[j]
                }))
            });
            let same = |a: &[f64x4; 2 * SQ_STRIDE]| {
                (0..2 * SQ_STRIDE).all(|k| a[k].to_array() == controls[k].to_array())
            };
            if !pool.last().is_some_and(same) {
                pool.push(controls);
            }
            let mut pieces = block
                .iter()
                .filter(|r| r.exact[seg].is_some())
                .map(|r| r.piece[seg]);
            let piece = pieces.next().expect("a lane of the entry is exact");
            debug_assert!(pieces.all(|p| p == piece), "one piece per block");
            out.push(Exact {
                mask,
                value_mask,
                piece,
                block: u32::try_from(b).expect("fewer than 2^32 blocks"),
                controls: u32::try_from(pool.len() - 1).expect("fewer than 2^32 entries"),
                values: value_mask.any(),
            });
        }
    }
    at.push(out.len() as u32);
    if out.is_empty() {
        at = Vec::new(); // nothing exact: no table to keep
    }
    ExactTable {
        at,
        entries: out,
        controls: pool,
    }
}
