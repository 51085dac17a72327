//! A hadou scene file (`.toml`) as a Bevy asset: [`HadouScene`], read by [`HadouSceneLoader`]
//! with hadou-scene's own reader, so a file the CLI rejects fails to load with the same
//! `file:line:col: message`.

use bevy::asset::io::Reader;
use bevy::asset::{AssetLoader, LoadContext};
use bevy::prelude::*;
use std::path::PathBuf;

/// A loaded, validated hadou scene: the scene file's camera, light, objects, waves and tracks.
#[derive(Asset, TypePath, Debug)]
pub struct HadouScene(pub hadou_scene::Scene);

/// Why a scene asset did not load.
#[derive(Debug, thiserror::Error)]
pub enum HadouSceneLoadError {
    /// The asset's bytes could not be read.
    #[error("cannot read the scene file: {0}")]
    Io(#[from] std::io::Error),
    /// hadou-scene rejected the file: `file:line:col: message`, as `hadou render` prints it.
    #[error("{0}")]
    Scene(#[from] hadou_scene::SceneError),
}

/// Reads `.toml` assets as [`HadouScene`]s. Files a scene names (glTF models, textures) are read
/// from the file system relative to the scene, under `root` (the asset folder): see
/// [`crate::HadouPlugin::asset_root`].
#[derive(TypePath)]
pub struct HadouSceneLoader {
    /// The directory the asset paths are relative to.
    pub root: PathBuf,
}

/// Parses scene `text` as the file at `path` (which anchors its relative file names and names it
/// in messages).
pub fn parse_scene(text: &[u8], path: &std::path::Path) -> Result<HadouScene, HadouSceneLoadError> {
    let text = std::str::from_utf8(text).map_err(|e| {
        HadouSceneLoadError::Io(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{}: the scene file is not UTF-8 text (byte {})", path.display(), e.valid_up_to()),
        ))
    })?;
    let scene = hadou_scene::Scene::parse(text, path)?;
    for warning in scene.warnings() {
        warn!("{}: {warning}", path.display());
    }
    Ok(HadouScene(scene))
}

impl AssetLoader for HadouSceneLoader {
    type Asset = HadouScene;
    type Settings = ();
    type Error = HadouSceneLoadError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<HadouScene, HadouSceneLoadError> {
        let mut bytes = Vec::new();
        reader.read_to_end(&mut bytes).await?;
        parse_scene(&bytes, &self.root.join(load_context.path().path()))
    }

    fn extensions(&self) -> &[&str] {
        &["toml"]
    }
}
