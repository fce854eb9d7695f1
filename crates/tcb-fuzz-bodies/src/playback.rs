//! The `playback` target: instances in every [`Playback`] mode and speed,
//! with and without a rig, against a fresh instance, a plain instance and
//! the scalar reference at the same clip time.

use crate::edges::edge_times;
use crate::inputs::{assert_rotation, same};
use arbitrary::{Arbitrary, Unstructured};
use std::sync::Arc;
use tcb_core::{TrackData, TrackKind};
use tcb_runtime::{Instance, Playback, Rig, RigTrack};

/// The clip time and velocity factor `mode` at `speed` plays for `time`,
/// as [`Instance::set_playback`] documents it: `speed * time`, then in
/// `Loop` wrapped into the keys, in `Clamp` held at the ends (velocity 0),
/// in `PingPong` reflected (velocity negated on the way back), and at the
/// first key (velocity 0) when the keys span no time or the time is not
/// finite. Written from the documentation, not copied from the instance.
pub fn clip_time(mode: Playback, speed: f64, time: f64, range: Option<(f64, f64)>) -> (f64, f32) {
    let t = time * speed;
    let (Some((t0, t1)), false) = (range, mode == Playback::Clip) else {
        return (t, speed as f32);
    };
    let d = t1 - t0;
    if mode == Playback::Clamp {
        return if t < t0 {
            (t0, 0.0)
        } else if t > t1 {
            (t1, 0.0)
        } else {
            (t, speed as f32)
        };
    }
    if d <= 0.0 || !t.is_finite() {
        return (t0, 0.0);
    }
    let into = |c: f64| c.clamp(t0, t1);
    if mode == Playback::Loop {
        return (into(t0 + (t - t0).rem_euclid(d)), speed as f32);
    }
    let u = (t - t0).rem_euclid(2.0 * d);
    if u <= d {
        (into(t0 + u), speed as f32)
    } else {
        (into(t0 + 2.0 * d - u), -speed as f32)
    }
}

/// A structured clip (as `runtime`'s) played in a mode and at a speed
/// (negative, zero, tiny, huge, arbitrary finite), sometimes through a rig
/// that holds the clip's tracks in another order and one track more, at
/// edge times (around the keys divided by the speed, so that the mapped
/// time lands near them). Each sample equals, bit for bit: a fresh
/// instance's (a seek); a plain instance's (mode `Clip`, speed 1) at the
/// clip time [`clip_time`] gives, velocities times its factor; through the
/// rig, the instance's without it (and the extra track its rest value).
/// Against the scalar reference at that clip time: vector channels equal
/// as numbers where the reference is finite, rotations within 1e-6. In
/// `Loop`, `Clamp` and `PingPong` a finite time's clip time is within the
/// keys.
pub fn playback(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Ok(doc) = crate::inputs::arbitrary_doc(&mut u) else {
        return;
    };
    let Ok(clip) = doc.build() else {
        return;
    };
    let Some(mode) = choose_mode(&mut u) else {
        return;
    };
    let speed = choose_speed(&mut u);
    let compiled = Arc::new(tcb_runtime::Clip::compile(&clip));
    if !speed.is_finite() {
        let refused = Instance::new(compiled).set_playback(mode, speed);
        assert!(refused.is_err(), "a speed of {speed} accepted");
        return;
    }
    let rigged = u.ratio(1, 3u8).unwrap_or(false);
    let rest = crate::inputs::value(&mut u).unwrap_or([0.5; 4]);
    let times = instance_times(&mut u, &clip, speed);
    let play = Player {
        compiled,
        mode,
        speed,
    };
    let rig = rigged.then(|| reversed_rig(&clip, rest));
    let mut playing = play.plain();
    let mut rig_playing = rig.as_ref().map(|r| play.rigged(r));
    let mut reference = Reference::new(&clip);
    for &t in &times {
        let got = row(&mut playing, t);
        let seek = row(&mut play.plain(), t);
        assert!(
            same(&got.0, &seek.0) && same(&got.1, &seek.1),
            "{mode:?} x{speed}: forward playback differs from a seek at {t}"
        );
        let (c, rate) = play.check_clip_time(&clip, t);
        play.check_plain(&got, t, c, rate);
        reference.check(&got, mode, speed, t, c, rate);
        if let (Some(rig), Some(inst)) = (&rig, &mut rig_playing) {
            play.check_rig(&clip, rig, inst, &got, t);
        }
    }
}

/// The playback mode, from the input (`None` when it runs out).
fn choose_mode(u: &mut Unstructured) -> Option<Playback> {
    u.choose(&[
        Playback::Clip,
        Playback::Loop,
        Playback::Clamp,
        Playback::PingPong,
    ])
    .ok()
    .copied()
}

/// The speed: 1, one of the edge speeds (signed zeros, tiny, huge, the
/// largest finite), any f64 (infinities and NaN included), or a small
/// fraction.
fn choose_speed(u: &mut Unstructured) -> f64 {
    match u.int_in_range(0..=5u8).unwrap_or(0) {
        0 => 1.0,
        1 => *u
            .choose(&[
                -1.0,
                0.0,
                -0.0,
                0.5,
                2.0,
                1e-300,
                -1e-300,
                5e-324,
                1e300,
                -1e300,
                f64::MAX,
                -f64::MAX,
            ])
            .unwrap_or(&1.0),
        2 => f64::arbitrary(u).unwrap_or(1.0),
        _ => f64::from(i16::arbitrary(u).unwrap_or(1)) / 256.0,
    }
}

/// Edge times in clip time, then half of them again divided by the speed:
/// instance times whose clip times land near the keys.
fn instance_times(u: &mut Unstructured, clip: &tcb_core::SourceClip, speed: f64) -> Vec<f64> {
    let keys: Vec<f64> = clip.key_times().into_iter().take(200).collect();
    let mut times = edge_times(u, &keys, 48);
    if speed != 0.0 && speed.is_finite() {
        let n = times.len();
        times.extend_from_within(..n / 2);
        for t in &mut times[n..] {
            *t /= speed;
        }
    }
    times
}

/// A rig of the clip's tracks reversed, then one the clip lacks
/// (`fuzz.extra`, a vec4 at `rest`, made finite).
fn reversed_rig(clip: &tcb_core::SourceClip, rest: [f32; 4]) -> Arc<Rig> {
    let mut tracks: Vec<RigTrack> = clip
        .tracks()
        .iter()
        .rev()
        .map(|t| RigTrack {
            name: t.name.clone(),
            kind: t.data.kind(),
            rest: [0.0, 0.0, 0.0, 1.0],
        })
        .collect();
    tracks.push(RigTrack {
        name: "fuzz.extra".into(),
        kind: TrackKind::Vec4,
        rest: rest.map(|x| if x.is_finite() { x } else { 0.5 }),
    });
    Arc::new(Rig::new(tracks).expect("distinct names, finite rests"))
}

/// The values and velocities `i` samples at `t`, in its pose's layout.
fn row(i: &mut Instance, t: f64) -> (Vec<f32>, Vec<f32>) {
    let channels: usize = i
        .pose()
        .layout()
        .tracks()
        .iter()
        .map(|s| s.kind().dim())
        .sum();
    let (mut v, mut d) = (vec![0.0f32; channels], vec![0.0f32; channels]);
    i.sample(t).write_row(&mut v, Some(&mut d));
    (v, d)
}

/// The compiled clip and the mode and speed it is played in.
struct Player {
    compiled: Arc<tcb_runtime::Clip>,
    mode: Playback,
    speed: f64,
}

impl Player {
    /// A fresh instance with velocities, in the mode and at the speed.
    fn plain(&self) -> Instance {
        let mut i = Instance::new(self.compiled.clone()).with_velocities();
        i.set_playback(self.mode, self.speed)
            .expect("a finite speed");
        i
    }

    /// A fresh instance through `rig`, with velocities, in the mode and at
    /// the speed.
    fn rigged(&self, rig: &Arc<Rig>) -> Instance {
        let mut i = Instance::with_rig(self.compiled.clone(), rig)
            .expect("every track in the rig")
            .with_velocities();
        i.set_playback(self.mode, self.speed)
            .expect("a finite speed");
        i
    }

    /// The clip time and velocity factor of `t` ([`clip_time`]), checked
    /// to be within the keys in `Loop`, `Clamp` and `PingPong` when `t` is
    /// finite.
    fn check_clip_time(&self, clip: &tcb_core::SourceClip, t: f64) -> (f64, f32) {
        let (mode, speed) = (self.mode, self.speed);
        let range = clip.time_range();
        let (c, rate) = clip_time(mode, speed, t, range);
        if let (Some((t0, t1)), true) = (range, mode != Playback::Clip && t.is_finite()) {
            assert!(
                (t0..=t1).contains(&c),
                "{mode:?} x{speed} at {t}: clip time {c} outside the keys"
            );
        }
        (c, rate)
    }

    /// `got` (sampled at `t`) equals a plain instance's row at the clip
    /// time `c`, its velocities times `rate`.
    fn check_plain(&self, got: &(Vec<f32>, Vec<f32>), t: f64, c: f64, rate: f32) {
        let (mode, speed) = (self.mode, self.speed);
        let mut plain = Instance::new(self.compiled.clone()).with_velocities();
        let (pv, mut pd) = row(&mut plain, c);
        pd.iter_mut().for_each(|x| *x *= rate);
        assert!(
            same(&got.0, &pv) && same(&got.1, &pd),
            "{mode:?} x{speed} at {t} (clip time {c}, velocity x{rate}): \
             instance {got:?}, plain instance {pv:?} {pd:?}"
        );
    }

    /// Through the rig: forward playback equals a seek, each of the clip's
    /// tracks equals `got` (the instance without the rig) and the extra
    /// track holds its rest value with velocity 0.
    fn check_rig(
        &self,
        clip: &tcb_core::SourceClip,
        rig: &Arc<Rig>,
        inst: &mut Instance,
        got: &(Vec<f32>, Vec<f32>),
        t: f64,
    ) {
        let (mode, speed) = (self.mode, self.speed);
        let (rv, rd) = row(inst, t);
        let seek = row(&mut self.rigged(rig), t);
        assert!(
            same(&rv, &seek.0) && same(&rd, &seek.1),
            "rig {mode:?} x{speed}: forward playback differs from a seek at {t}"
        );
        // Rig order: the clip's tracks reversed, then the extra one.
        let mut ra = 0;
        for rt in rig.tracks() {
            let dim = rt.kind.dim();
            let rr = ra..ra + dim;
            ra += dim;
            let (v, d) = (&rv[rr.clone()], &rd[rr]);
            match clip.tracks().iter().position(|c| c.name == rt.name) {
                Some(i) => {
                    let ca: usize = clip.tracks()[..i].iter().map(|c| c.data.kind().dim()).sum();
                    let cr = ca..ca + dim;
                    assert!(
                        same(v, &got.0[cr.clone()]) && same(d, &got.1[cr.clone()]),
                        "rig {} {mode:?} x{speed} at {t}: {v:?} {d:?}, without the rig \
                         {:?} {:?}",
                        rt.name,
                        &got.0[cr.clone()],
                        &got.1[cr]
                    );
                }
                None => assert!(
                    same(v, &rt.rest[..dim]) && d.iter().all(|x| *x == 0.0),
                    "rig {} (not in the clip) at {t}: {v:?} {d:?}, rest {:?}",
                    rt.name,
                    rt.rest
                ),
            }
        }
    }
}

/// The scalar reference and the rows it samples into.
struct Reference<'a> {
    clip: &'a tcb_core::SourceClip,
    want: Vec<f32>,
    want_v: Vec<f32>,
}

impl<'a> Reference<'a> {
    /// Rows for `clip`'s channels.
    fn new(clip: &'a tcb_core::SourceClip) -> Self {
        let n = clip.channel_count();
        Self {
            clip,
            want: vec![0.0; n],
            want_v: vec![0.0; n],
        }
    }

    /// `got` (sampled at `t`) against the reference at the clip time `c`,
    /// velocities times `rate`: vector channels equal as numbers where the
    /// reference is finite, rotations within 1e-6 up to sign.
    fn check(
        &mut self,
        got: &(Vec<f32>, Vec<f32>),
        mode: Playback,
        speed: f64,
        t: f64,
        c: f64,
        rate: f32,
    ) {
        let (want, want_v) = (&mut self.want, &mut self.want_v);
        self.clip.sample_into(c, want, Some(want_v));
        want_v.iter_mut().for_each(|x| *x *= rate);
        let mut at = 0;
        for track in self.clip.tracks() {
            let r = at..at + track.data.kind().dim();
            at = r.end;
            if let TrackData::Quat(_) = track.data {
                assert_rotation(&got.0[r.clone()], &want[r], &track.name, t);
                continue;
            }
            for (what, g, w) in [("value", &got.0, &*want), ("velocity", &got.1, &*want_v)] {
                let (g, w) = (&g[r.clone()], &w[r.clone()]);
                assert!(
                    w.iter().any(|x| !x.is_finite()) || same(g, w),
                    "{} {what} {mode:?} x{speed} at {t} (clip time {c}): runtime {g:?}, \
                     reference {w:?}",
                    track.name
                );
            }
        }
    }
}
