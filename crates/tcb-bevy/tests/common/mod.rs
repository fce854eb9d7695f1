//! A headless app (`MinimalPlugins`, assets from a folder, fixed 60 Hz
//! frames) and the clips the tests play.

#![allow(dead_code)] // each test file uses part of this

use bevy::MinimalPlugins;
use bevy::app::App;
use bevy::asset::{AssetPlugin, AssetServer, Assets, Handle};
use bevy::time::TimeUpdateStrategy;
use bevy::transform::TransformPlugin;
use std::path::Path;
use std::time::Duration;
use tcb_bevy::{TcbClip, TcbPlugin};

/// The frame time the apps advance by: 1/60 s in whole nanoseconds, as
/// `Time` holds it.
pub const DT: f64 = 16_666_667e-9;

/// The repository's `data/` folder.
pub fn data_dir() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/../../data").to_string()
}

/// An app reading assets from `assets`, each update 1/60 s later.
pub fn app(assets: &Path) -> App {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin {
            file_path: assets.display().to_string(),
            ..Default::default()
        },
        TransformPlugin,
        TcbPlugin,
    ))
    .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_nanos(
        16_666_667,
    )));
    app.finish();
    app.cleanup();
    app
}

/// Load `path` and update until it has loaded (or failed: `None`).
pub fn load(app: &mut App, path: &str) -> Option<Handle<TcbClip>> {
    let handle = app
        .world()
        .resource::<AssetServer>()
        .load::<TcbClip>(path.to_string());
    for _ in 0..5000 {
        app.update();
        if app.world().resource::<Assets<TcbClip>>().contains(&handle) {
            return Some(handle);
        }
        let server = app.world().resource::<AssetServer>();
        if server.load_state(&handle).is_failed() {
            return None;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    panic!("{path} did not load");
}
