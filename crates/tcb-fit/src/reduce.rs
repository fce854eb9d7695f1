//! The whole reduction (`tcb reduce`, `docs/reduce.md`).
//!
//! 1. Play the input on the runtime at the check times (the reference).
//! 2. Give every track a tolerance of its own in its own units, such that
//!    the errors of all tracks together stay within the clip's tolerance:
//!
//!    ```text
//!    value    vectors: E per component; rotations: sin(θ/2) <= sin(θ_E/2)
//!    shell    a point x in joint a's frame moves by |(R'_a - R_a) x| <= 2 sin(θ_a/2) |x|
//!             when only a's rotation is off by θ_a, and by |Δt_a| when only its
//!             translation is; |x| <= L_a = (longest rest chain below a) + R.
//!             Errors along a chain add at worst, so each of the n tracks on the
//!             longest chain through a gets e = κ E / n:
//!             rotation sin(θ/2) <= e / (2 L_a), translation |Δt| <= e,
//!             scale |Δs| <= e / L_a.
//!    ```
//!
//!    κ = 1 is the guaranteed bound, but errors of a chain rarely line up:
//!    every group starts at κ = 16 and is tightened only where it is shown
//!    to be too loose.
//! 3. Fit each group of tracks sharing key times (`--knots`) with
//!    [`crate::fit::fit`], in parallel.
//! 4. Write the clip, build it, play it on the runtime, and measure the
//!    error by the contract's metric, per joint (or track). Groups that
//!    move a joint over the tolerance by r get κ / (1.05 r)^0.5 and are
//!    refitted; the others keep their fit. Only a clip that holds is
//!    returned.
//! 5. Bytes: fits that keep most of their keys (a loose lane stores about
//!    twice a shared grid's bytes per key) are put back on the input's
//!    keys, those keeping the largest share first, where the compiled clip
//!    gets smaller and still holds.
//! 6. Speed ([`ReduceOptions::speed`]): a fit taken off the input's
//!    shared key grid plays as a loose lane, dearer per frame than its lane
//!    in the grid's blocks ([`crate::cost`]). Where the clip's estimated
//!    cost per frame is above the input's, fitted tracks (not those of 2
//!    keys) are put back on the input's keys where that brings it within
//!    the input's cost, with the fewest bytes: by default ([`Speed::Balanced`])
//!    only when the fits save a smaller share of the input's bytes than
//!    they add to its cost (capture, where most tracks stay dense), always
//!    with [`Speed::NeverSlower`], never with [`Speed::FewestBytes`]. Where
//!    nothing brings it within, the fewest bytes are kept. Either way both
//!    costs are reported.
//!
//! Tracks the fitter does not take are kept as they are (exact): tracks
//! whose `linear` or `offset-repeat` extrapolation is checked outside their
//! keys, tracks no joint uses (under `shell`), and tracks whose fit would
//! store as many numbers as they already do.

use crate::cost;
use crate::fit::{self, Fit, Norm, Series, Tangents};
use crate::metric::{self, Worst};
use rayon::prelude::*;
use std::fmt;
use std::str::FromStr;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use tcb_core::skeleton::Skeleton;
use tcb_core::{
    Ends, Extrapolation, Hemisphere, RotationMode, SourceClip, TangentRule, TrackKind,
    TrackSettings,
};
use tcb_io::{ClipDoc, KeyDoc, SettingsDoc, TrackDoc};

/// The error measure (`--metric`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    /// Model-space error of virtual points around each joint (needs a skeleton).
    Shell,
    /// Per component for vectors, angle for rotations.
    Value,
}

impl Metric {
    /// The contract's name.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Shell => "shell",
            Metric::Value => "value",
        }
    }
}

impl FromStr for Metric {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "shell" => Ok(Metric::Shell),
            "value" => Ok(Metric::Value),
            _ => Err(format!("unknown metric '{s}' (expected shell or value)")),
        }
    }
}

/// Which tracks share key times (`--knots`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Knots {
    /// Every track has its own key times (fewest keys).
    #[default]
    Track,
    /// The tracks of one joint (`<joint>.translation`, `.rotation`, `.scale`) share them.
    Joint,
    /// Every track shares them (one Hermite row per frame for the whole clip).
    Clip,
}

impl Knots {
    /// The contract's name.
    pub fn name(self) -> &'static str {
        match self {
            Knots::Track => "track",
            Knots::Joint => "joint",
            Knots::Clip => "clip",
        }
    }
}

impl FromStr for Knots {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "track" => Ok(Knots::Track),
            "joint" => Ok(Knots::Joint),
            "clip" => Ok(Knots::Clip),
            _ => Err(format!(
                "unknown knot sharing '{s}' (expected track, joint or clip)"
            )),
        }
    }
}

/// Options of [`reduce`]; `None` takes the contract's default.
///
/// Start from [`Default`] and set fields with the builder methods, so that
/// a field added later does not break the code that builds these:
///
/// ```
/// use tcb_fit::{Knots, Metric, ReduceOptions};
/// let options = ReduceOptions::default()
///     .tolerance(Some(0.01))
///     .metric(Some(Metric::Value))
///     .knots(Knots::Clip);
/// assert_eq!(options.tolerance, Some(0.01));
/// assert_eq!(options.knots, Knots::Clip);
/// ```
///
/// The struct is `#[non_exhaustive]`: a struct literal does not compile
/// outside this crate.
///
/// ```compile_fail
/// let options = tcb_fit::ReduceOptions {
///     tolerance: Some(0.01),
///     ..Default::default()
/// };
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct ReduceOptions {
    /// `--tolerance E` (model-space distance for `shell`, track units for `value`).
    pub tolerance: Option<f64>,
    /// `--shell R`, the radius of the virtual points.
    pub shell: Option<f64>,
    /// `--metric`; default `shell` with a skeleton, else `value`.
    pub metric: Option<Metric>,
    /// `--rotation-tolerance DEG` (`value`).
    pub rotation_tolerance: Option<f64>,
    /// `--knots`.
    pub knots: Knots,
    /// Stored or derived tangents (`--tangents`).
    pub tangents: Tangents,
    /// When fitted tracks go back on their input's shared key grid, at the
    /// cost of bytes, because the reduced clip would otherwise cost more
    /// per frame than its source by [`crate::cost::frame_cost`]
    /// (`--speed`; both costs are reported: [`Reduced::before_cost`],
    /// [`Reduced::after_cost`]).
    pub speed: Speed,
}

/// When [`reduce`] trades bytes for speed (step 6 of the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Speed {
    /// Put fits back on the input's grid where the fewest bytes would cost
    /// a larger share more per frame than they save of the input's bytes
    /// (`(after - before) / before` of the cost above `1 - after / before`
    /// of the compiled bytes). Capture, whose jitter leaves most tracks
    /// dense, plays no slower; a smooth clip keeps its few keys.
    #[default]
    Balanced,
    /// Put fits back wherever the fewest bytes would play slower.
    NeverSlower,
    /// Keep the fewest bytes.
    FewestBytes,
}

impl std::str::FromStr for Speed {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "balanced" => Ok(Speed::Balanced),
            "never-slower" => Ok(Speed::NeverSlower),
            "fewest-bytes" => Ok(Speed::FewestBytes),
            _ => Err(format!(
                "unknown speed rule {s:?} (expected balanced, never-slower or fewest-bytes)"
            )),
        }
    }
}

impl ReduceOptions {
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

    /// These options with [`knots`](Self::knots) set to `knots`.
    #[must_use]
    pub fn knots(mut self, knots: Knots) -> Self {
        self.knots = knots;
        self
    }

    /// These options with [`tangents`](Self::tangents) set to `tangents`.
    #[must_use]
    pub fn tangents(mut self, tangents: Tangents) -> Self {
        self.tangents = tangents;
        self
    }

    /// These options with [`speed`](Self::speed) set to `rule`.
    #[must_use]
    pub fn speed(mut self, rule: Speed) -> Self {
        self.speed = rule;
        self
    }
}

/// What [`reduce`] reads.
#[derive(Clone, Copy, Debug)]
pub struct Input<'a> {
    /// The input as a document (its tracks' settings are kept).
    pub doc: &'a ClipDoc,
    /// The input, built.
    pub clip: &'a SourceClip,
    /// Its rig (BVH End Sites are leaf joints in it, as `tcb_io::load` gives them).
    pub skeleton: Option<&'a Skeleton>,
}

/// The values [`reduce`] worked with.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// The metric.
    pub metric: Metric,
    /// E.
    pub tolerance: f64,
    /// R (`shell`).
    pub shell: f64,
    /// Degrees (`value`).
    pub rotation_tolerance: f64,
    /// H, the skeleton's rest-pose height (0 without one).
    pub height: f64,
    /// Knot sharing.
    pub knots: Knots,
    /// Tangents.
    pub tangents: Tangents,
}

/// Counts of a clip, as the summary line gives them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Counts {
    /// Keys over all tracks.
    pub keys: usize,
    /// Stored numbers: each key's value and explicit tangents, all components.
    pub values: usize,
    /// The compiled runtime clip's memory ([`tcb_runtime::Clip::memory_bytes`]).
    pub bytes: usize,
}

/// One round of fitting and measuring.
#[derive(Clone, Debug, PartialEq)]
pub struct Attempt {
    /// Round, from 0.
    pub round: usize,
    /// Groups of tracks fitted this round (the others reused or kept).
    pub fitted: usize,
    /// Stored numbers written.
    pub values: usize,
    /// The measured error over the tolerance.
    pub ratio: f64,
    /// Where it was largest.
    pub worst: Worst,
}

/// The reduced clip and what was measured.
#[derive(Clone, Debug)]
pub struct Reduced {
    /// The clip to write.
    pub doc: ClipDoc,
    /// It, built (what was verified).
    pub clip: SourceClip,
    /// The values used.
    pub settings: Settings,
    /// The input's counts.
    pub before: Counts,
    /// The output's counts.
    pub after: Counts,
    /// The input's estimated runtime instructions per frame
    /// ([`crate::cost::frame_cost`]).
    pub before_cost: f64,
    /// The output's.
    pub after_cost: f64,
    /// The fewest bytes the fits gave, where they were declined for a
    /// clip within the input's cost ([`ReduceOptions::speed`]): their
    /// counts and estimated cost.
    pub declined: Option<(Counts, f64)>,
    /// The measured error of the output, by the metric, on the runtime.
    pub worst: Worst,
    /// Tracks kept as they were.
    pub kept: Vec<String>,
    /// Every round.
    pub attempts: Vec<Attempt>,
}

impl Reduced {
    /// The contract's last line.
    pub fn summary_line(&self) -> String {
        format!(
            "reduced: tracks {}, keys {} -> {}, values {} -> {}, bytes {} -> {}, max error {:e} ({}, joint {}, time {})",
            self.doc.tracks.len(),
            self.before.keys,
            self.after.keys,
            self.before.values,
            self.after.values,
            self.before.bytes,
            self.after.bytes,
            self.worst.error,
            self.settings.metric.name(),
            self.worst.at,
            self.worst.time
        )
    }
}

/// Why nothing was reduced.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ReduceError {
    /// An option is out of range.
    Option(String),
    /// `--metric shell` without a skeleton.
    NoSkeleton,
    /// Nothing to reduce.
    Empty,
    /// No clip within the tolerance was found.
    CannotMeet {
        /// Best error over tolerance reached.
        ratio: f64,
        /// Where.
        worst: Worst,
    },
    /// The reduced clip did not build (a bug).
    Build(String),
}

impl fmt::Display for ReduceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReduceError::Option(s) => f.write_str(s),
            ReduceError::NoSkeleton => f.write_str(
                "--metric shell needs a skeleton: this clip has none (BVH and glTF files carry one, and so do clips `tcb import` writes; or use --metric value)",
            ),
            ReduceError::Empty => f.write_str("the clip has no key times to reduce"),
            ReduceError::CannotMeet { ratio, worst } => write!(
                f,
                "cannot meet the tolerance: the best reduction found is {ratio:.3}x over it ({} at time {}); nothing written",
                worst.at, worst.time
            ),
            ReduceError::Build(s) => write!(f, "the reduced clip does not build: {s}"),
        }
    }
}

impl std::error::Error for ReduceError {}

/// The metric, tolerance, shell radius and rotation tolerance `options`
/// ask for, with the contract's defaults (`docs/reduce.md`): what `tcb
/// reduce` and `tcb compress` measure by.
pub fn resolve(
    options: &ReduceOptions,
    skeleton: Option<&Skeleton>,
) -> Result<Settings, ReduceError> {
    let input_skeleton = skeleton;
    let metric = match (options.metric, input_skeleton) {
        (Some(Metric::Shell), None) => return Err(ReduceError::NoSkeleton),
        (Some(m), _) => m,
        (None, Some(_)) => Metric::Shell,
        (None, None) => Metric::Value,
    };
    let height = input_skeleton.map_or(0.0, metric::rest_height);
    let tolerance = match options.tolerance {
        Some(e) => positive("--tolerance", e)?,
        None if metric == Metric::Shell => {
            if height.is_nan() || height <= 0.0 {
                return Err(ReduceError::Option(
                    "the skeleton's rest-pose height is zero: give --tolerance".into(),
                ));
            }
            6e-5 * height
        }
        None => 1e-4,
    };
    let shell = match options.shell {
        Some(r) if r >= 0.0 && r.is_finite() => r,
        Some(r) => {
            return Err(ReduceError::Option(format!(
                "--shell must be a number >= 0, got {r}"
            )));
        }
        None => 0.018 * height,
    };
    let rotation_tolerance = positive(
        "--rotation-tolerance",
        options.rotation_tolerance.unwrap_or(0.01),
    )?;
    Ok(Settings {
        metric,
        tolerance,
        shell,
        rotation_tolerance,
        height,
        knots: options.knots,
        tangents: options.tangents,
    })
}

/// Numbers stored by a track: each key's value and explicit tangents.
pub fn stored_values(track: &TrackDoc) -> usize {
    let dim = track.kind.dim();
    let tangents: usize = track
        .keys
        .iter()
        .map(|k| usize::from(k.tangent_in.is_some()) + usize::from(k.tangent_out.is_some()))
        .sum();
    dim * (track.times.len() + tangents)
}

fn counts(doc: &ClipDoc, compiled: &tcb_runtime::Clip) -> Counts {
    Counts {
        keys: doc.tracks.iter().map(|t| t.times.len()).sum(),
        values: doc.tracks.iter().map(stored_values).sum(),
        bytes: compiled.memory_bytes(),
    }
}

fn positive(name: &str, v: f64) -> Result<f64, ReduceError> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(ReduceError::Option(format!(
            "{name} must be a positive number, got {v}"
        )))
    }
}

/// Tolerance budget left for the fitter below the target, for f32 rounding
/// of the written keys and the runtime's own rounding.
const MARGIN: f64 = 0.9;

/// Rounds of budget refinement before giving up.
const MAX_ROUNDS: usize = 16;

/// A group over its tolerance by r is tightened by r^STEP per round: full
/// steps (1) tighten a root, which every joint's error involves, by the
/// worst ratio anywhere; smaller steps let the joints that recover stop
/// pulling it down.
const STEP: f64 = 0.5;

/// Below this budget scale a group is kept as it is.
const MIN_SCALE: f64 = 1.0 / 64.0;

/// Fits keeping fewer than this share of their track's keys are never put
/// back for bytes: a loose lane holds at most about 3.5 times a grid
/// lane's bytes per key (a scalar: time, order entry, `P TO TI`, against
/// `P TO`).
const MIN_SHARE: f64 = 0.25;

/// Reduce `input`. `progress(done, total)` is called as groups of tracks are
/// fitted (from several threads).
pub fn reduce(
    input: Input,
    options: &ReduceOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Reduced, ReduceError> {
    let settings = resolve(options, input.skeleton)?;
    let times = metric::check_times(input.clip);
    if times.len() < 2 {
        return Err(ReduceError::Empty);
    }
    // The input is compiled and played once: the reference for the fitter
    // and for every round's measurement.
    let reference = Reference::new(input.clip, input.skeleton, &times);
    let plan = Plan::new(input, &settings, &reference);
    let before = counts(input.doc, &reference.compiled);
    let verify = |clip: &Arc<tcb_runtime::Clip>| reference.measure(&settings, clip);
    let mut cache: Vec<Option<(f64, Option<Fit>)>> = vec![None; plan.groups.len()];
    let (fitted, attempts) = fit_in_rounds(&plan, &mut cache, &verify, progress)?;
    let best = put_back_for_bytes(&plan, &cache, fitted, &verify)?;
    let before_cost = cost::frame_cost(&reference.compiled, input.clip);
    let smallest = (
        counts(&best.doc, &best.compiled),
        cost::frame_cost(&best.compiled, &best.clip),
    );
    let put_back = match options.speed {
        Speed::FewestBytes => false,
        Speed::NeverSlower => true,
        Speed::Balanced => {
            let saved = 1.0 - smallest.0.bytes as f64 / before.bytes as f64;
            smallest.1 / before_cost - 1.0 > saved
        }
    };
    // The clip kept, its counts and cost, and the fewest bytes if declined.
    let (best, (after, after_cost), declined) = if !put_back {
        (best, smallest, None)
    } else {
        let faster = put_back_for_speed(&plan, &cache, best, &verify, before_cost)?;
        let kept = (
            counts(&faster.doc, &faster.compiled),
            cost::frame_cost(&faster.compiled, &faster.clip),
        );
        let declined = (kept.0 != smallest.0).then_some(smallest);
        (faster, kept, declined)
    };
    let kept = (0..best.kept.len())
        .filter(|&i| best.kept[i])
        .map(|i| input.clip.tracks()[i].name.clone())
        .collect();
    Ok(Reduced {
        doc: best.doc,
        clip: best.clip,
        settings,
        before,
        after,
        before_cost,
        after_cost,
        declined,
        worst: best.worst,
        kept,
        attempts,
    })
}

/// A written clip, built, compiled and measured.
struct Candidate {
    doc: ClipDoc,
    clip: SourceClip,
    compiled: Arc<tcb_runtime::Clip>,
    worst: Worst,
    /// Per track: kept as it was.
    kept: Vec<bool>,
}

/// The input as every candidate is measured against it: compiled once and
/// played at the check times.
pub(crate) struct Reference<'a> {
    /// The input.
    pub(crate) source: &'a SourceClip,
    /// Its rig (`shell`).
    pub(crate) skeleton: Option<&'a Skeleton>,
    /// The check times ([`metric::check_times`]).
    pub(crate) times: &'a [f64],
    /// The input on the runtime.
    pub(crate) compiled: Arc<tcb_runtime::Clip>,
    /// The input played at the check times ([`metric::play`]).
    pub(crate) rows: Vec<f32>,
}

impl<'a> Reference<'a> {
    /// `source` compiled and played at `times`.
    pub(crate) fn new(
        source: &'a SourceClip,
        skeleton: Option<&'a Skeleton>,
        times: &'a [f64],
    ) -> Self {
        let compiled = Arc::new(tcb_runtime::Clip::compile(source));
        let rows = metric::play(&compiled, times);
        Reference {
            source,
            skeleton,
            times,
            compiled,
            rows,
        }
    }

    /// The error of `clip` against the input by `settings`' metric.
    pub(crate) fn measure(
        &self,
        settings: &Settings,
        clip: &Arc<tcb_runtime::Clip>,
    ) -> metric::Measured {
        match settings.metric {
            Metric::Shell => metric::shell_error(
                self.skeleton.expect("shell has a skeleton"),
                &self.compiled,
                clip,
                self.times,
                settings.shell,
                settings.tolerance,
            ),
            Metric::Value => metric::value_error(
                self.source,
                &self.rows,
                clip,
                self.times,
                settings.tolerance,
                settings.rotation_tolerance,
            ),
        }
    }
}

/// `doc` built and compiled.
fn build(doc: &ClipDoc) -> Result<(SourceClip, Arc<tcb_runtime::Clip>), ReduceError> {
    let clip = doc.build().map_err(|e| ReduceError::Build(e.to_string()))?;
    let compiled = Arc::new(tcb_runtime::Clip::compile(&clip));
    Ok((clip, compiled))
}

/// Steps 3 and 4: rounds of fit, write, build and measure until the clip
/// holds, each round tightening the groups that moved a joint (or track)
/// over its tolerance; every round is an [`Attempt`].
fn fit_in_rounds(
    plan: &Plan,
    cache: &mut [Option<(f64, Option<Fit>)>],
    verify: &dyn Fn(&Arc<tcb_runtime::Clip>) -> metric::Measured,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(Candidate, Vec<Attempt>), ReduceError> {
    // Budgets: every group starts loose (κ = 16 for shell, whose bound is
    // loose; 1 for value, which is exact). After each round, the groups
    // that can move a joint (or track) measured over its tolerance are
    // tightened, and only they are fitted again.
    let start = match plan.settings.metric {
        Metric::Shell => 16.0,
        Metric::Value => 1.0,
    };
    let units = plan.units();
    let mut scale = vec![start; plan.groups.len()];
    let mut attempts = Vec::new();
    let mut round = 0;
    loop {
        let (doc, kept, fitted) = plan.run(&scale, cache, progress);
        let (clip, compiled) = build(&doc)?;
        let measured = verify(&compiled);
        attempts.push(Attempt {
            round,
            fitted,
            values: doc.tracks.iter().map(stored_values).sum(),
            ratio: measured.worst.ratio,
            worst: measured.worst.clone(),
        });
        if measured.worst.ratio <= 1.0 {
            let candidate = Candidate {
                doc,
                clip,
                compiled,
                worst: measured.worst,
                kept,
            };
            return Ok((candidate, attempts));
        }
        round += 1;
        if round == MAX_ROUNDS {
            return Err(ReduceError::CannotMeet {
                ratio: measured.worst.ratio,
                worst: measured.worst,
            });
        }
        tighten(plan, &units, &measured, &kept, &mut scale);
    }
}

/// New budget scales for the groups whose units (`units[g]`, from
/// [`Plan::units`]) were measured over their tolerance: r over it takes
/// `scale / (1.05 r)^STEP`; a group already kept as it was, or tightened
/// below [`MIN_SCALE`], goes to 0 (kept).
fn tighten(
    plan: &Plan,
    units: &[Vec<usize>],
    measured: &metric::Measured,
    kept: &[bool],
    scale: &mut [f64],
) {
    for (g, units) in units.iter().enumerate() {
        let over = units.iter().map(|&u| measured.each[u]).fold(0.0, f64::max);
        if over > 1.0 || over.is_nan() {
            // Kept at this budget: kept at any smaller one.
            let all_kept = plan.groups[g].iter().all(|&i| kept[i]);
            let next = scale[g] / (1.05 * over).powf(STEP);
            scale[g] = if all_kept || !next.is_finite() || next < MIN_SCALE {
                0.0
            } else {
                next
            };
        }
    }
}

/// Step 5, bytes: a fitted track on key times of its own plays as a loose
/// lane, which holds about twice the bytes per key of a key grid that
/// tracks share. A fit that keeps most of its keys can so make the clip
/// larger than keeping the original keys on the input's grid. The fits
/// that keep the largest share of their keys are put back (exact) in
/// prefixes of 1, 2, 4, ... tracks (compiled in parallel); the prefix whose
/// compiled clip is smallest is taken if it is smaller than `fitted` and
/// still holds.
fn put_back_for_bytes(
    plan: &Plan,
    cache: &[Option<(f64, Option<Fit>)>],
    fitted: Candidate,
    verify: &dyn Fn(&Arc<tcb_runtime::Clip>) -> metric::Measured,
) -> Result<Candidate, ReduceError> {
    let candidates = put_back_order(plan, &fitted);
    let revert = |size: usize| {
        let mut r = vec![false; plan.input.doc.tracks.len()];
        for &i in &candidates[..size] {
            r[i] = true;
        }
        r
    };
    let sizes: Vec<usize> = std::iter::successors(Some(1usize), |&n| Some(2 * n))
        .take_while(|&n| n < candidates.len())
        .chain((!candidates.is_empty()).then_some(candidates.len()))
        .collect();
    // Only the bytes are kept: one compiled clip per thread at a time.
    let tried: Vec<(usize, usize)> = sizes
        .par_iter()
        .map(|&size| {
            let (d, _) = plan.write_fits(cache, &revert(size));
            let (_, compiled) = build(&d)?;
            Ok((compiled.memory_bytes(), size))
        })
        .collect::<Result<_, ReduceError>>()?;
    let smallest = tried
        .into_iter()
        .filter(|&(bytes, _)| bytes < fitted.compiled.memory_bytes())
        .min();
    let Some((_, size)) = smallest else {
        return Ok(fitted);
    };
    let (doc, kept) = plan.write_fits(cache, &revert(size));
    let (clip, compiled) = build(&doc)?;
    let measured = verify(&compiled);
    if measured.worst.ratio > 1.0 {
        return Ok(fitted);
    }
    Ok(Candidate {
        doc,
        clip,
        compiled,
        worst: measured.worst,
        kept,
    })
}

/// Step 6, speed: the runtime samples every lane every frame, so a track
/// taken off a key grid it shared moves from a group's block to a loose
/// lane, which costs more per frame than the group's (several times more
/// per lane: [`crate::cost`]); a clip whose tracks mostly stay dense can so
/// play slower than its source. Unless `fitted` costs no more per frame
/// than `limit` (the source's cost), its fitted tracks of more than 2 keys
/// (docs/reduce.md: "a constant track becomes 2 keys") are put back on the
/// input's keys, those keeping the largest share of their keys first, in
/// every prefix (up to 48 tracks; beyond, 32 prefixes evenly spaced and
/// all of them), and the prefix of fewest bytes within `limit` is taken.
/// Where none is within it (tracks of 2 keys alone cost a loose block: the
/// CMU clip's four constant rotations), `fitted` is kept: the fewest bytes,
/// its cost reported by [`Reduced::after_cost`].
fn put_back_for_speed(
    plan: &Plan,
    cache: &[Option<(f64, Option<Fit>)>],
    fitted: Candidate,
    verify: &dyn Fn(&Arc<tcb_runtime::Clip>) -> metric::Measured,
    limit: f64,
) -> Result<Candidate, ReduceError> {
    if cost::frame_cost(&fitted.compiled, &fitted.clip) <= limit {
        return Ok(fitted);
    }
    let (doc, input) = (&fitted.doc, plan.input.doc);
    let mut order: Vec<(f64, usize)> = (0..fitted.kept.len())
        .filter(|&i| !fitted.kept[i] && doc.tracks[i].times.len() > 2)
        .map(|i| {
            let share = doc.tracks[i].times.len() as f64 / input.tracks[i].times.len() as f64;
            (share, i)
        })
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let revert = |size: usize| {
        let mut r = fitted.kept.clone();
        for &(_, i) in &order[..size] {
            r[i] = true;
        }
        r
    };
    let n = order.len();
    if n == 0 {
        return Ok(fitted);
    }
    let sizes: Vec<usize> = if n <= 48 {
        (1..=n).collect()
    } else {
        let mut s: Vec<usize> = (1..=32).map(|k| k * n / 32).collect();
        s.dedup();
        s
    };
    type Built = (ClipDoc, Vec<bool>, SourceClip, Arc<tcb_runtime::Clip>);
    let build_at = |size: usize| -> Result<Built, ReduceError> {
        let (doc, kept) = plan.write_fits(cache, &revert(size));
        let (clip, compiled) = build(&doc)?;
        Ok((doc, kept, clip, compiled))
    };
    // Only bytes and costs are kept: one compiled clip per thread at a time.
    let tried: Vec<(usize, usize)> = sizes
        .par_iter()
        .map(|&size| {
            let (_, _, clip, compiled) = build_at(size)?;
            let within = cost::frame_cost(&compiled, &clip) <= limit;
            Ok(within.then(|| (compiled.memory_bytes(), size)))
        })
        .collect::<Result<Vec<_>, ReduceError>>()?
        .into_iter()
        .flatten()
        .collect();
    // Fewest bytes, then fewest tracks put back.
    let Some((_, size)) = tried.into_iter().min() else {
        return Ok(fitted);
    };
    let (doc, kept, clip, compiled) = build_at(size)?;
    let measured = verify(&compiled);
    if measured.worst.ratio > 1.0 {
        return Ok(fitted);
    }
    Ok(Candidate {
        doc,
        clip,
        compiled,
        worst: measured.worst,
        kept,
    })
}

/// The fitted tracks that may be put back on the input's keys, those
/// keeping the largest share of their keys first: fits of more than 2 keys
/// (docs/reduce.md: "a constant track becomes 2 keys") keeping at least
/// [`MIN_SHARE`].
fn put_back_order(plan: &Plan, fitted: &Candidate) -> Vec<usize> {
    let (doc, input) = (&fitted.doc, plan.input.doc);
    let mut candidates: Vec<(f64, usize)> = (0..fitted.kept.len())
        .filter(|&i| !fitted.kept[i] && doc.tracks[i].times.len() > 2)
        .map(|i| {
            let share = doc.tracks[i].times.len() as f64 / input.tracks[i].times.len() as f64;
            (share, i)
        })
        .filter(|&(share, _)| share >= MIN_SHARE)
        .collect();
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    candidates.into_iter().map(|(_, i)| i).collect()
}

/// What a track is to the fitter.
struct Prepared {
    /// Check-time indices it spans.
    first: usize,
    last: usize,
    /// Samples there (rotations normalized and sign-continuous).
    samples: Vec<[f64; 4]>,
    /// Joint and part (0 translation, 1 rotation, 2 scale), under `shell`.
    joint: Option<(usize, usize)>,
}

struct Plan<'a> {
    input: Input<'a>,
    settings: &'a Settings,
    times: &'a [f64],
    /// Per track: `None` when kept as it is.
    tracks: Vec<Option<Prepared>>,
    /// Per joint (`shell`): L_a and the number of fitted tracks on the
    /// longest chain through it.
    reach: Vec<f64>,
    chain: Vec<usize>,
    /// Groups of track indices sharing key times.
    groups: Vec<Vec<usize>>,
}

impl<'a> Plan<'a> {
    fn new(input: Input<'a>, settings: &'a Settings, reference: &'a Reference) -> Self {
        let (times, rows) = (reference.times, &reference.rows[..]);
        let tracks = prepare(input, settings, times, rows);
        let (reach, chain) = match input.skeleton {
            Some(s) if settings.metric == Metric::Shell => chains(
                s,
                &tracks,
                input.clip,
                rows,
                input.clip.channel_count(),
                settings.shell,
            ),
            _ => (Vec::new(), Vec::new()),
        };
        let groups = knot_groups(input.clip, settings.knots, &tracks);
        Plan {
            input,
            settings,
            times,
            tracks,
            reach,
            chain,
            groups,
        }
    }

    /// The tolerance and norm of track `i` at budget scale `scale`.
    fn budget(&self, i: usize, scale: f64) -> (Norm, f64) {
        let s = self.settings;
        let kind = self.input.clip.tracks()[i].data.kind();
        let p = self.tracks[i].as_ref().expect("a fitted track");
        match (s.metric, p.joint) {
            (Metric::Shell, Some((j, part))) => {
                let e = scale * MARGIN * s.tolerance / self.chain[j].max(1) as f64;
                let reach = self.reach[j].max(f64::MIN_POSITIVE);
                match part {
                    0 => (Norm::Euclid, e),
                    1 => (Norm::Rotation, (e / (2.0 * reach)).min(1.0)),
                    _ => (Norm::MaxAbs, e / reach),
                }
            }
            _ if kind == TrackKind::Quat => {
                let half = (scale * MARGIN * s.rotation_tolerance).to_radians() / 2.0;
                (Norm::Rotation, half.min(std::f64::consts::FRAC_PI_2).sin())
            }
            _ => (Norm::MaxAbs, scale * MARGIN * s.tolerance),
        }
    }

    /// Fit every group at its budget scale (0: kept as it is), reusing the
    /// fit in `cache` where the scale has not changed, and write the clip.
    /// Returns it, per track whether it was kept as it was, and how many
    /// groups were fitted.
    fn run(
        &self,
        scales: &[f64],
        cache: &mut [Option<(f64, Option<Fit>)>],
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> (ClipDoc, Vec<bool>, usize) {
        let done = AtomicUsize::new(0);
        let todo: Vec<usize> = (0..self.groups.len())
            .filter(|&g| scales[g] > 0.0 && cache[g].as_ref().is_none_or(|c| c.0 != scales[g]))
            .collect();
        let total = todo.len();
        let fresh: Vec<(usize, Option<Fit>)> = todo
            .par_iter()
            .map(|&gi| {
                let f = self.fit_group(gi, scales[gi]);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                (gi, f)
            })
            .collect();
        for (g, f) in fresh {
            cache[g] = Some((scales[g], f));
        }
        for (g, c) in cache.iter_mut().enumerate() {
            if scales[g] == 0.0 {
                *c = None;
            }
        }
        let (doc, kept) = self.write_fits(cache, &vec![false; self.tracks.len()]);
        (doc, kept, total)
    }

    /// The clip of the fits in `cache`, with the tracks of `revert` as
    /// they were; and per track whether it was kept as it was.
    fn write_fits(
        &self,
        cache: &[Option<(f64, Option<Fit>)>],
        revert: &[bool],
    ) -> (ClipDoc, Vec<bool>) {
        // Per track: its fit and its place in the group.
        let mut fitted: Vec<Option<(&Fit, usize)>> = vec![None; self.tracks.len()];
        for (g, c) in self.groups.iter().zip(cache.iter()) {
            if let Some((_, Some(f))) = c {
                for (s, &i) in g.iter().enumerate() {
                    fitted[i] = (!revert[i]).then_some((f, s));
                }
            }
        }
        self.write(&fitted)
    }

    fn fit_group(&self, gi: usize, scale: f64) -> Option<Fit> {
        let g = &self.groups[gi];
        let p0 = self.tracks[g[0]].as_ref().expect("a fitted track");
        let series: Vec<Series> = g
            .iter()
            .map(|&i| {
                let (norm, tol) = self.budget(i, scale);
                Series {
                    dim: self.input.clip.tracks()[i].data.kind().dim(),
                    samples: &self.tracks[i].as_ref().expect("fitted").samples,
                    norm,
                    tol,
                }
            })
            .collect();
        let original: usize = g
            .iter()
            .map(|&i| stored_values(&self.input.doc.tracks[i]))
            .sum();
        fit::fit_within(
            &self.times[p0.first..=p0.last],
            &series,
            self.settings.tangents,
            3 * original,
        )
    }

    /// Per group: the joints (`shell`, every joint its tracks can move) or
    /// tracks (`value`) whose measured error it affects.
    fn units(&self) -> Vec<Vec<usize>> {
        let skeleton = self.input.skeleton;
        self.groups
            .iter()
            .map(|g| {
                let mut units = Vec::new();
                for &i in g {
                    match (self.settings.metric, skeleton, &self.tracks[i]) {
                        (
                            Metric::Shell,
                            Some(s),
                            Some(Prepared {
                                joint: Some((a, _)),
                                ..
                            }),
                        ) => {
                            for d in 0..s.joints().len() {
                                if descends(s, d, *a) && !units.contains(&d) {
                                    units.push(d);
                                }
                            }
                        }
                        _ => units.push(i),
                    }
                }
                units
            })
            .collect()
    }

    /// The clip, and per track whether it was kept as it was.
    fn write(&self, fitted: &[Option<(&Fit, usize)>]) -> (ClipDoc, Vec<bool>) {
        let src = self.input.doc;
        let (base, _) = src.defaults.resolve();
        let defaults = reduced_defaults(&base);
        let mut tracks = Vec::new();
        let mut kept = vec![false; src.tracks.len()];
        for (i, doc) in src.tracks.iter().enumerate() {
            let (resolved, _) = doc.settings.or(&src.defaults).resolve();
            let reduced = fitted[i].map(|(f, s)| self.fitted_track(i, f, s, &resolved, &base));
            match reduced {
                Some(t) if stored_values(&t) < stored_values(doc) => tracks.push(t),
                _ => {
                    kept[i] = true;
                    tracks.push(kept_track(doc, &src.defaults, &defaults));
                }
            }
        }
        (
            ClipDoc {
                name: src.name.clone(),
                defaults,
                tracks,
                skeleton: src.skeleton.clone(),
            },
            kept,
        )
    }

    /// Track `i` as `fit` wrote it (its track number `slot` in the fit's
    /// group): the fitted keys, and only the settings that differ from the
    /// reduced clip's defaults (`base`, the input's, for pre and post).
    fn fitted_track(
        &self,
        i: usize,
        fit: &Fit,
        slot: usize,
        resolved: &TrackSettings,
        base: &TrackSettings,
    ) -> TrackDoc {
        let doc = &self.input.doc.tracks[i];
        let p = self.tracks[i].as_ref().expect("fitted");
        let times = fit.knots.iter().map(|&k| self.times[p.first + k]).collect();
        let to_f32 = |v: &[f64; 4]| v.map(|c| c as f32);
        let values = fit.values[slot].iter().map(to_f32).collect();
        let keys = match fit.mode {
            Tangents::Explicit => fit.tangents[slot]
                .iter()
                .map(|g| KeyDoc {
                    tangent_in: Some(to_f32(g)),
                    tangent_out: Some(to_f32(g)),
                    ..KeyDoc::default()
                })
                .collect(),
            _ => Vec::new(),
        };
        TrackDoc {
            name: doc.name.clone(),
            kind: doc.kind,
            times,
            values,
            keys,
            settings: SettingsDoc {
                pre: Some(resolved.pre).filter(|m| *m != base.pre),
                post: Some(resolved.post).filter(|m| *m != base.post),
                // Fitted to a curve that keeps its keys as written:
                // so do the fitted keys.
                hemisphere: (doc.kind == TrackKind::Quat
                    && resolved.hemisphere == Hemisphere::Keep)
                    .then_some(Hemisphere::Keep),
                ..SettingsDoc::default()
            },
        }
    }
}

/// The reduced clip's defaults: what the fitter's curves are (`adjusted`,
/// `copy` ends, tcb 0, `hermite` rotations), with the input's pre and post.
fn reduced_defaults(base: &TrackSettings) -> SettingsDoc {
    SettingsDoc {
        tangent_rule: Some(TangentRule::Adjusted),
        ends: Some(Ends::Copy),
        match_speed: Some(false),
        continuity_fade: Some(false),
        tcb: Some([0.0; 3]),
        pre: Some(base.pre),
        post: Some(base.post),
        rotation: Some(RotationMode::Hermite),
        hemisphere: None,
    }
}

/// The input's track `doc` as it was, with every setting it had (under
/// `input_defaults`) stated against the reduced clip's `defaults`.
fn kept_track(doc: &TrackDoc, input_defaults: &SettingsDoc, defaults: &SettingsDoc) -> TrackDoc {
    let (resolved, tcb) = doc.settings.or(input_defaults).resolve();
    let full = SettingsDoc {
        tangent_rule: Some(resolved.tangent_rule),
        ends: Some(resolved.ends),
        match_speed: Some(resolved.match_speed),
        continuity_fade: Some(resolved.continuity_fade),
        tcb: Some(tcb.to_array()),
        pre: Some(resolved.pre),
        post: Some(resolved.post),
        rotation: (doc.kind == TrackKind::Quat).then_some(resolved.rotation),
        hemisphere: (doc.kind == TrackKind::Quat).then_some(resolved.hemisphere),
    };
    TrackDoc {
        settings: only_different(&full, defaults),
        ..doc.clone()
    }
}

/// Per track: what the fitter takes (its span of check times and its
/// samples in `rows`, the input played there), or `None` where the track
/// is kept as it is: its `linear` or `offset-repeat` extrapolation is
/// checked outside its keys, it spans fewer than 2 check times, or no
/// joint uses it (under `shell`).
fn prepare(
    input: Input,
    settings: &Settings,
    times: &[f64],
    rows: &[f32],
) -> Vec<Option<Prepared>> {
    let channels = input.clip.channel_count();
    let n = times.len();
    let mut tracks = Vec::new();
    let mut at = 0;
    for (doc, track) in input.doc.tracks.iter().zip(input.clip.tracks()) {
        let kind = track.data.kind();
        let dim = kind.dim();
        let (t0, t1) = (track.data.times()[0], *track.data.times().last().unwrap());
        let first = times.partition_point(|&t| t < t0);
        let last = times.partition_point(|&t| t <= t1).saturating_sub(1);
        let (resolved, _) = doc.settings.or(&input.doc.defaults).resolve();
        let outside_line = |mode: Extrapolation| {
            matches!(mode, Extrapolation::Linear | Extrapolation::OffsetRepeat)
        };
        let joint = match (settings.metric, input.skeleton) {
            (Metric::Shell, Some(s)) => bound_joint(s, &track.name, kind),
            _ => None,
        };
        let fit_it = last > first
            && !(first > 0 && outside_line(resolved.pre))
            && !(last + 1 < n && outside_line(resolved.post))
            && (settings.metric == Metric::Value || joint.is_some());
        tracks.push(fit_it.then(|| {
            let mut samples: Vec<[f64; 4]> = (first..=last)
                .map(|i| {
                    let row = &rows[i * channels + at..i * channels + at + dim];
                    std::array::from_fn(|c| row.get(c).map_or(0.0, |v| f64::from(*v)))
                })
                .collect();
            if kind == TrackKind::Quat {
                continuous_rotations(&mut samples);
            }
            Prepared {
                first,
                last,
                samples,
                joint,
            }
        }));
        at += dim;
    }
    tracks
}

/// The fitted tracks in groups that share key times: by `knots` (the
/// track, its joint, or the whole clip) and the same span of check times.
fn knot_groups(clip: &SourceClip, knots: Knots, tracks: &[Option<Prepared>]) -> Vec<Vec<usize>> {
    let mut groups: Vec<(String, usize, usize, Vec<usize>)> = Vec::new();
    for (i, p) in tracks.iter().enumerate() {
        let Some(p) = p else { continue };
        let key = match knots {
            Knots::Track => clip.tracks()[i].name.clone(),
            Knots::Joint => joint_name(&clip.tracks()[i].name).to_owned(),
            Knots::Clip => String::new(),
        };
        match groups
            .iter_mut()
            .find(|g| g.0 == key && g.1 == p.first && g.2 == p.last)
        {
            Some(g) => g.3.push(i),
            None => groups.push((key, p.first, p.last, vec![i])),
        }
    }
    groups.into_iter().map(|g| g.3).collect()
}

/// The fields of `full` that differ from `defaults`.
fn only_different(full: &SettingsDoc, defaults: &SettingsDoc) -> SettingsDoc {
    fn diff<T: PartialEq + Copy>(a: Option<T>, b: Option<T>) -> Option<T> {
        if a == b { None } else { a }
    }
    SettingsDoc {
        tangent_rule: diff(full.tangent_rule, defaults.tangent_rule),
        ends: diff(full.ends, defaults.ends),
        match_speed: diff(full.match_speed, defaults.match_speed),
        continuity_fade: diff(full.continuity_fade, defaults.continuity_fade),
        tcb: diff(full.tcb, defaults.tcb),
        pre: diff(full.pre, defaults.pre),
        post: diff(full.post, defaults.post),
        rotation: full.rotation.and_then(|r| diff(Some(r), defaults.rotation)),
        hemisphere: full
            .hemisphere
            .and_then(|h| diff(Some(h), defaults.hemisphere.or(Some(Hemisphere::Nearest)))),
    }
}

/// Whether joint `d` is `a` or below it.
pub(crate) fn descends(skeleton: &Skeleton, mut d: usize, a: usize) -> bool {
    loop {
        if d == a {
            return true;
        }
        match skeleton.joints()[d].parent {
            Some(p) if p < d => d = p,
            _ => return false,
        }
    }
}

/// `Hips` of `Hips.rotation`.
fn joint_name(track: &str) -> &str {
    track.rsplit_once('.').map_or(track, |(j, _)| j)
}

/// The joint and part a track animates: `<joint>.translation` (vec3),
/// `.rotation` (quat), `.scale` (vec3).
pub(crate) fn bound_joint(
    skeleton: &Skeleton,
    name: &str,
    kind: TrackKind,
) -> Option<(usize, usize)> {
    let (joint, part) = name.rsplit_once('.')?;
    let part = match (part, kind) {
        ("translation", TrackKind::Vec3) => 0,
        ("rotation", TrackKind::Quat) => 1,
        ("scale", TrackKind::Vec3) => 2,
        _ => return None,
    };
    Some((skeleton.joint(joint)?, part))
}

/// Unit quaternions, each on the hemisphere of the one before.
fn continuous_rotations(samples: &mut [[f64; 4]]) {
    let mut prev: Option<[f64; 4]> = None;
    for q in samples.iter_mut() {
        let len = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        if len > 0.0 {
            q.iter_mut().for_each(|c| *c /= len);
        }
        if let Some(p) = prev
            && (0..4).map(|c| p[c] * q[c]).sum::<f64>() < 0.0
        {
            q.iter_mut().for_each(|c| *c = -*c);
        }
        prev = Some(*q);
    }
}

/// Per joint: `L_a` (the longest chain of rest or animated offsets below it,
/// plus the shell radius) and the number of fitted tracks on the longest
/// root-to-leaf chain through it.
fn chains(
    skeleton: &Skeleton,
    tracks: &[Option<Prepared>],
    clip: &SourceClip,
    rows: &[f32],
    channels: usize,
    radius: f64,
) -> (Vec<f64>, Vec<usize>) {
    let n = skeleton.joints().len();
    let mut offset: Vec<f64> = skeleton
        .joints()
        .iter()
        .map(|j| f64::from(j.rest.translation.length()))
        .collect();
    let mut count = vec![0usize; n];
    let mut at = 0;
    for (t, p) in clip.tracks().iter().zip(tracks) {
        let dim = t.data.kind().dim();
        if let Some(Prepared {
            joint: Some((j, part)),
            ..
        }) = p
        {
            count[*j] += 1;
            if *part == 0 {
                let longest = rows
                    .chunks_exact(channels)
                    .map(|r| {
                        r[at..at + 3]
                            .iter()
                            .map(|v| f64::from(*v).powi(2))
                            .sum::<f64>()
                            .sqrt()
                    })
                    .fold(0.0, f64::max);
                offset[*j] = offset[*j].max(longest);
            }
        }
        at += dim;
    }
    let parent = |j: usize| skeleton.joints()[j].parent.filter(|&p| p < j);
    // Below: longest offset chain and most tracks on a chain, leaves up.
    let mut reach = vec![0.0f64; n];
    let mut down = count.clone();
    for j in (0..n).rev() {
        if let Some(p) = parent(j) {
            reach[p] = reach[p].max(reach[j] + offset[j]);
            down[p] = down[p].max(count[p] + down[j]);
        }
    }
    let mut up = count.clone();
    for j in 0..n {
        if let Some(p) = parent(j) {
            up[j] += up[p];
        }
    }
    let chain = (0..n).map(|j| up[j] + down[j] - count[j]).collect();
    (reach.into_iter().map(|r| r + radius).collect(), chain)
}
