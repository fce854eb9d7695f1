//! The `.tcbc` file: a [`Packed`] clip in bytes (layout in `docs/tcbc.md`).
//!
//! Little-endian throughout: a 24-byte header (magic, version, length,
//! CRC-32 of everything after the header), then the description, the
//! per-lane widths, the block table and the stream. Reading checks the
//! header, the checksum and every length against the bytes left before it
//! allocates, and refuses a file that claims more keys than its block table
//! and headers can describe: no allocation is larger than the file (the
//! key times are not listed, and the block table is read from the file).

use super::{
    BlockScales, LooseTangents, LooseTrack, MAGIC, PackError, PackSource, PackTrack, Packed,
    SEGMENT_KEYS, VERSION, check_block, err,
};
use glam::{Quat, Vec3};
use tcb_core::params::{Ends, Extrapolation, Hemisphere, RotationMode, TangentRule, Tcb};
use tcb_core::skeleton::{Joint, Skeleton, Transform};
use tcb_core::{TrackKind, TrackSettings};

const HEADER: usize = 24;
const KINDS: [TrackKind; 5] = [
    TrackKind::Scalar,
    TrackKind::Vec2,
    TrackKind::Vec3,
    TrackKind::Vec4,
    TrackKind::Quat,
];

struct Writer(Vec<u8>);

impl Writer {
    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn len(&mut self, n: usize) {
        self.u32(u32::try_from(n).expect("lengths under 2^32 (checked when encoding)"));
    }
    fn str(&mut self, s: &str) {
        self.len(s.len());
        self.0.extend_from_slice(s.as_bytes());
    }
    fn kind_and_settings(&mut self, kind: TrackKind, s: &TrackSettings) {
        let ix = |i: Option<usize>| i.expect("a known value") as u8;
        self.u8(ix(KINDS.iter().position(|k| *k == kind)));
        self.u8(ix(TangentRule::ALL
            .iter()
            .position(|v| *v == s.tangent_rule)));
        self.u8(ix(Ends::ALL.iter().position(|v| *v == s.ends)));
        self.u8(u8::from(s.match_speed));
        self.u8(u8::from(s.continuity_fade));
        self.u8(ix(Extrapolation::ALL.iter().position(|v| *v == s.pre)));
        self.u8(ix(Extrapolation::ALL.iter().position(|v| *v == s.post)));
        self.u8(ix(RotationMode::ALL.iter().position(|v| *v == s.rotation)));
        self.u8(ix(Hemisphere::ALL.iter().position(|v| *v == s.hemisphere)));
    }
    /// Per component a base and a width, then the offsets (`Reader::ints`).
    fn ints(&mut self, comps: &[Vec<i32>]) {
        for c in comps {
            let base = c.iter().copied().min().unwrap_or(0);
            let span = c.iter().map(|x| x.abs_diff(base)).max().unwrap_or(0);
            let w = 32 - span.leading_zeros();
            self.u32(base as u32);
            self.u8(w as u8);
            let mut bits = vec![0u8; (c.len() * w as usize).div_ceil(8)];
            for (k, x) in c.iter().enumerate() {
                let v = x.abs_diff(base);
                for b in 0..w as usize {
                    let p = k * w as usize + b;
                    bits[p / 8] |= (((v >> b) & 1) as u8) << (p % 8);
                }
            }
            self.0.extend_from_slice(&bits);
        }
    }
}

/// `w` bits (at most 25) at bit `pos` of `bytes`, least significant first
/// (bits past the end read as 0).
fn bits_at(bytes: &[u8], pos: usize, w: u32) -> u32 {
    let mut window = [0u8; 8];
    let from = (pos / 8).min(bytes.len());
    let to = (from + 8).min(bytes.len());
    window[..to - from].copy_from_slice(&bytes[from..to]);
    ((u64::from_le_bytes(window) >> (pos % 8)) & ((1u64 << w) - 1)) as u32
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    /// The track count and the tracks (a count the file cannot hold is
    /// refused before anything is allocated for it).
    fn tracks(&mut self, file_len: usize) -> Result<Vec<PackTrack>, PackError> {
        let count = self.u32("the track count")? as usize;
        // A track takes at least 20 bytes (an empty name's length, 10 bytes
        // of settings, the tension flag, the step and the center flag):
        // refuse counts the file cannot hold.
        if count > self.bytes.len() / 20 {
            return err(format!(
                "{count} tracks claimed in a file of {file_len} bytes"
            ));
        }
        (0..count).map(|i| self.track(i)).collect()
    }

    /// The lane count (which must be the `stored` components of the
    /// tracks) and per lane the widths of block start values and deltas
    /// and its base width.
    fn block_widths(&mut self, stored: usize) -> Result<[Vec<u8>; 3], PackError> {
        let lanes = self.u32("the lane count")? as usize;
        if lanes != stored {
            return err(format!(
                "{lanes} lanes for tracks that store {stored} components"
            ));
        }
        let abs_bits = self.take(lanes, "the block widths")?.to_vec();
        let delta_bits = self.take(lanes, "the block widths")?.to_vec();
        let base_width = self.take(lanes, "the base widths")?.to_vec();
        let all = abs_bits.iter().chain(&delta_bits);
        if let Some(b) = all.into_iter().find(|b| **b > 31) {
            return err(format!("a block width of {b} bits (at most 31)"));
        }
        if let Some(b) = base_width.iter().find(|b| **b > super::FLAT) {
            return err(format!(
                "a base width of {b} bits (at most 31, or {} for a lane without headers)",
                super::FLAT
            ));
        }
        Ok([abs_bits, delta_bits, base_width])
    }

    /// The stream of `keys` keys of `lanes` lanes with headers in blocks
    /// of `block` keys: the block table (where each block starts, a `u32`
    /// each), the blocks' step factors, the stream as words, and its length
    /// in bytes. (Where the other segments start is not stored: playback
    /// reads on from the segment before.)
    fn stream(
        &mut self,
        keys: usize,
        block: usize,
        lanes: usize,
    ) -> Result<(Vec<u32>, BlockScales, Vec<u64>, usize), PackError> {
        let segments = keys.div_ceil(SEGMENT_KEYS);
        let blocks = keys.div_ceil(block);
        let table = self.take(blocks.saturating_mul(4), "the block table")?;
        let block_at: Vec<u32> = table
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")))
            .collect();
        if block_at.first().is_some_and(|b| *b != 0) || block_at.windows(2).any(|w| w[0] > w[1]) {
            return err(format!(
                "{keys} keys in blocks of {block}: the block table's offsets do not start at 0 and increase (the key count or the table is wrong)"
            ));
        }
        let codes = self.take(blocks, "the blocks' step factors")?;
        let scales = BlockScales {
            keys: block,
            codes: codes.to_vec(),
        }
        .canonical();
        let len = self.u32("the stream length")? as usize;
        // Every segment spends 3 bits at least per lane with headers on
        // them (an order bit and a width code): a file cannot describe more
        // keys than that (checked before the stream is copied).
        if keys < 2 || segments.saturating_mul(lanes).saturating_mul(3) > 8 * len {
            return err(format!(
                "{keys} keys of {lanes} lanes with headers claimed in a stream of {len} bytes"
            ));
        }
        let stream = super::to_words(self.take(len, "the stream")?);
        Ok((block_at, scales, stream, len))
    }

    /// The skeleton section (since version 2): a joint count (0: none), then per
    /// joint its name, parent (`u32::MAX`: a root; else an earlier joint),
    /// which of its rest rotation and scale follow (bit 0, bit 1; else
    /// identity and one), and its rest translation, rotation and scale
    /// (finite `f32`s).
    fn skeleton(&mut self) -> Result<Option<Skeleton>, PackError> {
        let count = self.u32("the joint count")? as usize;
        // A joint takes at least 21 bytes: refuse counts the file cannot hold.
        if count > (self.bytes.len() - self.at) / 21 {
            return err(format!(
                "{count} joints claimed with {} bytes left",
                self.bytes.len() - self.at
            ));
        }
        let mut skeleton = Skeleton::default();
        for i in 0..count {
            let name = self.str(&format!("joint {i}'s name"))?;
            let what = format!("joint {name}'s rest transform");
            let parent = match self.u32(&format!("joint {name}'s parent"))? {
                u32::MAX => None,
                p => Some(p as usize),
            };
            let flags = self.u8(&what)?;
            if flags > 3 {
                return err(format!("joint {name}: rest flags {flags} (at most 3)"));
            }
            let mut v = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
            let given = [true; 3].into_iter().chain([flags & 1 == 1; 4]);
            for (x, given) in v.iter_mut().zip(given.chain([flags & 2 == 2; 3])) {
                if given {
                    *x = self.f32(&what)?;
                }
            }
            if v.iter().any(|x| !x.is_finite()) {
                return err(format!("joint {name}: a rest transform that is not finite"));
            }
            let rest = Transform {
                translation: Vec3::from_slice(&v[0..3]),
                rotation: Quat::from_slice(&v[3..7]),
                scale: Vec3::from_slice(&v[7..10]),
            };
            skeleton
                .push(Joint { name, parent, rest })
                .map_err(|e| PackError(format!("skeleton: {e}")))?;
        }
        Ok((count > 0).then_some(skeleton))
    }

    /// Track `i`'s head: name, kind, settings, tension, continuity, bias,
    /// step and whether `w` is rebuilt (its integers are the stream's).
    fn track(&mut self, i: usize) -> Result<PackTrack, PackError> {
        let r = self;
        let name = r.str(&format!("track {i}'s name"))?;
        let what = |f: &str| format!("track {name}: {f}");
        let (kind, settings) = r.kind_and_settings(&name)?;
        let rebuild_w = r.pick(&[false, true], &what("rebuild_w"))?;
        // Tension, continuity and bias, where not all 0.
        let tcb = if r.pick(&[false, true], &what("tension flag"))? {
            Tcb::new(
                r.f64(&what("tension"))?,
                r.f64(&what("continuity"))?,
                r.f64(&what("bias"))?,
            )
        } else {
            Tcb::DEFAULT
        };
        let step = r.f32(&what("step"))?;
        let center = if r.pick(&[false, true], &what("center flag"))? {
            let mut c = [0.0f32; 4];
            for x in &mut c {
                *x = r.f32(&what("center"))?;
            }
            Some(c)
        } else {
            None
        };
        Ok(PackTrack {
            name,
            kind,
            settings,
            tcb,
            step,
            rebuild_w,
            center,
            values: Vec::new(),
        })
    }

    /// A track's kind and settings (a byte each).
    fn kind_and_settings(&mut self, name: &str) -> Result<(TrackKind, TrackSettings), PackError> {
        let r = self;
        let what = |f: &str| format!("track {name}: {f}");
        let kind = r.pick(&KINDS, &what("kind"))?;
        let settings = TrackSettings {
            tangent_rule: r.pick(TangentRule::ALL, &what("tangent rule"))?,
            ends: r.pick(Ends::ALL, &what("ends"))?,
            match_speed: r.pick(&[false, true], &what("match_speed"))?,
            continuity_fade: r.pick(&[false, true], &what("continuity_fade"))?,
            pre: r.pick(Extrapolation::ALL, &what("pre"))?,
            post: r.pick(Extrapolation::ALL, &what("post"))?,
            rotation: r.pick(RotationMode::ALL, &what("rotation mode"))?,
            hemisphere: r.pick(Hemisphere::ALL, &what("hemisphere"))?,
        };
        Ok((kind, settings))
    }

    /// The tracks on key times of their own (since version 6): a count,
    /// then per track its place among all tracks, name, kind and settings,
    /// key count and f64 times, value step and integers, and a flag for
    /// explicit tangents (then their step and integers, incoming then
    /// outgoing). Counts the bytes left cannot hold are refused before
    /// anything is allocated for them.
    fn loose(&mut self) -> Result<Vec<LooseTrack>, PackError> {
        let count = self.u32("the count of tracks on their own key times")? as usize;
        // A track takes at least 42 bytes (place, name length, kind and
        // settings, key count, two times, step, flag).
        if count > self.left() / 42 {
            return err(format!(
                "{count} tracks on their own key times claimed with {} bytes left",
                self.left()
            ));
        }
        (0..count)
            .map(|i| {
                let at = self.u32(&format!("loose track {i}'s place"))? as usize;
                let name = self.str(&format!("loose track {i}'s name"))?;
                let (kind, settings) = self.kind_and_settings(&name)?;
                let what = |f: &str| format!("track {name}: {f}");
                let n = self.u32(&what("key count"))? as usize;
                if n > self.left() / 8 {
                    return err(format!(
                        "track {name}: {n} keys claimed with {} bytes left",
                        self.left()
                    ));
                }
                let times = (0..n)
                    .map(|_| self.f64(&what("key times")))
                    .collect::<Result<Vec<f64>, _>>()?;
                let step = self.f32(&what("step"))?;
                let values = self.ints(kind.dim(), n, &what("values"))?;
                let tangents = if self.pick(&[false, true], &what("tangent flag"))? {
                    Some(LooseTangents {
                        step: self.f32(&what("tangent step"))?,
                        incoming: self.ints(kind.dim(), n, &what("incoming tangents"))?,
                        outgoing: self.ints(kind.dim(), n, &what("outgoing tangents"))?,
                    })
                } else {
                    None
                };
                let t = LooseTrack {
                    at,
                    name,
                    kind,
                    settings,
                    times,
                    step,
                    values,
                    tangents,
                };
                t.validate()?;
                Ok(t)
            })
            .collect()
    }

    /// `dim` components of `n` integers each: per component a base
    /// (`i32`) and a width (`u8`, at most 25), then the `n` offsets from
    /// the base in `width` bits each, least significant first, padded to a
    /// byte.
    fn ints(&mut self, dim: usize, n: usize, what: &str) -> Result<Vec<Vec<i32>>, PackError> {
        (0..dim)
            .map(|_| {
                let base = self.u32(what)? as i32;
                let w = u32::from(self.u8(what)?);
                if w > 25 {
                    return err(format!("{what}: a width of {w} bits (at most 25)"));
                }
                let bits = n * w as usize;
                let bytes = self.take(bits.div_ceil(8), what)?;
                let offsets: Vec<u32> = (0..n).map(|k| bits_at(bytes, k * w as usize, w)).collect();
                // Only as `Writer::ints` writes them (a file read writes back
                // the same bytes): the base the smallest value, the width
                // the fewest bits of the largest offset, the padding zero.
                let least = offsets.iter().copied().min().unwrap_or(0);
                let most = offsets.iter().copied().max().unwrap_or(0);
                let pad = bytes.last().map_or(0, |b| b >> (bits % 8) << (bits % 8));
                if least != 0 || w != 32 - most.leading_zeros() || (!bits.is_multiple_of(8) && pad != 0) {
                    return err(format!(
                        "{what}: not coded as written (the base is the smallest value, the width the fewest bits, the padding zero)"
                    ));
                }
                Ok(offsets
                    .into_iter()
                    .map(|off| base.wrapping_add(off as i32))
                    .collect())
            })
            .collect()
    }

    fn left(&self) -> usize {
        self.bytes.len() - self.at
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], PackError> {
        let left = self.bytes.len() - self.at;
        if n > left {
            return err(format!(
                "truncated: {what} needs {n} bytes at offset {}, {left} left",
                self.at + HEADER
            ));
        }
        let s = &self.bytes[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn u8(&mut self, what: &str) -> Result<u8, PackError> {
        Ok(self.take(1, what)?[0])
    }
    fn u32(&mut self, what: &str) -> Result<u32, PackError> {
        Ok(u32::from_le_bytes(
            self.take(4, what)?.try_into().expect("4 bytes"),
        ))
    }
    fn f32(&mut self, what: &str) -> Result<f32, PackError> {
        Ok(f32::from_le_bytes(
            self.take(4, what)?.try_into().expect("4 bytes"),
        ))
    }
    fn f64(&mut self, what: &str) -> Result<f64, PackError> {
        Ok(f64::from_le_bytes(
            self.take(8, what)?.try_into().expect("8 bytes"),
        ))
    }
    fn str(&mut self, what: &str) -> Result<String, PackError> {
        let n = self.u32(what)? as usize;
        let b = self.take(n, what)?;
        String::from_utf8(b.to_vec()).map_err(|_| PackError(format!("{what} is not UTF-8")))
    }
    fn pick<T: Copy>(&mut self, all: &[T], what: &str) -> Result<T, PackError> {
        let i = self.u8(what)?;
        all.get(usize::from(i)).copied().ok_or_else(|| {
            PackError(format!(
                "{what} {i} is not one of the {} known values",
                all.len()
            ))
        })
    }
}

impl Packed {
    /// The `.tcbc` bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let h = &self.head;
        let mut w = Writer(Vec::with_capacity(HEADER + self.stream_len + 4096));
        w.0.extend_from_slice(&[0; HEADER]);
        w.str(&h.name);
        w.str(&self.note);
        w.f64(h.start);
        w.f64(h.interval);
        w.len(h.keys);
        w.len(self.block);
        w.len(SEGMENT_KEYS);
        w.len(h.tracks.len());
        for t in &h.tracks {
            w.str(&t.name);
            w.kind_and_settings(t.kind, &t.settings);
            w.u8(u8::from(t.rebuild_w));
            let tcb = [t.tcb.tension, t.tcb.continuity, t.tcb.bias];
            let given = tcb.iter().any(|x| x.to_bits() != 0);
            w.u8(u8::from(given));
            for x in tcb.iter().filter(|_| given) {
                w.f64(*x);
            }
            w.f32(t.step);
            w.u8(u8::from(t.center.is_some()));
            for x in t.center.iter().flatten() {
                w.f32(*x);
            }
        }
        w.len(self.abs_bits.len());
        w.0.extend_from_slice(&self.abs_bits);
        w.0.extend_from_slice(&self.delta_bits);
        w.0.extend_from_slice(&self.base_width);
        for at in &self.block_at {
            w.u32(*at);
        }
        // Per block its step factor's code (0s where it has none).
        for b in 0..self.block_at.len() {
            w.0.push(h.scales.codes.get(b).copied().unwrap_or(0));
        }
        let bytes: Vec<u8> = self.stream.iter().flat_map(|x| x.to_le_bytes()).collect();
        w.len(self.stream_len);
        w.0.extend_from_slice(&bytes[..self.stream_len]);
        w.len(h.loose.len());
        for t in &h.loose {
            w.len(t.at);
            w.str(&t.name);
            w.kind_and_settings(t.kind, &t.settings);
            w.len(t.times.len());
            for x in &t.times {
                w.f64(*x);
            }
            w.f32(t.step);
            w.ints(&t.values);
            w.u8(u8::from(t.tangents.is_some()));
            if let Some(g) = &t.tangents {
                w.f32(g.step);
                w.ints(&g.incoming);
                w.ints(&g.outgoing);
            }
        }
        let joints = self.skeleton.as_ref().map_or(&[][..], Skeleton::joints);
        w.len(joints.len());
        for j in joints {
            w.str(&j.name);
            w.u32(j.parent.map_or(u32::MAX, |p| p as u32));
            let r = &j.rest;
            let (turned, scaled) = (r.rotation != Quat::IDENTITY, r.scale != Vec3::ONE);
            w.u8(u8::from(turned) | u8::from(scaled) << 1);
            let rotation = r.rotation.to_array();
            let scale = r.scale.to_array();
            let floats = r.translation.to_array().into_iter();
            let floats = floats.chain(rotation.into_iter().filter(|_| turned));
            for v in floats.chain(scale.into_iter().filter(|_| scaled)) {
                w.f32(v);
            }
        }
        let total = w.0.len() as u64;
        let crc = crc32fast::hash(&w.0[HEADER..]);
        let head = &mut w.0[..HEADER];
        head[..8].copy_from_slice(&MAGIC);
        head[8..12].copy_from_slice(&VERSION.to_le_bytes());
        head[12..20].copy_from_slice(&total.to_le_bytes());
        head[20..24].copy_from_slice(&crc.to_le_bytes());
        w.0
    }

    /// Read `.tcbc` bytes: the header, checksum, every length and value
    /// checked, and the stream decoded once to validate it. Errors are one
    /// line naming what is wrong.
    pub fn from_bytes(bytes: &[u8]) -> Result<Packed, PackError> {
        let packed = Packed::read(bytes)?;
        packed.decode()?;
        Ok(packed)
    }

    /// [`from_bytes`](Self::from_bytes) without decoding the stream: the
    /// header, checksum, lengths, settings and the stream's structure
    /// ([`Packed::stream_structure`]) checked, not the integers (what
    /// [`crate::Clip::from_bytes`] reads: about 0.1 ms for CMU 01_01 where
    /// decoding every key takes a few).
    pub(crate) fn read(bytes: &[u8]) -> Result<Packed, PackError> {
        let body = checked_body(bytes)?;
        let mut r = Reader { bytes: body, at: 0 };
        let name = r.str("the clip's name")?;
        let note = r.str("the note")?;
        let start = r.f64("the start time")?;
        let interval = r.f64("the key interval")?;
        let keys = r.u32("the key count")? as usize;
        let (block, seg) = (r.u32("keys per block")?, r.u32("keys per segment")?);
        if seg as usize != SEGMENT_KEYS {
            return err(format!(
                "segments of {seg} keys; this build reads {SEGMENT_KEYS} (compress the source again)"
            ));
        }
        let block = block as usize;
        check_block(block)?;
        let tracks = r.tracks(bytes.len())?;
        if tracks.is_empty() || keys.saturating_mul(tracks.len()) > super::MAX_TRACK_KEYS {
            return err(format!(
                "{keys} keys of {} tracks: a packed clip has 1 to {} track keys",
                tracks.len(),
                super::MAX_TRACK_KEYS
            ));
        }
        let stored: usize = tracks.iter().map(PackTrack::stored).sum();
        let [abs_bits, delta_bits, base_width] = r.block_widths(stored)?;
        let headed = base_width.iter().filter(|b| **b != super::FLAT).count();
        let (block_at, scales, stream, len) = r.stream(keys, block, headed)?;
        let loose = r.loose()?;
        let skeleton = r.skeleton()?;
        if r.at != body.len() {
            return err(format!("{} bytes after the stream", body.len() - r.at));
        }
        let packed = Packed {
            block,
            head: PackSource {
                name,
                start,
                interval,
                keys,
                tracks,
                scales,
                loose,
            },
            abs_bits,
            delta_bits,
            base_width,
            block_at,
            bits: 0,
            stream,
            stream_len: len,
            note,
            skeleton,
        };
        packed.head.validate_head()?;
        let mut packed = packed;
        packed.bits = packed.stream_structure()?;
        Ok(packed)
    }
}

/// The body of `.tcbc` bytes after their header, once the
/// magic number, version, length and checksum hold.
fn checked_body(bytes: &[u8]) -> Result<&[u8], PackError> {
    let n = bytes.len().min(MAGIC.len());
    if bytes.len() < HEADER && bytes.len() >= 4 && bytes[..n] == MAGIC[..n] {
        return err(format!(
            "cut short: {} bytes, shorter than a .tcbc header ({HEADER})",
            bytes.len()
        ));
    }
    if bytes.len() < HEADER || bytes[..8] != MAGIC {
        return err("not a .tcbc file (no TCBC magic number)");
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != VERSION {
        let why = if version < VERSION {
            "written by an older tcb, in a layout this build does not read: compress the source again"
        } else {
            "written by a newer tcb"
        };
        return err(format!(
            ".tcbc version {version}; this build reads version {VERSION} ({why})"
        ));
    }
    let total = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    if total != bytes.len() as u64 {
        return err(format!(
            "truncated or padded: the header says {total} bytes, the file has {}",
            bytes.len()
        ));
    }
    let crc = u32::from_le_bytes(bytes[20..24].try_into().expect("4 bytes"));
    let body = &bytes[HEADER..];
    if crc32fast::hash(body) != crc {
        return err("checksum mismatch: the file is corrupted");
    }
    Ok(body)
}
