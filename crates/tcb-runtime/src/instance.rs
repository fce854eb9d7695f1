//! Per-instance playback: cursors and a pose, sampled without allocating.

use crate::blend::BlendMask;
use crate::clip::Clip;
use crate::grid::Cursor;
use crate::loose::LooseState;
use crate::pose::Pose;
use crate::rig::{Rig, RigError, RigMap};
use crate::store::KeyCache;
use std::sync::Arc;
use wide::f32x8;

/// How an instance turns the time it is given into the clip's time,
/// whatever the clip's own `pre`/`post` say ([`Instance::set_playback`]).
/// Time is wrapped in f64 before anything becomes f32.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Playback {
    /// The clip's own time: outside its keys its `pre`/`post` modes apply.
    #[default]
    Clip,
    /// Over and over from the first key to the last.
    Loop,
    /// Held at the first key before it and at the last after it (velocity 0).
    Clamp,
    /// Forwards to the last key, backwards to the first, and so on
    /// (velocities change sign on the way back).
    PingPong,
}

/// A playback setting [`Instance::set_playback`] refuses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaybackError {
    /// The speed given.
    pub speed: f64,
}

impl std::fmt::Display for PlaybackError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "playback speed {} is not a finite number", self.speed)
    }
}

impl std::error::Error for PlaybackError {}

/// [`Instance::sample_to`] given a slice of another length than the
/// pose's channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OutputLength {
    /// Floats given.
    pub given: usize,
    /// Floats the pose has (its channels).
    pub want: usize,
}

impl std::fmt::Display for OutputLength {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a pose of {} floats written into a slice of {}",
            self.want, self.given
        )
    }
}

impl std::error::Error for OutputLength {}

/// One playing copy of a clip: a cursor per group and the output pose.
/// Allocates when created, never when sampling.
#[derive(Clone, Debug)]
pub struct Instance {
    clip: Arc<Clip>,
    cursors: Vec<Cursor>,
    loose: LooseState,
    loose_rot: LooseState,
    pose: Pose,
    /// Per group: expanded quantized keys (see `crate::store`).
    caches: Vec<KeyCache>,
    /// With a rig: the map into its layout and the pose in it.
    rig: Option<Box<RigOutput>>,
    /// Playback mode and speed.
    mode: Playback,
    speed: f64,
}

/// An instance's output in a rig's layout.
#[derive(Clone, Debug)]
struct RigOutput {
    /// From the clip's layout into the rig's.
    map: RigMap,
    /// The pose in the rig's layout.
    pose: Pose,
}

impl Instance {
    /// A new instance of `clip`, sampling values only (add velocities with
    /// [`with_velocities`](Self::with_velocities)).
    pub fn new(clip: Arc<Clip>) -> Self {
        Instance {
            cursors: vec![Cursor::default(); clip.groups.len()],
            loose: LooseState::new(&clip.loose),
            loose_rot: LooseState::new(&clip.loose_rot),
            pose: Pose::new(&clip),
            caches: clip.groups.iter().map(|g| g.keys.cache()).collect(),
            clip,
            rig: None,
            mode: Playback::Clip,
            speed: 1.0,
        }
    }

    /// Play the clip in `mode` at `speed` (1 is the clip's own speed, 2
    /// twice as fast, negative backwards): [`sample`](Self::sample)`(t)`
    /// then samples the clip at the time `mode` maps `speed * t` to, over
    /// the clip's keys, and scales velocities to match. A NaN or infinite
    /// speed is refused.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use tcb_runtime::{Clip, Instance, Playback};
    /// let clip = tcb_io::ClipDoc::parse(r#"{"format": "tcb-clip/1", "tracks": [
    ///   {"name": "x", "kind": "scalar", "times": [0, 2], "values": [0, 4]}]}"#)
    ///     .unwrap().build().unwrap();
    /// let mut inst = Instance::new(Arc::new(Clip::compile(&clip))).with_velocities();
    /// inst.set_playback(Playback::PingPong, 1.0).unwrap();
    /// let pose = inst.sample(3.0); // on the way back: clip time 1
    /// let x = pose.layout().track("x").unwrap();
    /// assert_eq!(pose.scalar(x), Some(2.0));
    /// assert!(pose.scalar_velocity(x).unwrap() < 0.0);
    /// ```
    pub fn set_playback(&mut self, mode: Playback, speed: f64) -> Result<(), PlaybackError> {
        if !speed.is_finite() {
            return Err(PlaybackError { speed });
        }
        (self.mode, self.speed) = (mode, speed);
        Ok(())
    }

    /// The playback mode and speed.
    pub fn playback(&self) -> (Playback, f64) {
        (self.mode, self.speed)
    }

    /// The clip time `time` plays, and the factor its velocities take.
    fn clip_time(&self, time: f64) -> (f64, f32) {
        let (mode, speed) = (self.mode, self.speed);
        let t = time * speed;
        if mode == Playback::Clip {
            return (t, speed as f32);
        }
        let Some((t0, t1)) = self.clip.time_range() else {
            return (t, speed as f32);
        };
        let d = t1 - t0;
        match mode {
            Playback::Clip => (t, speed as f32),
            Playback::Clamp if t < t0 => (t0, 0.0),
            Playback::Clamp if t > t1 => (t1, 0.0),
            Playback::Clamp => (t, speed as f32),
            _ if d <= 0.0 || !t.is_finite() => (t0, 0.0),
            // Clamped into the keys: `t0 + u` rounds, and a hair outside them
            // the clip's own `pre` or `post` would apply.
            Playback::Loop => ((t0 + (t - t0).rem_euclid(d)).clamp(t0, t1), speed as f32),
            Playback::PingPong => {
                let u = (t - t0).rem_euclid(2.0 * d);
                if u <= d {
                    ((t0 + u).clamp(t0, t1), speed as f32)
                } else {
                    ((t0 + 2.0 * d - u).clamp(t0, t1), -speed as f32)
                }
            }
        }
    }

    /// An instance whose [`pose`](Self::pose) is in `rig`'s layout (see
    /// [`crate::rig`]): every track of `clip` must be a rig track of the same
    /// kind; rig tracks the clip lacks keep their rest values.
    pub fn with_rig(clip: Arc<Clip>, rig: &Arc<Rig>) -> Result<Self, RigError> {
        let map = rig.map(&clip)?;
        let mut inst = Instance::new(clip);
        inst.rig = Some(Box::new(RigOutput {
            map,
            pose: rig.rest_pose(),
        }));
        Ok(inst)
    }

    /// This instance sampling velocities too: d/dt of every track, in its
    /// pose's `*_velocity` accessors (about twice the work per sample).
    #[must_use]
    pub fn with_velocities(mut self) -> Self {
        self.pose.add_velocities();
        if let Some(rig) = self.rig.as_deref_mut() {
            rig.pose.add_velocities();
        }
        self
    }

    /// Per track of the pose: 1 where the clip animates it, 0 where it
    /// keeps its rest value (every track, without a rig). Multiply it into a
    /// layer's mask so that a clip's missing tracks do not pull the blend
    /// towards the rest pose.
    pub fn coverage_mask(&self) -> BlendMask {
        match &self.rig {
            Some(rig) => BlendMask::for_layout(&rig.pose.layout, |t| {
                f32::from(u8::from(rig.map.covered[t.index]))
            }),
            None => BlendMask::new(&self.clip, |_| 1.0),
        }
    }

    /// The clip.
    pub fn clip(&self) -> &Arc<Clip> {
        &self.clip
    }

    /// The last sampled pose (in the rig's layout if the instance has one).
    pub fn pose(&self) -> &Pose {
        match &self.rig {
            Some(rig) => &rig.pose,
            None => &self.pose,
        }
    }

    /// Sample at `time` (as [`sample`](Self::sample)) and write the pose
    /// into the caller's `out`: every track's components in the order of
    /// [`Pose::layout`]`().tracks()` (file order for a clip, the rig's order
    /// with a rig), components consecutive (`x y z` for a vec3, `x y z w`
    /// for a rotation, one float for a scalar): [`Clip::channel_count`]
    /// floats (the rig's channel count with a rig). The kernels write 8
    /// channels a vector into the instance's blocks, then one pass gathers
    /// them into `out`; nothing is allocated. A slice of another length is
    /// an error, and nothing is sampled or written.
    ///
    /// ```
    /// use std::sync::Arc;
    /// let clip = tcb_io::ClipDoc::parse(r#"{"format": "tcb-clip/1", "tracks": [
    ///   {"name": "x", "kind": "scalar", "times": [0, 2], "values": [0, 4]},
    ///   {"name": "p", "kind": "vec3", "times": [0, 2], "values": [[0, 0, 0], [2, 4, 6]]}]}"#)
    ///     .unwrap().build().unwrap();
    /// let mut inst = tcb_runtime::Instance::new(Arc::new(tcb_runtime::Clip::compile(&clip)));
    /// let mut row = [0.0f32; 4]; // x, then p's x y z
    /// inst.sample_to(1.0, &mut row).unwrap();
    /// assert_eq!(row, [2.0, 1.0, 2.0, 3.0]);
    /// assert!(inst.sample_to(1.0, &mut [0.0; 3]).is_err());
    /// ```
    ///
    /// [`Clip::channel_count`]: crate::Clip::channel_count
    pub fn sample_to(&mut self, time: f64, out: &mut [f32]) -> Result<(), OutputLength> {
        let want: usize = self.pose().layout.slots.iter().map(|s| s.kind.dim()).sum();
        if out.len() != want {
            return Err(OutputLength {
                given: out.len(),
                want,
            });
        }
        self.sample(time).write_row(out, None);
        Ok(())
    }

    /// Sample every track at `time` (seconds; any f64) into the pose,
    /// through the [playback](Self::set_playback) mode and speed.
    pub fn sample(&mut self, time: f64) -> &Pose {
        let (time, rate) = self.clip_time(time);
        sample_into(
            &self.clip,
            time,
            &mut self.cursors,
            &mut self.loose,
            &mut self.loose_rot,
            &mut self.pose,
            &mut self.caches,
        );
        if rate != 1.0
            && let Some(v) = &mut self.pose.velocities
        {
            let r = f32x8::splat(rate);
            v.iter_mut().for_each(|x| *x *= r);
        }
        match self.rig.as_deref_mut() {
            Some(RigOutput { map, pose }) => {
                map.apply(&self.pose, pose);
                pose
            }
            None => &self.pose,
        }
    }
}

/// Sample `clip` at `time` into `pose`, with one cursor per group.
pub(crate) fn sample_into(
    clip: &Clip,
    time: f64,
    cursors: &mut [Cursor],
    loose: &mut LooseState,
    loose_rot: &mut LooseState,
    pose: &mut Pose,
    caches: &mut [KeyCache],
) {
    let Pose {
        values, velocities, ..
    } = pose;
    if clip.packed.is_some() {
        sample_packed(
            clip,
            time,
            (cursors, caches),
            loose,
            loose_rot,
            values,
            velocities,
        );
        return;
    }
    sample_rest(
        clip,
        0,
        time,
        (cursors, caches),
        loose,
        loose_rot,
        values,
        velocities,
    );
}

/// [`sample_into`] of a packed clip: its first group decodes its keys from
/// the stream (`crate::pack`); the others, and loose lanes, hold its tracks
/// on key times of their own. Out of line, so that the f32 clips' path
/// stays as it was.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn sample_packed(
    clip: &Clip,
    time: f64,
    (cursors, caches): (&mut [Cursor], &mut [KeyCache]),
    loose: &mut LooseState,
    loose_rot: &mut LooseState,
    values: &mut [f32x8],
    velocities: &mut Option<Vec<f32x8>>,
) {
    let v = velocities.as_deref_mut();
    clip.groups[0].sample_packed(time, &mut cursors[0], &mut caches[0], values, v);
    // Capture packs into the first group alone: then nothing else to set
    // up (the loop's bounds and the loose lanes' checks took about 15
    // instructions a frame).
    if clip.groups.len() > 1 || clip.loose.blocks > 0 || clip.loose_rot.blocks > 0 {
        let rest = (&mut cursors[1..], &mut caches[1..]);
        sample_rest_packed(clip, time, rest, loose, loose_rot, values, velocities);
    }
}

/// [`sample_rest`] after a packed clip's first group, out of line: inlined
/// into [`sample_packed`], its stack and registers were set up on every
/// frame of a clip with nothing else (about 30 instructions).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn sample_rest_packed(
    clip: &Clip,
    time: f64,
    rest: (&mut [Cursor], &mut [KeyCache]),
    loose: &mut LooseState,
    loose_rot: &mut LooseState,
    values: &mut [f32x8],
    velocities: &mut Option<Vec<f32x8>>,
) {
    sample_rest(clip, 1, time, rest, loose, loose_rot, values, velocities);
}

/// [`sample_into`] of `clip`'s groups from `first` on (with their cursors
/// and caches) and its loose lanes.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sample_rest(
    clip: &Clip,
    first: usize,
    time: f64,
    (cursors, caches): (&mut [Cursor], &mut [KeyCache]),
    loose: &mut LooseState,
    loose_rot: &mut LooseState,
    values: &mut [f32x8],
    velocities: &mut Option<Vec<f32x8>>,
) {
    for ((g, cursor), cache) in clip.groups[first..].iter().zip(cursors).zip(caches) {
        g.sample(time, cursor, cache, values, velocities.as_deref_mut());
    }
    if clip.loose.blocks > 0 {
        crate::loose::sample::<false>(&clip.loose, loose, time, values, velocities.as_deref_mut());
    }
    let r = &clip.loose_rot;
    if r.blocks > 0 {
        crate::loose::sample::<true>(r, loose_rot, time, values, velocities.as_deref_mut());
    }
}
