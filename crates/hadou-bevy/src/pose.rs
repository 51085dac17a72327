//! [`HadouPose`]: a character Bevy's glTF loader spawned (`WorldAssetRoot`), posed by hadou-scene
//! rather than by Bevy's animation: every frame each glTF node's entity gets its local
//! `Transform` and its mesh's `MorphWeights` from hadou-scene's pose of the node
//! ([`hadou_scene::NodePose`], `Scene::object_node_pose_at`: the clip, clip time, expressions and
//! spring-bone and gaze rotations the mesh `hadou render` draws is skinned by; glTF 2.0 §3.5.3
//! `L = T·R·S`, §3.7.2.2 morph weights). Bevy's skinning then draws hadou's pose (glTF 2.0
//! §3.7.3.3, the sum `Σ w_k · G(joint_k) · IBM_k` that `Rig::pose` takes), and its shadows
//! (drawn_pose.rs) and the area light's casters follow it. A spawned scene puts one on each
//! `kind = "gltf"` object hadou poses beyond a clip of its own file (`Scene::object_posed_by_hadou`:
//! a VRM Animation `animation_file`, `expressions`, spring bones, `look_at`), in place of a
//! [`crate::HadouClip`], and sets it from the scene's time every frame. Spring bones are not
//! simulated here: the pose carries hadou-scene's states.
//!
//! The glTF nodes are found by name (Bevy names a node's entity by its `name`, else
//! `GltfNode{index}`) down the file's hierarchy: a root node is the shallowest entity of that name
//! under the model, a child node the first of its parent's child entities of that name.

use bevy::gltf::{Gltf, GltfNode};
use bevy::mesh::morph::MorphWeights;
use bevy::prelude::*;
use bevy::world_serialization::WorldAssetRoot;
use hadou_scene::NodePose;

/// Poses the glTF nodes of the model this entity's `WorldAssetRoot` spawns with hadou-scene's
/// pose (see the module's notes). A pose that does not fit the file (another number of nodes
/// than the file's) is logged once as an error naming the entity and `path`, and the model stays
/// at rest ([`PoseRejected`]); a node whose values are not finite keeps its last transform.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct HadouPose(pub NodePose);

/// Put on an entity whose [`HadouPose`] does not fit its file: the model is drawn at rest.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct PoseRejected(pub String);

/// The error line of a pose of `pose_nodes` nodes on `entity`, whose file has `file_nodes`.
pub fn pose_rejection_message(
    entity: Entity,
    who: Option<&Name>,
    pose_nodes: usize,
    file_nodes: usize,
) -> String {
    let who = who.map_or_else(|| format!("{entity}"), |n| format!("{entity} (\"{n}\")"));
    format!(
        "hadou pose of {who} not applied: the pose has {pose_nodes} glTF nodes, the file its `path` names has \
         {file_nodes}; drawn at rest"
    )
}

/// How a [`HadouPose`] is applied: the file, and once bound each node's entity (`None` for a
/// node the spawned scene lacks, e.g. one of another glTF scene).
#[derive(Component, Debug)]
pub(crate) struct PoseBinding {
    gltf: Handle<Gltf>,
    nodes: Option<Vec<Option<Entity>>>,
}

impl PoseBinding {
    /// Whether the pose is being applied.
    pub(crate) fn is_bound(&self) -> bool {
        self.nodes.is_some()
    }
}

type PosedModel = (
    Entity,
    &'static HadouPose,
    &'static WorldAssetRoot,
    Option<&'static Name>,
    Option<&'static mut PoseBinding>,
    Has<PoseRejected>,
);

/// Per node of a file, its name, its children and whether it is a root.
type NodeTree = (Vec<String>, Vec<Vec<usize>>, Vec<bool>);

/// The file's [`NodeTree`], from Bevy's `Gltf` asset.
fn node_tree(gltf: &Gltf, nodes: &Assets<GltfNode>) -> Option<NodeTree> {
    let n = gltf.nodes.len();
    let (mut names, mut children, mut root) = (vec![String::new(); n], vec![Vec::new(); n], vec![true; n]);
    for handle in &gltf.nodes {
        let node = nodes.get(handle)?;
        let slot = names.get_mut(node.index)?;
        slot.clone_from(&node.name);
        for child in &node.children {
            let c = nodes.get(child)?.index;
            children[node.index].push(c);
            *root.get_mut(c)? = false;
        }
    }
    Some((names, children, root))
}

/// Each glTF node's entity under `model` (see the module's notes), or `None` while the scene is
/// not spawned (no root node found).
fn bind_nodes(
    model: Entity,
    (names, children, root): &NodeTree,
    kids: &Query<&Children>,
    named: &Query<&Name, Without<Mesh3d>>,
) -> Option<Vec<Option<Entity>>> {
    let mut out: Vec<Option<Entity>> = vec![None; names.len()];
    // The model's descendants, shallowest first.
    let mut below = Vec::new();
    let mut level = vec![model];
    while !level.is_empty() {
        let next: Vec<Entity> =
            level.iter().flat_map(|&e| kids.get(e).into_iter().flatten().copied()).collect();
        below.extend(next.iter().copied());
        level = next;
    }
    let mut queue: Vec<usize> = (0..names.len()).filter(|&i| root[i]).collect();
    let mut head = 0;
    while let Some(&i) = queue.get(head) {
        head += 1;
        if root[i] {
            let found = below
                .iter()
                .find(|e| named.get(**e).is_ok_and(|n| n.as_str() == names[i]) && !out.contains(&Some(**e)))
                .copied();
            out[i] = found;
        }
        let Some(entity) = out[i] else { continue };
        for &c in &children[i] {
            let found = kids
                .get(entity)
                .into_iter()
                .flatten()
                .find(|e| named.get(**e).is_ok_and(|n| n.as_str() == names[c]) && !out.contains(&Some(**e)))
                .copied();
            out[c] = found;
            queue.push(c);
        }
    }
    out.iter().any(Option::is_some).then_some(out)
}

/// Binds every [`HadouPose`] to its model's node entities once the file and its scene have
/// loaded, and sets the nodes' `Transform`s and `MorphWeights` from the pose every frame
/// (`Update`, after the scenes are animated; Bevy propagates and skins in `PostUpdate`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn apply_poses(
    mut commands: Commands,
    mut models: Query<PosedModel>,
    kids: Query<&Children>,
    named: Query<&Name, Without<Mesh3d>>,
    mut transforms: Query<&mut Transform>,
    mut weights: Query<&mut MorphWeights>,
    gltfs: Option<Res<Assets<Gltf>>>,
    gltf_nodes: Option<Res<Assets<GltfNode>>>,
    asset_server: Res<AssetServer>,
) {
    let (Some(gltfs), Some(gltf_nodes)) = (gltfs, gltf_nodes) else { return };
    for (entity, pose, root, name, binding, rejected) in &mut models {
        let Some(mut binding) = binding else {
            let Some(path) = root.0.path() else { continue };
            let gltf = asset_server.load::<Gltf>(path.without_label().into_owned());
            commands.entity(entity).insert(PoseBinding { gltf, nodes: None });
            continue;
        };
        let Some(gltf) = gltfs.get(&binding.gltf) else { continue };
        if pose.0.locals.len() != gltf.nodes.len() {
            if !rejected {
                let message = pose_rejection_message(entity, name, pose.0.locals.len(), gltf.nodes.len());
                error!("{message}");
                commands.entity(entity).insert(PoseRejected(message));
            }
            continue;
        }
        if rejected {
            commands.entity(entity).remove::<PoseRejected>();
        }
        if binding.nodes.is_none() {
            let Some(tree) = node_tree(gltf, &gltf_nodes) else { continue };
            binding.nodes = bind_nodes(entity, &tree, &kids, &named);
        }
        let Some(nodes) = &binding.nodes else { continue }; // the scene is not spawned yet
        for (i, node) in nodes.iter().enumerate() {
            let Some(node) = *node else { continue };
            if let (Some((t, r, s)), Ok(mut transform)) = (pose.0.locals[i], transforms.get_mut(node)) {
                let next = Transform {
                    translation: Vec3::from_array(t),
                    rotation: Quat::from_array(r),
                    scale: Vec3::from_array(s),
                };
                let finite = t.iter().chain(&r).chain(&s).all(|x| x.is_finite());
                if finite && *transform != next {
                    *transform = next;
                }
            }
            let Some(w) = pose.0.weights.get(i).filter(|w| !w.is_empty()) else { continue };
            if let Ok(mut m) = weights.get_mut(node) {
                let fits = m.weights().len() == w.len() && w.iter().all(|x| x.is_finite());
                if fits && m.weights() != w.as_slice() {
                    m.weights_mut().copy_from_slice(w);
                }
            }
        }
    }
}
