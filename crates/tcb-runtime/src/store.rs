//! A group's controls, stored once per key.
//!
//! Every key (and sentinel pseudo-key, see [`per_key`]) holds three
//! sections of `planes` vectors of 8 lanes: `P`, `TO` (the outgoing
//! tangent, `M0` of the segment it starts) and `TI` (the incoming one,
//! `M1` of the segment it ends). A group's planes are its vector blocks
//! (one plane each) then its rotation blocks (four planes each, `x y z w`),
//! as the pose lays them out. `TI` is stored only where it differs from
//! `TO` in some bit of some lane; elsewhere the key's `TI` *is* its `TO`
//! section. On keys of even spacing with continuity 0 the two are equal
//! (2750 of the 2752 keys of the CMU capture in `hermite` mode), so such a
//! clip stores two sections per key, not three, and the kernels read
//! exactly the numbers they read before.
//!
//! ```text
//! key k at at[k][0]:  [P; planes] [TO; planes] ([TI; planes] where TI != TO)
//! TI of key k:        at[k][1] (at[k][0] + planes where TI == TO)
//! ```
//!
//! With quantization ([`crate::CompileOptions::quantize`]) the same layout
//! holds 16-bit numbers; `TO` and `TI` of a plane share one range, so a
//! `TI` equal to its `TO` quantizes to the same numbers (see `crate::quant`).

use crate::pack::store::{PackCache, PackedKeys};
use crate::quant::Quantized;
use crate::segment::Segment;
use wide::f32x8;

/// `[P, TO, TI]` of one channel at one key ([`per_key`]).
pub(crate) const KEY_STRIDE: usize = 3;
/// `[P, TO, TI]` x `[x, y, z, w]` of one rotation at one key.
pub(crate) const HQ_STRIDE: usize = 12;

/// A channel's controls per key, `[P, TO, TI]` (`TO_k` = `M0` of segment
/// k, `TI_k` = `M1` of segment k-1; nothing is stored twice), for the n
/// keys, then the sentinels as four pseudo-keys `pre_a pre_b post_a post_b`
/// that give back `[P0, P1, M0, M1]` of stored segments 0 and n the same
/// way (see `TimeGrid::key_pair`).
pub(crate) fn per_key(rows: &[[f32; 4]]) -> Vec<[f32; KEY_STRIDE]> {
    let n = rows.len() - 1;
    let mut out: Vec<[f32; KEY_STRIDE]> = (0..n)
        .map(|k| {
            let p = if k < n - 1 {
                rows[k + 1][0]
            } else {
                rows[n][0]
            };
            let to = if k < n - 1 { rows[k + 1][2] } else { 0.0 };
            let ti = if k > 0 { rows[k][3] } else { 0.0 };
            [p, to, ti]
        })
        .collect();
    // The sentinels are read only through the fixed rows of `grid.rs` (hold,
    // reset, line, at the last key), whose zeros must not meet an infinite
    // tangent (a key whose parameters overflow f32): there, 0 * inf would
    // be NaN where the reference returns the key, or zero.
    let finite = |x: f32| {
        if x.is_nan() {
            0.0
        } else {
            x.clamp(-f32::MAX, f32::MAX)
        }
    };
    for r in [rows[0], rows[n]].map(|r| r.map(finite)) {
        out.push([r[0], r[2], 0.0]);
        out.push([r[1], 0.0, r[3]]);
    }
    out
}

/// The numbers, in f32 or in 16 bits.
#[derive(Clone, Debug)]
enum Data {
    F32(Vec<f32x8>),
    Q16(Quantized),
}

/// One group's controls per key (see the module docs).
#[derive(Clone, Debug)]
pub(crate) struct KeyStore {
    planes: usize,
    /// Per key: where its `P` section starts (`TO` follows) and where its
    /// `TI` section starts.
    at: Vec<[u32; 2]>,
    data: Data,
    /// Values only, decoded per instance (`crate::pack`): when set, `at`
    /// and `data` are empty.
    packed: Option<Box<PackedKeys>>,
}

/// Per control (`P`, `TO`, `TI`), plane and lane: the largest error
/// quantization made on any key.
pub(crate) type QuantError = [Vec<[f32; 8]>; 3];

impl KeyStore {
    /// Store `keys` keys of `planes` planes; `control(k, j, p)` is control
    /// `j` (`0` P, `1` TO, `2` TI) of plane `p` at key `k`. Quantized, it
    /// also returns the error made per control, plane and lane.
    pub fn new(
        keys: usize,
        planes: usize,
        quantize: bool,
        control: impl Fn(usize, usize, usize) -> f32x8,
    ) -> (Self, Option<QuantError>) {
        let mut at = Vec::with_capacity(keys);
        let mut data = Vec::with_capacity(keys * 2 * planes);
        let offset =
            |x: usize| u32::try_from(x).expect("a group's controls under 2^32 vectors (128 GiB)");
        for k in 0..keys {
            let start = data.len();
            data.extend((0..planes).map(|p| control(k, 0, p)));
            data.extend((0..planes).map(|p| control(k, 1, p)));
            data.extend((0..planes).map(|p| control(k, 2, p)));
            let (to, ti) = data[start + planes..].split_at(planes);
            let ti_at = if ti.iter().zip(to).all(|(i, o)| bits(*i) == bits(*o)) {
                data.truncate(start + 2 * planes);
                start + planes
            } else {
                start + 2 * planes
            };
            at.push([offset(start), offset(ti_at)]);
        }
        // Quantized unless asked not to, or where a range 16 bits cannot
        // span within a finite bound (then kept in f32).
        let quantized = if quantize {
            Quantized::new(&data, &at, planes)
        } else {
            None
        };
        let Some((q, error)) = quantized else {
            let store = KeyStore {
                planes,
                at,
                data: Data::F32(data),
                packed: None,
            };
            return (store, None);
        };
        let store = KeyStore {
            planes,
            at,
            data: Data::Q16(q),
            packed: None,
        };
        (store, Some(error))
    }

    /// Of the first `keys` keys, those whose `TI` is stored apart.
    pub fn own_ti(&self, keys: usize) -> usize {
        let n = self.planes as u32;
        self.at
            .iter()
            .take(keys)
            .filter(|[p, i]| *i != p + n)
            .count()
    }

    /// Planes per section.
    pub fn planes(&self) -> usize {
        self.planes
    }

    /// Heap bytes.
    pub fn heap_bytes(&self) -> usize {
        std::mem::size_of_val(self.at.as_slice())
            + match &self.data {
                Data::F32(d) => std::mem::size_of_val(d.as_slice()),
                Data::Q16(q) => q.heap_bytes(),
            }
            + self.packed.as_ref().map_or(0, |p| p.heap_bytes())
    }

    /// Whether the numbers are 16-bit.
    pub fn quantized(&self) -> bool {
        matches!(self.data, Data::Q16(_))
    }

    /// The controls of the segment from key `a` to key `b`: slices of the
    /// f32 storage, or, quantized, expanded into `cache` (only the keys it
    /// does not hold yet).
    #[inline(always)]
    pub fn segment<'a>(&'a self, a: usize, b: usize, cache: &'a mut KeyCache) -> Segment<'a> {
        let n = self.planes;
        match &self.data {
            Data::F32(d) => {
                let [pa, _] = self.at[a];
                let [pb, ib] = self.at[b];
                let (pa, pb, ib) = (pa as usize, pb as usize, ib as usize);
                Segment {
                    p0: &d[pa..pa + n],
                    m0: &d[pa + n..pa + 2 * n],
                    p1: &d[pb..pb + n],
                    m1: &d[ib..ib + n],
                }
            }
            Data::Q16(q) => self.expanded(q, a, b, cache),
        }
    }

    /// [`segment`](Self::segment) of a quantized group. Only the sections the
    /// segment reads are expanded: `P` and `TO` of its first key, `P` and
    /// `TI` (`TO`'s where shared) of its second; a key read again keeps what
    /// it has.
    #[inline(always)]
    fn expanded<'a>(
        &self,
        q: &Quantized,
        a: usize,
        b: usize,
        cache: &'a mut KeyCache,
    ) -> Segment<'a> {
        let n = self.planes;
        let sa = cache.slot(a, b);
        let sb = cache.slot(b, a);
        let ([pa, _], [pb, ib]) = (self.at[a], self.at[b]);
        let (pa, pb, ib) = (pa as usize, pb as usize, ib as usize);
        let ti = if ib == pb + n { TO } else { TI };
        let avx2 = crate::isa::Avx2Kernels::now();
        cache.ensure(q, sa, P, pa, avx2);
        cache.ensure(q, sa, TO, pa + n, avx2);
        cache.ensure(q, sb, P, pb, avx2);
        cache.ensure(q, sb, ti, ib, avx2);
        Segment {
            p0: cache.section(sa, P, n),
            m0: cache.section(sa, TO, n),
            p1: cache.section(sb, P, n),
            m1: cache.section(sb, ti, n),
        }
    }

    /// A cache for [`segment`](Self::segment), per instance.
    pub fn cache(&self) -> KeyCache {
        let n = if self.quantized() { self.planes } else { 0 };
        KeyCache {
            keys: [usize::MAX; 2],
            valid: [0; 2],
            planes: n,
            data: vec![f32x8::ZERO; 2 * 3 * n],
            pack: self.packed.as_ref().map(|p| Box::new(p.cache())),
        }
    }

    /// Sections `[P, TO, TI]` of key `k` of an f32 store (`None` otherwise).
    pub fn f32_key(&self, k: usize) -> Option<[&[f32x8]; 3]> {
        let Data::F32(d) = &self.data else {
            return None;
        };
        let n = self.planes;
        let [p, i] = self.at[k].map(|x| x as usize);
        Some([&d[p..p + n], &d[p + n..p + 2 * n], &d[i..i + n]])
    }

    /// This store with its numbers replaced by `packed` (its key table
    /// kept only for sizes).
    pub fn set_packed(&mut self, packed: PackedKeys) {
        self.at = Vec::new();
        self.data = Data::F32(Vec::new());
        self.packed = Some(Box::new(packed));
    }

    /// A packed group's controls and its cache's decoder state: such a
    /// group is sampled apart (`instance::sample_packed`), so that the f32
    /// and 16-bit path stays as it was.
    #[inline(always)]
    pub fn packed<'a>(
        &'a self,
        cache: &'a mut KeyCache,
    ) -> Option<(&'a PackedKeys, &'a mut PackCache)> {
        let p = self.packed.as_deref()?;
        Some((
            p,
            cache.pack.as_deref_mut().expect("a packed group's cache"),
        ))
    }
}

/// Two expanded keys of a quantized group (forward playback reuses the
/// previous frame's second key as this one's first), `[P TO TI]` each,
/// each section expanded when a segment first reads it.
#[derive(Clone, Debug)]
pub(crate) struct KeyCache {
    keys: [usize; 2],
    /// Per slot, the sections expanded (bit `P`, `TO`, `TI`).
    valid: [u8; 2],
    planes: usize,
    data: Vec<f32x8>,
    /// A packed group's decoder state.
    pack: Option<Box<PackCache>>,
}

/// Sections of a key: `P`, `TO`, `TI`.
const P: usize = 0;
const TO: usize = 1;
const TI: usize = 2;

impl KeyCache {
    /// The slot holding key `k`, or a slot given to it (not the one
    /// holding `keep`, the other key of the segment), emptied.
    #[inline(always)]
    fn slot(&mut self, k: usize, keep: usize) -> usize {
        if let Some(s) = self.keys.iter().position(|&c| c == k) {
            return s;
        }
        let s = usize::from(self.keys[0] == keep);
        self.keys[s] = k;
        self.valid[s] = 0;
        s
    }

    /// Expand section `j` of slot `s` from the quantized numbers at `at`,
    /// unless it is there (`avx2`: as [`Quantized::expand`] takes it).
    #[inline(always)]
    fn ensure(
        &mut self,
        q: &Quantized,
        s: usize,
        j: usize,
        at: usize,
        avx2: Option<crate::isa::Avx2Kernels>,
    ) {
        if self.valid[s] & (1 << j) == 0 {
            let n = self.planes;
            let start = (3 * s + j) * n;
            q.expand(at, j != P, &mut self.data[start..start + n], avx2);
            self.valid[s] |= 1 << j;
        }
    }

    #[inline(always)]
    fn section(&self, s: usize, j: usize, n: usize) -> &[f32x8] {
        let start = (3 * s + j) * n;
        &self.data[start..start + n]
    }
}

fn bits(x: f32x8) -> [u32; 8] {
    x.to_array().map(f32::to_bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three keys of two planes: key 1's `TI` equals its `TO` and is not
    /// stored; keys 0 and 2 differ in one lane of one plane and are.
    fn controls(k: usize, j: usize, p: usize) -> f32x8 {
        let mut x = [0.0f32; 8];
        for (l, x) in x.iter_mut().enumerate() {
            let to = (10 * k + p) as f32 + 0.25 * l as f32;
            *x = match j {
                0 => -((10 * k + p) as f32) - l as f32,
                2 if k != 1 && p == 1 && l == 5 => to + 1.0,
                _ => to,
            };
        }
        f32x8::new(x)
    }

    #[test]
    fn ti_is_stored_only_where_it_differs() {
        let (store, err) = KeyStore::new(3, 2, false, controls);
        assert!(err.is_none());
        // Keys 0 and 2: P TO TI; key 1: P TO.
        assert_eq!(store.heap_bytes(), 2 * 32 * (3 + 2 + 3) + 3 * 8);
        assert_eq!((store.own_ti(3), store.own_ti(2)), (2, 1));
        let mut cache = store.cache();
        for (a, b) in [(0, 1), (1, 2), (2, 0), (1, 1)] {
            let s = store.segment(a, b, &mut cache);
            for p in 0..2 {
                assert_eq!(bits(s.p0[p]), bits(controls(a, 0, p)), "{a} {b} {p}");
                assert_eq!(bits(s.m0[p]), bits(controls(a, 1, p)), "{a} {b} {p}");
                assert_eq!(bits(s.p1[p]), bits(controls(b, 0, p)), "{a} {b} {p}");
                assert_eq!(bits(s.m1[p]), bits(controls(b, 2, p)), "{a} {b} {p}");
            }
        }
    }

    #[test]
    #[allow(clippy::needless_range_loop)] // p indexes four slices and the errors
    fn quantized_keys_expand_within_their_error() {
        let (store, err) = KeyStore::new(3, 2, true, controls);
        let err = err.expect("quantized");
        assert!(store.quantized());
        let mut cache = store.cache();
        for (a, b) in [(0, 1), (1, 2), (2, 0), (0, 2), (1, 1)] {
            let s = store.segment(a, b, &mut cache);
            for p in 0..2 {
                let near = |x: f32x8, j: usize, k: usize| {
                    let (x, want) = (x.to_array(), controls(k, j, p).to_array());
                    (0..8).all(|l| (x[l] - want[l]).abs() <= err[j][p][l] && err[j][p][l] < 1e-3)
                };
                assert!(near(s.p0[p], 0, a) && near(s.m0[p], 1, a), "{a} {b} {p}");
                assert!(near(s.p1[p], 0, b) && near(s.m1[p], 2, b), "{a} {b} {p}");
            }
            // A TI equal to its TO stays equal once quantized.
            if b == 1 {
                let s = store.segment(b, b, &mut cache);
                assert_eq!(bits(s.m0[0]), bits(s.m1[0]));
            }
        }
    }
}
