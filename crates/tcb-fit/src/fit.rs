//! Fitting cubic Hermite keys to dense samples within a tolerance at every
//! sample (the check times of `docs/reduce.md`).
//!
//! For fixed key times the curve is linear in its unknowns, so the best
//! curve in the least-squares sense is one banded solve (`band.rs`).
//! Keys are chosen by *greedy insertion*: start from the two end keys, fit,
//! and split every span where some sample is out of tolerance at its worst
//! sample within the span's middle half; repeat until every sample is
//! within tolerance. A *removal* pass then tries each inserted key in turn
//! and drops it where refitting the keys around it still holds.
//!
//! Two representations ([`Tangents`]):
//!
//! ```text
//! explicit   unknowns p_k, g_k (value, time-unit tangent; in = out = g_k)
//!            segment k: h1 p_k + h2 p_{k+1} + h3 D_k g_k + h4 D_k g_{k+1}
//! derived    unknowns P_k only; DS_k, DD_k from the `adjusted` rule with
//!            t = c = b = 0 and `copy` ends (tangent.rs: DS = in_a A + in_b B,
//!            DD = out_a A + out_b B), the paper's own representation
//!            segment k: h1 P_k + h2 P_{k+1} + h3 DD_k + h4 DS_{k+1}
//! ```
//!
//! Several series (tracks) may share the key times: the solve is shared and
//! a span is split where any of them is out of its own tolerance.

use crate::band::{Normal, Row, WIDTH};
use tcb_core::simd::basis::hermite_basis;
use tcb_core::tangent::ChordWeights;
use tcb_core::{TangentRule, Tcb};

/// How a sample's error is measured against its tolerance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Norm {
    /// Largest absolute component difference.
    MaxAbs,
    /// Euclidean distance.
    Euclid,
    /// Rotations (samples are unit quaternions, sign-continuous): the curve
    /// is normalized and the error is `sin(θ/2) = sqrt(1 - (q·q')²)`,
    /// θ the angle of the rotation between them.
    Rotation,
}

/// Where a key's tangents come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tangents {
    /// Stored: value and one time-unit tangent per key (written as `in` = `out`).
    Explicit,
    /// Derived by the TCB rule from the neighbouring key values (t = c = b = 0):
    /// only the value is stored.
    Derived,
    /// Both fitted; the one that stores fewer numbers is kept. Derived
    /// tangents win on noisy data (motion capture, where keys stay dense),
    /// explicit ones on smooth data (fewer, wider keys).
    #[default]
    Best,
}

impl Tangents {
    /// Numbers a key stores per component: the value, and with explicit
    /// tangents its `in` and `out`.
    fn numbers_per_component(self) -> usize {
        if self == Tangents::Explicit { 3 } else { 1 }
    }

    /// The command line's name.
    pub fn name(self) -> &'static str {
        match self {
            Tangents::Explicit => "explicit",
            Tangents::Derived => "derived",
            Tangents::Best => "best",
        }
    }
}

impl std::str::FromStr for Tangents {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "explicit" => Ok(Tangents::Explicit),
            "derived" => Ok(Tangents::Derived),
            "best" => Ok(Tangents::Best),
            _ => Err(format!(
                "unknown tangents '{s}' (expected best, derived or explicit)"
            )),
        }
    }
}

/// One track's samples at the check times, with its error measure.
#[derive(Clone, Debug)]
pub struct Series<'a> {
    /// Components used (1 to 4).
    pub dim: usize,
    /// A sample per check time.
    pub samples: &'a [[f64; 4]],
    /// How the error is measured.
    pub norm: Norm,
    /// The largest error allowed, in the norm's units.
    pub tol: f64,
}

/// Fitted keys for a group of series.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// Key positions, as indices into the check times (first and last included).
    pub knots: Vec<usize>,
    /// Per series, per key: the value.
    pub values: Vec<Vec<[f64; 4]>>,
    /// Per series, per key: the time-unit tangent ([`Tangents::Explicit`]; empty otherwise).
    pub tangents: Vec<Vec<[f64; 4]>>,
    /// How the tangents come ([`Tangents::Explicit`] or [`Tangents::Derived`]).
    pub mode: Tangents,
}

impl Fit {
    /// Numbers stored: each key's value, and with explicit tangents its
    /// `in` and `out`, all components.
    pub fn stored_values(&self, series: &[Series]) -> usize {
        let dims: usize = series.iter().map(|s| s.dim).sum();
        self.knots.len() * dims * self.mode.numbers_per_component()
    }
}

/// Fit keys to `series`, all sampled at `times` (strictly increasing, at
/// least 2). `None` when no curve on these check times can hold the
/// tolerance (a span with no sample inside fails, or the data is not finite).
pub fn fit(times: &[f64], series: &[Series], tangents: Tangents) -> Option<Fit> {
    fit_within(times, series, tangents, usize::MAX)
}

/// [`fit`], giving up (`None`) on a representation once its insertion has
/// placed keys that would store more than `max_values` numbers: a caller
/// that keeps the original track beyond some size need not wait for a fit
/// it will not use. (Insertion places about twice the keys removal keeps.)
pub fn fit_within(
    times: &[f64],
    series: &[Series],
    tangents: Tangents,
    max_values: usize,
) -> Option<Fit> {
    if tangents == Tangents::Best {
        let a = fit_within(times, series, Tangents::Derived, max_values);
        let b = fit_within(times, series, Tangents::Explicit, max_values);
        return match (a, b) {
            (Some(a), Some(b)) => Some(if b.stored_values(series) < a.stored_values(series) {
                b
            } else {
                a
            }),
            (a, b) => a.or(b),
        };
    }
    let n = times.len();
    if n < 2 || series.iter().any(|s| s.samples.len() != n) {
        return None;
    }
    let problem = Problem {
        times,
        series,
        tangents,
        cols: series.iter().map(|s| s.dim).sum(),
    };
    let max_keys = max_values / (problem.cols * tangents.numbers_per_component()).max(1);
    let (mut knots, mut x) = problem.insert_keys(max_keys)?;
    problem.remove_keys(&mut knots, &mut x);
    let solved = problem.evaluate(&knots, &x, 0..n);
    solved.holds().then(|| problem.finish(&knots, &x))
}

impl Problem<'_> {
    /// Insertion: from the two end keys, split the failing spans (in their
    /// middle half) and solve again until every sample holds. The keys and
    /// their solution; `None` if the fit cannot hold or needs more than
    /// `max_keys` keys.
    fn insert_keys(&self, max_keys: usize) -> Option<(Vec<usize>, Vec<f64>)> {
        let n = self.times.len();
        let mut knots = vec![0, n - 1];
        loop {
            let x = self.solve(&knots)?;
            let solved = self.evaluate(&knots, &x, 0..n);
            let split = spans_to_split(&knots, &solved);
            let inserts: Vec<usize> = (0..split.len())
                .filter(|&k| split[k])
                .map(|k| {
                    // At the worst sample, kept to the middle half of the span:
                    // a key beside a key adds little, and splitting near the
                    // middle halves the span every round.
                    let (a, b) = (knots[k], knots[k + 1]);
                    let quarter = (b - a) / 4;
                    let (lo, hi) = (a + quarter.max(1), b - quarter.max(1));
                    lo + argmax(&solved.ratio[lo..=hi])
                })
                .collect();
            if inserts.is_empty() {
                return solved.holds().then_some((knots, x));
            }
            knots.extend(inserts);
            knots.sort_unstable();
            if knots.len() > max_keys {
                return None;
            }
        }
    }

    /// Removal: drop each key in turn where refitting the keys around it
    /// (the rest held) keeps every sample they reach within tolerance.
    fn remove_keys(&self, knots: &mut Vec<usize>, x: &mut Vec<f64>) {
        let mut k = 1;
        while k + 1 < knots.len() {
            // Only the keys around k take part: a slice wide enough that the
            // rows refitted and checked never reach its ends (unless they are
            // the track's own ends).
            let lo = k.saturating_sub(WINDOW + 3);
            let hi = (k + WINDOW + 3).min(knots.len() - 1);
            let per = self.unknowns(1) * self.cols;
            match self.without(&knots[lo..=hi], &x[lo * per..(hi + 1) * per], k - lo) {
                Some(local) => {
                    knots.remove(k);
                    x.splice(lo * per..(hi + 1) * per, local);
                }
                None => k += 1,
            }
        }
    }
}

/// Per span between `knots`, whether to split it: those with a failing
/// sample, and where a span has no sample inside, the nearest span on each
/// side that has one (the least-squares compromise there is what pulls the
/// keys off).
fn spans_to_split(knots: &[usize], solved: &Solved) -> Vec<bool> {
    let spans = knots.len() - 1;
    let wide = |k: usize| knots[k + 1] - knots[k] >= 2;
    let mut split = vec![false; spans];
    for (k, w) in knots.windows(2).enumerate() {
        let worst = solved.ratio[w[0]..=w[1]]
            .iter()
            .copied()
            .fold(0.0, f64::max);
        if worst <= 1.0 && !solved.flipped[k] {
            continue;
        }
        if wide(k) {
            split[k] = true;
        } else {
            if let Some(l) = (0..k).rev().find(|&l| wide(l)) {
                split[l] = true;
            }
            if let Some(r) = (k + 1..spans).find(|&r| wide(r)) {
                split[r] = true;
            }
        }
    }
    split
}

/// Keys on each side of a removed one that are refitted.
const WINDOW: usize = 3;

fn argmax(v: &[f64]) -> usize {
    let mut best = 0;
    for (i, x) in v.iter().enumerate() {
        if *x > v[best] {
            best = i;
        }
    }
    best
}

struct Problem<'a> {
    times: &'a [f64],
    series: &'a [Series<'a>],
    tangents: Tangents,
    cols: usize,
}

struct Solved {
    /// Per sample: the largest error / tolerance over the series.
    ratio: Vec<f64>,
    /// Per span: a rotation's consecutive keys point to opposite hemispheres.
    flipped: Vec<bool>,
}

impl Solved {
    fn holds(&self) -> bool {
        self.ratio.iter().all(|r| *r <= 1.0) && !self.flipped.iter().any(|f| *f)
    }
}

/// The `adjusted` rule's chord weights with t = c = b = 0.
fn weights(d_in: f64, d_out: f64) -> ChordWeights {
    ChordWeights::new(TangentRule::Adjusted, Tcb::DEFAULT, d_in, d_out)
}

impl Problem<'_> {
    fn unknowns(&self, keys: usize) -> usize {
        match self.tangents {
            Tangents::Explicit => 2 * keys,
            _ => keys,
        }
    }

    /// The unknown holding key `k`'s value.
    fn value_unknown(&self, k: usize) -> usize {
        match self.tangents {
            Tangents::Explicit => 2 * k,
            _ => k,
        }
    }

    /// The design row of `time` in span `k` of `knots`.
    fn row(&self, knots: &[usize], k: usize, time: f64) -> Row {
        let (t0, t1) = (self.times[knots[k]], self.times[knots[k + 1]]);
        let d = t1 - t0;
        let u = ((time - t0) / d).clamp(0.0, 1.0);
        let h = hermite_basis(u);
        match self.tangents {
            Tangents::Explicit => Row {
                start: 2 * k,
                coeffs: [h[0], h[2] * d, h[1], h[3] * d],
            },
            _ => {
                let last = knots.len() - 1;
                let interval = |j: usize| self.times[knots[j + 1]] - self.times[knots[j]];
                // Coefficients over P_{k-1} .. P_{k+2} (index 0..4).
                let mut c = [0.0; WIDTH];
                c[1] += h[0];
                c[2] += h[1];
                // DD_k (h3)
                if k == 0 {
                    let w = weights(d, d);
                    let s = w.out_a + w.out_b;
                    c[1] -= h[2] * s;
                    c[2] += h[2] * s;
                } else {
                    let w = weights(interval(k - 1), d);
                    c[0] -= h[2] * w.out_a;
                    c[1] += h[2] * (w.out_a - w.out_b);
                    c[2] += h[2] * w.out_b;
                }
                // DS_{k+1} (h4)
                if k + 1 == last {
                    let w = weights(d, d);
                    let s = w.in_a + w.in_b;
                    c[1] -= h[3] * s;
                    c[2] += h[3] * s;
                } else {
                    let w = weights(d, interval(k + 1));
                    c[1] -= h[3] * w.in_a;
                    c[2] += h[3] * (w.in_a - w.in_b);
                    c[3] += h[3] * w.in_b;
                }
                if k == 0 {
                    Row {
                        start: 0,
                        coeffs: [c[1], c[2], c[3], 0.0],
                    }
                } else {
                    Row {
                        start: k - 1,
                        coeffs: c,
                    }
                }
            }
        }
    }

    /// Rows of every sample in `range`, on `knots`.
    fn rows(&self, knots: &[usize], range: std::ops::Range<usize>) -> Vec<Row> {
        let mut k = knots
            .partition_point(|&kn| kn < range.start)
            .saturating_sub(1);
        range
            .map(|i| {
                while k + 2 < knots.len() && i > knots[k + 1] {
                    k += 1;
                }
                self.row(knots, k, self.times[i])
            })
            .collect()
    }

    /// The targets of sample `i`, one per column.
    fn targets(&self, i: usize, y: &mut [f64]) {
        let mut c = 0;
        for s in self.series {
            y[c..c + s.dim].copy_from_slice(&s.samples[i][..s.dim]);
            c += s.dim;
        }
    }

    /// Normalize the values of rotation series at keys `keys`: clips
    /// normalize rotation keys when they are loaded, so the curve is
    /// measured through them as it will play.
    fn normalize(&self, x: &mut [f64], keys: std::ops::Range<usize>) {
        let mut col = 0;
        for s in self.series {
            if s.norm == Norm::Rotation {
                for key in keys.clone() {
                    let at = self.value_unknown(key) * self.cols + col;
                    let v = &mut x[at..at + 4];
                    let len = v.iter().map(|c| c * c).sum::<f64>().sqrt();
                    if len > 0.0 {
                        v.iter_mut().for_each(|c| *c /= len);
                    }
                }
            }
            col += s.dim;
        }
    }

    /// The least-squares fit on `knots`: the unknowns, `x[unknown * cols + col]`.
    fn solve(&self, knots: &[usize]) -> Option<Vec<f64>> {
        let n = self.times.len();
        let mut normal = Normal::new(self.unknowns(knots.len()), self.cols);
        let mut y = vec![0.0; self.cols];
        for (i, row) in self.rows(knots, 0..n).iter().enumerate() {
            self.targets(i, &mut y);
            normal.add(row, &y);
        }
        let mut x = normal.solve(1e-12)?;
        self.normalize(&mut x, 0..knots.len());
        Some(x)
    }

    /// The error of the samples in `range` for unknowns `x` on `knots`.
    /// `ratio` is indexed from `range.start`; `flipped` covers every span.
    fn evaluate(&self, knots: &[usize], x: &[f64], range: std::ops::Range<usize>) -> Solved {
        let spans = 0..knots.len() - 1;
        self.evaluate_spans(knots, x, range, spans)
    }

    /// [`Self::evaluate`] with `flipped` checked only for `spans` (false elsewhere).
    fn evaluate_spans(
        &self,
        knots: &[usize],
        x: &[f64],
        range: std::ops::Range<usize>,
        spans: std::ops::Range<usize>,
    ) -> Solved {
        let first = range.start;
        let rows = self.rows(knots, range);
        let mut ratio = vec![0.0f64; rows.len()];
        let mut f = [0.0; 4];
        let mut col = 0;
        for s in self.series {
            for (r, row) in rows.iter().enumerate() {
                for (c, f) in f.iter_mut().enumerate().take(s.dim) {
                    *f = row.dot(x, self.cols, col + c);
                }
                let e = error(s.norm, &f, &s.samples[first + r], s.dim);
                ratio[r] = ratio[r].max(e / s.tol);
            }
            col += s.dim;
        }
        let mut flipped = vec![false; knots.len() - 1];
        let mut col = 0;
        for s in self.series {
            if s.norm == Norm::Rotation {
                let value = |key: usize, c: usize| x[self.value_unknown(key) * self.cols + col + c];
                for (k, flip) in flipped
                    .iter_mut()
                    .enumerate()
                    .take(spans.end)
                    .skip(spans.start)
                {
                    let dot: f64 = (0..4).map(|c| value(k, c) * value(k + 1, c)).sum();
                    *flip |= dot <= 0.0;
                }
            }
            col += s.dim;
        }
        Solved { ratio, flipped }
    }

    /// The unknowns with key `k` of `knots` removed and the keys within
    /// [`WINDOW`] of it refitted (the others held), if every sample that
    /// changes stays within tolerance.
    fn without(&self, knots: &[usize], x: &[f64], k: usize) -> Option<Vec<f64>> {
        let per = self.unknowns(1);
        let cols = self.cols;
        let mut fewer = knots.to_vec();
        fewer.remove(k);
        let mut x2 = x.to_vec();
        x2.drain(k * per * cols..(k + 1) * per * cols);
        // Free keys (new indices), and the spans whose rows touch them.
        let (k0, k1) = (
            k.saturating_sub(WINDOW),
            (k + WINDOW - 1).min(fewer.len() - 1),
        );
        let reach = match self.tangents {
            Tangents::Explicit => (1, 0),
            _ => (2, 1),
        };
        let s0 = k0.saturating_sub(reach.0);
        let s1 = (k1 + reach.1).min(fewer.len() - 2);
        let range = fewer[s0]..fewer[s1 + 1] + 1;
        let (u0, u1) = (k0 * per, (k1 + 1) * per);
        let mut normal = Normal::new(u1 - u0, cols);
        let mut y = vec![0.0; cols];
        for (r, row) in self.rows(&fewer, range.clone()).iter().enumerate() {
            self.targets(range.start + r, &mut y);
            let mut local = Row {
                start: 0,
                coeffs: [0.0; WIDTH],
            };
            let first = row.start.max(u0);
            local.start = first - u0;
            for (j, &c) in row.coeffs.iter().enumerate() {
                let u = row.start + j;
                if (u0..u1).contains(&u) {
                    local.coeffs[u - first] = c;
                } else if u < fewer.len() * per {
                    for (col, y) in y.iter_mut().enumerate() {
                        *y -= c * x2[u * cols + col];
                    }
                }
            }
            normal.add(&local, &y);
        }
        let local = normal.solve(1e-12)?;
        x2[u0 * cols..u1 * cols].copy_from_slice(&local);
        self.normalize(&mut x2, k0..k1 + 1);
        let solved = self.evaluate_spans(&fewer, &x2, range, s0..s1 + 1);
        let flips = &solved.flipped[s0..=s1];
        (solved.ratio.iter().all(|r| *r <= 1.0) && !flips.iter().any(|f| *f)).then_some(x2)
    }

    fn finish(&self, knots: &[usize], x: &[f64]) -> Fit {
        let mut values = Vec::new();
        let mut tangents = Vec::new();
        let mut col = 0;
        let stride = self.cols;
        for s in self.series {
            let get = |unknown: usize| {
                let mut v = [0.0; 4];
                v[..s.dim].copy_from_slice(&x[unknown * stride + col..][..s.dim]);
                v
            };
            match self.tangents {
                Tangents::Explicit => {
                    values.push((0..knots.len()).map(|k| get(2 * k)).collect());
                    tangents.push((0..knots.len()).map(|k| get(2 * k + 1)).collect());
                }
                _ => {
                    values.push((0..knots.len()).map(get).collect());
                    tangents.push(Vec::new());
                }
            }
            col += s.dim;
        }
        Fit {
            knots: knots.to_vec(),
            values,
            tangents,
            mode: self.tangents,
        }
    }
}

/// The error of curve value `f` against sample `y` in `norm`.
pub fn error(norm: Norm, f: &[f64; 4], y: &[f64; 4], dim: usize) -> f64 {
    match norm {
        Norm::MaxAbs => (0..dim).map(|c| (f[c] - y[c]).abs()).fold(0.0, f64::max),
        Norm::Euclid => (0..dim).map(|c| (f[c] - y[c]).powi(2)).sum::<f64>().sqrt(),
        Norm::Rotation => {
            // Both normalized: 1 - dot² would amplify a sample's own
            // rounding off unit length (1e-7) to sqrt(2e-7).
            let len = |v: &[f64; 4]| v.iter().map(|c| c * c).sum::<f64>().sqrt();
            let (lf, ly) = (len(f), len(y));
            if !(lf > 0.0 && ly > 0.0) {
                return f64::INFINITY;
            }
            let dot = (0..4).map(|c| f[c] * y[c]).sum::<f64>() / (lf * ly);
            (1.0 - dot * dot).max(0.0).sqrt()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest error at the samples of the curve tcb-core builds from
    /// `fit` (as a written clip plays it, not the fitter's own evaluation).
    fn played_error(times: &[f64], y: &[[f64; 4]], fit: &Fit) -> f64 {
        use tcb_core::{KeyParams, Track, TrackSettings};
        let key_times = fit.knots.iter().map(|&k| times[k]).collect();
        let values = fit.values[0].iter().map(|v| v[0] as f32).collect();
        let keys = fit.tangents[0]
            .iter()
            .map(|g| KeyParams {
                tangent_in: Some(g[0] as f32),
                tangent_out: Some(g[0] as f32),
                ..KeyParams::default()
            })
            .collect();
        let track = Track::new(key_times, values, keys, &TrackSettings::default()).unwrap();
        times
            .iter()
            .zip(y)
            .map(|(&t, y)| (f64::from(track.sample(t)) - y[0]).abs())
            .fold(0.0, f64::max)
    }

    fn samples(n: usize, f: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<[f64; 4]>) {
        let times: Vec<f64> = (0..n).map(|i| i as f64 / (n - 1) as f64 * 2.0).collect();
        let values = times.iter().map(|&t| [f(t), 0.0, 0.0, 0.0]).collect();
        (times, values)
    }

    #[test]
    fn a_cubic_needs_two_keys_with_explicit_tangents() {
        let (times, y) = samples(41, |t| t * t * t - 2.0 * t + 1.0);
        let s = [Series {
            dim: 1,
            samples: &y,
            norm: Norm::MaxAbs,
            tol: 1e-9,
        }];
        let fit = fit(&times, &s, Tangents::Explicit).unwrap();
        assert_eq!(fit.knots, [0, 40]);
        assert!((fit.values[0][0][0] - 1.0).abs() < 1e-9);
        assert!((fit.tangents[0][1][0] - 10.0).abs() < 1e-8); // 3 t² - 2 at t = 2
    }

    #[test]
    fn a_line_needs_two_keys_with_derived_tangents() {
        let (times, y) = samples(41, |t| 3.0 * t - 1.0);
        let s = [Series {
            dim: 1,
            samples: &y,
            norm: Norm::MaxAbs,
            tol: 1e-9,
        }];
        let fit = fit(&times, &s, Tangents::Derived).unwrap();
        assert_eq!(fit.knots, [0, 40]);
    }

    #[test]
    fn every_sample_is_within_tolerance_and_tighter_needs_more_keys() {
        let (times, y) = samples(401, |t| (5.0 * t).sin() + 0.3 * (17.0 * t).cos());
        let mut counts = Vec::new();
        for mode in [Tangents::Explicit, Tangents::Derived] {
            for tol in [1e-2, 1e-4] {
                let s = [Series {
                    dim: 1,
                    samples: &y,
                    norm: Norm::MaxAbs,
                    tol,
                }];
                let fit = fit(&times, &s, mode).unwrap();
                let e = played_error(&times, &y, &fit);
                assert!(e <= tol + 1e-6, "{mode:?} {tol}: {e}");
                counts.push(fit.knots.len());
            }
        }
        assert!(counts[0] < counts[1] && counts[2] < counts[3], "{counts:?}");
    }

    #[test]
    fn a_jump_gets_keys_on_both_sides_and_nan_fails() {
        let (times, y) = samples(81, |t| if t > 1.0 { 1.0 } else { 0.0 });
        let s = [Series {
            dim: 1,
            samples: &y,
            norm: Norm::MaxAbs,
            tol: 1e-6,
        }];
        for mode in [Tangents::Explicit, Tangents::Derived] {
            let fit = fit(&times, &s, mode).unwrap();
            assert!(played_error(&times, &y, &fit) <= 2e-6, "{mode:?}");
            assert!(
                fit.knots.contains(&40) && fit.knots.contains(&41),
                "{:?}",
                fit.knots
            );
            assert!(fit.knots.len() < 20, "{:?}", fit.knots);
        }
        let mut bad = y.clone();
        bad[7][0] = f64::NAN;
        let s = [Series {
            samples: &bad,
            ..s[0].clone()
        }];
        assert!(fit(&times, &s, Tangents::Derived).is_none());
    }

    #[test]
    fn rotation_error_is_the_half_angle_sine() {
        let half = 0.01f64;
        let q = [0.0, 0.0, half.sin(), half.cos()];
        let e = error(Norm::Rotation, &[0.0, 0.0, 0.0, 2.0], &q, 4);
        assert!((e - half.sin()).abs() < 1e-15);
    }
}
