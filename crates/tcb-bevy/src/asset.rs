//! The clip asset and its loader: clip JSON, BVH and glTF through
//! [`tcb_io::load_bytes`], `.tcbc` through [`tcb_runtime::Clip::from_bytes`].

use bevy_asset::io::Reader;
use bevy_asset::{Asset, AssetLoader, LoadContext};
use bevy_reflect::TypePath;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;
use tcb_core::skeleton::Skeleton;
use tcb_io::{Format, ImportOptions};
use tcb_runtime::Clip;

/// A clip, compiled for playback, and the skeleton its file carried (BVH
/// and glTF files carry one; a clip JSON or a `.tcbc` may).
///
/// Load it with the [`AssetServer`](bevy_asset::AssetServer) once
/// [`TcbPlugin`](crate::TcbPlugin) is added, and play it with a
/// [`TcbPlayer`](crate::TcbPlayer).
#[derive(Asset, TypePath, Debug)]
pub struct TcbClip {
    clip: Arc<Clip>,
    skeleton: Option<Skeleton>,
    warnings: Vec<String>,
}

impl TcbClip {
    /// A clip asset of `clip` (and its `skeleton`, if any), for clips made
    /// in code: add it to `Assets<TcbClip>`.
    pub fn new(clip: Arc<Clip>, skeleton: Option<Skeleton>) -> Self {
        TcbClip {
            clip,
            skeleton,
            warnings: Vec::new(),
        }
    }

    /// The compiled clip (shared by every player of it).
    pub fn clip(&self) -> &Arc<Clip> {
        &self.clip
    }

    /// The joint hierarchy the file carried.
    pub fn skeleton(&self) -> Option<&Skeleton> {
        self.skeleton.as_ref()
    }

    /// What the importer read but found odd (a BVH's or glTF's warnings).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }
}

/// Loads [`TcbClip`]s from `.json` (tcb clip JSON), `.bvh`, `.gltf`, `.glb`
/// and `.tcbc` files. A `.gltf`'s buffers must be embedded (`data:` URIs);
/// a `.glb` holds its own.
///
/// bevy's own glTF loader (and any other `.json` loader) registers the
/// same extensions: load typed, `asset_server.load::<TcbClip>(path)`, and
/// bevy picks this loader; an untyped or labeled load (`walk.glb#Scene0`)
/// picks the loader registered last.
#[derive(Default, TypePath)]
pub struct TcbClipLoader;

/// Settings of a [`TcbClipLoader`] load (a `.meta` file's, or
/// `AssetServer::load_with_settings`).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct TcbClipSettings {
    /// glTF: the animation to import, by name or index (default: the first).
    pub animation: Option<String>,
}

/// Why a clip file could not be loaded: the asset path and the importer's
/// message.
#[derive(Debug)]
pub struct TcbLoadError {
    path: String,
    message: String,
}

impl fmt::Display for TcbLoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path, self.message)
    }
}

impl std::error::Error for TcbLoadError {}

/// The extensions [`TcbClipLoader`] registers.
pub const EXTENSIONS: &[&str] = &["json", "bvh", "gltf", "glb", "tcbc"];

impl AssetLoader for TcbClipLoader {
    type Asset = TcbClip;
    type Settings = TcbClipSettings;
    type Error = TcbLoadError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        settings: &TcbClipSettings,
        load_context: &mut LoadContext<'_>,
    ) -> Result<TcbClip, TcbLoadError> {
        let path = load_context.path().path().to_path_buf();
        let error = |message: String| TcbLoadError {
            path: path.display().to_string(),
            message,
        };
        let mut bytes = Vec::new();
        reader
            .read_to_end(&mut bytes)
            .await
            .map_err(|e| error(e.to_string()))?;
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if ext == "tcbc" {
            let clip = Clip::from_bytes(&bytes).map_err(|e| error(e.to_string()))?;
            // Format 2 keeps the skeleton `tcb compress` was given.
            let skeleton = clip.packed().and_then(|p| p.skeleton.clone());
            return Ok(TcbClip::new(Arc::new(clip), skeleton));
        }
        let format = Format::from_extension(&ext).ok_or_else(|| {
            error(format!(
                "unknown file type '.{ext}' (expected .json, .bvh, .gltf, .glb or .tcbc)"
            ))
        })?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let options = ImportOptions::default().animation(settings.animation.clone());
        let loaded = tcb_io::load_bytes(&bytes, format, &name, &options)
            .map_err(|e| error(e.to_string()))?;
        Ok(TcbClip {
            clip: Arc::new(Clip::compile(&loaded.clip)),
            skeleton: loaded.skeleton,
            warnings: loaded.warnings,
        })
    }

    fn extensions(&self) -> &[&str] {
        EXTENSIONS
    }
}
