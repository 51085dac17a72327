// The traced resolve of the `[area_light]` (twin of hadou-cpu's traced.rs; hadou's own, issue 43):
// every visible point's visibility is the share of the lamp it sees, from the lamp's samples
// against the casters' triangles found through the flattened bounding volume hierarchy
// (hadou_math::soft::Bvh, the same bytes as the CPU's). Per pixel: the receiver moved off its
// surface (TRACE_BIAS), the lamp as seen from it (lamp_frame), the stackless walk of the nodes whose
// ball meets the capsule between the receiver and the lamp's ball and whose box's projection meets
// the lamp (capsule_hits, box_may_hide), each triangle not leaving both on one side (one_side)
// setting the samples it hides in the pixel's mask (occlude), the walk ending once every sample is
// hidden; the visibility is the mask's weighted share of clear samples (mask_visibility). The
// samples depend only on the pixel's global coordinates (pixel_offset). Prepended by common.wgsl
// and soft_trace.wgsl (the per-pixel work).
//
// Whole-image buffers (passes/soft.rs `SoftTargets`): soft_world[i] = (world point as f32 bits,
// class), soft_normal[i] = (unit normal as f32 bits, …), visibility[i] (written here).

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(0) @binding(1) var<uniform> traced: TracedUniforms;
@group(0) @binding(2) var<storage, read> soft_world: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read> soft_normal: array<vec4<u32>>;
@group(0) @binding(4) var<storage, read_write> visibility: array<f32>;
@group(0) @binding(5) var<storage, read> nodes: array<BvhNode>;
@group(0) @binding(6) var<storage, read> tris: array<BvhTri>;

// hadou_math::soft::Class::None.
const CLASS_NONE: u32 = 0u;

// Per image pixel of the sample frame, once every tile's points are gathered (cs_points): the
// traced visibility of its visible point, 0 where nothing is drawn.
@compute @workgroup_size(8, 8, 1)
fn cs_traced(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= frame.image_size.x || id.y >= frame.image_size.y) {
        return;
    }
    let gi = id.y * frame.image_size.x + id.x;
    let w = soft_world[gi];
    if (w.w == CLASS_NONE) {
        visibility[gi] = 0.0;
        return;
    }
    let world = bitcast<vec3<f32>>(w.xyz);
    let n = bitcast<vec3<f32>>(soft_normal[gi].xyz);
    let r = world + n * (TRACE_BIAS * length3(world - frame.area_position));
    visibility[gi] = pixel_visibility(r, id.x, id.y);
}
