//! [`HadouShaded`]: one component that switches a model loaded by Bevy's own loaders (a glTF
//! character's `SceneRoot`, skinned and animated by Bevy) from Bevy's `StandardMaterial` to
//! hadou's shading ([`HadouMaterial`]: the toon ramp, the wave as a light, glow, shadows) and
//! outlines ([`HadouOutline`]).

use crate::material::HadouMaterial;
use crate::outline::HadouOutline;
use bevy::image::{ImageAddressMode, ImageFilterMode, ImageSampler};
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::storage::ShaderBuffer;
use hadou_scene::{Filter, Texture, TextureRef, Wrap};
use std::collections::HashMap;
use std::sync::Arc;

/// Put on the root of a model spawned by Bevy (e.g. a glTF `SceneRoot`): every mesh below it
/// drawn with a `StandardMaterial` is given a [`HadouMaterial`] instead: `material`'s model, ramp,
/// `wave_blend` and outline under `light`, its base colour multiplied by the `StandardMaterial`'s
/// base colour, and the `StandardMaterial`'s base-colour texture (an 8-bit RGBA image kept in the
/// main world, as Bevy's glTF loader keeps it) as hadou's base texture. Meshes spawned later
/// (the scene loads asynchronously) are switched when they appear. With an outline in `material`,
/// each mesh gets a hull (pushed along the mesh's own normals; a skinned mesh's hull is skinned by
/// the same joints).
#[derive(Component, Clone, Debug)]
pub struct HadouShaded {
    /// hadou's look: `model`, `ramp`, `wave_blend`, `outline`, and a base colour that multiplies
    /// the model's own.
    pub material: hadou_scene::Material,
    /// The light of the look (`[light]`).
    pub light: hadou_scene::Light,
    /// The shadows the model receives ([`HadouMaterial::with_shadow_mask`]).
    pub shadow_mask: u32,
    /// hadou's own looks for the glTF file's materials, by slot (the file's materials in order,
    /// then its default material: a frame object's `materials` when the object is that file).
    /// When not empty, a mesh whose `StandardMaterial` Bevy's glTF loader made from material `i`
    /// takes `slots[i]` as it is (its colours and textures already read from the file) instead
    /// of `material` times the `StandardMaterial`. Empty for a model of the game's own.
    pub slots: Vec<hadou_scene::Material>,
    /// The scene time in seconds an MToon look's UV animation is at ([`HadouMaterial::set_time`]);
    /// a spawned scene sets it every frame.
    pub time: f32,
}

impl HadouShaded {
    /// `material` under `light` for every mesh, receiving the shadows of `shadow_mask`.
    pub fn new(material: hadou_scene::Material, light: hadou_scene::Light, shadow_mask: u32) -> Self {
        HadouShaded { material, light, shadow_mask, slots: Vec::new(), time: 0.0 }
    }
}

/// The slot of a `StandardMaterial` that Bevy's glTF loader made (its label is `Material{i}/std`,
/// `Material{i} (inverted)/std` or `DefaultMaterial/std`) among `slots` slots (the file's
/// materials, then its default one); `None` for a material of any other origin.
pub fn gltf_slot(handle: &Handle<StandardMaterial>, slots: usize) -> Option<usize> {
    let path = handle.path()?;
    let label = path.label()?.strip_suffix("/std")?;
    if label == "DefaultMaterial" {
        return slots.checked_sub(1);
    }
    let index = label.strip_prefix("Material")?;
    let index = index.strip_suffix(" (inverted)").unwrap_or(index);
    index.parse::<usize>().ok().filter(|&i| i < slots)
}

/// The look of a mesh drawn with `source` (the `StandardMaterial` behind `handle`) under
/// `shaded`: the glTF slot's own look, or `shaded.material` with its base colour multiplied by
/// the `StandardMaterial`'s (the texture is added by the caller). The flag is true for a slot's
/// own look.
fn look_of(
    shaded: &HadouShaded,
    handle: &Handle<StandardMaterial>,
    source: &StandardMaterial,
) -> (hadou_scene::Material, bool) {
    if let Some(slot) = gltf_slot(handle, shaded.slots.len()) {
        return (shaded.slots[slot].clone(), true);
    }
    let mut look = shaded.material.clone();
    let base = source.base_color.to_linear();
    look.base_color =
        [look.base_color[0] * base.red, look.base_color[1] * base.green, look.base_color[2] * base.blue];
    (look, false)
}

fn wrap(mode: ImageAddressMode) -> Wrap {
    match mode {
        ImageAddressMode::ClampToEdge | ImageAddressMode::ClampToBorder => Wrap::Clamp,
        ImageAddressMode::MirrorRepeat => Wrap::Mirror,
        _ => Wrap::Repeat,
    }
}

/// `image` as a hadou texture (its texels, and its sampler's wrap and filter), when its texels are
/// 8-bit sRGB or linear RGBA held in the main world; `None` otherwise.
pub fn hadou_texture(name: &str, image: &Image) -> Option<TextureRef> {
    let format = image.texture_descriptor.format;
    if !matches!(format, TextureFormat::Rgba8UnormSrgb | TextureFormat::Rgba8Unorm) {
        return None;
    }
    let (width, height) = (image.width(), image.height());
    let data = image.data.as_ref()?;
    let texels: Vec<[u8; 4]> = data.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    if width == 0 || height == 0 || texels.len() != width as usize * height as usize {
        return None;
    }
    let (wrap_uv, filter) = match &image.sampler {
        ImageSampler::Descriptor(d) => (
            [wrap(d.address_mode_u), wrap(d.address_mode_v)],
            if d.mag_filter == ImageFilterMode::Nearest { Filter::Nearest } else { Filter::Linear },
        ),
        ImageSampler::Default => ([Wrap::Repeat; 2], Filter::Linear),
    };
    Some(TextureRef {
        image: Arc::new(Texture { name: name.to_string(), width, height, texels }),
        wrap: wrap_uv,
        filter,
    })
}

/// The `HadouMaterial` made for each (root, `StandardMaterial`) pair, shared by its meshes, with
/// the `StandardMaterial` it replaces.
type Made = HashMap<(Entity, AssetId<StandardMaterial>), (Handle<StandardMaterial>, Handle<HadouMaterial>)>;

/// Switches the `StandardMaterial` meshes below every [`HadouShaded`] root (see there).
#[allow(clippy::too_many_arguments)]
pub(crate) fn shade_models(
    mut commands: Commands,
    standard: Query<(
        Entity,
        &MeshMaterial3d<StandardMaterial>,
        &Mesh3d,
        Option<&bevy::mesh::skinning::SkinnedMesh>,
    )>,
    parents: Query<&ChildOf>,
    transforms: Query<&Transform>,
    roots: Query<&HadouShaded>,
    changed: Query<(Entity, &HadouShaded), Changed<HadouShaded>>,
    standard_materials: Res<Assets<StandardMaterial>>,
    images: Res<Assets<Image>>,
    assets: Res<AssetServer>,
    mut materials: ResMut<Assets<HadouMaterial>>,
    mut outlines: ResMut<Assets<HadouOutline>>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
    mut made: Local<Made>,
) {
    // A root whose look changed (a scene track, a game system) updates the materials made for it.
    for (root, shaded) in &changed {
        for ((_, standard_id), (standard_handle, handle)) in made.iter().filter(|((r, _), _)| *r == root) {
            let Some(source) = standard_materials.get(*standard_id) else { continue };
            let (look, _) = look_of(shaded, standard_handle, source);
            let differs = materials.get(handle).is_some_and(|m| {
                let mut next = m.clone();
                next.update(&look, &shaded.light) | next.set_time(shaded.time)
            });
            if differs {
                if let Some(mut m) = materials.get_mut(handle) {
                    m.update(&look, &shaded.light);
                    m.set_time(shaded.time);
                }
            }
        }
    }
    for (entity, standard_material, mesh, skinned) in &standard {
        let Some((root, shaded)) =
            parents.iter_ancestors(entity).find_map(|a| roots.get(a).ok().map(|s| (a, s)))
        else {
            continue;
        };
        let Some(source) = standard_materials.get(&standard_material.0) else { continue };
        let key = (root, standard_material.0.id());
        let handle = match made.get(&key) {
            Some((_, h)) => h.clone(),
            None => {
                let (mut look, own) = look_of(shaded, &standard_material.0, source);
                if let Some(texture) = source.base_color_texture.as_ref().filter(|_| !own) {
                    match images.get(texture) {
                        Some(image) => {
                            look.base_texture = hadou_texture("base colour", image);
                            if look.base_texture.is_none() {
                                warn!(
                                    "{entity}: its `base_color_texture` is not 8-bit RGBA kept in the main world; \
                                     drawn without it"
                                );
                            }
                        }
                        None if assets.load_state(texture).is_failed() => {
                            let path = texture.path().map_or_else(|| "?".to_string(), |p| p.to_string());
                            error!("{entity}: its `base_color_texture` ({path}) failed to load; drawn without it");
                        }
                        None => continue, // still loading
                    }
                }
                let mut material = HadouMaterial::with_textures(&look, &shaded.light, &mut buffers)
                    .with_shadow_mask(shaded.shadow_mask);
                material.set_time(shaded.time);
                let h = materials.add(material);
                made.insert(key, (standard_material.0.clone(), h.clone()));
                h
            }
        };
        let mut e = commands.entity(entity);
        e.remove::<MeshMaterial3d<StandardMaterial>>().insert(MeshMaterial3d(handle));
        let look = match gltf_slot(&standard_material.0, shaded.slots.len()) {
            Some(slot) => &shaded.slots[slot],
            None => &shaded.material,
        };
        if let Some(outline) = HadouOutline::of(look, &shaded.light) {
            // The hull and its closing hull are drawn from the same mesh (skinned by the same
            // joints: a sibling of the mesh entity keeps its transform and skin).
            for outline in [outline.closing(), outline] {
                let mut hull = commands.spawn((
                    Name::new("outline"),
                    Mesh3d(mesh.0.clone()),
                    MeshMaterial3d(outlines.add(outline)),
                ));
                match skinned {
                    Some(skin) => {
                        // Skinned bounds move with the joints; the hull is never culled.
                        hull.insert((skin.clone(), bevy::camera::visibility::NoFrustumCulling));
                        if let Ok(parent) = parents.get(entity) {
                            hull.insert((
                                ChildOf(parent.parent()),
                                transforms.get(entity).copied().unwrap_or_default(),
                            ));
                        }
                    }
                    None => {
                        hull.insert(ChildOf(entity));
                    }
                }
            }
        }
    }
}
