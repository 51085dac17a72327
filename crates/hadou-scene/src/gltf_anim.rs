//! The animation clips of a glTF file (glTF 2.0 §3.11): every channel's keys read, checked and
//! turned into a [`Clip`] of the file's [`crate::rig::Rig`].
//!
//! The file is untrusted: every sampler's input must be a float scalar accessor with finite,
//! strictly increasing times; outputs must have the type the channel's path requires (float
//! VEC3 for translation and scale; float or normalised integer VEC4 for rotation; float or
//! normalised integer SCALAR for weights), finite values, and exactly as many elements as the
//! keys need (`keys × 3` for CUBICSPLINE, `× targets` for weights). The floats of all clips
//! together count against [`MAX_ANIMATION_VALUES`].

use crate::gltf_accessor::check_accessor;
use crate::rig::{Channel, ChannelPath, Clip, RestLocal, RigNode};
use gltf::accessor::{DataType, Dimensions};
use gltf::animation::{util::ReadOutputs, Interpolation, Property};
use hadou_math::keyframes::Sampling;

/// Most keyframe floats (times and values) of one glTF file's clips together: 2²⁴ (64 MiB).
pub const MAX_ANIMATION_VALUES: usize = 1 << 24;

/// Reads every animation of `gltf` against the rig's `nodes`. Names: the animation's `name`, or
/// `animation N`; a name used twice gets a warning (the first clip of that name is the one a
/// scene can choose).
pub(crate) fn read_clips(
    gltf: &gltf::Gltf,
    raw: &serde_json::Value,
    buffers: &[Vec<u8>],
    nodes: &[RigNode],
    warnings: &mut Vec<String>,
) -> Result<Vec<Clip>, String> {
    let mut clips: Vec<Clip> = Vec::new();
    let mut budget = MAX_ANIMATION_VALUES;
    for anim in gltf.animations() {
        let name = raw
            .get("animations")
            .and_then(|a| a.get(anim.index()))
            .and_then(|a| a.get("name"))
            .and_then(serde_json::Value::as_str)
            .map_or_else(|| format!("animation {}", anim.index()), str::to_string);
        let what = format!("animation {} (\"{}\")", anim.index(), crate::error::escape_controls(&name));
        let mut channels = Vec::new();
        let mut duration = 0.0f32;
        for ch in anim.channels() {
            let c = read_channel(&ch, buffers, nodes, &mut budget)
                .map_err(|e| format!("{what} channel {}: {e}", ch.index()))?;
            duration = duration.max(*c.times.last().unwrap_or(&0.0));
            channels.push(c);
        }
        if clips.iter().any(|c| c.name == name) {
            warnings.push(format!(
                "{what}: another animation has the same name; a scene's `animation = \"{name}\"` plays the first"
            ));
        }
        clips.push(Clip { name, duration, channels });
    }
    Ok(clips)
}

fn read_channel(
    ch: &gltf::animation::Channel<'_>,
    buffers: &[Vec<u8>],
    nodes: &[RigNode],
    budget: &mut usize,
) -> Result<Channel, String> {
    let node = ch.target().node().index();
    let rig_node = nodes.get(node).ok_or_else(|| format!("targets node {node}, which does not exist"))?;
    let sampler = ch.sampler();
    let path = match ch.target().property() {
        Property::Translation => ChannelPath::Translation,
        Property::Rotation => ChannelPath::Rotation,
        Property::Scale => ChannelPath::Scale,
        Property::MorphTargetWeights => ChannelPath::Weights,
    };
    if path != ChannelPath::Weights && matches!(rig_node.rest, RestLocal::Matrix(_)) {
        return Err(format!(
            "animates node {node}, which has a `matrix` (an animated node must give translation, rotation \
             and scale instead)"
        ));
    }
    let sampling = match sampler.interpolation() {
        Interpolation::Step => Sampling::Step,
        Interpolation::Linear => Sampling::Linear,
        Interpolation::CubicSpline => Sampling::CubicSpline,
    };
    let width = match path {
        ChannelPath::Translation | ChannelPath::Scale => 3,
        ChannelPath::Rotation => 4,
        ChannelPath::Expression => 1,
        ChannelPath::Weights => {
            let n = rig_node.weights.len();
            if n == 0 {
                return Err(format!(
                    "animates the morph weights of node {node}, whose mesh has no morph targets"
                ));
            }
            n
        }
    };
    let input = sampler.input();
    check_accessor(&input, &[Dimensions::Scalar], &[DataType::F32], buffers)
        .map_err(|e| format!("input: {e}"))?;
    let output = sampler.output();
    let norm = [DataType::F32, DataType::I8, DataType::U8, DataType::I16, DataType::U16];
    let (dims, types): (&[Dimensions], &[DataType]) = match path {
        ChannelPath::Translation | ChannelPath::Scale => (&[Dimensions::Vec3], &[DataType::F32]),
        ChannelPath::Rotation => (&[Dimensions::Vec4], &norm),
        ChannelPath::Weights | ChannelPath::Expression => (&[Dimensions::Scalar], &norm),
    };
    check_accessor(&output, dims, types, buffers).map_err(|e| format!("output: {e}"))?;
    let keys = input.count();
    let per_key = if sampling == Sampling::CubicSpline { 3 } else { 1 }
        * if path == ChannelPath::Weights { width } else { 1 };
    let want = keys.checked_mul(per_key).ok_or("too many keys")?;
    if output.count() != want {
        return Err(format!(
            "its output accessor {} has {} elements, but {keys} keys{} need {want}",
            output.index(),
            output.count(),
            match (sampling, path) {
                (Sampling::CubicSpline, ChannelPath::Weights) =>
                    format!(" × 3 (in-tangent, value, out-tangent) × {width} morph targets"),
                (Sampling::CubicSpline, _) => " × 3 (in-tangent, value, out-tangent)".to_string(),
                (_, ChannelPath::Weights) => format!(" × {width} morph targets"),
                _ => String::new(),
            }
        ));
    }
    let floats = keys + want * if path == ChannelPath::Weights { 1 } else { width };
    if floats > *budget {
        return Err(format!(
            "the file's clips hold more than {MAX_ANIMATION_VALUES} keyframe numbers together (the limit)"
        ));
    }
    *budget -= floats;
    let get = |b: gltf::Buffer<'_>| buffers.get(b.index()).map(|d| d.as_slice());
    let reader = ch.reader(get);
    let times: Vec<f32> = reader.read_inputs().ok_or("its input cannot be read")?.collect();
    if let Some(k) = times.iter().position(|t| !t.is_finite()) {
        return Err(format!("key time {k} is not a finite number"));
    }
    if let Some(k) = times.windows(2).position(|w| w[1] <= w[0]) {
        return Err(format!(
            "key times must increase strictly, but key {} ({}) does not come after key {k} ({})",
            k + 1,
            times[k + 1],
            times[k]
        ));
    }
    if times.first().is_some_and(|t| *t < 0.0) {
        return Err(format!("key times must not be negative (the first is {})", times[0]));
    }
    let values: Vec<f32> = match reader.read_outputs().ok_or("its output cannot be read")? {
        ReadOutputs::Translations(it) => it.flatten().collect(),
        ReadOutputs::Scales(it) => it.flatten().collect(),
        ReadOutputs::Rotations(r) => r.into_f32().flatten().collect(),
        ReadOutputs::MorphTargetWeights(w) => w.into_f32().collect(),
    };
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!("output value {k} is not a finite number"));
    }
    // Translations and scales within the scene's coordinate bound, so posed matrices stay finite.
    let values = match path {
        ChannelPath::Translation | ChannelPath::Scale => {
            values.into_iter().map(|v| v.clamp(-crate::limits::COORD_MAX, crate::limits::COORD_MAX)).collect()
        }
        _ => values,
    };
    if values.len() != want * if path == ChannelPath::Weights { 1 } else { width } {
        return Err("its output could not be read whole".into());
    }
    Ok(Channel { node, path, sampling, times, values, width })
}
