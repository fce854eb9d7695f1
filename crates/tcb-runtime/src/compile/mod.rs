//! Compiling a validated [`tcb_core::SourceClip`] into the runtime's layout
//! ([`crate::clip`]), offline, in named steps:
//!
//! 1. [`group_tracks`]: tracks by identical time grid, each as per-channel
//!    controls (rotations checked against squad, `rotation`).
//! 2. [`choose_loose`]: small groups become loose lanes (`crate::loose`),
//!    rotations the cubic misses are split where pieces hold.
//! 3. [`build_group`] per remaining group: [`assign_group_slots`],
//!    [`pack_keys`] (the controls per key, f32 or 16-bit),
//!    [`bound_quantization`], the exact-segment table.
//! 4. [`build_loose`]: loose lanes' slots, their quantization, and the
//!    identity lanes that pad rotations to whole blocks.
//!
//! Sampling modules never import this one: it builds a [`Clip`] and its
//! parts, and they only read them.

mod controls;
mod lanes;
mod packed;
mod rotation;

use crate::clip::Clip;
use crate::grid::TimeGrid;
use crate::group::Group;
use crate::layout::{PoseLayout, TrackSlot, plane_slots};
use crate::loose::{Loose, LooseLane};
use crate::quant;
use crate::store::{HQ_STRIDE, KEY_STRIDE, KeyStore, QuantError, per_key};
use controls::{Controls, GridKey, grid_key, grid_of, vector_controls};
use lanes::{IDENTITY_PAD, identity_lane, pack};
use rotation::{RotationControls, exact_table, normalize_gain, rotation_controls, split_rotation};
use std::collections::HashMap;
use std::sync::Arc;
use tcb_core::{Extrapolation, TrackData};
use wide::f32x8;

/// Choices made when a clip is compiled: `Default` and the builders, so
/// that a new option does not break callers (a struct literal does not
/// compile outside the crate).
///
/// ```
/// let options = tcb_runtime::CompileOptions::default().quantize(true);
/// assert!(options.quantize && !options.exact_velocities);
/// ```
///
/// ```compile_fail
/// let options = tcb_runtime::CompileOptions { quantize: true, exact_velocities: false };
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct CompileOptions {
    /// Store the controls in 16 bits per component with a per-channel
    /// range (each track's error bound: [`Clip::quantization_error`]).
    /// Tracks on their own
    /// key times are expanded only when they cross a key.
    pub quantize: bool,
    /// Evaluate every squad (and slerp) segment's velocity by squad's own
    /// formula in f64, as the kernel does where the cubic misses, instead
    /// of by the cubic that plays its values. The cubic's velocity is
    /// checked at 17 points of each segment to 5e-5 of the rotation's
    /// fastest component (1.5e-4 off in one CMU component of 0.15); this
    /// one is the reference's to about 1e-7, for tools that print or compare velocities (`tcb sample
    /// --velocity`). Instances without velocities are unchanged; instances
    /// with velocities run squad in f64 (values and velocities) on every such
    /// segment, and the clip stores its squad controls (about 1 KB per block
    /// of 8 rotations per segment: the CMU capture compiles to 15.6 MB
    /// instead of 3.8).
    pub exact_velocities: bool,
}

impl CompileOptions {
    /// These options with [`quantize`](Self::quantize) set to `on`.
    #[must_use]
    pub fn quantize(mut self, on: bool) -> Self {
        self.quantize = on;
        self
    }

    /// These options with [`exact_velocities`](Self::exact_velocities) set to `on`.
    #[must_use]
    pub fn exact_velocities(mut self, on: bool) -> Self {
        self.exact_velocities = on;
        self
    }
}

/// One vector channel of a group: its track, its component, its controls.
struct VectorRow {
    track: usize,
    component: usize,
    controls: Controls,
}

/// One rotation of a group: its track and its controls.
struct RotationRow {
    track: usize,
    controls: RotationControls,
}

/// Step 1's result: per group its grid and rows, and whether it stays a
/// group (step 2 clears `keep` for groups that become loose lanes).
struct Grouping {
    grids: Vec<TimeGrid>,
    vectors: Vec<Vec<VectorRow>>,
    rotations: Vec<Vec<RotationRow>>,
    keep: Vec<bool>,
}

/// Step 2's result: tracks on their own key times, one lane each.
#[derive(Default)]
struct LooseTracks {
    vectors: Vec<(usize, LooseLane)>,
    rotations: Vec<(usize, LooseLane)>,
}

/// Where the next blocks of the pose go, and which of them start a
/// rotation's 4 planes.
#[derive(Default)]
struct PoseBlocks {
    at: usize,
    quat_blocks: Vec<usize>,
}

/// What the steps fill per track: its slot in the pose and its
/// quantization bound.
struct PerTrack {
    slots: Vec<TrackSlot>,
    quant_error: Vec<f32>,
    quantized: Vec<bool>,
}

impl Clip {
    /// Compile a validated clip.
    ///
    /// ```
    /// let clip = tcb_io::ClipDoc::parse(r#"{"format": "tcb-clip/1", "tracks": [
    ///   {"name": "x", "kind": "vec3", "times": [0, 1], "values": [[0, 0, 0], [1, 2, 3]]}]}"#)
    ///     .unwrap().build().unwrap();
    /// let clip = tcb_runtime::Clip::compile(&clip);
    /// assert_eq!(clip.track("x").map(|t| t.index()), Some(0));
    /// ```
    pub fn compile(source: &tcb_core::SourceClip) -> Self {
        Clip::compile_with(source, &CompileOptions::default())
    }

    /// [`compile`](Self::compile) with options (quantization).
    ///
    /// ```
    /// # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    /// # /*
    /// let path = "data/cmu-01_01.bvh"; // from the repository's root
    /// # */
    /// let source = tcb_io::load(path).unwrap().clip;
    /// let plain = tcb_runtime::Clip::compile(&source);
    /// let options = tcb_runtime::CompileOptions::default().quantize(true);
    /// let small = tcb_runtime::Clip::compile_with(&source, &options);
    /// assert!(small.memory_bytes() * 3 < plain.memory_bytes() * 2);
    /// let hips = small.track("Hips.translation").unwrap();
    /// assert!(small.quantization_error(hips).unwrap() < 1e-3); // in the clip's units
    /// ```
    pub fn compile_with(source: &tcb_core::SourceClip, options: &CompileOptions) -> Self {
        compile_impl(source, options, None)
    }
}

/// [`Clip::compile_with`]; with `pinned`, the group of that track stays a
/// group, however small, and comes first (a packed clip's group on its
/// grid).
pub(crate) fn compile_impl(
    source: &tcb_core::SourceClip,
    options: &CompileOptions,
    pinned: Option<usize>,
) -> Clip {
    let mut grouping = group_tracks(source, options);
    // How much normalizing can grow a quantization error of each rotation
    // (before its rows are moved into loose lanes).
    let mut rot_gain = vec![2.0f32; source.tracks().len()];
    if options.quantize {
        for row in grouping.rotations.iter().flatten() {
            rot_gain[row.track] = normalize_gain(&row.controls);
        }
    }
    // The pinned group: the first to take the track's grid.
    let pinned_group = pinned.and_then(|track| {
        let rows = grouping.vectors.iter().zip(&grouping.rotations);
        rows.enumerate()
            .find(|(_, (v, r))| {
                v.iter().any(|x| x.track == track) || r.iter().any(|x| x.track == track)
            })
            .map(|(g, _)| g)
    });
    join_constants(&mut grouping, pinned_group);
    let loose = choose_loose(&mut grouping, options, pinned_group);
    let mut per_track = PerTrack {
        slots: source
            .tracks()
            .iter()
            .map(|t| TrackSlot {
                name: t.name.clone(),
                kind: t.data.kind(),
                index: [0; 4],
            })
            .collect(),
        quant_error: vec![0.0f32; source.tracks().len()],
        quantized: vec![false; source.tracks().len()],
    };
    let mut blocks = PoseBlocks::default();
    let first = pinned_group.map(|g| grouping.keep[..g].iter().filter(|k| **k).count());
    let Grouping {
        grids,
        vectors,
        rotations,
        keep,
    } = grouping;
    let mut groups: Vec<Group> = grids
        .into_iter()
        .zip(vectors)
        .zip(rotations)
        .zip(keep)
        .filter(|(_, keep)| *keep)
        .map(|(((grid, v), r), _)| build_group(grid, &v, &r, options, &mut per_track, &mut blocks))
        .collect();
    if let Some(i) = first {
        groups[..=i].rotate_right(1);
    }
    let (loose, loose_rot, loose_rot_tracks) =
        build_loose(loose, options, &rot_gain, &mut per_track, &mut blocks);
    Clip {
        name: source.name().to_string(),
        groups,
        layout: Arc::new(PoseLayout::new(
            per_track.slots,
            blocks.at,
            blocks.quat_blocks,
        )),
        loose,
        loose_rot,
        loose_rot_tracks,
        time_range: source.time_range(),
        quant_error: per_track.quant_error,
        quantized: per_track.quantized,
        packed: None,
    }
}

/// Step 1: tracks grouped by identical grid (times, eases, steps, `pre`
/// and `post`), each as its channels' controls.
fn group_tracks(source: &tcb_core::SourceClip, options: &CompileOptions) -> Grouping {
    let mut group_of: HashMap<GridKey, usize> = HashMap::new();
    let mut out = Grouping {
        grids: Vec::new(),
        vectors: Vec::new(),
        rotations: Vec::new(),
        keep: Vec::new(),
    };
    for (track, t) in source.tracks().iter().enumerate() {
        let grid = grid_of(&t.data);
        let g = *group_of.entry(grid_key(&grid)).or_insert_with(|| {
            out.grids.push(grid);
            out.vectors.push(Vec::new());
            out.rotations.push(Vec::new());
            out.keep.push(true);
            out.grids.len() - 1
        });
        let mut vectors = |ctl: Vec<Controls>| {
            for (component, controls) in ctl.into_iter().enumerate() {
                out.vectors[g].push(VectorRow {
                    track,
                    component,
                    controls,
                });
            }
        };
        match &t.data {
            TrackData::Scalar(v) => vectors(vector_controls(v)),
            TrackData::Vec2(v) => vectors(vector_controls(v)),
            TrackData::Vec3(v) => vectors(vector_controls(v)),
            TrackData::Vec4(v) => vectors(vector_controls(v)),
            TrackData::Quat(r) => out.rotations[g].push(RotationRow {
                track,
                controls: rotation_controls(r, options.exact_velocities),
            }),
        }
    }
    out
}

/// Step 1b: a constant rotation (every key the same, the curve still) that
/// would be a loose lane takes a free lane of a group's last rotation block
/// instead, on that group's key times: it costs nothing there, where a
/// loose block costs more per frame than a group's (`tcb_fit::cost`). A
/// reduced clip keeps each constant track as 2 keys of its own (the
/// contract of `docs/reduce.md`), which would otherwise play as loose
/// lanes beside a grid that has room for them.
///
/// The lane plays `normalize((h1 + h2) q)` at the group's `s` where the
/// reference plays it at the track's own (the identity exactly; any other
/// rotation within an ulp or two, inside the 1e-6 rotations are held to).
/// Neither the track nor the group may `reset` (the identity rather than
/// the constant outside the keys), and the pinned group (a packed clip's,
/// whose lanes are the stream's) neither gives nor takes a lane.
fn join_constants(grouping: &mut Grouping, pinned: Option<usize>) {
    let Grouping {
        grids,
        vectors,
        rotations,
        ..
    } = grouping;
    let resets = |g: &TimeGrid| [g.pre, g.post].contains(&Extrapolation::Reset);
    // Groups that stay groups whatever joins them, with a free lane.
    let targets: Vec<usize> = (0..grids.len())
        .filter(|&h| {
            Some(h) != pinned
                && !resets(&grids[h])
                && (!vectors[h].is_empty() || rotations[h].len() >= 8)
        })
        .collect();
    let mut targets = targets.into_iter();
    let mut target = targets.next();
    for g in 0..grids.len() {
        // Only rotations that would be loose lanes (`choose_loose`); the
        // pinned group keeps its lanes, however few.
        if Some(g) == pinned
            || !vectors[g].is_empty()
            || rotations[g].len() >= 8
            || resets(&grids[g])
        {
            continue;
        }
        let mut i = 0;
        while i < rotations[g].len() {
            while let Some(h) = target
                && rotations[h].len().is_multiple_of(8)
            {
                target = targets.next();
            }
            let Some(h) = target else {
                return;
            };
            if h == g || !rotation::is_constant(&rotations[g][i].controls) {
                i += 1;
                continue;
            }
            let row = rotations[g].remove(i);
            let controls = rotation::held(&row.controls, grids[h].times.len() + 1);
            // In track order, as if it had been on the grid: a clip whose
            // other tracks are its source's compiles as the source does.
            let at = rotations[h].partition_point(|r| r.track < row.track);
            rotations[h].insert(
                at,
                RotationRow {
                    track: row.track,
                    controls,
                },
            );
        }
    }
}

/// Step 2: small groups of vector channels only, and of fewer than 8
/// rotations only, become loose lanes (one per track, see `crate::loose`).
/// A rotation with exact segments goes as the cubic pieces of
/// `split_rotation`, or stays a group of its own, split where pieces hold
/// the values (so that squad runs in f64 for values only inside the
/// segments left). Groups with `reset` rotations stay groups (reset gives
/// the identity rather than zero).
fn choose_loose(
    grouping: &mut Grouping,
    options: &CompileOptions,
    pinned: Option<usize>,
) -> LooseTracks {
    let mut out = LooseTracks::default();
    for g in (0..grouping.grids.len()).filter(|g| Some(*g) != pinned) {
        let grid = &mut grouping.grids[g];
        let (vectors, rotations) = (&grouping.vectors[g], &mut grouping.rotations[g]);
        let resets = [grid.pre, grid.post].contains(&Extrapolation::Reset);
        if vectors.is_empty() && !rotations.is_empty() && rotations.len() < 8 && !resets {
            let split: Vec<(TimeGrid, RotationControls)> = rotations
                .iter()
                .map(|row| {
                    // Loose pieces play their cubic's velocity: not with
                    // `exact_velocities`.
                    let rot = &row.controls;
                    if rot.exact.iter().all(Option::is_none) || options.exact_velocities {
                        (grid.clone(), rot.clone())
                    } else {
                        split_rotation(grid, rot, false)
                    }
                })
                .collect();
            if split
                .iter()
                .all(|(_, r)| r.exact.iter().all(Option::is_none))
            {
                grouping.keep[g] = false;
                for (row, (grid, rot)) in rotations.iter().zip(split) {
                    let comps: Vec<&Controls> = rot.comps.iter().collect();
                    out.rotations
                        .push((row.track, LooseLane::new(grid, &comps)));
                }
                continue;
            }
            if let [row] = rotations.as_mut_slice() {
                (*grid, row.controls) = split_rotation(grid, &row.controls, true);
            }
        }
        if rotations.is_empty() && vectors.len() < 8 {
            grouping.keep[g] = false;
            let mut by_track: Vec<(usize, Vec<&Controls>)> = Vec::new();
            for row in vectors {
                match by_track.last_mut() {
                    Some((t, comps)) if *t == row.track => comps.push(&row.controls),
                    _ => by_track.push((row.track, vec![&row.controls])),
                }
            }
            for (track, comps) in by_track {
                out.vectors
                    .push((track, LooseLane::new(grid.clone(), &comps)));
            }
        }
    }
    out
}

/// Step 3, one group: its slots in the pose, its keys, the bound of their
/// quantization, its `offset-repeat` deltas and its exact-segment table.
fn build_group(
    grid: TimeGrid,
    vectors: &[VectorRow],
    rotations: &[RotationRow],
    options: &CompileOptions,
    per_track: &mut PerTrack,
    blocks: &mut PoseBlocks,
) -> Group {
    let (vec_out, vec_blocks, hq_blocks) =
        assign_group_slots(vectors, rotations, &mut per_track.slots, blocks);
    // Groups only: loose lanes search their own listed times.
    let grid = TimeGrid {
        times: grid.times.into_even(),
        ..grid
    };
    let segments = grid.times.len() + 1;
    let delta = if [grid.pre, grid.post].contains(&Extrapolation::OffsetRepeat) {
        let d: Vec<Vec<[f32; 1]>> = vectors
            .iter()
            .map(|r| vec![[r.controls[segments - 1][0] - r.controls[0][0]]])
            .collect();
        pack(&d, 1, [0.0])
    } else {
        Vec::new()
    };
    let (keys, err) = pack_keys(&grid, vectors, rotations, vec_blocks, hq_blocks, options);
    if let Some(err) = err {
        bound_quantization(&err, vectors, rotations, vec_blocks, per_track);
    }
    let controls: Vec<&RotationControls> = rotations.iter().map(|r| &r.controls).collect();
    let unbounded = vectors
        .iter()
        .any(|r| r.controls.iter().flatten().any(|x| !x.is_finite()));
    Group {
        unbounded,
        vector_channels: vectors.len(),
        rotations: rotations.len(),
        exact: exact_table(&controls, segments),
        keys,
        delta,
        vec_blocks,
        vec_out,
        hq_blocks,
        grid,
    }
}

/// The pose blocks of one group: its vector channels (one lane each, 8 to
/// a block), then its rotations (4 planes x, y, z, w per 8). Returns where
/// the vectors start, and the vector and rotation block counts.
fn assign_group_slots(
    vectors: &[VectorRow],
    rotations: &[RotationRow],
    slots: &mut [TrackSlot],
    blocks: &mut PoseBlocks,
) -> (usize, usize, usize) {
    let vec_out = blocks.at;
    let vec_blocks = vectors.len().div_ceil(8);
    for (lane, row) in vectors.iter().enumerate() {
        slots[row.track].index[row.component] = vec_out * 8 + lane;
    }
    blocks.at += vec_blocks;
    let hq_out = blocks.at;
    let hq_blocks = rotations.len().div_ceil(8);
    for (lane, row) in rotations.iter().enumerate() {
        slots[row.track].index = plane_slots(hq_out, lane);
    }
    for b in 0..hq_blocks {
        blocks.quat_blocks.push(hq_out + 4 * b);
    }
    blocks.at += 4 * hq_blocks;
    (vec_out, vec_blocks, hq_blocks)
}

/// A group's controls per key (and sentinel pseudo-key, see [`per_key`]):
/// plane `p`, control `j` (`P TO TI`) of key `k` holds vector blocks, then
/// rotation blocks of 4 planes (x y z w); unused lanes are 0, or the
/// identity for rotations. With `options.quantize`, in 16 bits, with the
/// errors quantization made per control, plane and lane.
fn pack_keys(
    grid: &TimeGrid,
    vectors: &[VectorRow],
    rotations: &[RotationRow],
    vec_blocks: usize,
    hq_blocks: usize,
    options: &CompileOptions,
) -> (KeyStore, Option<QuantError>) {
    // [P TO TI] x [x y z w] per key (and sentinel pseudo-key).
    let hrows: Vec<Vec<[f32; HQ_STRIDE]>> = rotations
        .iter()
        .map(|row| {
            let keys: Vec<Vec<[f32; KEY_STRIDE]>> =
                row.controls.comps.iter().map(|c| per_key(c)).collect();
            (0..keys[0].len())
                .map(|k| std::array::from_fn(|j| keys[j % 4][k][j / 4]))
                .collect()
        })
        .collect();
    let vkeys: Vec<Vec<[f32; KEY_STRIDE]>> = vectors.iter().map(|r| per_key(&r.controls)).collect();
    let control = |k: usize, j: usize, p: usize| {
        f32x8::new(std::array::from_fn(|l| {
            if p < vec_blocks {
                vkeys.get(8 * p + l).map_or(0.0, |r| r[k][j])
            } else {
                let (b, c) = ((p - vec_blocks) / 4, (p - vec_blocks) % 4);
                let pad = IDENTITY_PAD[4 * j + c];
                hrows.get(8 * b + l).map_or(pad, |r| r[k][4 * j + c])
            }
        }))
    };
    let keys = grid.times.len() + 4;
    let planes = vec_blocks + 4 * hq_blocks;
    KeyStore::new(keys, planes, options.quantize, control)
}

/// Each track's bound on what quantization moves its samples
/// ([`quant::sample_bound`]; for rotations, times what normalizing can
/// grow it), from the errors per control, plane and lane.
fn bound_quantization(
    err: &QuantError,
    vectors: &[VectorRow],
    rotations: &[RotationRow],
    vec_blocks: usize,
    per_track: &mut PerTrack,
) {
    let bound = |lane: usize, plane: usize| {
        quant::sample_bound(std::array::from_fn(|j| err[j][plane][lane % 8]))
    };
    for (lane, row) in vectors.iter().enumerate() {
        let e = &mut per_track.quant_error[row.track];
        *e = quant::worse(*e, bound(lane, lane / 8));
        per_track.quantized[row.track] = true;
    }
    for (lane, row) in rotations.iter().enumerate() {
        let b = (0..4)
            .map(|c| bound(lane, vec_blocks + 4 * (lane / 8) + c))
            .fold(0.0f32, quant::worse);
        let e = &mut per_track.quant_error[row.track];
        *e = quant::worse(*e, b * normalize_gain(&row.controls));
        per_track.quantized[row.track] = true;
    }
}

/// Step 4: the loose lanes' pose slots (planes of 8 lanes, like
/// rotations), their quantization (expanded only on key crossings), and
/// loose rotations padded with identity lanes to whole blocks. Returns the
/// vector lanes, the rotation lanes and the count of real rotation tracks.
fn build_loose(
    mut loose: LooseTracks,
    options: &CompileOptions,
    rot_gain: &[f32],
    per_track: &mut PerTrack,
    blocks: &mut PoseBlocks,
) -> (Loose, Loose, usize) {
    let mut quantize_lane = |track: usize, lane: &mut LooseLane, gain: f32| {
        if !options.quantize {
            return;
        }
        // `None`: a range 16 bits cannot span, kept in f32 (no error).
        if let Some(errors) = lane.quantize() {
            let bound = errors
                .into_iter()
                .map(quant::sample_bound)
                .fold(0.0f32, quant::worse);
            per_track.quant_error[track] = gain * bound;
            per_track.quantized[track] = true;
        }
    };
    for (track, lane) in &mut loose.vectors {
        quantize_lane(*track, lane, 1.0);
    }
    for (track, lane) in &mut loose.rotations {
        quantize_lane(*track, lane, rot_gain[*track]);
    }
    for (lane, (track, _)) in loose.vectors.iter().enumerate() {
        per_track.slots[*track].index = plane_slots(blocks.at, lane);
    }
    let vectors = Loose::new(
        loose.vectors.into_iter().map(|(_, l)| l).collect(),
        blocks.at,
    );
    blocks.at += 4 * vectors.blocks;
    // Loose rotations: planes of 8 lanes, blended as rotations.
    for (lane, (track, _)) in loose.rotations.iter().enumerate() {
        per_track.slots[*track].index = plane_slots(blocks.at, lane);
    }
    let tracks = loose.rotations.len();
    let mut lanes: Vec<LooseLane> = loose.rotations.into_iter().map(|(_, l)| l).collect();
    while !lanes.len().is_multiple_of(8) {
        lanes.push(identity_lane());
    }
    let rotations = Loose::new(lanes, blocks.at);
    for b in 0..rotations.blocks {
        blocks.quat_blocks.push(blocks.at + 4 * b);
    }
    blocks.at += 4 * rotations.blocks;
    (vectors, rotations, tracks)
}
