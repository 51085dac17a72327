//! `.vrm` files (VRM 1.0 and 0.x avatars, which are glTF binaries) loaded by Bevy's own glTF
//! loader ([`VrmLoader`]), as a scene's `kind = "gltf"` objects and [`crate::HadouShaded`] models
//! are: Bevy's loader takes only `.gltf` and `.glb` by name. hadou reads the VRM extensions
//! (MToon, spring bones, expressions) itself; Bevy's loader skips them.

use bevy::asset::io::Reader;
use bevy::asset::{AssetLoader, LoadContext};
use bevy::gltf::extensions::GltfExtensionHandlers;
use bevy::gltf::{DefaultGltfImageSampler, Gltf, GltfError, GltfLoader, GltfLoaderSettings};
use bevy::image::{CompressedImageFormatSupport, CompressedImageFormats};
use bevy::prelude::*;

/// Bevy's glTF loader under the `.vrm` extension: the same `Gltf` asset, labels and settings. A
/// file whose MToon extension is broken (a key of the wrong type, a texture index out of range)
/// is logged once as an error naming the file, the material and the key, and still loaded.
#[derive(TypePath)]
pub struct VrmLoader(pub GltfLoader);

impl AssetLoader for VrmLoader {
    type Asset = Gltf;
    type Settings = GltfLoaderSettings;
    type Error = GltfError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        settings: &GltfLoaderSettings,
        load_context: &mut LoadContext<'_>,
    ) -> Result<Gltf, GltfError> {
        let mut bytes = Vec::new();
        reader.read_to_end(&mut bytes).await?;
        // hadou's check of the file's MToon materials (`hadou_scene::check_gltf_materials`, the
        // error `hadou render` gives): a broken extension is one error naming the file, the
        // material and the key; Bevy's loader reads the rest, and the materials are drawn without
        // MToon (as every material of a `.vrm` Bevy loads itself is).
        if let Err(why) = hadou_scene::check_gltf_materials(&bytes) {
            error!("{}: {why}; its materials are drawn without MToon", load_context.path());
        }
        GltfLoader::load_gltf(&self.0, &bytes, load_context, settings).await
    }

    fn extensions(&self) -> &[&str] {
        &["vrm"]
    }
}

/// Registers [`VrmLoader`] with the glTF plugin's own settings (its default sampler, extension
/// handlers and the device's compressed formats), once that plugin has finished; nothing in an
/// app without it.
pub(crate) fn register(app: &mut App) {
    let world = app.world();
    let (Some(handlers), Some(sampler)) =
        (world.get_resource::<GltfExtensionHandlers>(), world.get_resource::<DefaultGltfImageSampler>())
    else {
        return;
    };
    let loader = GltfLoader {
        supported_compressed_formats: world
            .get_resource::<CompressedImageFormatSupport>()
            .map_or(CompressedImageFormats::NONE, |f| f.0),
        custom_vertex_attributes: Default::default(),
        default_sampler: sampler.get_internal(),
        default_convert_coordinates: Default::default(),
        extensions: handlers.0.clone(),
        default_skinned_mesh_bounds_policy: Default::default(),
    };
    app.register_asset_loader(VrmLoader(loader));
}
