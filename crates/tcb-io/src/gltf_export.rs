//! Export to glTF 2.0 (`.gltf` with an embedded buffer, or `.glb`).
//!
//! With a skeleton (the clip's `skeleton`), its joints become the node
//! hierarchy: children, and the rest translation, rotation and scale. Tracks
//! named `<node>.translation|rotation|scale` and `<node>.weights.<i>` become
//! animation channels of the node `<node>` (a root node of its own when the
//! skeleton has no such joint). A node with weight tracks gets a mesh with
//! that many morph targets (one point, zero displacements), because glTF
//! only animates the weights of a mesh's morph targets. What glTF can
//! express is written exactly:
//!
//! - vector tracks and `hermite` rotations as `CUBICSPLINE`, with
//!   `out_k = DD_k / D_k` and `in_k+1 = DS_k+1 / D_k` (time-unit tangents;
//!   the first key's in-tangent and the last key's out-tangent, which no
//!   segment uses, are zero, as the glTF spec asks);
//! - tracks whose every segment is `step` as `STEP`;
//! - rotations whose every segment is `linear` (slerp), without ease, as
//!   `LINEAR`.
//!
//! The rest (squad, ease, slerp segments of hermite rotations, `step`
//! segments inside a curve) is resampled: each segment is split into 1, 2,
//! 4, ... 64 pieces until the cubic through the reference's values and
//! derivatives is within the requested error of the reference, measured at
//! 8 points per piece; the error reached is reported per track. glTF holds
//! the end values outside the keys, so other `pre`/`post` modes are
//! reported as notes. The document is built with the `gltf-json` types.
//!
//! glTF's key times are f32. Times beyond f32's range, and distinct times
//! that are one f32, are refused (the file would not read back). Where
//! f32 moves a key (0.1 s is not an f32; at 1e6 s, f32 steps by 1/16 s),
//! the track is not exact: it is read back as `tcb import` reads it and
//! measured against the clip, and that error is reported
//! ([`TrackExport::time_rounding`]).
//!
//! The error reported for a resampled or moved track is a bound, not a
//! few samples: between the keys of both curves and the ends of the
//! clip's ease phases a vector track and its read-back are polynomials
//! in time (of degree 3, or 6 where the clip is eased), and 9 (33 where
//! eased) samples of each interval bound their difference, and the least
//! `|value|` it is divided by, everywhere in it:
//!
//! ```text
//! error <= max over samples i of
//!          (max(|d_i|, |d_i+1|) + s range(d)) / max(1, min(|v_i|, |v_i+1|) - s range(v))
//! ```
//!
//! with `d` the difference, `v` the clip's value (0 in place of the
//! second term where it changes sign) and `s` from Markov's inequality:
//! 0.116 for degree 3 at 8 intervals, 0.13 for degree 6 at 32. Where
//! the two curves do not play one segment with the same key times and
//! controls, f32 playback (`s` and the basis in f32) puts each sample off
//! its polynomial by up to 2^-21 (|p0| + |p1| + |m0| + |m1|), which the
//! bound adds where that is more than 5e-5 of the value: on controls far
//! larger than the value, a key moved by f32 makes the reader's `s` round
//! apart from the clip's between the samples. Rotations
//! are normalized (or squad), no polynomials: their error is an estimate
//! from samples taken more densely wherever either curve turns fast, plus,
//! for hermite rotations, the f32 rounding of their cubics divided by the
//! least length of the cubics at the samples (where more than 5e-5). A
//! track whose read-back overflows f32 where the clip is finite is refused.

use crate::error::Error;
use gltf::json;
use json::accessor::Type as AccessorType;
use json::animation::Interpolation;
use json::validation::{Checked, USize64};
use std::path::Path;
use tcb_core::ease::SegmentEase;
use tcb_core::skeleton::Skeleton;
use tcb_core::{Extrapolation, Interp, Track, TrackData, TrackKind, Value as TcbValue};

/// How one track was written.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackExport {
    /// The track.
    pub name: String,
    /// `None` when the curve is written as it is; else the largest
    /// difference from the reference (relative to max(1, |value|)) of the
    /// resampled curve as `tcb import` reads the export back, measured as
    /// [`TimeRounding::error`] is (and no less than the resampling's own
    /// measure).
    pub resampled_error: Option<f64>,
    /// `None` when every time written is the track's own (an f32); else
    /// what rounding them to glTF's f32 key times did.
    pub time_rounding: Option<TimeRounding>,
    /// `None` when the track is resampled, its times moved, or it reads
    /// back within [`F32_ROUNDING`] of the clip; else, for a track written
    /// as its own curve on its own times, the largest difference from the
    /// reference (relative to max(1, |value|)) that storing its values and
    /// tangents in f32 left (bounded as [`TimeRounding::error`] is).
    /// Tangents large beside a value can come back an ulp off, far off the
    /// value (`per_second` avoids it where an f32 allows).
    pub f32_rounding: Option<f64>,
}

impl TrackExport {
    /// `None` when exact; else the largest difference from the reference
    /// (relative to max(1, |value|)) that a reader of the export gets,
    /// resampling, f32 key times and f32 tangents included.
    pub fn error(&self) -> Option<f64> {
        match (self.resampled_error, self.time_rounding, self.f32_rounding) {
            (None, None, None) => None,
            (e, r, t) => Some(
                e.unwrap_or(0.0)
                    .max(r.map_or(0.0, |r| r.error))
                    .max(t.unwrap_or(0.0)),
            ),
        }
    }
}

/// Below this, a track written as its own curve on its own times is
/// reported exact ([`TrackExport::f32_rounding`]): the f32 rounding of
/// its values themselves (a unit rotation written in f32 and normalized
/// again by the reader is some 3e-8 off), which any f32 file has.
pub const F32_ROUNDING: f64 = 1e-6;

/// What glTF's f32 key times did to a track whose times are not all f32s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeRounding {
    /// The largest distance a key (or a resampled knot) moved, seconds.
    pub largest_shift: f64,
    /// The largest difference from the reference (relative to max(1,
    /// |value|)) of the track as `tcb import` reads the export back,
    /// bounded over every interval between the keys, the stored times and
    /// the ends of ease phases from 9 points in each (33 where eased),
    /// f32 playback's rounding included where it is large (see the module
    /// docs).
    pub error: f64,
}

/// What [`export`] did.
#[derive(Clone, Debug, Default)]
pub struct ExportReport {
    /// Every track, in clip order.
    pub tracks: Vec<TrackExport>,
    /// What glTF cannot hold at all (extrapolation modes).
    pub notes: Vec<String>,
}

impl ExportReport {
    /// The largest error of a track ([`TrackExport::error`]; 0 when
    /// everything is exact).
    pub fn max_error(&self) -> f64 {
        self.tracks
            .iter()
            .filter_map(TrackExport::error)
            .fold(0.0, f64::max)
    }
}

/// One sampler's data.
struct Sampler {
    /// The times the curve was built on.
    source_times: Vec<f64>,
    /// Those times as glTF stores them.
    times: Vec<f32>,
    interpolation: Interpolation,
    /// Output elements (for CUBICSPLINE: in, value, out per key).
    output: Vec<f32>,
    /// The output accessor's element type.
    kind: AccessorType,
}

/// Keys with values and time-unit tangents, `dim` components each.
struct Cubic {
    times: Vec<f64>,
    values: Vec<Vec<f32>>,
    tin: Vec<Vec<f32>>,
    tout: Vec<Vec<f32>>,
}

/// A track's own keys and tangents as glTF CUBICSPLINE keys (time-unit tangents over the f32 spans).
fn exact_cubic<V: TcbValue>(t: &Track<V>) -> Cubic {
    let times = t.times().to_vec();
    let n = times.len();
    let arr = |v: V| v.to_array()[..V::DIM].to_vec();
    let mut tin = vec![vec![0.0; V::DIM]; n];
    let mut tout = vec![vec![0.0; V::DIM]; n];
    for (k, s) in t.segments().iter().enumerate() {
        // glTF key times are f32, and readers take the span from those:
        // divide by that span so that `tangent * span` gives M back.
        let d = (f64::from(times[k + 1] as f32) - f64::from(times[k] as f32)) as f32;
        tout[k] = arr(s.m0).iter().map(|&m| per_second(m, d)).collect();
        tin[k + 1] = arr(s.m1).iter().map(|&m| per_second(m, d)).collect();
    }
    // tin[0] and tout[n - 1] stay zero: no segment uses them.
    Cubic {
        values: t.values().iter().map(|v| arr(*v)).collect(),
        times,
        tin,
        tout,
    }
}

/// The time-unit tangent glTF stores for `m` (value per segment) over the
/// f32 span `d`: `m / d`, or the f32 next to it (up to 4 steps away) that
/// a reader's f32 `tangent * d` (`tcb import`'s) turns back into `m`
/// exactly. `m / d` rounded alone can come back an ulp of `m` off, which
/// is far off a value small beside its tangent (issue 29 class 6).
fn per_second(m: f32, d: f32) -> f32 {
    let tau = m / d;
    let mut candidates = [tau; 9];
    let (mut up, mut down) = (tau, tau);
    for pair in candidates[1..].chunks_mut(2) {
        (up, down) = (up.next_up(), down.next_down());
        pair.copy_from_slice(&[up, down]);
    }
    candidates.into_iter().find(|c| c * d == m).unwrap_or(tau)
}

/// How glTF can hold a vector track: STEP, its own cubic, or resampled.
fn exact_shape<V: TcbValue>(t: &Track<V>) -> Shape {
    let segs = t.segments();
    if segs.iter().all(|s| s.interp == Interp::Step) {
        Shape::Step
    } else if segs
        .iter()
        .all(|s| s.ease.is_none() && s.interp != Interp::Step)
    {
        Shape::Cubic
    } else {
        Shape::Resample
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Shape {
    Step,
    Linear,
    Cubic,
    Resample,
}

/// Hermite on one component over `[0, 1]` with time-unit tangents and span `d`.
fn hermite(p0: f32, p1: f32, m0: f32, m1: f32, d: f32, u: f32) -> f32 {
    let h = tcb_core::simd::basis::hermite_basis(u);
    h[0] * p0 + h[1] * p1 + h[2] * m0 * d + h[3] * m1 * d
}

/// Value, in tangent and out tangent at a knot.
type Knot = (Vec<f32>, Vec<f32>, Vec<f32>);

/// Resample `data` (dim components) as a cubic within `max_error`.
fn resample(data: &TrackData, max_error: f64) -> (Cubic, f64) {
    let reference = Reference {
        data,
        dim: data.kind().dim(),
        rotation: matches!(data, TrackData::Quat(_)),
    };
    let keys = data.times();
    let (v0, d0) = reference.sample(keys[0]);
    let mut out = Cubic {
        times: vec![keys[0]],
        values: vec![v0],
        tin: vec![vec![0.0; reference.dim]],
        tout: vec![d0],
    };
    let mut worst = 0.0f64;
    for k in 0..keys.len() - 1 {
        let (knots, at, err) = reference.fit_segment(keys[k], keys[k + 1], max_error);
        worst = worst.max(err);
        // The knot at `a` is already there: set its out tangent, add the rest.
        let last = out.times.len() - 1;
        out.tout[last] = at[0].2.clone();
        for (t, (v, din, dout)) in knots.into_iter().zip(at).skip(1) {
            out.times.push(t);
            out.values.push(v);
            out.tin.push(din);
            out.tout.push(dout);
        }
    }
    // The last key's out tangent is unused: zero, as glTF asks.
    if let Some(last) = out.tout.last_mut() {
        last.iter_mut().for_each(|x| *x = 0.0);
    }
    (out, worst)
}

/// The track [`resample`] follows.
struct Reference<'a> {
    data: &'a TrackData,
    dim: usize,
    rotation: bool,
}

impl Reference<'_> {
    /// Value and velocity at `t`.
    fn sample(&self, t: f64) -> (Vec<f32>, Vec<f32>) {
        let (mut v, mut d) = (vec![0.0f32; self.dim], vec![0.0f32; self.dim]);
        self.data.sample_into(t, &mut v, Some(&mut d));
        (v, d)
    }

    /// Segment `[a, b]` split into 1, 2, 4, ... 64 equal pieces until the
    /// cubic through the knots is within `max_error` (bounded between the
    /// measured points): the knots, their samples and the error, of the
    /// best try.
    fn fit_segment(&self, a: f64, b: f64, max_error: f64) -> (Vec<f64>, Vec<Knot>, f64) {
        let mut best: Option<(Vec<f64>, Vec<Knot>, f64)> = None;
        let mut pieces = 1;
        while pieces <= 64 {
            let knots: Vec<f64> = (0..=pieces)
                .map(|j| a + (b - a) * j as f64 / pieces as f64)
                .collect();
            // glTF stores the knots as f32: finer pieces than f32 tells
            // apart would be keys at one time (the keys themselves are
            // apart in f32, `check_times`).
            if pieces > 1 && knots.windows(2).any(|w| w[0] as f32 >= w[1] as f32) {
                break;
            }
            let at = self.knot_samples(&knots, a, b);
            let err = self.pieces_error(&knots, &at);
            if best.as_ref().is_none_or(|b| err < b.2) {
                best = Some((knots, at, err));
            }
            if err * BETWEEN_POINTS <= max_error {
                break;
            }
            pieces *= 2;
        }
        best.expect("at least one try")
    }

    /// (value, in tangent, out tangent) at each knot of `[a, b]`. The in
    /// tangent at b is the left derivative; its out tangent is replaced by
    /// the next segment's first knot (and at the last key the reference's
    /// velocity is already the left derivative).
    fn knot_samples(&self, knots: &[f64], a: f64, b: f64) -> Vec<Knot> {
        let last = knots.len() - 1;
        knots
            .iter()
            .enumerate()
            .map(|(j, &t)| {
                let (v, d) = self.sample(t);
                let din = if j == last {
                    self.sample(b - (b - a) * 1e-7).1
                } else {
                    d.clone()
                };
                (v, din, d)
            })
            .collect()
    }

    /// The largest difference between the reference and the cubic pieces
    /// through `at`, at 7 points inside each piece.
    fn pieces_error(&self, knots: &[f64], at: &[Knot]) -> f64 {
        let mut err = 0.0f64;
        for j in 0..knots.len() - 1 {
            let d = (knots[j + 1] - knots[j]) as f32;
            for i in 1..8 {
                let u = i as f32 / 8.0;
                let t = knots[j] + f64::from(u) * (knots[j + 1] - knots[j]);
                let mut got: Vec<f32> = (0..self.dim)
                    .map(|c| hermite(at[j].0[c], at[j + 1].0[c], at[j].2[c], at[j + 1].1[c], d, u))
                    .collect();
                if self.rotation {
                    let l = got.iter().map(|x| x * x).sum::<f32>().sqrt();
                    got.iter_mut().for_each(|x| *x /= l);
                }
                err = err.max(difference(&self.sample(t).0, &got, self.rotation));
            }
        }
        err
    }
}

/// `got` against `want` relative to max(1, |value|), rotations up to sign:
/// the error [`resample`] measures at its check points (what is reported
/// is [`read_back_error`]'s bound, where larger).
fn difference(want: &[f32], got: &[f32], rotation: bool) -> f64 {
    let diff = |s: f32| {
        want.iter()
            .zip(got)
            .map(|(w, g)| f64::from((w - s * g).abs() / w.abs().max(1.0)))
            .fold(0.0, f64::max)
    };
    if rotation {
        diff(1.0).min(diff(-1.0))
    } else {
        diff(1.0)
    }
}

/// A CUBICSPLINE sampler of `c`: in-tangent, value, out-tangent per key.
fn cubic_sampler(c: &Cubic, kind: AccessorType) -> Sampler {
    let width = c.values[0].len();
    let mut output = Vec::with_capacity(c.times.len() * width * 3);
    for k in 0..c.times.len() {
        output.extend_from_slice(&c.tin[k]);
        output.extend_from_slice(&c.values[k]);
        output.extend_from_slice(&c.tout[k]);
    }
    Sampler {
        source_times: c.times.clone(),
        times: c.times.iter().map(|&t| t as f32).collect(),
        interpolation: Interpolation::CubicSpline,
        output,
        kind,
    }
}

/// Where a track goes: node name and glTF path (and the morph target).
fn target(name: &str, data: &TrackData) -> Result<(String, &'static str, usize), String> {
    use tcb_core::TrackKind::*;
    let kind = data.kind();
    for (suffix, path, want) in [
        (".translation", "translation", Vec3),
        (".rotation", "rotation", Quat),
        (".scale", "scale", Vec3),
    ] {
        if let Some(node) = name.strip_suffix(suffix) {
            if kind != want {
                return Err(format!(
                    "track '{name}' is {kind}; glTF {path} needs {want}"
                ));
            }
            return Ok((node.to_string(), path, 0));
        }
    }
    if let Some((node, i)) = name.rsplit_once(".weights.")
        && let Ok(i) = i.parse::<usize>()
    {
        if kind != Scalar {
            return Err(format!(
                "track '{name}' is {kind}; morph weights are scalar"
            ));
        }
        return Ok((node.to_string(), "weights", i));
    }
    let base = name.rsplit_once('.').map_or(name, |p| p.0);
    let hint = match kind {
        Vec3 => format!(
            "; to export it as a translation, rename it: --rename '{name}={base}.translation' (or .scale)"
        ),
        Quat => format!("; rename it: --rename '{name}={base}.rotation'"),
        Scalar => format!(
            "; to export it as a morph weight, rename it: --rename '{name}={base}.weights.0'"
        ),
        Vec2 | Vec4 => "; glTF has no animation target of this kind".to_string(),
    };
    Err(format!(
        "track '{name}' ({kind}) has no glTF target: glTF animates <node>.translation, <node>.rotation, <node>.scale and <node>.weights.<i>{hint}"
    ))
}

/// Choices for [`export`].
///
/// Start from [`Default`] and set fields with the builder methods, so that
/// a field added later does not break the code that builds these:
///
/// ```
/// use tcb_io::gltf_export::ExportOptions;
/// let options = ExportOptions::default()
///     .max_error(1e-4)
///     .rename(vec![("ball.position".into(), "ball.translation".into())]);
/// assert_eq!(options.max_error, 1e-4);
/// assert_eq!(options.rename.len(), 1);
/// ```
///
/// The struct is `#[non_exhaustive]`: a struct literal does not compile
/// outside this crate.
///
/// ```compile_fail
/// let options = tcb_io::gltf_export::ExportOptions {
///     max_error: 1e-4,
///     ..Default::default()
/// };
/// ```
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct ExportOptions {
    /// Largest error allowed where a curve must be resampled (relative to
    /// max(1, |value|)); default 1e-5.
    pub max_error: f64,
    /// Track renames applied before names are matched to nodes, `(from,
    /// to)`: for example `("ball.position", "ball.translation")`.
    pub rename: Vec<(String, String)>,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            max_error: 1e-5,
            rename: Vec::new(),
        }
    }
}

impl ExportOptions {
    /// These options with [`max_error`](Self::max_error) set to `error`.
    #[must_use]
    pub fn max_error(mut self, error: f64) -> Self {
        self.max_error = error;
        self
    }

    /// These options with [`rename`](Self::rename) set to `renames`, `(from, to)`.
    #[must_use]
    pub fn rename(mut self, renames: Vec<(String, String)>) -> Self {
        self.rename = renames;
        self
    }
}

/// A node of the exported scene.
struct NodeOut {
    name: String,
    parent: Option<usize>,
    rest: Option<tcb_core::skeleton::Transform>,
    /// Morph targets its weight channel animates (0: no mesh).
    morphs: usize,
}

/// The track names after `renames`, checked: every `from` names a track,
/// and no two tracks end up with one name.
fn renamed(
    clip: &tcb_core::SourceClip,
    renames: &[(String, String)],
) -> Result<Vec<String>, Error> {
    let mut names: Vec<String> = clip.tracks().iter().map(|t| t.name.clone()).collect();
    for (from, to) in renames {
        let i = clip
            .tracks()
            .iter()
            .position(|t| t.name == *from)
            .ok_or_else(|| Error::import(format!("--rename {from}={to}: no track '{from}'")))?;
        names[i] = to.clone();
    }
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            return Err(Error::import(format!(
                "two tracks would be named '{n}' after renaming"
            )));
        }
    }
    Ok(names)
}

/// The container [`export`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Container {
    /// `.gltf`: JSON, the buffer as a `data:` URI inside it.
    Gltf,
    /// `.glb`: binary, the JSON and the buffer in one file.
    Glb,
}

impl Container {
    /// `.glb` for a path ending in `glb` (any case), else `.gltf`.
    pub fn for_path(path: impl AsRef<Path>) -> Container {
        if path
            .as_ref()
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
        {
            Container::Glb
        } else {
            Container::Gltf
        }
    }
}

/// Export `clip` to glTF in `container`. With `skeleton`, its
/// joints are the node hierarchy (children and rest transforms); tracks
/// animate the node of their name. Returns the file bytes and the report.
pub fn export(
    clip: &tcb_core::SourceClip,
    skeleton: Option<&Skeleton>,
    container: Container,
    options: &ExportOptions,
) -> Result<(Vec<u8>, ExportReport), Error> {
    let max_error = options.max_error;
    let track_names = renamed(clip, &options.rename)?;
    let mut scene = Scene::of(skeleton);
    let mut notes = Vec::new();
    // Weight tracks per node: (node, [(target index, track index)]).
    let mut weights: Vec<(usize, Vec<(usize, usize)>)> = Vec::new();
    for (ti, t) in clip.tracks().iter().enumerate() {
        let (node, path, morph) = target(&track_names[ti], &t.data).map_err(Error::import)?;
        let ni = scene.node(node);
        notes.extend(extrapolation_notes(&t.name, &t.data));
        if path == "weights" {
            match weights.iter_mut().find(|w| w.0 == ni) {
                Some(w) => w.1.push((morph, ti)),
                None => weights.push((ni, vec![(morph, ti)])),
            }
            continue;
        }
        scene.add(ni, path, export_track(&t.name, &t.data, max_error)?);
    }
    for (ni, list) in weights {
        scene.add_weights(clip, ni, list, max_error)?;
    }
    notes.extend(resampling_note(&scene.tracks, &scene.fits, max_error));
    notes.extend(time_rounding_note(&scene.tracks, &scene.fits, max_error));
    let bytes = write(
        clip.name(),
        &scene.nodes,
        &scene.channels,
        container == Container::Glb,
    )?;
    // Weight tracks were written after the others: the report lists them
    // in clip order, as documented (names are unique in a clip).
    let mut tracks = scene.tracks;
    tracks.sort_by_key(|r| clip.tracks().iter().position(|t| t.name == r.name));
    let report = ExportReport { tracks, notes };
    Ok((bytes, report))
}

/// What [`export`] builds: the nodes, the channels, and per track its
/// report and the resampling's own measure.
struct Scene {
    nodes: Vec<NodeOut>,
    /// (node, path, sampler)
    channels: Vec<(usize, &'static str, Sampler)>,
    tracks: Vec<TrackExport>,
    fits: Vec<Option<f64>>,
}

impl Scene {
    /// The skeleton's joints as nodes (none without one).
    fn of(skeleton: Option<&Skeleton>) -> Scene {
        let nodes = skeleton
            .map(|s| {
                s.joints()
                    .iter()
                    .map(|j| NodeOut {
                        name: j.name.clone(),
                        parent: j.parent,
                        rest: Some(j.rest),
                        morphs: 0,
                    })
                    .collect()
            })
            .unwrap_or_default();
        Scene {
            nodes,
            channels: Vec::new(),
            tracks: Vec::new(),
            fits: Vec::new(),
        }
    }

    /// The node named `name`, a new root node if there is none.
    fn node(&mut self, name: String) -> usize {
        match self.nodes.iter().position(|n| n.name == name) {
            Some(i) => i,
            None => {
                self.nodes.push(NodeOut {
                    name,
                    parent: None,
                    rest: None,
                    morphs: 0,
                });
                self.nodes.len() - 1
            }
        }
    }

    /// A written track as the channel `path` of node `ni`.
    fn add(&mut self, ni: usize, path: &'static str, w: Written) {
        self.tracks.push(w.report);
        self.fits.push(w.fit);
        self.channels.push((ni, path, w.sampler));
    }

    /// Node `ni`'s weight tracks `list` ((target index, track index)) as
    /// one channel of a mesh with that many morph targets.
    fn add_weights(
        &mut self,
        clip: &tcb_core::SourceClip,
        ni: usize,
        mut list: Vec<(usize, usize)>,
        max_error: f64,
    ) -> Result<(), Error> {
        list.sort();
        if list.iter().enumerate().any(|(i, (m, _))| *m != i) {
            return Err(Error::import(format!(
                "node '{}': weight tracks must be numbered 0, 1, 2, ... without gaps or repeats",
                self.nodes[ni].name
            )));
        }
        let per: Vec<Written> = list
            .iter()
            .map(|(_, ti)| {
                let t = &clip.tracks()[*ti];
                export_track(&t.name, &t.data, max_error)
            })
            .collect::<Result<_, _>>()?;
        let first = &per[0].sampler;
        if per.iter().any(|w| {
            w.sampler.times != first.times || w.sampler.interpolation != first.interpolation
        }) {
            return Err(Error::import(format!(
                "node '{}': glTF stores all morph weights of a node in one sampler; its weight tracks need the same key times and the same exactness (all exact or all resampled the same way)",
                self.nodes[ni].name
            )));
        }
        self.tracks.extend(per.iter().map(|w| w.report.clone()));
        self.fits.extend(per.iter().map(|w| w.fit));
        self.nodes[ni].morphs = list.len();
        let merged = merge(&per.iter().map(|w| &w.sampler).collect::<Vec<_>>());
        self.channels.push((ni, "weights", merged));
        Ok(())
    }
}

/// Notes for `pre`/`post` modes glTF cannot hold (it holds the end values).
fn extrapolation_notes(name: &str, data: &TrackData) -> Vec<String> {
    let (pre, post) = match data {
        TrackData::Quat(r) => (r.settings().pre, r.settings().post),
        TrackData::Scalar(x) => (x.settings().pre, x.settings().post),
        TrackData::Vec2(x) => (x.settings().pre, x.settings().post),
        TrackData::Vec3(x) => (x.settings().pre, x.settings().post),
        TrackData::Vec4(x) => (x.settings().pre, x.settings().post),
    };
    [("pre", pre), ("post", post)]
        .into_iter()
        .filter(|(_, mode)| *mode != Extrapolation::Constant)
        .map(|(side, mode)| {
            format!(
                "track '{name}': {side} '{}' is not expressible; glTF holds the end value",
                mode.name()
            )
        })
        .collect()
}

/// One note for the tracks whose resampling stopped above `max_error`
/// by its own measure (`fits`, one per track).
fn resampling_note(tracks: &[TrackExport], fits: &[Option<f64>], max_error: f64) -> Option<String> {
    let over: Vec<(&str, f64)> = tracks
        .iter()
        .zip(fits)
        .filter_map(|(t, f)| f.filter(|f| *f > max_error).map(|f| (t.name.as_str(), f)))
        .collect();
    let (name, worst) = over.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1))?;
    let what = match over.len() {
        1 => format!("track '{name}': resampled to {worst:e} at best"),
        n => format!("{n} tracks: resampled to up to {worst:e} at best (in '{name}')"),
    };
    Some(format!(
        "{what}, above the max error {max_error:e} (a step inside a curve track cannot be followed by a cubic)"
    ))
}

/// One note for the tracks that glTF's f32 key times put further off than
/// `max_error` where their curve (exact, or resampled by its own measure,
/// `fits`) is within it: why, and what to do.
fn time_rounding_note(
    tracks: &[TrackExport],
    fits: &[Option<f64>],
    max_error: f64,
) -> Option<String> {
    let over: Vec<(&str, TimeRounding)> = tracks
        .iter()
        .zip(fits)
        .filter(|(_, f)| f.unwrap_or(0.0) <= max_error)
        .filter_map(|(t, _)| t.time_rounding.map(|r| (t.name.as_str(), r)))
        .filter(|(_, r)| r.error > max_error)
        .collect();
    let shift = over
        .iter()
        .map(|(_, r)| r.largest_shift)
        .fold(0.0, f64::max);
    let (name, worst) = over
        .iter()
        .max_by(|a, b| a.1.error.total_cmp(&b.1.error))
        .map(|(n, r)| (*n, r.error))?;
    let what = match over.len() {
        1 => format!(
            "track '{name}': glTF's f32 key times move its keys by up to {shift:.2e} s, which puts it {worst:.4e} off the clip"
        ),
        n => format!(
            "{n} tracks: glTF's f32 key times move their keys by up to {shift:.2e} s, which puts them up to {worst:.4e} off the clip (in '{name}')"
        ),
    };
    Some(format!(
        "{what}, above the max error {max_error:e} (f32 keeps about 7 significant digits of a time: put the keys on times f32 holds, such as multiples of 1/64 s, or shift the clip's times toward 0, or accept it with a larger max error)"
    ))
}

/// One track as written.
struct Written {
    sampler: Sampler,
    report: TrackExport,
    /// The resampling's own measure (`None`: written as it is).
    fit: Option<f64>,
}

/// Track `name`'s sampler and report: its times checked against glTF's
/// f32 key times (`check_times`), and, where it is resampled or f32 moves
/// its times, the track read back as `tcb import` reads it and measured.
fn export_track(name: &str, data: &TrackData, max_error: f64) -> Result<Written, Error> {
    check_times(name, data.times())?;
    let (sampler, fit) = track_sampler(data, max_error);
    if let Some(x) = sampler.output.iter().find(|x| !x.is_finite()) {
        return Err(Error::import(format!(
            "track '{name}': a key or tangent is {x} in f32 (a tension, continuity or bias \
             so large that a tangent overflows); glTF stores finite f32 numbers, so it cannot \
             be exported: bring the parameter within a few units"
        )));
    }
    let largest_shift = sampler
        .source_times
        .iter()
        .zip(&sampler.times)
        .map(|(&t, &f)| (f64::from(f) - t).abs())
        .fold(0.0, f64::max);
    // Every track is read back, the exact ones too: their tangents are
    // stored per second in f32 and may not come back bit for bit.
    let back = read_back(data.kind(), &sampler).map_err(|e| {
        Error::import(format!(
            "track '{name}': its glTF keys would not read back ({e})"
        ))
    })?;
    let measured = read_back_error(data, &back);
    if measured == f64::INFINITY {
        return Err(Error::import(format!(
            "track '{name}': as glTF's f32 keys and tangents, its curve overflows f32 between \
             keys where the clip's is finite (tangents far larger than its values); it cannot \
             be exported: bring its tension, continuity, bias and explicit tangents within a \
             few units"
        )));
    }
    let report = TrackExport {
        name: name.to_string(),
        resampled_error: fit.map(|f| f.max(measured)),
        time_rounding: (largest_shift > 0.0).then_some(TimeRounding {
            largest_shift,
            error: measured,
        }),
        f32_rounding: (fit.is_none() && largest_shift == 0.0 && measured > F32_ROUNDING)
            .then_some(measured),
    };
    Ok(Written {
        sampler,
        report,
        fit,
    })
}

/// `t` in seconds as a message writes it (`1e39`, not 40 digits).
fn seconds(t: f64) -> String {
    if t != 0.0 && !(1e-4..1e16).contains(&t.abs()) {
        format!("{t:e}")
    } else {
        format!("{t}")
    }
}

/// Refuses key times glTF cannot store: beyond f32's range, or two
/// distinct times that are one f32 (the export would not read back).
fn check_times(name: &str, times: &[f64]) -> Result<(), Error> {
    for (k, &t) in times.iter().enumerate() {
        if !(t as f32).is_finite() {
            return Err(Error::import(format!(
                "track '{name}': key {k} is at {} s, beyond glTF's key times (f32, at most {:e} s); scale or shift the clip's times into that range before exporting",
                seconds(t),
                f32::MAX
            )));
        }
        if k > 0 && times[k - 1] as f32 == t as f32 {
            let at = t as f32;
            let step = f64::from(at.next_up()) - f64::from(at);
            return Err(Error::import(format!(
                "track '{name}': keys {} and {k} (at {} and {} s) are one time in glTF's f32 key times ({} s apart at that time); shift the clip's times toward 0, or space those keys further apart, before exporting",
                k - 1,
                seconds(times[k - 1]),
                seconds(t),
                seconds(step)
            )));
        }
    }
    Ok(())
}

/// `sampler` as `tcb import` reads it: its f32 times, its output, the
/// importer's own conversion (`gltf_import::sampler_track`).
fn read_back(kind: TrackKind, sampler: &Sampler) -> Result<TrackData, tcb_core::TrackError> {
    let times = sampler.times.iter().map(|&t| f64::from(t)).collect();
    let dim = kind.dim();
    let per_key = if sampler.interpolation == Interpolation::CubicSpline {
        3
    } else {
        1
    };
    let value = |k: usize, e: usize| {
        let at = (k * per_key + e) * dim;
        let mut v = [0.0; 4];
        v[..dim].copy_from_slice(&sampler.output[at..at + dim]);
        v
    };
    crate::gltf_import::sampler_track(String::new(), kind, times, sampler.interpolation, value)
        .build(&crate::clip_json::SettingsDoc::default())
}

/// How much more than its largest value at 9 evenly spaced points a cubic
/// can reach between them: with `h = 1/8` of the interval, Markov's
/// inequality bounds the second derivative by `96 max|p|`, so linear
/// interpolation misses by at most `12 h² max|p|`, and
/// `max|p| <= max|p(x_i)| / (1 - 12/64) = 1.23 max|p(x_i)|`.
const BETWEEN_POINTS: f64 = 1.25;

/// How [`read_back_error`] samples an interval where the clip is a
/// polynomial of degree 3 or less in time (no ease) and where it is one of
/// degree 6 (an eased cubic): points per interval, and how far such a
/// polynomial can stray from the line between two neighbouring samples,
/// as a fraction of the range of the samples.
///
/// For degree `n` over an interval of length 1 the second derivative is at
/// most `K max|p - c|` (Markov: `K = 4 n² (n² - 1) / 3`, 96 for `n = 3`,
/// 1680 for `n = 6`), so a line between points `h` apart misses by at most
/// `m = K h² / 8` of `max|p - c|`; with `c` the middle of the samples'
/// range `r`, `max|p - c| <= (r / 2) / (1 - m)`, and the miss is at most
/// `m / (1 - m) r / 2`: 0.115 r for `n = 3` at 8 intervals (`m = 0.1875`),
/// 0.129 r for `n = 6` at 32 (`m = 0.205`).
const CUBIC_SAMPLING: (usize, f64) = (8, 0.116);
/// See [`CUBIC_SAMPLING`].
const EASED_SAMPLING: (usize, f64) = (32, 0.13);

/// An upper bound of the difference between `data` and `back`
/// (relative to max(1, |value|)) wherever `data` is finite, `data` held at
/// its end values outside its keys as glTF holds them: what a reader of
/// the export gets, resampling and f32 key times included. Both are
/// sampled at evenly spaced points of each interval between the keys of
/// both and the ends of `data`'s ease phases, where for vector tracks
/// both are polynomials in time ([`CUBIC_SAMPLING`], [`EASED_SAMPLING`]).
/// Between two samples, the difference is bounded by the larger of its two
/// ends plus a fraction of its range in the interval, and divided by
/// max(1, the least `|value|` there) bounded the same way (0 where the
/// value changes sign). The value's range matters: a curve that crosses
/// zero between keys 1e12 apart is held to the absolute difference there,
/// which f32 keys and tangents of that size cannot keep small (issue 29
/// class 6). Rotations (up to sign) are no polynomials: for them an
/// estimate that samples where they turn fast
/// ([`rotation_interval_error`]). Vector tracks' samples are each off
/// their polynomial by f32 playback's rounding ([`PlaybackRounding`]),
/// counted where it is more than [`PLAYBACK_ROUNDING_FLOOR`]; hermite
/// rotations add it as [`hermite_rotation_rounding`] estimates it, on the
/// same condition. Infinite where `back` is not finite and `data` is.
fn read_back_error(data: &TrackData, back: &TrackData) -> f64 {
    let dim = data.kind().dim();
    let rotation = data.kind() == TrackKind::Quat;
    let own = data.times();
    let (first, last) = (own[0], own[own.len() - 1]);
    let eased = eased_segments(data);
    let mut times: Vec<f64> = own.iter().chain(back.times()).copied().collect();
    for &(t0, t1, e) in &eased {
        // Where an ease changes phase, `u = a` and `u = 1 - e`: one
        // polynomial in time on each side.
        times.extend(
            [e.from(), 1.0 - e.to()]
                .into_iter()
                .filter(|u| *u > 0.0 && *u < 1.0)
                .map(|u| t0 + (t1 - t0) * u),
        );
    }
    times.sort_by(f64::total_cmp);
    times.dedup();
    let mut want = vec![[0.0f32; 4]; EASED_SAMPLING.0 + 1];
    let mut got = want.clone();
    let mut worst = 0.0f64;
    for w in times.windows(2) {
        let mid = 0.5 * (w[0] + w[1]);
        let (points, slack) = if eased.iter().any(|&(t0, t1, _)| t0 < mid && mid < t1) {
            EASED_SAMPLING
        } else {
            CUBIC_SAMPLING
        };
        if rotation {
            let sample = |t: f64| {
                let (mut a, mut b) = ([0.0f32; 4], [0.0f32; 4]);
                data.sample_into(t.clamp(first, last), &mut a, None);
                back.sample_into(t, &mut b, None);
                (a, b)
            };
            let e = rotation_interval_error(sample, w[0], w[1], points);
            let rounding = hermite_rotation_rounding(data, back, w, first, last, points);
            worst = worst.max(if rounding > PLAYBACK_ROUNDING_FLOOR {
                e + rounding
            } else {
                e
            });
            if worst == f64::INFINITY {
                break;
            }
            continue;
        }
        for (i, (want, got)) in want.iter_mut().zip(&mut got).take(points + 1).enumerate() {
            let t = if i == points {
                w[1]
            } else {
                w[0] + (w[1] - w[0]) * i as f64 / points as f64
            };
            data.sample_into(t.clamp(first, last), &mut want[..dim], None);
            back.sample_into(t, &mut got[..dim], None);
        }
        let rounding = PlaybackRounding::between(data, back, mid.clamp(first, last), mid);
        let e = interval_error(&want[..=points], &got[..=points], dim, slack, rounding);
        worst = worst.max(e);
        if worst == f64::INFINITY {
            break;
        }
    }
    worst
}

/// [`read_back_error`]'s bound over one interval from the samples `want`
/// and `got` (`dim` components each) at its evenly spaced points, a
/// polynomial straying `slack` of its samples' range between two of them,
/// each sample off its polynomial by up to `rounding` (f32 playback).
///
/// With `n` the difference's rounding and `r` its samples' range, the
/// polynomial difference is within `max |d_i| + n + slack (r + 2 n)` of 0
/// and a sample of it, played, within `n` more; the least `|value|` is
/// bounded the same way with the clip's own rounding.
fn interval_error(
    want: &[[f32; 4]],
    got: &[[f32; 4]],
    dim: usize,
    slack: f64,
    rounding: PlaybackRounding,
) -> f64 {
    let mut worst = 0.0f64;
    for c in 0..dim {
        let w: Vec<f64> = want.iter().map(|v| f64::from(v[c])).collect();
        let g: Vec<f64> = got.iter().map(|v| f64::from(v[c])).collect();
        if w.iter()
            .zip(&g)
            .any(|(w, g)| w.is_finite() && !g.is_finite())
        {
            return f64::INFINITY;
        }
        if w.iter().any(|x| !x.is_finite()) {
            // The clip itself is not finite here (tangents that overflow
            // f32): no polynomial to bound; where it is finite, as is.
            let pointwise = w.iter().zip(&g).filter(|(w, _)| w.is_finite());
            for (w, g) in pointwise {
                worst = worst.max((w - g).abs() / w.abs().max(1.0));
            }
            continue;
        }
        let d: Vec<f64> = w.iter().zip(&g).map(|(w, g)| w - g).collect();
        let range = |x: &[f64]| {
            x.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                - x.iter().copied().fold(f64::INFINITY, f64::min)
        };
        let (n, own) = (rounding.difference[c], rounding.clip[c]);
        let (d_slack, w_slack) = (slack * range(&d), slack * range(&w));
        for i in 0..d.len() - 1 {
            let off = d[i].abs().max(d[i + 1].abs()) + d_slack;
            let least = if w[i].signum() == w[i + 1].signum() {
                w[i].abs().min(w[i + 1].abs()) - w_slack
            } else {
                0.0
            };
            let sampled = off / least.max(1.0);
            // With f32 playback's rounding, where it is more than the
            // floor (below it, the curve's own f32 precision).
            let rounded =
                (off + (2.0 + 2.0 * slack) * n) / (least - (2.0 + 2.0 * slack) * own).max(1.0);
            worst = worst.max(if rounded - sampled > PLAYBACK_ROUNDING_FLOOR {
                rounded
            } else {
                sampled
            });
        }
    }
    worst
}

/// How far one f32 evaluation of a vector segment (`tcb_core::Track`'s,
/// the runtime's kernels') can be from the segment's polynomial at the
/// exact parameter, per unit of `|p0| + |p1| + |m0| + |m1|` (each
/// component): `s` rounded to f32 (half an ulp of `s`, on a slope of at
/// most 1.5 per unit), the Hermite basis (a few ulps near `s` = 1, where
/// `2 s^3 - 3 s^2 + 1` cancels), the four products and the three sums.
/// 2^-21 (8 f32 ulps of 1); the worst of 2 million random segments was 6.
/// On controls far larger than the value (tangents of 1e24 leading to a
/// key of 1.85) this is far larger than the value's own ulp.
const PLAYBACK_ROUNDING: f64 = 4.0 * f32::EPSILON as f64;

/// Below this (relative to max(1, |value|)), what [`PLAYBACK_ROUNDING`]
/// adds to a track's bound is left out: the f32 precision of a curve whose
/// controls are not far larger than its values, which the clip played in
/// f32 has as well. The bound of [`PLAYBACK_ROUNDING`] is a worst case,
/// some 10 times what such a curve's samples show (a vector track on 0.3
/// s and 1.1 s keys, tangents of 5 beside values of 1: bounded at 3e-5,
/// read back within 1e-6); counted, it would put every export of 30 fps
/// keys above the default `max_error`.
const PLAYBACK_ROUNDING_FLOOR: f64 = 5e-5;

/// How far f32 playback can put a sample off its polynomial, per
/// component, in one interval of [`read_back_error`]: the clip's own
/// ([`PLAYBACK_ROUNDING`] times its segment's controls) and the difference
/// of the clip and its read-back (both curves'). Zero where both play one
/// segment on the same key times with the same controls: then they
/// compute the same f32 numbers at every time, and only there. Where a key
/// moved (glTF's f32 times), one `s` can round apart from the other and
/// the two differ by the segment's rounding, which on controls far larger
/// than the value is far more than the value's ulp (issue 29 class 6:
/// reported exact, read back 1.7e-4 off a component of 1.1e21 beside
/// controls of 1e24).
#[derive(Clone, Copy, Default)]
struct PlaybackRounding {
    clip: [f64; 4],
    difference: [f64; 4],
}

impl PlaybackRounding {
    /// For `data` played at `t` (inside its keys) and `back` at `t_back`.
    fn between(data: &TrackData, back: &TrackData, t: f64, t_back: f64) -> PlaybackRounding {
        let (a, b) = (played_segment(data, t), played_segment(back, t_back));
        if a == b {
            return PlaybackRounding::default();
        }
        let size = |p: &Option<PlayedSegment>| {
            let mut s = [0.0f64; 4];
            if let Some(p) = p {
                for control in &p.controls {
                    for (s, x) in s.iter_mut().zip(control) {
                        *s += f64::from(x.abs());
                    }
                }
            }
            s
        };
        let (sa, sb) = (size(&a), size(&b));
        PlaybackRounding {
            clip: sa.map(|x| PLAYBACK_ROUNDING * x),
            difference: std::array::from_fn(|c| PLAYBACK_ROUNDING * (sa[c] + sb[c])),
        }
    }
}

/// The segment a vector track (or a hermite rotation's cubic) plays at a
/// time inside its keys: its key times, controls (`p0`, `p1`, `m0`, `m1`)
/// and ease, all its f32 value depends on there.
#[derive(PartialEq)]
struct PlayedSegment {
    times: (f64, f64),
    controls: [[f32; 4]; 4],
    ease: SegmentEase,
}

/// The segment `data` plays at `t` in f32 (for a rotation, its hermite
/// cubic's); `None` outside the keys and at the last key (held: the key
/// itself), on `step` segments (the key itself: basis `[1, 0, 0, 0]`) and
/// on rotations' slerp and squad segments (played in f64).
fn played_segment(data: &TrackData, t: f64) -> Option<PlayedSegment> {
    fn of<V: TcbValue>(track: &Track<V>, t: f64) -> Option<PlayedSegment> {
        let times = track.times();
        if !(times[0] <= t && t < times[times.len() - 1]) {
            return None;
        }
        let k = tcb_core::track::segment_from(times, t, 0);
        let seg = &track.segments()[k];
        (seg.interp != Interp::Step).then(|| PlayedSegment {
            times: (times[k], times[k + 1]),
            controls: [seg.p0, seg.p1, seg.m0, seg.m1].map(V::to_array),
            ease: seg.ease,
        })
    }
    match data {
        TrackData::Scalar(t_) => of(t_, t),
        TrackData::Vec2(t_) => of(t_, t),
        TrackData::Vec3(t_) => of(t_, t),
        TrackData::Vec4(t_) => of(t_, t),
        // A hermite rotation plays its curve segments as a Vec4 cubic in
        // f32, normalized; slerp and squad segments in f64, `step` holds.
        TrackData::Quat(r) => {
            let h = r.hermite_track()?;
            let k = tcb_core::track::segment_from(h.times(), t, 0);
            if r.interps()[k] == Interp::Curve {
                of(h, t)
            } else {
                None
            }
        }
    }
}

/// For a hermite rotation ([`read_back_error`]'s interval `w`): what f32
/// playback's rounding of the un-normalized cubics ([`PlaybackRounding`],
/// largest component) can move the rotation, divided by the least length
/// of the clip's or the read-back's cubic at `points + 1` samples (an
/// estimate, as the rotation's error is). 0 where both play one segment
/// on the same times and controls, or neither plays a hermite segment.
fn hermite_rotation_rounding(
    data: &TrackData,
    back: &TrackData,
    w: &[f64],
    first: f64,
    last: f64,
    points: usize,
) -> f64 {
    let mid = 0.5 * (w[0] + w[1]);
    let rounding = PlaybackRounding::between(data, back, mid.clamp(first, last), mid);
    let n = rounding.difference.into_iter().fold(0.0, f64::max);
    if n == 0.0 {
        return 0.0;
    }
    fn cubic(d: &TrackData) -> Option<&Track<glam::Vec4>> {
        match d {
            TrackData::Quat(r) => r.hermite_track(),
            _ => None,
        }
    }
    let length = |h: Option<&Track<glam::Vec4>>, t: f64| {
        h.map_or(f64::INFINITY, |h| f64::from(h.sample(t).length()))
    };
    let least = (0..=points)
        .map(|i| w[0] + (w[1] - w[0]) * i as f64 / points as f64)
        .map(|t| length(cubic(data), t.clamp(first, last)).min(length(cubic(back), t)))
        .fold(f64::INFINITY, f64::min);
    // Unit rotations up to sign are never more than 2 apart in a
    // component (and a cubic of length 0 would give infinity).
    (2.0 * n / least).min(2.0)
}

/// How far apart (largest component) two neighbouring samples of a
/// rotation may be before [`rotation_interval_error`] samples between them.
const ROTATION_STEP: f32 = 0.02;
/// The most samples [`rotation_interval_error`] takes in one interval.
const ROTATION_SAMPLES: usize = 4096;

/// [`read_back_error`]'s estimate over one interval `[a, b]` for a
/// rotation, from `sample(t)` (the clip's and the read-back's): `points`
/// evenly spaced samples, and more between any two where either curve
/// moves more than [`ROTATION_STEP`] (down to f64's resolution, up to
/// [`ROTATION_SAMPLES`]). Between two samples, the difference (up to sign,
/// the better one at both ends) is taken as the larger of its two ends
/// plus half its change: an estimate, not a bound (a rotation is
/// normalized, or squad, not a polynomial), but one that follows the
/// curves where they turn fast, as a squad between far keys or a curve
/// leaving a key with a huge tangent does (issue 29 class 6: reported
/// 0.0024, read back 1.0 off one f32 step after a key).
fn rotation_interval_error(
    sample: impl Fn(f64) -> ([f32; 4], [f32; 4]),
    a: f64,
    b: f64,
    points: usize,
) -> f64 {
    let step = |p: &[f32; 4], q: &[f32; 4]| (0..4).map(|c| (p[c] - q[c]).abs()).fold(0.0, f32::max);
    let mut samples: Vec<(f64, [f32; 4], [f32; 4])> = (0..=points)
        .map(|i| {
            let t = if i == points {
                b
            } else {
                a + (b - a) * i as f64 / points as f64
            };
            let (w, g) = sample(t);
            (t, w, g)
        })
        .collect();
    let mut i = 0;
    while i + 1 < samples.len() {
        let ((t0, w0, g0), (t1, w1, g1)) = (samples[i], samples[i + 1]);
        let mid = 0.5 * (t0 + t1);
        let fast = step(&w0, &w1) > ROTATION_STEP || step(&g0, &g1) > ROTATION_STEP;
        if fast && t0 < mid && mid < t1 && samples.len() < ROTATION_SAMPLES {
            let (w, g) = sample(mid);
            samples.insert(i + 1, (mid, w, g));
        } else {
            i += 1;
        }
    }
    let mut worst = 0.0f64;
    for pair in samples.windows(2) {
        let ((_, w0, g0), (_, w1, g1)) = (pair[0], pair[1]);
        if w0.iter().chain(&w1).any(|x| !x.is_finite()) {
            continue; // the clip itself is not finite here
        }
        if g0.iter().chain(&g1).any(|x| !x.is_finite()) {
            return f64::INFINITY;
        }
        let at = |s: f64| {
            (0..4)
                .map(|c| {
                    let d0 = f64::from(w0[c]) - s * f64::from(g0[c]);
                    let d1 = f64::from(w1[c]) - s * f64::from(g1[c]);
                    d0.abs().max(d1.abs()) + 0.5 * (d1 - d0).abs()
                })
                .fold(0.0, f64::max)
        };
        worst = worst.max(at(1.0).min(at(-1.0)));
    }
    worst
}

/// `data`'s eased segments: start and end time, and the ease.
fn eased_segments(data: &TrackData) -> Vec<(f64, f64, SegmentEase)> {
    fn of(times: &[f64], eases: impl Iterator<Item = SegmentEase>) -> Vec<(f64, f64, SegmentEase)> {
        eases
            .zip(times.windows(2))
            .filter(|(e, _)| !e.is_none())
            .map(|(e, w)| (w[0], w[1], e))
            .collect()
    }
    fn vector<V: TcbValue>(t: &Track<V>) -> Vec<(f64, f64, SegmentEase)> {
        of(t.times(), t.segments().iter().map(|s| s.ease))
    }
    match data {
        TrackData::Scalar(t) => vector(t),
        TrackData::Vec2(t) => vector(t),
        TrackData::Vec3(t) => vector(t),
        TrackData::Vec4(t) => vector(t),
        TrackData::Quat(r) => of(r.times(), r.eases().iter().copied()),
    }
}

/// The sampler of `data` in the shape glTF can hold, and the resampling's own error (`None`: written as it is).
fn track_sampler(data: &TrackData, max_error: f64) -> (Sampler, Option<f64>) {
    let kind = match data.kind().dim() {
        1 => AccessorType::Scalar,
        3 => AccessorType::Vec3,
        _ => AccessorType::Vec4,
    };
    let shape = match data {
        TrackData::Scalar(t) => exact_shape(t),
        TrackData::Vec2(t) => exact_shape(t),
        TrackData::Vec3(t) => exact_shape(t),
        TrackData::Vec4(t) => exact_shape(t),
        TrackData::Quat(r) => {
            let interps = &r.interps()[..r.interps().len() - 1];
            let eased = r.eases().iter().any(|e| !e.is_none());
            match r.hermite_track() {
                Some(h) if !interps.contains(&Interp::Linear) => exact_shape(h),
                _ if interps.iter().all(|i| *i == Interp::Step) => Shape::Step,
                // glTF LINEAR is slerp the short way (glTF 2.0, Appendix:
                // `a = arccos(|q_k . q_k+1|)`); ours goes the long way
                // between keys on opposite hemispheres (`hemisphere: keep`),
                // so only keys on one hemisphere, as written in f32.
                _ if !eased
                    && interps.iter().all(|i| *i == Interp::Linear)
                    && r.keys()
                        .windows(2)
                        .all(|w| w[0].as_quat().dot(w[1].as_quat()) > 0.0) =>
                {
                    Shape::Linear
                }
                _ => Shape::Resample,
            }
        }
    };
    match shape {
        Shape::Step | Shape::Linear => {
            let dim = data.kind().dim();
            let mut output = Vec::new();
            let mut v = vec![0.0f32; dim];
            for &t in data.times() {
                data.sample_into(t, &mut v, None);
                output.extend_from_slice(&v);
            }
            let sampler = Sampler {
                source_times: data.times().to_vec(),
                times: data.times().iter().map(|&t| t as f32).collect(),
                interpolation: if shape == Shape::Step {
                    Interpolation::Step
                } else {
                    Interpolation::Linear
                },
                output,
                kind,
            };
            (sampler, None)
        }
        Shape::Cubic => {
            let c = match data {
                TrackData::Scalar(t) => exact_cubic(t),
                TrackData::Vec2(t) => exact_cubic(t),
                TrackData::Vec3(t) => exact_cubic(t),
                TrackData::Vec4(t) => exact_cubic(t),
                TrackData::Quat(r) => exact_cubic(r.hermite_track().expect("checked above")),
            };
            (cubic_sampler(&c, kind), None)
        }
        Shape::Resample => {
            let (c, err) = resample(data, max_error);
            (cubic_sampler(&c, kind), Some(err))
        }
    }
}

/// One sampler of several morph targets' samplers (same times), outputs interleaved per element.
fn merge(samplers: &[&Sampler]) -> Sampler {
    let targets = samplers.len();
    let per_key = if samplers[0].interpolation == Interpolation::CubicSpline {
        3
    } else {
        1
    };
    let elements = samplers[0].times.len() * per_key;
    let mut output = Vec::with_capacity(elements * targets);
    for e in 0..elements {
        for s in samplers {
            output.push(s.output[e]);
        }
    }
    Sampler {
        source_times: samplers[0].source_times.clone(),
        times: samplers[0].times.clone(),
        interpolation: samplers[0].interpolation,
        output,
        kind: AccessorType::Scalar,
    }
}

/// The binary buffer and the document that describes it.
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

impl Builder {
    /// Append `data` as one buffer view and an f32 accessor of `count`
    /// elements of type `ty`, with per-component min and max when `bounds`
    /// (glTF requires them on animation inputs and on `POSITION`).
    fn accessor(
        &mut self,
        data: &[f32],
        count: usize,
        ty: json::accessor::Type,
        bounds: bool,
        vertex: bool,
    ) -> json::Index<json::Accessor> {
        let offset = self.bin.len();
        for x in data {
            self.bin.extend_from_slice(&x.to_le_bytes());
        }
        let view = self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(data.len() * 4),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: vertex.then_some(Checked::Valid(json::buffer::Target::ArrayBuffer)),
            extensions: None,
            extras: Default::default(),
        });
        let (min, max) = if bounds {
            let width = data.len() / count.max(1);
            let fold = |init: f32, f: fn(f32, f32) -> f32| {
                (0..width)
                    .map(|c| data.iter().skip(c).step_by(width).copied().fold(init, f))
                    .collect::<Vec<f32>>()
            };
            (
                Some(serde_json::json!(fold(f32::INFINITY, f32::min))),
                Some(serde_json::json!(fold(f32::NEG_INFINITY, f32::max))),
            )
        } else {
            (None, None)
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Checked::Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Checked::Valid(ty),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// A mesh of one point with `targets` morph targets that move nothing:
    /// what glTF needs before a node's weights can be animated.
    fn morph_mesh(&mut self, targets: usize) -> json::Index<json::Mesh> {
        use json::accessor::Type::Vec3;
        let position = self.accessor(&[0.0; 3], 1, Vec3, true, true);
        let targets: Vec<json::mesh::MorphTarget> = (0..targets)
            .map(|_| json::mesh::MorphTarget {
                positions: Some(self.accessor(&[0.0; 3], 1, Vec3, true, true)),
                normals: None,
                tangents: None,
            })
            .collect();
        let weights = vec![0.0; targets.len()];
        self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: None,
            primitives: vec![json::mesh::Primitive {
                attributes: [(Checked::Valid(json::mesh::Semantic::Positions), position)].into(),
                extensions: None,
                extras: Default::default(),
                indices: None,
                material: None,
                mode: Checked::Valid(json::mesh::Mode::Points),
                targets: Some(targets),
            }],
            weights: Some(weights),
        })
    }
}

/// The glTF (or GLB) file of `nodes` and one animation `name` of `channels`.
fn write(
    name: &str,
    nodes: &[NodeOut],
    channels: &[(usize, &'static str, Sampler)],
    binary: bool,
) -> Result<Vec<u8>, Error> {
    let mut b = Builder {
        root: json::Root {
            asset: json::Asset {
                generator: Some("tcb export".into()),
                ..Default::default()
            },
            ..Default::default()
        },
        bin: Vec::new(),
    };
    // Accessors are numbered as they are pushed: the animation's first,
    // then the morph meshes'.
    b.animation(name, channels);
    b.nodes(nodes);
    b.finish(binary)
}

impl Builder {
    /// The animation `name`: a sampler (input and output accessors) and a
    /// channel per entry of `channels`.
    fn animation(&mut self, name: &str, channels: &[(usize, &'static str, Sampler)]) {
        use json::accessor::Type;
        let mut samplers = Vec::new();
        let mut anim_channels = Vec::new();
        for (node, path, s) in channels {
            let input = self.accessor(&s.times, s.times.len(), Type::Scalar, true, false);
            let count = s.output.len() / s.kind.multiplicity();
            let output = self.accessor(&s.output, count, s.kind, false, false);
            samplers.push(json::animation::Sampler {
                extensions: None,
                extras: Default::default(),
                input,
                interpolation: Checked::Valid(s.interpolation),
                output,
            });
            let property = match *path {
                "translation" => json::animation::Property::Translation,
                "rotation" => json::animation::Property::Rotation,
                "scale" => json::animation::Property::Scale,
                _ => json::animation::Property::MorphTargetWeights,
            };
            anim_channels.push(json::animation::Channel {
                sampler: json::Index::new(samplers.len() as u32 - 1),
                target: json::animation::Target {
                    extensions: None,
                    extras: Default::default(),
                    node: json::Index::new(*node as u32),
                    path: Checked::Valid(property),
                },
                extensions: None,
                extras: Default::default(),
            });
        }
        self.root.push(json::Animation {
            extensions: None,
            extras: Default::default(),
            channels: anim_channels,
            name: Some(name.to_string()),
            samplers,
        });
    }

    /// The nodes (children, rest transforms without their identity parts,
    /// a morph mesh where weights are animated) and the scene of their roots.
    fn nodes(&mut self, nodes: &[NodeOut]) {
        let meshes: Vec<Option<json::Index<json::Mesh>>> = nodes
            .iter()
            .map(|n| (n.morphs > 0).then(|| self.morph_mesh(n.morphs)))
            .collect();
        let mut roots = Vec::new();
        let mut children: Vec<Vec<json::Index<json::Node>>> = vec![Vec::new(); nodes.len()];
        for (i, n) in nodes.iter().enumerate() {
            match n.parent {
                Some(p) => children[p].push(json::Index::new(i as u32)),
                None => roots.push(json::Index::new(i as u32)),
            }
        }
        for (i, n) in nodes.iter().enumerate() {
            let rest = n.rest.unwrap_or_default();
            let node = json::Node {
                name: Some(n.name.clone()),
                children: (!children[i].is_empty()).then(|| children[i].clone()),
                mesh: meshes[i],
                // Identity parts are left out, as glTF writers do.
                translation: (rest.translation != glam::Vec3::ZERO)
                    .then(|| <[f32; 3]>::from(rest.translation)),
                rotation: (rest.rotation != glam::Quat::IDENTITY).then(|| {
                    json::scene::UnitQuaternion(<[f32; 4]>::from(rest.rotation.normalize()))
                }),
                scale: (rest.scale != glam::Vec3::ONE).then(|| <[f32; 3]>::from(rest.scale)),
                ..Default::default()
            };
            self.root.push(node);
        }
        let scene = self.root.push(json::Scene {
            extensions: None,
            extras: Default::default(),
            name: None,
            nodes: roots,
        });
        self.root.scene = Some(scene);
    }

    /// The file: the buffer padded to 4 bytes, then GLB chunks or a
    /// `.gltf` with the buffer as a data URI.
    fn finish(mut self, binary: bool) -> Result<Vec<u8>, Error> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let too_big = || Error::import("the export is larger than glTF's 4 GiB limit");
        let mut buffer = json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        };
        let serialize = |e: serde_json::Error| Error::import(format!("writing the glTF JSON: {e}"));
        if binary {
            self.root.push(buffer);
            let json_bytes = self.root.to_vec().map_err(serialize)?;
            let length = 12 + 8 + json_bytes.len().next_multiple_of(4) + 8 + self.bin.len();
            let glb = gltf::binary::Glb {
                header: gltf::binary::Header {
                    magic: *b"glTF",
                    version: 2,
                    length: u32::try_from(length).map_err(|_| too_big())?,
                },
                json: json_bytes.into(),
                bin: Some(self.bin.into()),
            };
            glb.to_vec()
                .map_err(|e| Error::import(format!("writing the GLB: {e}")))
        } else {
            buffer.uri = Some(format!(
                "data:application/octet-stream;base64,{}",
                crate::gltf_import::base64_encode(&self.bin)
            ));
            self.root.push(buffer);
            let mut text = self.root.to_vec_pretty().map_err(serialize)?;
            text.push(b'\n');
            Ok(text)
        }
    }
}

/// Export to `path` (`.glb` binary, else `.gltf`), written atomically.
pub fn export_file(
    clip: &tcb_core::SourceClip,
    skeleton: Option<&Skeleton>,
    path: impl AsRef<Path>,
    options: &ExportOptions,
) -> Result<ExportReport, Error> {
    let path = path.as_ref();
    let (bytes, report) =
        export(clip, skeleton, Container::for_path(path), options).map_err(|e| e.in_file(path))?;
    crate::files::write_atomically(path, &bytes)?;
    Ok(report)
}
