//! The component that plays clips on a joint hierarchy: playback mode and
//! speed, switching and cross-fading.

use crate::asset::TcbClip;
use bevy_asset::Handle;
use bevy_ecs::component::Component;
use bevy_ecs::entity::Entity;
use std::sync::Arc;
use tcb_core::skeleton::Transform as TcbTransform;
use tcb_runtime::{Instance, Playback, Pose, Rig, SkeletonBinding};

/// Plays [`TcbClip`]s on the entity it is on and its descendants.
///
/// Joints are found by [`Name`](bevy_ecs::name::Name): a descendant (or
/// the entity itself) called `Hips` takes the clip's `Hips.translation`,
/// `Hips.rotation` and `Hips.scale` tracks. Once the first clip is loaded
/// the player binds once (and allocates then, never per frame): it
/// finds the joints, makes a [`Rig`] whose rest values are the joints'
/// `Transform`s at that moment (parts a clip does not animate keep them),
/// and from then on writes each joint's `Transform` once per frame in
/// [`TcbSystems::Animate`](crate::TcbSystems::Animate).
///
/// Time is the player's own: a clip shows its time 0 on the frame it
/// starts (the player's first frame bound, or the frame a requested clip
/// has loaded on), then each frame adds `Time::delta * speed` to it,
/// and the [`Playback`] mode maps it onto the clip's keys (loop, clamp,
/// ping-pong, or the clip's own extrapolation). A cross-fade blends the
/// clip that was playing (which goes on playing) into the new one
/// (started at time 0) with weights that move linearly over the fade.
///
/// ```
/// use tcb_bevy::{Playback, TcbPlayer};
/// # let walk = bevy_asset::Handle::<tcb_bevy::TcbClip>::default();
/// # let run = walk.clone();
/// let mut player = TcbPlayer::new(walk).with_playback(Playback::PingPong).with_speed(0.5);
/// player.cross_fade(run, 0.25); // from the next frame the clip is loaded on
/// assert_eq!(player.speed(), 0.5);
/// ```
#[derive(Component)]
pub struct TcbPlayer {
    pub(crate) clip: Handle<TcbClip>,
    pub(crate) playback: Playback,
    pub(crate) speed: f64,
    /// A clip to switch to (fade seconds; 0 switches at once) once loaded.
    pub(crate) request: Option<(Handle<TcbClip>, f64)>,
    pub(crate) rig: Option<Arc<Rig>>,
    pub(crate) bound: Option<Box<Bound>>,
    pub(crate) error: Option<String>,
}

/// What a player holds once bound: nothing in it is allocated per frame.
pub(crate) struct Bound {
    pub(crate) rig: Arc<Rig>,
    pub(crate) binding: SkeletonBinding,
    /// The joints' entities, in the binding's skeleton's order.
    pub(crate) joints: Vec<Entity>,
    /// Local transforms, one per joint, rewritten every frame.
    pub(crate) locals: Vec<TcbTransform>,
    /// The blended pose (in the rig's layout) during a cross-fade.
    pub(crate) out: Pose,
    pub(crate) current: Layer,
    /// The clip fading out, and the fade's elapsed and total seconds.
    pub(crate) fading: Option<(Layer, f64, f64)>,
}

/// One playing clip.
pub(crate) struct Layer {
    pub(crate) instance: Instance,
    /// The player's time in this clip (seconds, before the playback mode).
    pub(crate) time: f64,
    /// Started this frame: shown at time 0, advanced from the next.
    pub(crate) fresh: bool,
}

impl TcbPlayer {
    /// A player of `clip`, looping at speed 1.
    pub fn new(clip: Handle<TcbClip>) -> Self {
        TcbPlayer {
            clip,
            playback: Playback::Loop,
            speed: 1.0,
            request: None,
            rig: None,
            bound: None,
            error: None,
        }
    }

    /// This player with playback mode `mode` (default [`Playback::Loop`]).
    #[must_use]
    pub fn with_playback(mut self, mode: Playback) -> Self {
        self.set_playback(mode);
        self
    }

    /// This player at `speed` (1 the clip's own, negative backwards).
    #[must_use]
    pub fn with_speed(mut self, speed: f64) -> Self {
        self.set_speed(speed);
        self
    }

    /// This player with `rig` as the layout every clip is played in,
    /// instead of one made from the first clip and the joints' transforms
    /// (a rig's rest values for the tracks a clip lacks, say).
    #[must_use]
    pub fn with_rig(mut self, rig: Arc<Rig>) -> Self {
        self.rig = Some(rig);
        self
    }

    /// Set the playback mode (for the clips playing and those to come).
    pub fn set_playback(&mut self, mode: Playback) {
        self.playback = mode;
        if let Some(b) = &mut self.bound {
            b.current.set_playback(mode);
            if let Some((old, _, _)) = &mut b.fading {
                old.set_playback(mode);
            }
        }
    }

    /// Set the speed; a NaN or infinite speed is ignored.
    pub fn set_speed(&mut self, speed: f64) {
        if speed.is_finite() {
            self.speed = speed;
        }
    }

    /// The playback mode.
    pub fn playback(&self) -> Playback {
        self.playback
    }

    /// The speed.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// Switch to `clip` at time 0 on the first frame it is loaded on.
    pub fn play(&mut self, clip: Handle<TcbClip>) {
        self.request = Some((clip, 0.0));
    }

    /// Cross-fade to `clip` over `seconds` (of the player's time, so
    /// speed scales it), starting it at time 0 on the first frame it is
    /// loaded on; the clip playing goes on playing as it fades out. A
    /// fade already under way is cut: its fading clip stops.
    pub fn cross_fade(&mut self, clip: Handle<TcbClip>, seconds: f64) {
        let seconds = if seconds.is_finite() {
            seconds.max(0.0)
        } else {
            0.0
        };
        self.request = Some((clip, seconds));
    }

    /// The clip playing (or to be played first).
    pub fn clip(&self) -> &Handle<TcbClip> {
        &self.clip
    }

    /// The player's time in the clip playing (seconds since it started,
    /// times speed; `None` before the player is bound).
    pub fn time(&self) -> Option<f64> {
        self.bound.as_ref().map(|b| b.current.time)
    }

    /// Jump to `time` in the clip playing (no effect before the player is
    /// bound, or for a time that is not finite).
    pub fn seek(&mut self, time: f64) {
        if let Some(b) = &mut self.bound
            && time.is_finite()
        {
            b.current.time = time;
        }
    }

    /// The weight of the clip playing: below 1 during a cross-fade.
    pub fn weight(&self) -> f32 {
        match self.bound.as_ref().and_then(|b| b.fading.as_ref()) {
            Some(&(_, elapsed, total)) => fade_weight(elapsed, total),
            None => 1.0,
        }
    }

    /// Whether the player has found its joints and is playing.
    pub fn is_bound(&self) -> bool {
        self.bound.is_some()
    }

    /// The number of joints the player writes (0 before it is bound).
    pub fn joint_count(&self) -> usize {
        self.bound.as_ref().map_or(0, |b| b.joints.len())
    }

    /// The rig every pose of this player is in (once bound).
    pub fn rig(&self) -> Option<&Arc<Rig>> {
        self.bound.as_ref().map(|b| &b.rig).or(self.rig.as_ref())
    }

    /// The last reason a clip could not be played (a clip with a track the
    /// rig lacks, no joint found); the player keeps playing what it was.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }
}

impl Layer {
    /// A layer of `instance` at time 0 in `mode`.
    pub(crate) fn new(mut instance: Instance, mode: Playback) -> Self {
        // Speed is applied to the player's time, so that changing it does
        // not jump: the instance plays at 1.
        instance.set_playback(mode, 1.0).expect("speed 1 is finite");
        Layer {
            instance,
            time: 0.0,
            fresh: true,
        }
    }

    /// Move the time on by `step`, except on the frame the layer started.
    pub(crate) fn advance(&mut self, step: f64) {
        if self.fresh {
            self.fresh = false;
        } else {
            self.time += step;
        }
    }

    fn set_playback(&mut self, mode: Playback) {
        self.instance
            .set_playback(mode, 1.0)
            .expect("speed 1 is finite");
    }
}

/// The incoming clip's weight `elapsed` seconds into a fade of `total`.
pub(crate) fn fade_weight(elapsed: f64, total: f64) -> f32 {
    if total > 0.0 {
        (elapsed / total).clamp(0.0, 1.0) as f32
    } else {
        1.0
    }
}
