//! Compiling a [`Packed`] clip: the reference compiled as usual into one
//! group, then its controls replaced by the packed stream, checked segment
//! by segment to give the same bits.

use super::store::PackedKeys;
use super::{PackError, Packed};
use crate::clip::{Clip, CompileOptions, key_pair};
use crate::pack::err;
use std::sync::Arc;
use tcb_core::TrackKind;
use wide::f32x8;

impl Clip {
    /// Compile a packed clip: the runtime keeps its stream and decodes keys
    /// as playback reaches them (see [`crate::pack`]). Every stored segment
    /// is checked to give the controls its reference
    /// ([`crate::PackSource::to_clip`]) compiles to, bit for bit.
    pub fn from_packed(packed: Arc<Packed>) -> Result<Clip, PackError> {
        let source = packed.decode()?;
        Clip::from_decoded(packed, &source)
    }

    /// [`from_packed`](Self::from_packed) given `packed`'s decoded integers.
    fn from_decoded(packed: Arc<Packed>, source: &super::PackSource) -> Result<Clip, PackError> {
        let reference = source.to_clip()?;
        let mut clip = Clip::compile_impl(&reference, &CompileOptions::default(), true);
        if clip.groups.len() != 1 {
            return err(format!(
                "a packed clip compiles to one group, not {}",
                clip.groups.len()
            ));
        }
        let g = &clip.groups[0];
        let (np, n) = (g.keys.planes(), source.keys);
        let mut lane_slot = Vec::with_capacity(source.lanes());
        let mut step = vec![[0.0f32; 8]; np];
        let mut weights = vec![[[0.0f32; 8]; 4]; np];
        let mut rebuild = vec![[true; 8]; g.hq_blocks];

        let rot_from = g.vec_blocks;
        let times = source.times();
        for (t, slot) in source.tracks.iter().zip(clip.layout.tracks()) {
            // Every interior key's weights are key 1's (`PackSource::validate`).
            let w = if n > 2 {
                super::key_weights(&times, t, 1)
            } else {
                [0.0; 4]
            };
            for c in 0..t.kind.dim() {
                let at = slot.index[c];
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
                let at = slot.index[0];
                let b = (at / 8 - rot_from) / 4;
                rebuild[b][at % 8] = t.rebuild_w;
            }
        }
        let f32_key = |k: usize| g.keys.f32_key(k).expect("compiled in f32");
        let mut table = Vec::with_capacity(18 * np);
        for e in [0, n - 1, n, n + 1, n + 2, n + 3] {
            for section in f32_key(e) {
                table.extend_from_slice(section);
            }
        }
        let keys = PackedKeys {
            packed: packed.clone(),
            keys: n,
            planes: np,
            lane_slot,
            step: step.into_iter().map(f32x8::new).collect(),
            weights: weights.into_iter().map(|w| w.map(f32x8::new)).collect(),
            rot_from,
            rebuild: rebuild
                .into_iter()
                .map(|m| f32x8::new(m.map(|r| f32::from_bits(if r { u32::MAX } else { 0 }))))
                .collect(),

            table,
        };
        // Every stored segment, forward: the packed controls are the
        // reference's, bit for bit.
        let mut cache = keys.cache();
        let mut f32_cache = g.keys.cache();
        for seg in 0..=n {
            let (a, b) = key_pair(&g.grid, seg);
            let want = g.keys.segment(a, b, &mut f32_cache);
            let got = keys.segment(a, b, &mut cache);
            let pairs = [
                ("P0", want.p0, got.p0),
                ("M0", want.m0, got.m0),
                ("P1", want.p1, got.p1),
                ("M1", want.m1, got.m1),
            ];
            for (what, w, h) in pairs {
                let bits = |v: &[f32x8]| -> Vec<u32> {
                    v.iter()
                        .flat_map(|x| x.to_array().map(f32::to_bits))
                        .collect()
                };
                if bits(w) != bits(h) {
                    let lane = bits(w).iter().zip(bits(h)).position(|(x, y)| *x != y);
                    return err(format!(
                        "packed keys miss their reference at stored segment {seg} ({what}, plane lane {lane:?})"
                    ));
                }
            }
        }
        let g = &mut clip.groups[0];
        g.keys.set_packed(keys);
        clip.packed = Some(packed);
        Ok(clip)
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
        // The file's check decodes every key: compile from those.
        let (packed, source) = Packed::read(bytes)?;
        Clip::from_decoded(Arc::new(packed), &source)
    }

    /// The `.tcbc` bytes of a clip compiled from a packed one; `None` for
    /// others (compile them with `tcb compress` first).
    pub fn to_bytes(&self) -> Option<Vec<u8>> {
        self.packed.as_ref().map(|p| p.to_bytes())
    }

    /// The packed clip this clip was compiled from, if any.
    pub fn packed(&self) -> Option<&Arc<Packed>> {
        self.packed.as_ref()
    }
}
