//! Random clips for the runtime's tests (shared by `equivalence.rs` and
//! `isa.rs`; not every test file uses every generator).
#![allow(dead_code)]

use glam::{Quat, Vec2, Vec3, Vec4};
use tcb_core::{
    Ease, Ends, Extrapolation, Hemisphere, Interp, KeyParams, NamedTrack, RotationMode,
    RotationTrack, TangentRule, Tcb, Track, TrackData, TrackSettings, Value,
};

/// A small deterministic generator (xorshift64*), so failures replay from a seed.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    pub fn f(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    pub fn chance(&mut self, p: f64) -> bool {
        self.f(0.0, 1.0) < p
    }
}

pub fn settings(rng: &mut Rng, rotation: bool) -> TrackSettings {
    let rules = [
        TangentRule::Uniform,
        TangentRule::Adjusted,
        TangentRule::Secant,
        TangentRule::Parabolic,
    ];
    let mut ends = [Ends::Copy, Ends::Zero, Ends::Natural, Ends::Cyclic][rng.below(4)];
    let modes = if rotation { 4 } else { 6 };
    let mode = |rng: &mut Rng| Extrapolation::ALL[rng.below(modes)];
    let rot = if rng.chance(0.5) {
        RotationMode::Squad
    } else {
        RotationMode::Hermite
    };
    if rotation && rot == RotationMode::Squad && ends == Ends::Natural {
        ends = Ends::Copy;
    }
    TrackSettings {
        tangent_rule: rules[rng.below(4)],
        ends,
        match_speed: rng.chance(0.3),
        continuity_fade: rng.chance(0.3),
        pre: mode(rng),
        post: mode(rng),
        rotation: rot,
        // Keys given at random signs (rotation_track) go the long way
        // round where the track keeps them as written.
        hemisphere: if rotation && rng.chance(0.3) {
            Hemisphere::Keep
        } else {
            Hemisphere::Nearest
        },
    }
}

pub fn key_params<V: Copy>(
    rng: &mut Rng,
    n: usize,
    tangent: impl Fn(&mut Rng) -> V,
    explicit: bool,
) -> Vec<KeyParams<V>> {
    (0..n)
        .map(|_| KeyParams {
            tcb: Tcb::new(rng.f(-1.0, 1.0), rng.f(-1.0, 1.0), rng.f(-1.0, 1.0)),
            ease: if rng.chance(0.3) {
                Ease {
                    to: rng.f(0.0, 1.0),
                    from: rng.f(0.0, 1.0),
                }
            } else {
                Ease::NONE
            },
            interp: [
                Interp::Curve,
                Interp::Curve,
                Interp::Curve,
                Interp::Linear,
                Interp::Step,
            ][rng.below(5)],
            tangent_in: (explicit && rng.chance(0.2)).then(|| tangent(rng)),
            tangent_out: (explicit && rng.chance(0.2)).then(|| tangent(rng)),
        })
        .collect()
}

pub fn times(rng: &mut Rng, n: usize) -> Vec<f64> {
    let mut t = vec![rng.f(-2.0, 2.0)];
    for _ in 1..n {
        let next = t[t.len() - 1] + rng.f(0.05, 1.5);
        t.push(next);
    }
    t
}

pub fn vector_track<V: Value>(rng: &mut Rng, t: &[f64], s: &TrackSettings) -> Track<V> {
    let n = t.len();
    let rnd = |rng: &mut Rng| {
        let a: [f32; 4] = std::array::from_fn(|_| rng.f(-10.0, 10.0) as f32);
        V::from_array(a)
    };
    let mut values: Vec<V> = (0..n).map(|_| rnd(rng)).collect();
    if s.ends == Ends::Cyclic {
        values[n - 1] = values[0];
    }
    let keys = key_params(rng, n, rnd, true);
    Track::new(t.to_vec(), values, keys, s).expect("valid random track")
}

/// Random rotations: a random walk with up to `max_turn` radians between
/// consecutive keys, each key given at a random scale and sign (the track
/// normalizes and aligns hemispheres).
pub fn rotation_track(rng: &mut Rng, t: &[f64], s: &TrackSettings) -> RotationTrack {
    rotation_track_with(rng, t, s, 1.5)
}

pub fn rotation_track_with(
    rng: &mut Rng,
    t: &[f64],
    s: &TrackSettings,
    max_turn: f64,
) -> RotationTrack {
    let n = t.len();
    let base = Quat::from_xyzw(
        rng.f(-1.0, 1.0) as f32,
        rng.f(-1.0, 1.0) as f32,
        rng.f(-1.0, 1.0) as f32,
        1.0,
    )
    .normalize();
    let mut walk = base;
    let mut q: Vec<Quat> = (0..n)
        .map(|_| {
            let axis = Vec3::new(
                rng.f(-1.0, 1.0) as f32,
                rng.f(-1.0, 1.0) as f32,
                rng.f(-1.0, 1.0) as f32,
            );
            let axis = axis.try_normalize().unwrap_or(Vec3::Z);
            walk = if s.ends == Ends::Cyclic {
                // Keys around a base, so that the closing chord is no longer than the others.
                (base * Quat::from_axis_angle(axis, rng.f(0.0, max_turn / 2.0) as f32)).normalize()
            } else {
                (walk * Quat::from_axis_angle(axis, rng.f(0.0, max_turn) as f32)).normalize()
            };
            let scale = rng.f(0.5, 2.0) as f32 * if rng.chance(0.3) { -1.0 } else { 1.0 };
            walk * scale
        })
        .collect();
    if s.ends == Ends::Cyclic {
        q[n - 1] = if rng.chance(0.5) { q[0] } else { -q[0] };
    }
    let explicit = s.rotation == RotationMode::Hermite;
    let rnd = |rng: &mut Rng| {
        Quat::from_xyzw(
            rng.f(-1.0, 1.0) as f32,
            rng.f(-1.0, 1.0) as f32,
            rng.f(-1.0, 1.0) as f32,
            rng.f(-1.0, 1.0) as f32,
        )
    };
    let keys = key_params(rng, n, rnd, explicit);
    RotationTrack::new(t.to_vec(), q, keys, s).expect("valid random rotation")
}

/// A clip with `channels` scalar channels on one grid (in tracks of mixed
/// kinds) plus rotations and a few tracks on grids of their own.
pub fn random_clip(seed: u64, channels: usize) -> tcb_core::Clip {
    let mut rng = Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
    let n = 3 + rng.below(6);
    let shared = times(&mut rng, n);
    let s = {
        let mut s = settings(&mut rng, false);
        if s.ends == Ends::Cyclic && n < 3 {
            s.ends = Ends::Copy;
        }
        s
    };
    let mut tracks = Vec::new();
    let mut left = channels;
    while left > 0 {
        let data = match (left.min(4), rng.below(4)) {
            (1, _) | (_, 0) => TrackData::Scalar(vector_track(&mut rng, &shared, &s)),
            (2, _) | (_, 1) => TrackData::Vec2(vector_track::<Vec2>(&mut rng, &shared, &s)),
            (3, _) | (_, 2) => TrackData::Vec3(vector_track::<Vec3>(&mut rng, &shared, &s)),
            _ => TrackData::Vec4(vector_track::<Vec4>(&mut rng, &shared, &s)),
        };
        left -= data.kind().dim();
        tracks.push(data);
    }
    // Rotations on the shared grid (one settings each: squad or hermite).
    for _ in 0..rng.below(12) {
        let mut rs = settings(&mut rng, true);
        rs.pre = s.pre.min_rotation();
        rs.post = s.post.min_rotation();
        tracks.push(TrackData::Quat(rotation_track(&mut rng, &shared, &rs)));
    }
    // Tracks on grids of their own.
    for _ in 0..rng.below(4) {
        let m = 2 + rng.below(5);
        let own = times(&mut rng, m);
        let mut os = settings(&mut rng, false);
        if m < 3 {
            os.ends = Ends::Copy;
        }
        tracks.push(TrackData::Vec3(vector_track::<Vec3>(&mut rng, &own, &os)));
        let mut rs = settings(&mut rng, true);
        if m < 3 {
            rs.ends = Ends::Zero;
        }
        tracks.push(TrackData::Quat(rotation_track(&mut rng, &own, &rs)));
    }
    tcb_core::Clip::new(
        format!("random-{seed}"),
        tracks
            .into_iter()
            .enumerate()
            .map(|(i, data)| NamedTrack {
                name: format!("t{i}"),
                data,
            })
            .collect(),
    )
    .expect("unique track names")
}

pub trait RotationSafe {
    fn min_rotation(self) -> Self;
}

impl RotationSafe for Extrapolation {
    /// The same mode where rotations allow it, else `constant`.
    fn min_rotation(self) -> Self {
        match self {
            Extrapolation::Linear | Extrapolation::OffsetRepeat => Extrapolation::Constant,
            m => m,
        }
    }
}

pub fn sample_times(rng: &mut Rng, clip: &tcb_core::Clip) -> Vec<f64> {
    let (a, b) = clip.time_range().unwrap();
    let mut t: Vec<f64> = clip.key_times();
    for _ in 0..40 {
        t.push(rng.f(a - 3.0, b + 3.0));
    }
    t.extend([
        a - 100.0,
        b + 1e6 + 0.3,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ]);
    t
}
