//! Tests of the spring-bone simulation (`spring`) against an independent f64 reference of the
//! VRMC_springBone-1.0 reference implementation, and of the reader (`spring_def`): the VRM 0.x →
//! 1.0 conversion and located errors for bad data.

use crate::rig::{PoseInput, RestLocal, Rig, RigNode, VrmVersion};
use crate::spring::{turn_to, SpringBones, SpringState, StepInput};
use crate::spring_def::read_springs;
use hadou_math::{Mat4, Vec3f};
use serde_json::{json, Value};

const DT: f64 = 1.0 / 60.0;

fn node(parent: Option<usize>, t: [f32; 3]) -> RigNode {
    RigNode { parent, rest: RestLocal::Trs { t, r: [0.0, 0.0, 0.0, 1.0], s: [1.0; 3] }, weights: Vec::new() }
}

/// A rig of `nodes` (parents listed before children) with the springs of `ext` (the file's
/// `extensions`).
fn rig(nodes: Vec<RigNode>, ext: Value) -> Rig {
    let order: Vec<usize> = (0..nodes.len()).collect();
    let raw = json!({ "extensions": ext });
    let springs = read_springs(&raw, &nodes, &order).expect("valid springs");
    Rig {
        nodes,
        order,
        skins: Vec::new(),
        parts: Vec::new(),
        clips: Vec::new(),
        expressions: Vec::new(),
        humanoid: Vec::new(),
        vrm: Some(VrmVersion::V1),
        base: Mat4::IDENTITY,
        groups: Vec::new(),
        group_count: 0,
        springs,
        look_at: None,
    }
}

fn no_wind(_: Vec3f) -> Vec3f {
    Vec3f::ZERO
}

/// Runs `steps` steps, calling `each` with the nodes' globals after each: the steps of a
/// character without a clip, from its still pose ([`Rig::still_pose`]), as a scene runs them.
fn run(
    rig: &Rig,
    steps: usize,
    wind: &dyn Fn(Vec3f) -> Vec3f,
    each: impl FnMut(usize, &[Mat4]),
) -> SpringState {
    let still = rig.still_pose();
    run_from(rig, steps, wind, still.as_ref(), each)
}

/// [`run`] from `still`, or (`None`) sampling the pose at each step as under a clip.
fn run_from(
    rig: &Rig,
    steps: usize,
    wind: &dyn Fn(Vec3f) -> Vec3f,
    still: Option<&crate::spring::StillPose>,
    mut each: impl FnMut(usize, &[Mat4]),
) -> SpringState {
    let input = StepInput { clip: None, clip_time: 0.0, wind, windy: true, still };
    let mut state = rig.spring_rest(0, &input).expect("springs");
    let sb: &SpringBones = rig.springs.as_ref().expect("springs");
    for k in 0..steps {
        rig.spring_step(&mut state, &input, DT as f32);
        let rot = state.rotations(sb);
        let g = rig.node_globals(&PoseInput { rotations: &rot, ..Default::default() });
        each(k, &g);
    }
    state
}

fn pos(m: &Mat4) -> [f64; 3] {
    [m.cols[3][0] as f64, m.cols[3][1] as f64, m.cols[3][2] as f64]
}

type V = [f64; 3];
fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn mul(a: V, s: f64) -> V {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn len(a: V) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn norm(a: V) -> V {
    mul(a, 1.0 / len(a))
}

/// The f64 reference: one chain of joints hanging from a fixed `head0`, each joint's tail the next
/// joint's head, with the spec's verlet step (no stiffness: the rest direction does not matter),
/// optional sphere colliders `(centre, radius)`.
struct Reference {
    tails: Vec<(V, V)>,
    lengths: Vec<f64>,
    drag: f64,
    gravity: V,
    colliders: Vec<(V, f64)>,
    hit: f64,
}

impl Reference {
    fn new(head0: V, tails: &[V], drag: f64, gravity: V) -> Self {
        let mut head = head0;
        let mut lengths = Vec::new();
        for t in tails {
            lengths.push(len(sub(*t, head)));
            head = *t;
        }
        Reference {
            tails: tails.iter().map(|t| (*t, *t)).collect(),
            lengths,
            drag,
            gravity,
            colliders: Vec::new(),
            hit: 0.0,
        }
    }

    fn step(&mut self, head0: V) {
        let mut head = head0;
        for (i, (prev, cur)) in self.tails.iter_mut().enumerate() {
            let l = self.lengths[i];
            let mut next = add(add(*cur, mul(sub(*cur, *prev), 1.0 - self.drag)), mul(self.gravity, DT));
            next = add(head, mul(norm(sub(next, head)), l));
            for &(c, r) in &self.colliders {
                let d = sub(next, c);
                if len(d) < r + self.hit {
                    next = add(c, mul(norm(d), r + self.hit));
                    next = add(head, mul(norm(sub(next, head)), l));
                }
            }
            *prev = *cur;
            *cur = next;
            head = next;
        }
    }
}

fn joint(node: usize, extra: Value) -> Value {
    let mut j = json!({ "node": node, "stiffness": 0.0, "dragForce": 0.0, "gravityPower": 1.0 });
    if let (Some(o), Some(e)) = (j.as_object_mut(), extra.as_object()) {
        o.extend(e.clone());
    }
    j
}

#[test]
fn a_pendulum_follows_the_reference_and_swings_with_the_verlet_period() {
    // Head at (0, 1, 0), a bone of length 1 resting 0.1 rad off the vertical: it swings about the
    // straight-down position. The step adds gravity·Δt each step, an acceleration of g/Δt, so the
    // small-angle period is 2π·√(L·Δt/g).
    let a0 = 0.1f64;
    let tail = [a0.sin() as f32, -a0.cos() as f32, 0.0];
    let nodes = vec![node(None, [0.0; 3]), node(Some(0), [0.0, 1.0, 0.0]), node(Some(1), tail)];
    let r = rig(
        nodes,
        json!({ "VRMC_springBone": { "springs": [{ "joints": [joint(1, json!({})), joint(2, json!({}))] }] } }),
    );
    let head = [0.0, 1.0, 0.0];
    let mut reference = Reference::new(head, &[add(head, [a0.sin(), -a0.cos(), 0.0])], 0.0, [0.0, -1.0, 0.0]);
    let mut crossings = Vec::new();
    let mut last_x = a0.sin();
    let mut worst = 0.0f64;
    run(&r, 600, &no_wind, |k, g| {
        reference.step(head);
        let p = pos(&g[2]);
        worst = worst.max(len(sub(p, reference.tails[0].1)));
        if (p[0] > 0.0) != (last_x > 0.0) {
            // Linear interpolation of the crossing time, in steps.
            crossings.push(k as f64 + last_x / (last_x - p[0]));
        }
        last_x = p[0];
        assert!((len(sub(p, head)) - 1.0).abs() < 1e-5, "the bone keeps its length");
    });
    assert!(worst < 1e-3, "the f32 simulation strays {worst} from the f64 reference");
    assert!(crossings.len() >= 4, "it swings: {crossings:?}");
    let period = 2.0 * (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64 * DT;
    let want = 2.0 * std::f64::consts::PI * (1.0 * DT / 1.0).sqrt();
    assert!((period / want - 1.0).abs() < 0.01, "period {period} s, small-angle {want} s");
}

#[test]
fn stiffness_against_gravity_rests_at_the_balance_angle() {
    // A horizontal bone pulled back to +x by stiffness s and down by gravity g rests where the
    // tangential parts cancel: s·sin θ = g·cos θ, θ = atan(g/s) below the horizontal.
    for (s, g) in [(2.0f64, 1.0f64), (1.0, 3.0), (5.0, 0.5)] {
        let nodes =
            vec![node(None, [0.0; 3]), node(Some(0), [0.0, 1.0, 0.0]), node(Some(1), [0.5, 0.0, 0.0])];
        let j = |n| joint(n, json!({ "stiffness": s, "gravityPower": g, "dragForce": 0.3 }));
        let r = rig(nodes, json!({ "VRMC_springBone": { "springs": [{ "joints": [j(1), j(2)] }] } }));
        let mut last = [0.0; 3];
        run(&r, 1500, &no_wind, |_, gl| last = pos(&gl[2]));
        let d = sub(last, [0.0, 1.0, 0.0]);
        let angle = (-d[1]).atan2(d[0]);
        assert!((angle - (g / s).atan()).abs() < 2e-3, "s {s} g {g}: {angle} rad, want {}", (g / s).atan());
    }
}

#[test]
fn a_chain_settles_under_gravity_as_the_reference_does() {
    // Three joints of 0.4 each, out along +x, falling and settling straight down.
    let nodes = vec![
        node(None, [0.0; 3]),
        node(Some(0), [0.0, 2.0, 0.0]),
        node(Some(1), [0.4, 0.0, 0.0]),
        node(Some(2), [0.4, 0.0, 0.0]),
        node(Some(3), [0.4, 0.0, 0.0]),
    ];
    let j = |n| joint(n, json!({ "gravityPower": 2.0, "dragForce": 0.2 }));
    let r = rig(nodes, json!({ "VRMC_springBone": { "springs": [{ "joints": [j(1), j(2), j(3), j(4)] }] } }));
    let head = [0.0, 2.0, 0.0];
    let mut reference =
        Reference::new(head, &[[0.4, 2.0, 0.0], [0.8, 2.0, 0.0], [1.2, 2.0, 0.0]], 0.2, [0.0, -2.0, 0.0]);
    let mut worst = 0.0f64;
    let mut last = Vec::new();
    run(&r, 1200, &no_wind, |_, g| {
        reference.step(head);
        for (i, n) in [2, 3, 4].into_iter().enumerate() {
            worst = worst.max(len(sub(pos(&g[n]), reference.tails[i].1)));
        }
        last = vec![pos(&g[2]), pos(&g[3]), pos(&g[4])];
    });
    assert!(worst < 2e-3, "the chain strays {worst} from the f64 reference");
    for (i, p) in last.iter().enumerate() {
        let want = [0.0, 2.0 - 0.4 * (i + 1) as f64, 0.0];
        assert!(len(sub(*p, want)) < 1e-3, "joint {i} rests at {p:?}, want {want:?}");
    }
}

#[test]
fn the_steps_from_a_still_pose_are_the_steps_that_sample_the_pose() {
    // A chain hanging from a turned, scaled parent: the pose worked out once for all steps and
    // the pose sampled at each step give the same motion (to rounding).
    let mut nodes = vec![node(None, [0.0; 3]), node(Some(0), [0.0, 2.0, 0.0])];
    nodes[1].rest = RestLocal::Trs { t: [0.0, 2.0, 0.0], r: [0.0, 0.3826834, 0.0, 0.9238795], s: [1.5; 3] };
    nodes.extend([
        node(Some(1), [0.4, 0.0, 0.0]),
        node(Some(2), [0.4, 0.0, 0.0]),
        node(Some(3), [0.4, 0.0, 0.0]),
    ]);
    let j = |n| joint(n, json!({ "gravityPower": 2.0, "dragForce": 0.2, "stiffness": 0.5 }));
    let r = rig(nodes, json!({ "VRMC_springBone": { "springs": [{ "joints": [j(1), j(2), j(3), j(4)] }] } }));
    let still = r.still_pose().expect("springs");
    let wind = |p: Vec3f| Vec3f::new(0.0, 0.0, 1.0 + p.x);
    let mut a = Vec::new();
    run_from(&r, 300, &wind, Some(&still), |_, g| a.push(g.to_vec()));
    let mut worst = 0.0f64;
    let mut moved = 0.0f64;
    run_from(&r, 300, &wind, None, |k, g| {
        for n in 2..5 {
            worst = worst.max(len(sub(pos(&g[n]), pos(&a[k][n]))));
            moved = moved.max(len(sub(pos(&g[n]), pos(&a[0][n]))));
        }
    });
    assert!(worst < 1e-4, "the two ways differ by {worst}");
    assert!(moved > 0.1, "the chain swings: {moved}");
}

#[test]
fn a_sphere_collider_pushes_the_tail_out() {
    // The bone would fall straight down through a sphere below-right of its head; the sphere
    // holds it out, as in the reference.
    let nodes = vec![node(None, [0.0; 3]), node(Some(0), [0.0, 1.0, 0.0]), node(Some(1), [1.0, 0.0, 0.0])];
    let j = |n| joint(n, json!({ "hitRadius": 0.05, "dragForce": 0.4 }));
    let ext = json!({ "VRMC_springBone": {
        "colliders": [{ "node": 0, "shape": { "sphere": { "offset": [0.3, 0.2, 0.0], "radius": 0.25 } } }],
        "colliderGroups": [{ "colliders": [0] }],
        "springs": [{ "joints": [j(1), j(2)], "colliderGroups": [0] }]
    } });
    let r = rig(nodes, ext);
    let head = [0.0, 1.0, 0.0];
    let mut reference = Reference::new(head, &[[1.0, 1.0, 0.0]], 0.4, [0.0, -1.0, 0.0]);
    reference.colliders.push(([0.3, 0.2, 0.0], 0.25));
    reference.hit = 0.05;
    let mut worst = 0.0f64;
    let mut last = [0.0; 3];
    run(&r, 900, &no_wind, |_, g| {
        reference.step(head);
        last = pos(&g[2]);
        worst = worst.max(len(sub(last, reference.tails[0].1)));
    });
    assert!(worst < 1e-3, "strays {worst} from the reference");
    assert!(last[0] > 0.3, "held out to the right: {last:?}");
    let gap = len(sub(last, [0.3, 0.2, 0.0]));
    // Pushed out to the sphere plus the hit radius, then back onto the bone's length (the spec's
    // order), which may leave it a little inside.
    assert!(gap > 0.28, "outside the sphere plus the hit radius: {gap}");
    // Without the collider it hangs straight down.
    let nodes = vec![node(None, [0.0; 3]), node(Some(0), [0.0, 1.0, 0.0]), node(Some(1), [1.0, 0.0, 0.0])];
    let free = rig(nodes, json!({ "VRMC_springBone": { "springs": [{ "joints": [j(1), j(2)] }] } }));
    run(&free, 900, &no_wind, |_, g| last = pos(&g[2]));
    assert!(last[0].abs() < 1e-2, "{last:?}");
}

#[test]
fn huge_forces_stay_finite_and_bounded() {
    let nodes = vec![
        node(None, [0.0; 3]),
        node(Some(0), [0.0, 1.0, 0.0]),
        node(Some(1), [1.0, 0.0, 0.0]),
        node(Some(2), [1.0, 0.0, 0.0]),
    ];
    let j = |n| joint(n, json!({ "gravityPower": 3.0e38, "stiffness": 3.0e38, "dragForce": 0.0 }));
    let r = rig(nodes, json!({ "VRMC_springBone": { "springs": [{ "joints": [j(1), j(2), j(3)] }] } }));
    let storms: [&dyn Fn(Vec3f) -> Vec3f; 3] = [
        &|p: Vec3f| Vec3f::new(f32::MAX, -f32::MAX, 1e30) + p,
        &|_| Vec3f::new(f32::INFINITY, 0.0, 0.0),
        &|_| Vec3f::new(f32::NAN, 1.0, 0.0),
    ];
    for wind in storms {
        run(&r, 200, wind, |_, g| {
            let (a, b) = (pos(&g[2]), pos(&g[3]));
            assert!(a.iter().chain(&b).all(|c| c.is_finite()), "{a:?} {b:?}");
            assert!((len(sub(a, [0.0, 1.0, 0.0])) - 1.0).abs() < 1e-3);
            assert!((len(sub(b, a)) - 1.0).abs() < 1e-3);
        });
    }
}

#[test]
fn turn_to_turns_one_direction_onto_another_of_any_length() {
    let cases = [
        (Vec3f::X, Vec3f::Y),
        (Vec3f::X, -Vec3f::X),
        (Vec3f::Z, Vec3f::Z),
        (Vec3f::Y, Vec3f::new(0.6, 0.0, 0.8)),
        (Vec3f::new(0.0, 0.6, -0.8), Vec3f::new(-0.48, 0.0, 0.64)),
    ];
    for (a, b) in cases {
        for scale in [1.0, 3.7, 0.02] {
            let q = turn_to(a, b * scale);
            let unit = (q.iter().map(|c| c * c).sum::<f32>() - 1.0).abs();
            assert!(unit < 1e-6, "{a:?} → {b:?}·{scale}: |q| − 1 = {unit}");
            let got = hadou_math::keyframes::quat_matrix(q).transform_vector(a);
            assert!((got - b * (1.0 / b.length())).length() < 1e-5, "{a:?} → {b:?}·{scale}: {got:?}");
        }
    }
    for nothing in [Vec3f::ZERO, Vec3f::new(f32::NAN, 0.0, 1.0), Vec3f::new(f32::INFINITY, 0.0, 0.0)] {
        assert_eq!(turn_to(Vec3f::X, nothing), [0.0, 0.0, 0.0, 1.0]);
    }
}

/// Nodes of a small 0.x-style hair: root, a hair bone with a chain of two below it and a branch.
fn hair_nodes(with_tail: bool) -> Vec<RigNode> {
    let mut n = vec![
        node(None, [0.0; 3]),
        node(Some(0), [0.0, 1.5, 0.0]),
        node(Some(1), [0.0, -0.2, 0.0]),
        node(Some(2), [0.0, -0.2, 0.0]),
    ];
    if with_tail {
        // The 1.0 twin names the 0.x end tail as a node: 0.07 below the last bone.
        n.push(node(Some(3), [0.0, -0.07, 0.0]));
    }
    n
}

#[test]
fn vrm_0x_secondary_animation_converts_to_its_1_0_twin() {
    let v0 = json!({ "VRM": { "secondaryAnimation": {
        "colliderGroups": [{ "node": 0, "colliders": [{ "offset": { "x": 0.1, "y": 1.2, "z": 0.3 }, "radius": 0.1 }] }],
        "boneGroups": [{ "bones": [1], "stiffiness": 0.8, "gravityPower": 0.3,
            "gravityDir": { "x": 0.0, "y": -1.0, "z": 0.0 }, "dragForce": 0.35, "hitRadius": 0.03,
            "center": -1, "colliderGroups": [0] }]
    } } });
    let j = |n| json!({ "node": n, "stiffness": 0.8, "gravityPower": 0.3, "gravityDir": [0.0, -1.0, 0.0], "dragForce": 0.35, "hitRadius": 0.03 });
    let v1 = json!({ "VRMC_springBone": {
        "colliders": [{ "node": 0, "shape": { "sphere": { "offset": [0.1, 1.2, -0.3], "radius": 0.1 } } }],
        "colliderGroups": [{ "colliders": [0] }],
        "springs": [{ "joints": [j(1), j(2), j(3), j(4)], "colliderGroups": [0] }]
    } });
    let a = rig(hair_nodes(false), v0).springs.expect("0.x springs");
    let b = rig(hair_nodes(true), v1).springs.expect("1.0 springs");
    assert_eq!(a.springs.len(), 1);
    assert_eq!(a.colliders, b.colliders);
    assert_eq!(a.springs[0].colliders, b.springs[0].colliders);
    assert_eq!(a.springs[0].center, None);
    assert_eq!(a.springs[0].joints.len(), 3);
    for (x, y) in a.springs[0].joints.iter().zip(&b.springs[0].joints) {
        assert_eq!(
            (x.node, x.stiffness, x.drag, x.gravity_power, x.hit_radius),
            (y.node, y.stiffness, y.drag, y.gravity_power, y.hit_radius)
        );
        assert!((x.gravity_dir - y.gravity_dir).length() < 1e-7);
        assert!((x.tail - y.tail).length() < 1e-6, "{:?} vs {:?}", x.tail, y.tail);
    }
    // A branch starts a chain of its own; a bone listed twice is a joint once.
    let mut nodes = hair_nodes(false);
    nodes.push(node(Some(1), [0.1, -0.2, 0.0]));
    let v0 = json!({ "VRM": { "secondaryAnimation": { "boneGroups": [{ "bones": [1, 2] }] } } });
    let sb = rig(nodes, v0).springs.expect("springs");
    let chains: Vec<Vec<usize>> =
        sb.springs.iter().map(|s| s.joints.iter().map(|j| j.node).collect()).collect();
    assert_eq!(chains, vec![vec![1, 2, 3], vec![4]]);
}

#[test]
fn vrm_0x_thumbs_take_their_1_0_names() {
    let raw = json!({ "extensions": { "VRM": { "humanoid": { "humanBones": [
        { "bone": "leftThumbProximal", "node": 0 }, { "bone": "leftThumbIntermediate", "node": 1 },
        { "bone": "leftThumbDistal", "node": 2 }, { "bone": "rightThumbProximal", "node": 3 },
        { "bone": "rightThumbIntermediate", "node": 4 }, { "bone": "rightThumbDistal", "node": 5 },
        { "bone": "leftIndexProximal", "node": 6 }
    ] } } } });
    let got = crate::gltf_vrm::read_humanoid(&raw, 7).expect("humanoid");
    let names: Vec<&str> = got.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "leftThumbMetacarpal",
            "leftThumbProximal",
            "leftThumbDistal",
            "rightThumbMetacarpal",
            "rightThumbProximal",
            "rightThumbDistal",
            "leftIndexProximal"
        ]
    );
    // VRM 1.0 names are kept as they are.
    let raw = json!({ "extensions": { "VRMC_vrm": { "humanoid": { "humanBones": { "leftThumbProximal": { "node": 1 } } } } } });
    assert_eq!(crate::gltf_vrm::read_humanoid(&raw, 2).expect("humanoid")[0].0, "leftThumbProximal");
}

#[test]
fn bad_spring_data_is_a_located_error() {
    let nodes = hair_nodes(true);
    let order: Vec<usize> = (0..nodes.len()).collect();
    let err = |ext: Value| read_springs(&json!({ "extensions": ext }), &nodes, &order).expect_err("rejected");
    let spring = |joints: Value, more: Value| {
        let mut s = json!({ "joints": joints });
        if let (Some(o), Some(m)) = (s.as_object_mut(), more.as_object()) {
            o.extend(m.clone());
        }
        json!({ "VRMC_springBone": { "springs": [s] } })
    };
    let cases: Vec<(Value, &str)> = vec![
        (
            spring(json!([{ "node": 1 }, { "node": 9 }]), json!({})),
            "VRMC_springBone.springs[0].joints[1].node is 9",
        ),
        (spring(json!([{ "node": 1 }, { "node": 3 }]), json!({})), "not a child of the joint before it"),
        (
            spring(json!([{ "node": 1 }, { "node": 2 }, { "node": 1 }]), json!({})),
            "joints[2].node is node 1, which is not a child",
        ),
        (
            spring(json!([{ "node": 1, "stiffness": -1.0 }, { "node": 2 }]), json!({})),
            "joints[0].stiffness is -1",
        ),
        (
            spring(json!([{ "node": 1, "dragForce": "x" }, { "node": 2 }]), json!({})),
            "joints[0].dragForce must be a number",
        ),
        (
            spring(json!([{ "node": 1, "gravityDir": [0.0, 0.0, 0.0] }, { "node": 2 }]), json!({})),
            "gravityDir must not be zero",
        ),
        (
            spring(json!([{ "node": 2 }, { "node": 3 }]), json!({ "center": 3 })),
            "springs[0].center is node 3, which is not an ancestor",
        ),
        (
            json!({ "VRMC_springBone": { "colliders": [{ "node": 0, "shape": { "sphere": { "radius": -0.5 } } }] } }),
            "VRMC_springBone.colliders[0].shape.sphere.radius is -0.5",
        ),
        (
            json!({ "VRMC_springBone": { "springs": [
                { "joints": [{ "node": 1 }, { "node": 2 }, { "node": 3 }] },
                { "joints": [{ "node": 2 }, { "node": 3 }] }
            ] } }),
            "node 2 is a joint twice",
        ),
        (
            json!({ "VRM": { "secondaryAnimation": { "colliderGroups": [{ "node": 0, "colliders": [{ "radius": -1.0 }] }] } } }),
            "VRM.secondaryAnimation.colliderGroups[0].colliders[0].radius is -1",
        ),
        (
            json!({ "VRM": { "secondaryAnimation": { "boneGroups": [{ "bones": [1], "stiffiness": -2.0 }] } } }),
            "VRM.secondaryAnimation.boneGroups[0].stiffiness is -2",
        ),
    ];
    for (ext, want) in cases {
        let e = err(ext);
        assert!(e.contains(want), "{e:?} should contain {want:?}");
    }
    // Past the joint limit: a chain of MAX + 2 nodes.
    let n = crate::spring::MAX_SPRING_JOINTS + 2;
    let mut long = vec![node(None, [0.0; 3])];
    for i in 1..n {
        long.push(node(Some(i - 1), [0.0, -0.01, 0.0]));
    }
    let order: Vec<usize> = (0..n).collect();
    let joints: Vec<Value> = (0..n).map(|i| json!({ "node": i })).collect();
    let e = read_springs(
        &json!({ "extensions": { "VRMC_springBone": { "springs": [{ "joints": joints }] } } }),
        &long,
        &order,
    )
    .expect_err("too many joints");
    assert!(e.contains("over the limit of 4096"), "{e}");
    let e = read_springs(
        &json!({ "extensions": { "VRM": { "secondaryAnimation": { "boneGroups": [{ "bones": [0] }] } } } }),
        &long,
        &order,
    )
    .expect_err("too many joints");
    assert!(e.contains("past the limit of 4096"), "{e}");
}

mod look {
    use crate::look_at::{LookAt, LookAtKind, RangeMap};
    use hadou_math::keyframes::quat_matrix;
    use hadou_math::{Mat4, Vec3f};

    fn look(kind: LookAtKind, v0: bool) -> LookAt {
        LookAt {
            head: 0,
            offset: Vec3f::new(0.0, 0.1, 0.0),
            kind,
            inner: RangeMap { input_max: 90.0, output_scale: 8.0 },
            outer: RangeMap { input_max: 60.0, output_scale: 12.0 },
            down: RangeMap { input_max: 90.0, output_scale: 6.0 },
            up: RangeMap { input_max: 30.0, output_scale: 10.0 },
            v0,
        }
    }

    /// The direction eye rotation `q` turns the eye's forward (`+z`, or `−z` for VRM 0.x) to, as
    /// yaw and pitch in degrees (in the +z-facing frame).
    fn turned(q: [f32; 4], v0: bool) -> (f32, f32) {
        let f = if v0 { -Vec3f::Z } else { Vec3f::Z };
        let mut d = quat_matrix(q).transform_vector(f);
        if v0 {
            d = Vec3f::new(-d.x, d.y, -d.z);
        }
        (d.x.atan2(d.z).to_degrees(), d.y.atan2(d.x.hypot(d.z)).to_degrees())
    }

    #[test]
    fn eye_bones_turn_by_the_range_maps() {
        let head = [Mat4::translation(Vec3f::new(0.0, 1.5, 0.0))];
        let rest = |_| [0.0, 0.0, 0.0, 1.0];
        for v0 in [false, true] {
            let l = look(LookAtKind::Bone { left: Some(1), right: Some(2) }, v0);
            let s = if v0 { -1.0 } else { 1.0 };
            // 45° to the character's left (+x, or −x in a VRM 0.x file), level with the offset.
            let g = l.gaze(&head, Vec3f::new(s, 1.6, s), rest);
            assert_eq!(g.rotations.len(), 2);
            let (yl, pl) = turned(g.rotations[0].1, v0);
            let (yr, _) = turned(g.rotations[1].1, v0);
            assert!((yl - 9.0).abs() < 1e-3 && pl.abs() < 1e-3, "left eye, outer map: {yl} {pl}");
            assert!((yr - 4.0).abs() < 1e-3, "right eye, inner map: {yr}");
            // 45° to its right: the right eye turns outwards, the left inwards.
            let g = l.gaze(&head, Vec3f::new(-s, 1.6, s), rest);
            let ((yl, _), (yr, _)) = (turned(g.rotations[0].1, v0), turned(g.rotations[1].1, v0));
            assert!((yl + 4.0).abs() < 1e-3 && (yr + 9.0).abs() < 1e-3, "{yl} {yr}");
            // Up 45°: past the up map's 30°, its full 10°; down 45°: 45/90 · 6 = 3°.
            let g = l.gaze(&head, Vec3f::new(0.0, 2.6, s), rest);
            let (_, p) = turned(g.rotations[0].1, v0);
            assert!((p - 10.0).abs() < 1e-3, "up: {p}");
            let g = l.gaze(&head, Vec3f::new(0.0, 0.6, s), rest);
            let (_, p) = turned(g.rotations[0].1, v0);
            assert!((p + 3.0).abs() < 1e-3, "down: {p}");
        }
    }

    #[test]
    fn look_expressions_take_the_maps_as_weights() {
        let head = [Mat4::IDENTITY];
        let mut l = look(LookAtKind::Expression, false);
        l.outer = RangeMap { input_max: 90.0, output_scale: 1.0 };
        l.up = RangeMap { input_max: 90.0, output_scale: 1.0 };
        let g = l.gaze(&head, Vec3f::new(-1.0, 0.1, 1.0), |_| [0.0, 0.0, 0.0, 1.0]);
        let w = |n: &str| g.expressions.iter().find(|e| e.0 == n).map_or(-1.0, |e| e.1);
        assert!((w("lookRight") - 0.5).abs() < 1e-5 && w("lookLeft") == 0.0, "{g:?}");
        assert!(w("lookUp") == 0.0 && w("lookDown") == 0.0, "{g:?}");
        let g = l.gaze(&head, Vec3f::new(0.0, 1.1, 1.0), |_| [0.0, 0.0, 0.0, 1.0]);
        let w = |n: &str| g.expressions.iter().find(|e| e.0 == n).map_or(-1.0, |e| e.1);
        assert!((w("lookUp") - 0.5).abs() < 1e-5, "{g:?}");
        // A target at the eye gives no gaze; a NaN one neither.
        assert_eq!(l.gaze(&head, Vec3f::new(0.0, 0.1, 0.0), |_| [0.0; 4]).expressions.len(), 0);
        assert_eq!(l.gaze(&head, Vec3f::new(f32::NAN, 0.1, 0.0), |_| [0.0; 4]).expressions.len(), 0);
    }
}

#[test]
fn a_center_carries_the_tails_with_it() {
    use crate::rig::{Channel, ChannelPath, Clip};
    // The root slides 1 unit along +x in 0.5 s. A free chain (no stiffness, no gravity) lags
    // behind it; with `center` = the root, the tails are kept in the root's space and the chain
    // moves with it, unbent.
    let clip = Clip {
        name: "slide".into(),
        duration: 0.5,
        channels: vec![Channel {
            node: 0,
            path: ChannelPath::Translation,
            sampling: hadou_math::keyframes::Sampling::Linear,
            times: vec![0.0, 0.5],
            values: vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            width: 3,
        }],
    };
    let bend = |center: bool| {
        let nodes =
            vec![node(None, [0.0; 3]), node(Some(0), [0.0, 1.0, 0.0]), node(Some(1), [0.0, -0.5, 0.0])];
        let j = |n| joint(n, json!({ "gravityPower": 0.0, "dragForce": 0.1 }));
        let mut spring = json!({ "joints": [j(1), j(2)] });
        if center {
            spring["center"] = json!(0);
        }
        let r = rig(nodes, json!({ "VRMC_springBone": { "springs": [spring] } }));
        let wind = no_wind;
        let input = |k: u64| StepInput {
            clip: Some(&clip),
            clip_time: (k as f64 * DT) as f32,
            wind: &wind,
            windy: true,
            still: None,
        };
        let mut state = r.spring_rest(0, &input(0)).expect("springs");
        let sb = r.springs.as_ref().expect("springs");
        let mut worst = 0.0f64;
        for k in 1..=30u64 {
            r.spring_step(&mut state, &input(k), DT as f32);
            let rot = state.rotations(sb);
            let g = r.node_globals(&PoseInput {
                clip: Some(&clip),
                time: (k as f64 * DT) as f32,
                rotations: &rot,
                ..Default::default()
            });
            let d = sub(pos(&g[2]), pos(&g[1]));
            worst = worst.max(d[0].abs());
        }
        worst
    };
    assert!(bend(false) > 0.05, "without a center the chain lags: {}", bend(false));
    assert!(bend(true) < 1e-5, "with the root as center it moves along unbent: {}", bend(true));
}
