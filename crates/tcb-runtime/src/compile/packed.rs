//! Compiling a [`Packed`] clip without decoding it: the runtime decodes
//! keys as playback reaches them, and needs from the file only what no key
//! holds (the ends' controls and the sentinels, the chord weights, the
//! layout). Those come from a reference of the few keys at the ends
//! (`END_KEYS` each side), compiled as usual into one group, pinned first;
//! the grid is then the clip's own even one. Tracks on key times of their
//! own are in that reference in full and compile as any clip's (loose
//! lanes, or groups after the first). [`Clip::verify_packed`] compiles the
//! whole reference and checks every stored segment against the decoder,
//! bit for bit (what `tcb compress` runs before writing, and the tests).

use super::{CompileOptions, compile_impl};
use crate::clip::Clip;
use crate::grid::{KeyTimes, TimeGrid};
use crate::pack::store::{GATHER_WIDTH, KEY_LENGTH2, PackedKeys};
use crate::pack::{GROUP, PackError, Packed, err, key_weights};
use std::sync::Arc;
use tcb_core::TrackKind;
use wide::f32x8;

/// Keys of the reference at each end: the end tangents read their key's
/// neighbours (natural ends the tangent of the key after, cyclic ends the
/// keys at the other end), so 4 leave every key they read among its real
/// neighbours.
const END_KEYS: usize = 4;

impl Clip {
    /// Compile a packed clip: the runtime keeps its stream and decodes keys
    /// as playback reaches them (see [`crate::pack`]). It decodes the keys
    /// of the stream's first and last blocks only (about 0.3 ms for CMU
    /// 01_01, where the whole reference would take 30), and allocates a
    /// few bytes per component for the grid (its times are `start + k
    /// interval`, not a list); tracks on key times of their own are
    /// compiled in full, to f32 controls. See
    /// [`verify_packed`](Self::verify_packed) for the check of every key.
    pub fn from_packed(packed: Arc<Packed>) -> Result<Clip, PackError> {
        if packed.stream_structure()? != packed.bits {
            return Err(PackError(
                "the packed stream's length disagrees with its structure".into(),
            ));
        }
        packed.head().validate_head()?;
        Clip::from_checked(packed)
    }

    /// [`from_packed`](Self::from_packed) of a clip whose structure and
    /// head are checked: the end keys' reference compiled, its tables kept,
    /// the grid made the clip's own.
    fn from_checked(packed: Arc<Packed>) -> Result<Clip, PackError> {
        let head = packed.head();
        let mut clip = compile_ends(&packed)?;
        let keys = packed_keys(&packed, &clip);
        let g = &mut clip.groups[0];
        g.grid = TimeGrid {
            times: KeyTimes::even(head.start, head.interval, head.keys),
            eases: Vec::new(),
            steps: Vec::new(),
            pre: g.grid.pre,
            post: g.grid.post,
        };
        g.keys.set_packed(keys);
        clip.packed = Some(packed);
        Ok(clip)
    }

    /// Check a clip compiled from a packed one against its whole reference
    /// ([`crate::PackSource::to_clip`], every key decoded and validated,
    /// compiled as usual): the grid, the `offset-repeat` deltas and, for
    /// every stored segment, the four controls the decoder gives, bit for
    /// bit. `Ok` for clips not compiled from a packed one. Costs what a
    /// full compile costs (about 30 ms for CMU 01_01): for tools and tests,
    /// not for a game's loading.
    pub fn verify_packed(&self) -> Result<(), PackError> {
        let Some(packed) = &self.packed else {
            return Ok(());
        };
        let source = packed.decode()?;
        let reference = source.to_clip()?;
        let full = compile_impl(
            &reference,
            &CompileOptions::default(),
            Some(source.place(0)),
        );
        grid_group(&full, &source)?;
        // Tracks on key times of their own are compiled from the same
        // reference tracks both ways: their lanes and groups must agree.
        if full.layout != self.layout
            || format!("{:?}", (&full.loose, &full.loose_rot, &full.groups[1..]))
                != format!("{:?}", (&self.loose, &self.loose_rot, &self.groups[1..]))
        {
            return err("the tracks on key times of their own miss their reference");
        }
        let (Some(want), Some(got)) = (full.groups.first(), self.groups.first()) else {
            return err("a packed clip compiles to one group on its grid");
        };
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
        if bits(&want.grid.times.to_vec()) != bits(&got.grid.times.to_vec()) {
            return err("packed key times miss their reference");
        }
        let lanes = |v: &[f32x8]| -> Vec<u32> {
            v.iter()
                .flat_map(|x| x.to_array().map(f32::to_bits))
                .collect()
        };
        if lanes(&want.delta) != lanes(&got.delta) {
            return err("packed offset-repeat deltas miss their reference");
        }
        let mut state = got.keys.cache();
        let Some((keys, _)) = got.keys.packed(&mut state) else {
            return err("a packed clip's group is packed");
        };
        let n = source.keys;
        let mut cache = keys.cache();
        let mut f32_cache = want.keys.cache();
        for seg in 0..=n {
            let (a, b) = want.grid.key_pair(seg);
            let want = want.keys.segment(a, b, &mut f32_cache);
            let got = keys.segment(a, b, &mut cache);
            let pairs = [
                ("P0", want.p0, got.p0),
                ("M0", want.m0, got.m0),
                ("P1", want.p1, got.p1),
                ("M1", want.m1, got.m1),
            ];
            for (what, w, h) in pairs {
                if lanes(w) != lanes(h) {
                    let lane = lanes(w).iter().zip(lanes(h)).position(|(x, y)| *x != y);
                    return err(format!(
                        "packed keys miss their reference at stored segment {seg} ({what}, plane lane {lane:?})"
                    ));
                }
            }
        }
        Ok(())
    }

    /// Read a `.tcbc` file's bytes ([`Packed::from_bytes`]) and compile it.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use tcb_runtime::{Clip, Instance, PackSource, Packed};
    /// # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    /// # /*
    /// let path = "data/cmu-01_01.bvh"; // from the repository's root
    /// # */
    /// // What `tcb compress` writes (here in steps of 1/4096, not searched).
    /// let source = tcb_io::load(path).unwrap().clip;
    /// let steps = vec![1.0 / 4096.0; source.tracks().len()];
    /// let packed = Packed::encode(&PackSource::quantize(&source, &steps).unwrap()).unwrap();
    /// let bytes = packed.to_bytes(); // or std::fs::read("cmu.tcbc")
    ///
    /// // In the game: load once, share by Arc, sample every frame.
    /// let clip = Arc::new(Clip::from_bytes(&bytes).unwrap());
    /// let hips = clip.track("Hips.rotation").unwrap();
    /// let mut walk = Instance::new(clip.clone());
    /// for frame in 0..120 {
    ///     let q = walk.sample(frame as f64 / 60.0).quat(hips).unwrap();
    ///     assert!((q.length() - 1.0).abs() < 1e-5);
    /// }
    /// ```
    pub fn from_bytes(bytes: &[u8]) -> Result<Clip, PackError> {
        // `read` checks the structure and the head.
        Clip::from_checked(Arc::new(Packed::read(bytes)?))
    }
}

/// The reference of the stream's first and last `END_KEYS` keys (all of
/// them for a short clip), at their real times, compiled into one group
/// (first), with the tracks on key times of their own in full.
fn compile_ends(packed: &Packed) -> Result<Clip, PackError> {
    let head = packed.head();
    let n = head.keys;
    let at: Vec<usize> = if n <= 2 * END_KEYS {
        (0..n).collect()
    } else {
        (0..END_KEYS).chain(n - END_KEYS..n).collect()
    };
    let ints = packed.decode_keys(&at)?;
    let mut ends = head.clone();
    let mut lanes = ints.into_iter();
    for t in &mut ends.tracks {
        t.values = lanes.by_ref().take(t.stored()).collect();
    }
    let reference = ends.reference(&at)?;
    let clip = compile_impl(&reference, &CompileOptions::default(), Some(head.place(0)));
    grid_group(&clip, head)?;
    let g = &clip.groups[0];
    if !(g.grid.eases.is_empty() && g.grid.steps.is_empty() && g.exact.entries.is_empty()) {
        return err("a packed clip's keys have no eases, steps or exact segments");
    }
    Ok(clip)
}

/// Check that `clip`'s first group holds the grid's tracks of `head`, and
/// nothing else (a track on key times of its own whose times are the
/// reference's would join it).
fn grid_group(clip: &Clip, head: &crate::PackSource) -> Result<(), PackError> {
    let g = clip.groups.first();
    let vectors: usize = head
        .tracks
        .iter()
        .filter(|t| t.kind != TrackKind::Quat)
        .map(|t| t.kind.dim())
        .sum();
    let rotations = head
        .tracks
        .iter()
        .filter(|t| t.kind == TrackKind::Quat)
        .count();
    if g.is_none_or(|g| (g.vector_channels, g.rotations) != (vectors, rotations)) {
        return err(
            "a track on key times of its own has the key times of the grid's ends, and would share their group: a packed clip cannot hold it",
        );
    }
    Ok(())
}

/// The decoder's tables for `clip`'s first group (compiled by
/// [`compile_ends`]): per lane its slot, step and chord weights, the
/// rotations whose `w` is rebuilt, and the controls no decoded key gives
/// (keys 0 and n-1, the sentinels).
fn packed_keys(packed: &Arc<Packed>, clip: &Clip) -> PackedKeys {
    let head = packed.head();
    let n = head.keys;
    let g = &clip.groups[0];
    let np = g.keys.planes();
    let m = g.grid.times.len();
    let mut lane_slot = Vec::with_capacity(head.lanes());
    let mut step = vec![[0.0f32; 8]; np];
    let mut weights = vec![[[0.0f32; 8]; 4]; np];
    let mut rebuild = vec![[true; 8]; g.hq_blocks];
    let mut center: Vec<Option<[[f32; 8]; 4]>> = vec![None; g.hq_blocks];
    let rot_from = g.vec_blocks;
    // The rotations' weights, and whether they and the centers allow the
    // key form (`PackedKeys::key_weights`).
    let mut rotation_weights = Vec::new();
    let mut key_form = true;
    for (i, t) in head.tracks.iter().enumerate() {
        let slot = &clip.layout.tracks()[head.place(i)];
        // Flat indices in the group's planes.
        let index = slot.index.map(|at| at - 8 * g.vec_out);
        // Every interior key's weights are key 1's (`PackSource::validate`).
        let w = if n > 2 {
            key_weights(&[0, 1, 2].map(|k| head.time(k)), t, 1)
        } else {
            [0.0; 4]
        };
        for (c, &at) in index.iter().enumerate().take(t.kind.dim()) {
            let (p, l) = (at / 8, at % 8);
            if c < t.stored() {
                lane_slot.push(at as u32);
                step[p][l] = t.step;
            }
            for (j, wj) in w.iter().enumerate() {
                weights[p][j][l] = *wj;
            }
        }
        if t.kind == TrackKind::Quat {
            rotation_weights.push(w);
            key_form &= w.iter().all(|w| w.abs() <= 1.0);
            if let Some(c) = t.center {
                key_form &= c.iter().map(|x| x * x).sum::<f32>() <= KEY_LENGTH2;
            }
            let at = index[0];
            let b = (at / 8 - rot_from) / 4;
            rebuild[b][at % 8] = t.rebuild_w;
            if let Some(r) = t.center {
                let identity = [[0.0; 8], [0.0; 8], [0.0; 8], [1.0; 8]];
                let planes = center[b].get_or_insert(identity);
                for (plane, x) in planes.iter_mut().zip(r) {
                    plane[at % 8] = x;
                }
            }
        }
    }
    // The first and last keys, then the 4 sentinel pseudo-keys (see
    // `crate::store::per_key`): what the decoder does not make.
    let f32_key = |k: usize| g.keys.f32_key(k).expect("compiled in f32");
    let mut table = Vec::with_capacity(18 * np);
    for e in [0, m - 1, m, m + 1, m + 2, m + 3] {
        for section in f32_key(e) {
            table.extend_from_slice(section);
        }
    }
    let (headed, mut headed_base): (Vec<u32>, Vec<u8>) = lane_slot
        .iter()
        .zip(&packed.base_width)
        .filter(|(_, base)| **base != crate::pack::FLAT)
        .map(|(slot, base)| (*slot, *base))
        .unzip();
    // Groups of 8; the entry after them stays 0 (`store::Headers`): where
    // lanes without headers, and lanes not stored, find their coding.
    headed_base.resize(headed.len().next_multiple_of(GROUP), 0);
    let mut plane_index = vec![[headed_base.len() as i32; 8]; np];
    for (i, &slot) in headed.iter().enumerate() {
        plane_index[slot as usize / 8][slot as usize % 8] = i as i32;
    }
    let (start_gather, start_bits) = start_gather(packed, &lane_slot, np);
    let mut stored_planes: Vec<u32> = lane_slot.iter().map(|at| at / 8).collect();
    stored_planes.sort_unstable();
    stored_planes.dedup();
    PackedKeys {
        packed: packed.clone(),
        stored_planes,
        keys: n,
        planes: np,
        lane_slot,
        headed,
        headed_base,
        plane_index,
        step: step.into_iter().map(f32x8::new).collect(),
        weights: weights.into_iter().map(|w| w.map(f32x8::new)).collect(),
        rot_from,
        key_weights: rotation_weights
            .first()
            .copied()
            .filter(|w| key_form && rotation_weights.iter().all(|v| v == w)),
        rebuild_all: rebuild.iter().flatten().all(|&r| r),
        rebuild: rebuild
            .into_iter()
            .map(|m| f32x8::new(m.map(|r| f32::from_bits(if r { u32::MAX } else { 0 }))))
            .collect(),
        center: center
            .into_iter()
            .enumerate()
            .filter_map(|(b, c)| c.map(|planes| (b, planes.map(f32x8::new))))
            .collect(),
        table,
        start_gather,
        start_bits,
    }
}

/// [`PackedKeys::start_gather`] and [`PackedKeys::start_bits`]: a
/// block's start values (in the stream's lane order), then its deltas.
fn start_gather(packed: &Packed, lane_slot: &[u32], np: usize) -> (Vec<[[i32; 8]; 4]>, usize) {
    let widths = |b: &[u8]| b.iter().map(|&w| usize::from(w)).collect::<Vec<_>>();
    let (abs, delta) = (widths(&packed.abs_bits), widths(&packed.delta_bits));
    let mut at = [0, abs.iter().sum::<usize>()];
    let mut planes = vec![[[0i32; 8]; 4]; np];
    let mut fits = at[1] + delta.iter().sum::<usize>() < i32::MAX as usize;
    for ((&slot, &wa), &wd) in lane_slot.iter().zip(&abs).zip(&delta) {
        let (p, l) = (slot as usize / 8, slot as usize % 8);
        for (j, w) in [wa, wd].into_iter().enumerate() {
            fits &= w <= GATHER_WIDTH as usize;
            planes[p][2 * j][l] = at[j] as i32;
            planes[p][2 * j + 1][l] = w as i32;
            at[j] += w;
        }
    }
    if !fits {
        planes.clear();
    }
    (planes, at[1])
}
