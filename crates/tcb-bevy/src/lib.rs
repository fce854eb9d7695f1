//! # tcb-bevy
//!
//! Kochanek–Bartels clips in [bevy](https://bevy.org): a [`TcbPlugin`]
//! that loads [`TcbClip`] assets (tcb clip `.json`, `.bvh`, `.gltf`/`.glb`
//! through `tcb-io`, packed `.tcbc` through
//! [`tcb_runtime::Clip::from_bytes`]) and a [`TcbPlayer`] component that
//! plays them on an entity's joint hierarchy (entities named as the
//! clip's joints), with a playback mode, a speed, and cross-fades between
//! clips (blended in a [`Rig`](tcb_runtime::Rig)'s layout).
//!
//! One system, in [`TcbSystems::Animate`] (in `PostUpdate`, before
//! transform propagation), samples every player, blends while a fade
//! runs, and writes each joint's `Transform` once a frame; after a player
//! binds to its joints (once, when its first clip has loaded) nothing is
//! allocated per frame.
//!
//! ```
//! use bevy_app::{App, Startup};
//! use bevy_asset::{AssetPlugin, AssetServer};
//! use bevy_ecs::prelude::*;
//! use tcb_bevy::{Playback, TcbClip, TcbPlayer, TcbPlugin};
//!
//! fn setup(mut commands: Commands, assets: Res<AssetServer>) {
//!     let walk = assets.load::<TcbClip>("walk.bvh");
//!     // Its children named `Hips`, `LeftUpLeg`, ... are the joints.
//!     commands.spawn(TcbPlayer::new(walk).with_playback(Playback::PingPong));
//! }
//!
//! let mut app = App::new();
//! app.add_plugins((bevy_app::TaskPoolPlugin::default(), AssetPlugin::default(), TcbPlugin))
//!     .add_systems(Startup, setup);
//! ```

#![forbid(unsafe_code)]

mod asset;
mod player;
mod spawn;
mod systems;

pub use asset::{EXTENSIONS, TcbClip, TcbClipLoader, TcbClipSettings, TcbLoadError};
pub use player::TcbPlayer;
pub use spawn::spawn_skeleton;
pub use tcb_runtime::Playback;

use bevy_app::{App, Plugin, PostUpdate};
use bevy_asset::AssetApp;
use bevy_ecs::schedule::{IntoScheduleConfigs, SystemSet};
use bevy_transform::TransformSystems;

/// The system set the plugin's systems run in (`PostUpdate`, before
/// `TransformSystems::Propagate`): order systems that move players or
/// read joints' `Transform`s against it.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TcbSystems {
    /// Bind new players, then sample, blend and write `Transform`s.
    Animate,
}

/// Registers [`TcbClip`] and its loader and adds the player systems.
/// Needs bevy's `AssetPlugin` (in `DefaultPlugins`; add it to
/// `MinimalPlugins`), and `TransformPlugin` for `GlobalTransform`s.
#[derive(Default)]
pub struct TcbPlugin;

impl Plugin for TcbPlugin {
    fn build(&self, app: &mut App) {
        app.init_asset::<TcbClip>()
            .init_asset_loader::<TcbClipLoader>()
            .configure_sets(
                PostUpdate,
                TcbSystems::Animate.before(TransformSystems::Propagate),
            )
            .add_systems(
                PostUpdate,
                (systems::bind_players, systems::animate)
                    .chain()
                    .in_set(TcbSystems::Animate),
            );
    }
}
