//! The spring bones of a VRM file as `spring_def` reads them and `spring` steps them: springs
//! (chains of joints with their parameters), colliders and their groups (flattened per spring).

use hadou_math::{Mat4, Vec3f};

/// A spring-bone collider's shape, in its node's space (VRMC_springBone-1.0 `shape`).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum ColliderShape {
    /// A sphere at `offset`.
    Sphere { offset: Vec3f, radius: f32 },
    /// A capsule from `offset` to `tail`.
    Capsule { offset: Vec3f, tail: Vec3f, radius: f32 },
}

/// A collider attached to a node.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Collider {
    pub node: usize,
    pub shape: ColliderShape,
}

/// One joint of a spring: a node that turns so that its tail follows the simulation.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Joint {
    pub node: usize,
    /// The tail's rest position in the node's local space (the next joint's rest translation, or a
    /// VRM 0.x leaf's 7 cm tail).
    pub tail: Vec3f,
    pub hit_radius: f32,
    pub stiffness: f32,
    pub gravity_power: f32,
    /// Unit, in the file's space.
    pub gravity_dir: Vec3f,
    /// In `[0, 1]`.
    pub drag: f32,
    /// The node's rest rotation, of unit length (a joint turns from it); the identity for a node
    /// with a matrix.
    pub rest: [f32; 4],
    /// `tail` of unit length; `None` for a zero tail or a node with a matrix (such a joint stays
    /// at rest).
    pub axis: Option<Vec3f>,
}

/// A chain of joints, each the parent of the next.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Spring {
    pub joints: Vec<Joint>,
    /// The colliders of its collider groups (indices into [`SpringBones::colliders`]).
    pub colliders: Vec<usize>,
    /// The node whose space the tails are kept in.
    pub center: Option<usize>,
}

/// The spring bones of a VRM file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpringBones {
    pub(crate) springs: Vec<Spring>,
    pub(crate) colliders: Vec<Collider>,
    /// Per node, whether its global matrix depends on a joint's turn (a joint or below one); the
    /// others' are worked out once a step.
    pub(crate) moving: Vec<bool>,
}

impl SpringBones {
    /// The number of joints that turn (a 1.0 spring's last joint is only a tail).
    pub fn joint_count(&self) -> usize {
        self.springs.iter().map(|s| s.joints.len()).sum()
    }

    /// The number of colliders.
    pub fn collider_count(&self) -> usize {
        self.colliders.len()
    }
}

/// The inverse of an affine matrix (its 3×3 block inverted in f64); the identity for a singular
/// one.
pub(crate) fn affine_inverse(m: &Mat4) -> Mat4 {
    // `normal_matrix` is the block's inverse transposed.
    let inv_t = m.normal_matrix();
    let mut inv = inv_t.transpose();
    inv.cols[3] = [0.0, 0.0, 0.0, 1.0];
    for r in 0..3 {
        inv.cols[r][3] = 0.0;
    }
    let t = Vec3f::new(m.cols[3][0], m.cols[3][1], m.cols[3][2]);
    let it = inv.transform_vector(t);
    inv.cols[3] = [-it.x, -it.y, -it.z, 1.0];
    inv
}

impl SpringBones {
    /// Whether every spring hangs from, centres on and collides with nodes that no joint moves:
    /// then each spring's motion depends on the animation and the wind alone, and springs can be
    /// stepped apart from each other (on several threads) with the same result.
    pub(crate) fn independent(&self, parent_of: impl Fn(usize) -> Option<usize>) -> bool {
        let still = |n: usize| !self.moving.get(n).copied().unwrap_or(true);
        self.springs.iter().all(|s| {
            s.joints.first().is_none_or(|j| parent_of(j.node).is_none_or(still))
                && s.center.is_none_or(still)
                && s.colliders.iter().all(|&c| self.colliders.get(c).is_some_and(|c| still(c.node)))
        })
    }

    /// The springs in at most `parts` runs of about equal joint counts: each run's springs and
    /// joints (indices into the joints of all springs in order).
    pub(crate) fn runs(&self, parts: usize) -> Vec<(std::ops::Range<usize>, std::ops::Range<usize>)> {
        let total = self.joint_count();
        let parts = parts.clamp(1, self.springs.len().max(1));
        let mut out = Vec::new();
        let (mut s0, mut j0, mut j) = (0, 0, 0);
        for (i, s) in self.springs.iter().enumerate() {
            j += s.joints.len();
            if j * parts >= total * (out.len() + 1) && out.len() + 1 < parts {
                out.push((s0..i + 1, j0..j));
                (s0, j0) = (i + 1, j);
            }
        }
        out.push((s0..self.springs.len(), j0..j));
        out
    }
}
