//! `tcb compress`: a packed clip ([`tcb_runtime::pack`]) whose quantization
//! steps are the coarsest this search finds within the tolerance of
//! `docs/reduce.md`'s metric, measured on the runtime that plays it.
//!
//! 1. Every track gets a step from a budget: the tolerance shared by the
//!    tracks on the longest chain through its joint and, for rotations,
//!    divided by the lever `L` (the longest rest chain below the joint plus
//!    the shell radius), as `tcb reduce` budgets its fits:
//!    `step = kappa e / (sqrt(3) L)` for a rotation (three components off by
//!    `step / 2` turn it by at most `sqrt(3) step`), `2 kappa e / sqrt(3)`
//!    for a translation.
//! 2. `kappa` is bisected on the measured error (every check time of the
//!    contract, every joint and End Site, FK in f64).
//! 3. Rounds of rebalancing: each track's step is scaled by the slack of
//!    the joints it moves (`(1 / r)^0.5`, r the largest error ratio in its
//!    subtree), and `kappa` bisected again; the smallest file that holds is
//!    kept.
//! 4. Per block of keys, a factor on every step of the grid
//!    ([`tcb_runtime::BlockScales`]), bisected in all blocks at once on the
//!    error at the check times each block's keys reach: the steps of step
//!    3 hold in the block where the error is largest, and the others have
//!    room.
//!
//! Nothing is returned that was not measured within the tolerance.

use crate::metric::{self, Measured, Worst};
use crate::reduce::{
    Metric, ReduceError, ReduceOptions, Reference, Settings, bound_joint, descends, resolve,
};
use std::sync::Arc;
use tcb_core::params::Ends;
use tcb_core::skeleton::Skeleton;
use tcb_core::{SourceClip, TrackKind};
use tcb_runtime::{BlockScales, KeyValues, Packed};

/// Options of [`compress`]; `None` takes the contract's default.
///
/// Start from [`Default`] and set fields with the builder methods, so that
/// a field added later does not break the code that builds these:
///
/// ```
/// use tcb_fit::CompressOptions;
/// let options = CompressOptions::default()
///     .tolerance(Some(0.01))
///     .seek_keys(Some(32));
/// assert_eq!(options.tolerance, Some(0.01));
/// assert_eq!(options.seek_keys, Some(32));
/// ```
///
/// The struct is `#[non_exhaustive]`: a struct literal does not compile
/// outside this crate.
///
/// ```compile_fail
/// let options = tcb_fit::CompressOptions {
///     tolerance: Some(0.01),
///     ..Default::default()
/// };
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct CompressOptions {
    /// `--tolerance E`.
    pub tolerance: Option<f64>,
    /// `--shell R`.
    pub shell: Option<f64>,
    /// `--metric shell|value`.
    pub metric: Option<Metric>,
    /// `--rotation-tolerance DEG` (`value`).
    pub rotation_tolerance: Option<f64>,
    /// `--seek-keys N`: keys per block (a seek decodes up to N - 1 keys);
    /// default [`tcb_runtime::pack::BLOCK_KEYS`].
    pub seek_keys: Option<usize>,
}

impl CompressOptions {
    /// These options with [`tolerance`](Self::tolerance) set to `tolerance` (`None`: the default).
    #[must_use]
    pub fn tolerance(mut self, tolerance: Option<f64>) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// These options with [`shell`](Self::shell) set to `radius` (`None`: the default).
    #[must_use]
    pub fn shell(mut self, radius: Option<f64>) -> Self {
        self.shell = radius;
        self
    }

    /// These options with [`metric`](Self::metric) set to `metric` (`None`: the default).
    #[must_use]
    pub fn metric(mut self, metric: Option<Metric>) -> Self {
        self.metric = metric;
        self
    }

    /// These options with [`rotation_tolerance`](Self::rotation_tolerance) set to `degrees` (`None`: the default).
    #[must_use]
    pub fn rotation_tolerance(mut self, degrees: Option<f64>) -> Self {
        self.rotation_tolerance = degrees;
        self
    }

    /// These options with [`seek_keys`](Self::seek_keys) set to `keys` (`None`: the default).
    #[must_use]
    pub fn seek_keys(mut self, keys: Option<usize>) -> Self {
        self.seek_keys = keys;
        self
    }
}

/// The packed clip and what was measured.
#[derive(Clone, Debug)]
pub struct Compressed {
    /// The clip (its `note` says how it was made).
    pub packed: Packed,
    /// The values used.
    pub settings: Settings,
    /// The measured error, by the metric, on the runtime.
    pub worst: Worst,
    /// The file's bytes.
    pub bytes: usize,
    /// Values stored (keys times stored components).
    pub values: usize,
    /// Clips built and measured by the search.
    pub evaluations: usize,
}

impl Compressed {
    /// Bits of the file per stored value.
    pub fn bits_per_value(&self) -> f64 {
        8.0 * self.bytes as f64 / self.values.max(1) as f64
    }

    /// The last line `tcb compress` prints.
    pub fn summary_line(&self) -> String {
        format!(
            "compressed: tracks {}, keys {}, values {}, bytes {}, {:.2} bits per value, max error {:e} ({}, joint {}, time {})",
            self.packed.head().tracks.len() + self.packed.head().loose.len(),
            self.packed.head().keys,
            self.values,
            self.bytes,
            self.bits_per_value(),
            self.worst.error,
            self.settings.metric.name(),
            self.worst.at,
            self.worst.time
        )
    }
}

/// Compress `clip` (with its `skeleton` for the shell metric). `progress`
/// is called with (clips measured, of about how many).
pub fn compress(
    clip: &SourceClip,
    skeleton: Option<&Skeleton>,
    options: &CompressOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Compressed, ReduceError> {
    let settings = resolve(
        &ReduceOptions {
            tolerance: options.tolerance,
            shell: options.shell,
            metric: options.metric,
            rotation_tolerance: options.rotation_tolerance,
            ..Default::default()
        },
        skeleton,
    )?;
    let times = metric::check_times(clip);
    if times.len() < 2 {
        return Err(ReduceError::Empty);
    }
    let block = options.seek_keys.unwrap_or(tcb_runtime::pack::BLOCK_KEYS);
    // The clip's keys, sampled once (refusing what cannot be packed before
    // searching), and each track's largest magnitude.
    let keys = KeyValues::sample(clip).map_err(|e| ReduceError::Option(e.to_string()))?;
    let largest: Vec<f64> = (0..clip.tracks().len())
        .map(|t| f64::from(keys.largest(t)).max(1.0))
        .collect();
    let reference = Reference::new(clip, skeleton, &times);
    let budget = Budget::new(clip, skeleton, &settings, &largest);
    // Clips measured: the rounds' bisections (9, then 6 each) and step 4's
    // (the CMU clip takes exactly these, 84).
    let total = 9 + 6 * (ROUNDS - 1) + BLOCK_ROUNDS + 1;
    let mut evaluations = 0usize;
    let mut measure = |steps: &[f32], scales: &BlockScales| -> Result<Trial, ReduceError> {
        evaluations += 1;
        progress(evaluations.min(total - 1), total);
        let packed = encode(&keys, steps, scales, block)?;
        let compiled = tcb_runtime::Clip::from_packed(Arc::new(packed.clone()))
            .map_err(|e| ReduceError::Build(e.to_string()))?;
        Ok((reference.measure(&settings, &Arc::new(compiled)), packed))
    };
    let (trial, steps) = search(&budget, &mut |steps| {
        measure(steps, &BlockScales::default())
    })?;
    // Tracks the shell metric does not see keep their fixed steps: no
    // factors where the grid has any.
    let grid = &trial.1.head().tracks;
    let fixed_on_grid = (clip.tracks().iter().zip(&budget.fixed))
        .any(|(t, f)| f.is_some() && grid.iter().any(|g| g.name == t.name));
    let (measured, mut packed) = if fixed_on_grid {
        trial
    } else {
        let blocks = BlockSearch::new(&trial.1, block, &times);
        blocks.search(trial, &mut |scales| measure(&steps, scales))?
    };
    progress(total, total);
    packed.note = format!(
        "tcb compress: metric {}, tolerance {:e}, shell {:e}, seek keys {block}, max error {:e} at {} time {}",
        settings.metric.name(),
        settings.tolerance,
        settings.shell,
        measured.worst.error,
        measured.worst.at,
        measured.worst.time
    );
    packed.skeleton = skeleton.cloned();
    let bytes = check_written(&packed)?;
    let values = packed.head().stored_values();
    Ok(Compressed {
        packed,
        settings,
        worst: measured.worst,
        bytes,
        values,
        evaluations,
    })
}

/// A packed clip and its error as measured.
type Trial = (Measured, Packed);

/// The clip's keys quantized at `steps` (per track, the grid's times the
/// blocks' `scales`) and packed in blocks of `block` keys.
fn encode(
    keys: &KeyValues,
    steps: &[f32],
    scales: &BlockScales,
    block: usize,
) -> Result<Packed, ReduceError> {
    let source = keys
        .quantize_scaled(steps, scales)
        .map_err(|e| ReduceError::Option(e.to_string()))?;
    Packed::encode_with(&source, block)
        .map_err(|e| ReduceError::Option(format!("--seek-keys: {e}")))
}

/// Steps 2 and 3: rounds of bisecting kappa, then rebalancing the tracks'
/// weights by their slack; the smallest file that held, with what was
/// measured on it, and its steps. `measure` packs and measures the clip at
/// per-track steps.
fn search(
    budget: &Budget,
    measure: &mut dyn FnMut(&[f32]) -> Result<Trial, ReduceError>,
) -> Result<(Trial, Vec<f32>), ReduceError> {
    // Per track a relative weight (rebalanced below) times kappa.
    let mut weight = vec![1.0f64; budget.unit.len()];
    let mut best: Option<(usize, Measured, Packed, Vec<f32>)> = None;
    for round in 0..ROUNDS {
        // Every round bisects the whole range (later rounds, with weights
        // rebalanced, fewer times).
        let iterations = if round == 0 { 9 } else { 6 };
        let (m, p, steps) = bisect_kappa(iterations, &|k| budget.steps(k, &weight), measure)?;
        if m.worst.ratio > 1.0 {
            // Nothing at this round's weights holds: keep the best.
            if best.is_some() {
                break;
            }
            return Err(ReduceError::CannotMeet {
                ratio: m.worst.ratio,
                worst: m.worst,
            });
        }
        let bytes = p.to_bytes().len();
        if best.as_ref().is_none_or(|b| bytes < b.0) {
            best = Some((bytes, m.clone(), p, steps));
        }
        // Rebalance: tracks whose joints have slack get coarser.
        for (t, w) in weight.iter_mut().enumerate() {
            let r = budget.slack(t, &m.each);
            *w *= (1.0 / r.max(0.05)).sqrt().min(4.0);
        }
    }
    let (_, measured, packed, steps) = best.expect("a round that holds, or an error above");
    Ok(((measured, packed), steps))
}

/// Rounds of bisecting kappa: on CMU 01_01 at ACL's target the file takes
/// 186,948 bytes after 4 rounds (27 clips measured), 184,056 after 8 and
/// 12; every 4th frame 61,569, 61,145 and 60,656 bytes; at the default
/// tolerance 193,966 bytes each.
const ROUNDS: usize = 12;

/// Bisect kappa (log scale, `iterations` times) between one that holds
/// (0.25 is taken to) and one that does not (64): the last kappa that
/// held, or, if none did, the clip at 0.25, measured (which may not hold);
/// with its steps.
fn bisect_kappa(
    iterations: usize,
    steps_at: &dyn Fn(f64) -> Vec<f32>,
    measure: &mut dyn FnMut(&[f32]) -> Result<Trial, ReduceError>,
) -> Result<(Measured, Packed, Vec<f32>), ReduceError> {
    let (mut lo, mut hi) = (0.25f64, 64.0f64);
    let mut last_ok = None;
    for _ in 0..iterations {
        let mid = (lo * hi).sqrt();
        let steps = steps_at(mid);
        let (m, p) = measure(&steps)?;
        if m.worst.ratio <= 1.0 {
            lo = mid;
            last_ok = Some((m, p, steps));
        } else {
            hi = mid;
        }
    }
    match last_ok {
        Some(x) => Ok(x),
        None => {
            let steps = steps_at(lo);
            let (m, p) = measure(&steps)?;
            Ok((m, p, steps))
        }
    }
}

/// Step 4: per block of keys a factor on the grid's steps.
struct BlockSearch {
    /// Keys per block, and blocks of the grid.
    block: usize,
    blocks: usize,
    /// Per check time, the blocks whose keys it depends on.
    reach: Vec<Reach>,
}

/// The blocks `first ..= last`, and with `ends` the first and the last.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Reach {
    first: usize,
    last: usize,
    ends: bool,
}

/// The blocks (of `block` keys, of a grid of `n`) whose keys the grid's
/// values at `x` (in intervals from the first key) depend on: between keys
/// `k` and `k + 1`, keys `k - 1 ..= k + 2` (which make the interval's
/// tangents), and with `cyclic` ends the other end's too where those pass
/// an end. Outside the grid (extrapolated: `repeat` reads any key) or at
/// NaN, every block.
fn reach(n: usize, block: usize, cyclic: bool, x: f64) -> Reach {
    let last_key = (n - 1) as f64;
    if !(x >= -1e-6 && x <= last_key + 1e-6) {
        return Reach {
            first: 0,
            last: (n - 1) / block,
            ends: false,
        };
    }
    let k = (x.max(0.0).floor() as usize).min(n - 1);
    Reach {
        first: k.saturating_sub(1) / block,
        last: (k + 2).min(n - 1) / block,
        ends: cyclic && (k == 0 || k + 2 > n - 1),
    }
}

/// Rounds of step 4: enough to bisect a code of 8 bits.
const BLOCK_ROUNDS: usize = 8;

impl BlockSearch {
    fn new(packed: &Packed, block: usize, times: &[f64]) -> Self {
        let head = packed.head();
        let cyclic = head.tracks.iter().any(|t| t.settings.ends == Ends::Cyclic);
        let reach = times
            .iter()
            .map(|&t| reach(head.keys, block, cyclic, (t - head.start) / head.interval))
            .collect();
        BlockSearch {
            block,
            blocks: head.keys.div_ceil(block),
            reach,
        }
    }

    /// From `start` (every factor 1, within the tolerance): each block's
    /// code bisected between one that held (0) and one taken not to (256),
    /// all blocks in each measured clip, a block failing where a check time
    /// it reaches is over the tolerance. The smallest clip measured within
    /// the tolerance is returned.
    fn search(
        &self,
        start: Trial,
        measure: &mut dyn FnMut(&BlockScales) -> Result<Trial, ReduceError>,
    ) -> Result<Trial, ReduceError> {
        let bytes = |t: &Trial| t.1.to_bytes().len();
        let mut best = (bytes(&start), start);
        let (mut lo, mut hi) = (vec![0u16; self.blocks], vec![256u16; self.blocks]);
        let scales = |codes: &[u16]| BlockScales {
            keys: self.block,
            codes: codes.iter().map(|&c| c as u8).collect(),
        };
        for round in 0..=BLOCK_ROUNDS {
            // The last round measures what held in every block.
            let last = round == BLOCK_ROUNDS;
            let mid: Vec<u16> = if last {
                lo.clone()
            } else {
                lo.iter().zip(&hi).map(|(a, b)| (a + b) / 2).collect()
            };
            if mid.iter().all(|c| *c == 0) {
                break;
            }
            let trial = measure(&scales(&mid))?;
            let mut failed = vec![false; self.blocks];
            for (&r, reach) in trial.0.at_time.iter().zip(&self.reach) {
                if r > 1.0 {
                    failed[reach.first..=reach.last].fill(true);
                    if reach.ends {
                        failed[0] = true;
                        failed[self.blocks - 1] = true;
                    }
                }
            }
            let size = bytes(&trial);
            if trial.0.worst.ratio <= 1.0 && size < best.0 {
                best = (size, trial);
            }
            if last {
                break;
            }
            for b in 0..self.blocks {
                if failed[b] {
                    hi[b] = mid[b];
                } else {
                    lo[b] = mid[b];
                }
            }
        }
        Ok(best.1)
    }
}

/// The file's size, once checked: what is written must read back as it is
/// (the checks of a file read are not the encoder's), and the runtime
/// plays its keys as the reference compiles them, bit for bit (a loader
/// does not decode them all to check it).
fn check_written(packed: &Packed) -> Result<usize, ReduceError> {
    let file = packed.to_bytes();
    if Packed::from_bytes(&file).as_ref() != Ok(packed) {
        return Err(ReduceError::Build(
            "the packed clip does not read back from its bytes".into(),
        ));
    }
    tcb_runtime::Clip::from_packed(Arc::new(packed.clone()))
        .and_then(|c| c.verify_packed())
        .map_err(|e| ReduceError::Build(e.to_string()))?;
    Ok(file.len())
}

/// Per track: its share of the tolerance in its own units.
struct Budget {
    /// Per track: the step at kappa = 1.
    unit: Vec<f64>,
    /// Per track: the finest step it may take (its integers stay below
    /// 2^22), and a fixed step for a track the shell metric does not see:
    /// 2e-4, so that it is within 1e-4 per component, the `value`
    /// metric's default (docs/reduce.md), whatever kappa is.
    finest: Vec<f64>,
    fixed: Vec<Option<f64>>,
    /// Per track: the joints (shell) or the track itself (value) its error reaches.
    reaches: Vec<Vec<usize>>,
}

impl Budget {
    fn new(clip: &SourceClip, skeleton: Option<&Skeleton>, s: &Settings, largest: &[f64]) -> Self {
        let finest: Vec<f64> = largest.iter().map(|m| m / f64::from(1u32 << 22)).collect();
        let sqrt3 = 3f64.sqrt();
        let tracks = clip.tracks();
        match (s.metric, skeleton) {
            (Metric::Shell, Some(sk)) => {
                let n = sk.joints().len();
                let joint: Vec<Option<usize>> = tracks
                    .iter()
                    .map(|t| bound_joint(sk, &t.name, t.data.kind()).map(|(j, _)| j))
                    .collect();
                // Longest rest chain below each joint, and tracks per chain.
                let mut reach = vec![0.0f64; n];
                let mut count = vec![0usize; n];
                for j in joint.iter().flatten() {
                    count[*j] += 1;
                }
                let mut down = count.clone();
                for j in (0..n).rev() {
                    if let Some(p) = sk.joints()[j].parent.filter(|&p| p < j) {
                        let off = f64::from(sk.joints()[j].rest.translation.length());
                        reach[p] = reach[p].max(reach[j] + off);
                        down[p] = down[p].max(count[p] + down[j]);
                    }
                }
                let mut up = count.clone();
                for j in 0..n {
                    if let Some(p) = sk.joints()[j].parent.filter(|&p| p < j) {
                        up[j] += up[p];
                    }
                }
                let fixed = joint.iter().map(|j| j.is_none().then_some(2e-4)).collect();
                let unit = tracks
                    .iter()
                    .zip(&joint)
                    .map(|(t, j)| {
                        let Some(j) = *j else {
                            return 1.0; // moves no joint: `fixed`
                        };
                        let e = s.tolerance / (up[j] + down[j] - count[j]).max(1) as f64;
                        match t.data.kind() {
                            TrackKind::Quat => e / (sqrt3 * (reach[j] + s.shell)),
                            _ => 2.0 * e / sqrt3,
                        }
                    })
                    .collect();
                let reaches = joint
                    .iter()
                    .map(|j| match j {
                        Some(a) => (0..n).filter(|&d| descends(sk, d, *a)).collect(),
                        None => Vec::new(),
                    })
                    .collect();
                Budget {
                    unit,
                    finest,
                    fixed,
                    reaches,
                }
            }
            _ => Budget {
                unit: tracks
                    .iter()
                    .map(|t| match t.data.kind() {
                        TrackKind::Quat => (s.rotation_tolerance.to_radians() / 2.0).sin() / sqrt3,
                        _ => 2.0 * s.tolerance / sqrt3,
                    })
                    .collect(),
                reaches: (0..tracks.len()).map(|i| vec![i]).collect(),
                finest,
                fixed: vec![None; tracks.len()],
            },
        }
    }

    fn steps(&self, kappa: f64, weight: &[f64]) -> Vec<f32> {
        (0..self.unit.len())
            .map(|t| {
                let step = self.fixed[t].unwrap_or(self.unit[t] * weight[t] * kappa);
                // (A track of values above 2^22 * 1e3 has a finest step above 1e3.)
                let finest = self.finest[t];
                step.clamp(finest, finest.max(1e3)) as f32
            })
            .collect()
    }

    /// The largest error ratio among what track `t` moves (1 if nothing).
    fn slack(&self, t: usize, each: &[f64]) -> f64 {
        self.reaches[t]
            .iter()
            .map(|&j| each[j])
            .fold(0.0, f64::max)
            .max(if self.reaches[t].is_empty() { 1.0 } else { 0.0 })
    }
}

#[cfg(test)]
mod tests {
    use super::{Reach, reach};

    /// The blocks a check time depends on: the keys around its interval,
    /// the other end's with cyclic ends, every block outside the grid.
    #[test]
    fn a_check_time_reaches_the_blocks_of_its_tangents_keys() {
        let r = |first, last, ends| Reach { first, last, ends };
        // 200 keys in blocks of 64: blocks 0 to 3.
        assert_eq!(reach(200, 64, false, 0.5), r(0, 0, false));
        assert_eq!(reach(200, 64, false, 62.25), r(0, 1, false));
        assert_eq!(reach(200, 64, false, 64.0), r(0, 1, false));
        assert_eq!(reach(200, 64, false, 65.0), r(1, 1, false));
        assert_eq!(reach(200, 64, false, 199.0), r(3, 3, false));
        assert_eq!(reach(200, 64, true, 0.5), r(0, 0, true));
        assert_eq!(reach(200, 64, true, 197.5), r(3, 3, false));
        assert_eq!(reach(200, 64, true, 198.5), r(3, 3, true));
        assert_eq!(reach(200, 64, true, 100.5), r(1, 1, false));
        for outside in [-0.5, 199.5, f64::NAN, f64::INFINITY] {
            assert_eq!(reach(200, 64, false, outside), r(0, 3, false));
        }
        // One block, shorter than a block.
        assert_eq!(reach(10, 64, false, 4.5), r(0, 0, false));
    }
}
