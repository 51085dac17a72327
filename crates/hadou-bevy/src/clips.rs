//! [`HadouClip`]: a glTF file's named animation clip played by Bevy's own animation
//! (`AnimationPlayer`, an `AnimationGraph` of the clip from `Gltf::named_animations`) on a model
//! Bevy's glTF loader spawned (`WorldAssetRoot`), held at a clip time the component gives. A
//! spawned scene puts one on each `kind = "gltf"` object with an `animation` and sets its time
//! every frame from hadou-scene's clip time (`Scene::object_clip_at`: `animation_start`,
//! `animation_speed`, `animation_loop` or `animation_time`, the same rule as `hadou render`'s,
//! `hadou_scene::clip_time`); Bevy samples the clip and skins the meshes.

use bevy::animation::graph::{AnimationGraph, AnimationGraphHandle, AnimationNodeIndex};
use bevy::animation::AnimationPlayer;
use bevy::gltf::Gltf;
use bevy::prelude::*;
use bevy::world_serialization::WorldAssetRoot;

/// Plays the clip `name` of the glTF file whose scene this entity's `WorldAssetRoot` spawns,
/// held at `time` seconds into it (the clip's `AnimationPlayer` is paused there; Bevy's animation
/// sets the joints' `Transform`s and morph weights, its skinning poses the meshes). A clip the
/// file lacks is logged once as an error naming the entity and `animation`, and the model stays
/// at rest ([`ClipRejected`]).
#[derive(Component, Clone, Debug, PartialEq)]
pub struct HadouClip {
    /// The clip's name in the file (a scene's `animation`).
    pub name: String,
    /// Seconds into the clip, already wrapped or held at its ends (hadou-scene's clip time).
    pub time: f32,
}

/// Put on an entity whose [`HadouClip`] names a clip its file lacks: the model is drawn at rest.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct ClipRejected(pub String);

/// The error line of a clip `name` that `entity`'s file lacks, with the clips it has.
pub fn clip_rejection_message(entity: Entity, who: Option<&Name>, name: &str, clips: &[&str]) -> String {
    let who = who.map_or_else(|| format!("{entity}"), |n| format!("{entity} (\"{n}\")"));
    format!(
        "hadou clip of {who} not played: `animation` names \"{}\", which its glTF file lacks; its clips are [{}]; \
         drawn at rest",
        hadou_scene::escape_controls(name),
        clips.iter().map(|c| format!("\"{}\"", hadou_scene::escape_controls(c))).collect::<Vec<_>>().join(", ")
    )
}

/// How a [`HadouClip`] is played: the file, and once bound the player and the clip's node.
#[derive(Component, Debug)]
pub(crate) struct ClipPlayback {
    gltf: Handle<Gltf>,
    /// The clip bound to: its name, the `AnimationPlayer` entity and the graph node.
    bound: Option<(String, Entity, AnimationNodeIndex)>,
}

impl ClipPlayback {
    /// Whether the clip is being played.
    pub(crate) fn is_bound(&self) -> bool {
        self.bound.is_some()
    }
}

type ClipModel = (
    Entity,
    &'static HadouClip,
    &'static WorldAssetRoot,
    Option<&'static Name>,
    Option<&'static mut ClipPlayback>,
    Option<&'static ClipRejected>,
);

/// Binds every [`HadouClip`] to its model's `AnimationPlayer` once the file and its scene have
/// loaded, and seeks the clip to the component's time every frame (`Update`, before Bevy's
/// animation in `PostUpdate`).
pub(crate) fn play_clips(
    mut commands: Commands,
    mut models: Query<ClipModel>,
    children: Query<&Children>,
    mut players: Query<&mut AnimationPlayer>,
    gltfs: Option<Res<Assets<Gltf>>>,
    graphs: Option<ResMut<Assets<AnimationGraph>>>,
    asset_server: Res<AssetServer>,
) {
    // Without Bevy's glTF loader and animation (their plugins add these) nothing is played.
    let (Some(gltfs), Some(mut graphs)) = (gltfs, graphs) else { return };
    for (entity, clip, root, name, playback, rejected) in &mut models {
        let Some(mut playback) = playback else {
            let Some(path) = root.0.path() else { continue };
            let gltf = asset_server.load::<Gltf>(path.without_label().into_owned());
            commands.entity(entity).insert(ClipPlayback { gltf, bound: None });
            continue;
        };
        if playback.bound.as_ref().is_some_and(|(n, _, _)| *n != clip.name) {
            // Another clip: unbind (the old one stops) and bind again.
            if let Some((_, player, _)) = playback.bound.take() {
                if let Ok(mut p) = players.get_mut(player) {
                    p.stop_all();
                }
            }
        }
        if playback.bound.is_none() {
            let Some(gltf) = gltfs.get(&playback.gltf) else { continue };
            let Some(handle) = gltf.named_animations.get(clip.name.as_str()) else {
                if rejected.is_none_or(|r| !r.0.contains(&format!("\"{}\"", clip.name))) {
                    let mut clips: Vec<&str> = gltf.named_animations.keys().map(|k| &**k).collect();
                    clips.sort_unstable();
                    let message = clip_rejection_message(entity, name, &clip.name, &clips);
                    error!("{message}");
                    commands.entity(entity).insert(ClipRejected(message));
                }
                continue;
            };
            let Some(player) = std::iter::once(entity)
                .chain(children.iter_descendants(entity))
                .find(|&e| players.contains(e))
            else {
                continue; // the scene is not spawned yet
            };
            let (graph, node) = AnimationGraph::from_clip(handle.clone());
            commands.entity(player).insert(AnimationGraphHandle(graphs.add(graph)));
            if rejected.is_some() {
                commands.entity(entity).remove::<ClipRejected>();
            }
            playback.bound = Some((clip.name.clone(), player, node));
        }
        let Some((_, player, node)) = &playback.bound else { continue };
        let Ok(mut player) = players.get_mut(*player) else { continue };
        let time = if clip.time.is_finite() { clip.time } else { 0.0 };
        let active = player.play(*node);
        if active.seek_time() != time || !active.is_paused() {
            active.seek_to(time).pause();
        }
    }
}
