//! WGSL sources and how they are composed into shader modules.
//!
//! WGSL has no `#include`; each module is the concatenation of shared files and one pass file:
//! - raster module: `common.wgsl` + `raster.wgsl` (opaque geometry);
//! - wave module: `common.wgsl` + `energy.wgsl` + `curve.wgsl` + `wave_energy.wgsl` +
//!   `shading_bindings.wgsl` + `shading.wgsl` + `shadow_bindings.wgsl` + `shadow_lookup.wgsl` +
//!   `wave.wgsl` (surface shading with the waves as
//!   lights, hard shadows, energy integration, colour mapping); the wave samples module is the
//!   wave module + `wave_samples.wgsl` (the same pixel resolved from its anti-aliasing samples);
//! - wave overlay module: `common.wgsl` + `energy.wgsl` + `curve.wgsl` + `wave_energy.wgsl` +
//!   `wave_overlay.wgsl` (the waves' light into a caller's colour target against its depth);
//! - shadow module: `common.wgsl` + `shadow_raster.wgsl` (the plane-shadow pass and the shadow
//!   maps);
//! - soft-shadow modules: `common.wgsl` + `soft_map.wgsl` (the `[area_light]`'s maps) and
//!   `common.wgsl` + `soft.wgsl` (classes, penumbra resolve, gather);
//! - edge module: `common.wgsl` + `edges.wgsl` (outlines closed where objects meet);
//! - present module: `common.wgsl` + `present.wgsl` (a tile's colour into the window texture of
//!   [`crate::GpuBackend::render_to_texture`]).
//!
//! A wave, wave samples or wave overlay module is composed per frame with only the source
//! [`FEATURES`] the frame uses ([`compose_with`]: `// #if NAME` … `// #endif` lines in the WGSL),
//! so a frame without attenuation or 8-bit output compiles none of that code.
//!
//! A unit test parses and validates every composed module (every feature combination) with naga
//! (no adapter needed) and checks that the struct layouts naga computes equal the Rust ones in
//! [`crate::layout`].

/// Shared structs, pixel rays, shading and colour mapping.
pub const COMMON: &str = include_str!("shaders/common.wgsl");
/// WGSL twins of `hadou_math::energy`.
pub const ENERGY: &str = include_str!("shaders/energy.wgsl");
/// WGSL twins of `hadou_math::curve` (shape evaluation, default and Simpson integrators).
pub const CURVE: &str = include_str!("shaders/curve.wgsl");
/// WGSL twins of `hadou_math::toon` and `hadou-cpu`'s surface shading. It reads the bindings of
/// [`SHADING_BINDINGS`] (or a composer's own with the same names: `lights`, `shading_data`,
/// `polyline_point`) and a `frame` with the light, the wave count and `any_glow`.
pub const SHADING: &str = include_str!("shaders/shading.wgsl");
/// The wave pass's bindings of [`SHADING`] (materials, lights, shading data) and its
/// `polyline_point`.
pub const SHADING_BINDINGS: &str = include_str!("shaders/shading_bindings.wgsl");
/// The opaque geometry pass.
pub const RASTER: &str = include_str!("shaders/raster.wgsl");
/// The wave pass.
pub const WAVE: &str = include_str!("shaders/wave.wgsl");
/// The wave pass of a frame with several samples per pixel (entry point `cs_samples`).
pub const WAVE_SAMPLES: &str = include_str!("shaders/wave_samples.wgsl");
/// The waves' light on one pixel (shared by the wave pass and the wave overlay).
pub const WAVE_ENERGY: &str = include_str!("shaders/wave_energy.wgsl");
/// The wave overlay: the waves' light into a caller's colour target against its depth buffer.
pub const WAVE_OVERLAY: &str = include_str!("shaders/wave_overlay.wgsl");
/// The wave pass's hard-shadow lookups. They read `shadow_maps`, `shadow_word` and
/// `plane_cast_at` of [`SHADOW_BINDINGS`] (or a composer's own with the same names) and a `frame`
/// with the cast counts and offsets.
pub const SHADOW_LOOKUP: &str = include_str!("shaders/shadow_lookup.wgsl");
/// The wave pass's bindings of [`SHADOW_LOOKUP`] (the plane-shadow target, the shadow maps) and
/// how it reads its records.
pub const SHADOW_BINDINGS: &str = include_str!("shaders/shadow_bindings.wgsl");
/// The plane-shadow pass and the shadow-map pass.
pub const SHADOW_RASTER: &str = include_str!("shaders/shadow_raster.wgsl");
/// The `[area_light]`'s perspective shadow maps (render pass).
pub const SOFT_MAP: &str = include_str!("shaders/soft_map.wgsl");
/// The soft shadows' classification and penumbra resolve (compute passes).
pub const SOFT: &str = include_str!("shaders/soft.wgsl");
/// The traced resolve's per-pixel work (`occlude`, the hierarchy's tests).
pub const SOFT_TRACE: &str = include_str!("shaders/soft_trace.wgsl");
/// The traced resolve of the `[area_light]` (`cs_traced`).
pub const SOFT_TRACED: &str = include_str!("shaders/soft_traced.wgsl");
/// The edge pass: outlines closed where objects meet (render pass over the G-buffer).
pub const EDGES: &str = include_str!("shaders/edges.wgsl");
/// The present pass: a tile's final colour into the full-frame sRGB texture (render pass).
pub const PRESENT: &str = include_str!("shaders/present.wgsl");
/// The glare chain: prefilter, downsample, upsample, streak and composite (passes/bloom.rs).
pub const BLOOM: &str = include_str!("shaders/bloom.wgsl");

/// Every `.wgsl` file in `src/shaders/`, by file name.
pub const FILES: &[(&str, &str)] = &[
    ("bloom.wgsl", BLOOM),
    ("common.wgsl", COMMON),
    ("curve.wgsl", CURVE),
    ("edges.wgsl", EDGES),
    ("energy.wgsl", ENERGY),
    ("present.wgsl", PRESENT),
    ("raster.wgsl", RASTER),
    ("shading.wgsl", SHADING),
    ("shading_bindings.wgsl", SHADING_BINDINGS),
    ("shadow_bindings.wgsl", SHADOW_BINDINGS),
    ("shadow_lookup.wgsl", SHADOW_LOOKUP),
    ("shadow_raster.wgsl", SHADOW_RASTER),
    ("soft.wgsl", SOFT),
    ("soft_map.wgsl", SOFT_MAP),
    ("soft_trace.wgsl", SOFT_TRACE),
    ("soft_traced.wgsl", SOFT_TRACED),
    ("wave.wgsl", WAVE),
    ("wave_energy.wgsl", WAVE_ENERGY),
    ("wave_samples.wgsl", WAVE_SAMPLES),
    ("wave_overlay.wgsl", WAVE_OVERLAY),
];

/// The parts of the raster module, in order.
pub const RASTER_PARTS: &[&str] = &[COMMON, RASTER];
/// The parts of the wave module, in order.
pub const WAVE_PARTS: &[&str] =
    &[COMMON, ENERGY, CURVE, WAVE_ENERGY, SHADING_BINDINGS, SHADING, SHADOW_BINDINGS, SHADOW_LOOKUP, WAVE];
/// The parts of the wave samples module (anti-aliased frames), in order.
pub const WAVE_SAMPLES_PARTS: &[&str] = &[
    COMMON,
    ENERGY,
    CURVE,
    WAVE_ENERGY,
    SHADING_BINDINGS,
    SHADING,
    SHADOW_BINDINGS,
    SHADOW_LOOKUP,
    WAVE,
    WAVE_SAMPLES,
];
/// The parts of the wave overlay module, in order.
pub const WAVE_OVERLAY_PARTS: &[&str] = &[COMMON, ENERGY, CURVE, WAVE_ENERGY, WAVE_OVERLAY];
/// The parts of the shadow module, in order.
pub const SHADOW_PARTS: &[&str] = &[COMMON, SHADOW_RASTER];
/// The parts of the soft-shadow map module, in order.
pub const SOFT_MAP_PARTS: &[&str] = &[COMMON, SOFT_MAP];
/// The parts of the soft-shadow compute module, in order.
pub const SOFT_PARTS: &[&str] = &[COMMON, SOFT];
/// The traced resolve's module.
pub const SOFT_TRACED_PARTS: &[&str] = &[COMMON, SOFT_TRACE, SOFT_TRACED];
/// The parts of the present module, in order.
pub const PRESENT_PARTS: &[&str] = &[COMMON, PRESENT];
/// The parts of the glare module, in order.
pub const BLOOM_PARTS: &[&str] = &[COMMON, BLOOM];
/// The parts of the edge module, in order.
pub const EDGES_PARTS: &[&str] = &[COMMON, EDGES];

/// Concatenates module parts.
pub fn compose(parts: &[&str]) -> String {
    compose_with(parts, FEATURES)
}

/// The source features a composed module may leave out: the lines between `// #if NAME` and
/// `// #else` (or `// #endif`) are kept only when NAME is on, those between `// #else` and
/// `// #endif` only when it is off. Unlike a pipeline-overridable constant, whose dead branch
/// stays in the module for the driver to remove (and a software adapter may still run under an
/// execution mask), a feature that is off is not in the module at all.
/// - `ATTENUATION`: the distance attenuation `(1 − u)^j` (002 eq. 3.23): energy.wgsl's graded
///   march and curve.wgsl's attenuated pieces; without it every wave is integrated as `j = 0`.
/// - `SRGB8`: wave.wgsl writes each pixel as one word of 8-bit sRGB codes (a PNG's bytes, with
///   binding 13's thresholds) instead of the float colour, energy and depth.
pub const FEATURES: &[&str] = &["ATTENUATION", "SRGB8"];

/// [`compose`] with only the [`FEATURES`] in `on` (see there). Removed lines are left empty, so a
/// line number in a compiler's message is the same as in the full composition.
pub fn compose_with(parts: &[&str], on: &[&str]) -> String {
    let source = parts.join("\n");
    let mut out = String::with_capacity(source.len());
    // Per open `#if`: whether its enclosing region is kept, and whether its own branch is.
    let mut open: Vec<(bool, bool)> = Vec::new();
    let mut keep = true;
    for line in source.lines() {
        let directive = line.trim_start();
        if let Some(name) = directive.strip_prefix("// #if ") {
            let lit = on.contains(&name.trim());
            open.push((keep, lit));
            keep = keep && lit;
        } else if directive == "// #else" {
            if let Some(top) = open.last_mut() {
                top.1 = !top.1;
                keep = top.0 && top.1;
            }
        } else if directive == "// #endif" {
            if let Some((outer, _)) = open.pop() {
                keep = outer;
            }
        } else if keep {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// Every `// #if`, `// #else` and `// #endif` line of `source` balanced, and every `#if` naming one
/// of [`FEATURES`]: `Err` names the first line that is not.
pub fn check_directives(source: &str) -> Result<(), String> {
    let mut open: Vec<(usize, bool)> = Vec::new();
    for (i, line) in source.lines().enumerate() {
        let directive = line.trim_start();
        let at = i + 1;
        if let Some(name) = directive.strip_prefix("// #if ") {
            if !FEATURES.contains(&name.trim()) {
                return Err(format!(
                    "line {at}: `#if {}` names no feature of shaders::FEATURES",
                    name.trim()
                ));
            }
            open.push((at, false));
        } else if directive == "// #else" {
            match open.last_mut() {
                Some((_, seen)) if !*seen => *seen = true,
                Some(_) => return Err(format!("line {at}: a second `#else`")),
                None => return Err(format!("line {at}: `#else` outside any `#if`")),
            }
        } else if directive == "// #endif" {
            if open.pop().is_none() {
                return Err(format!("line {at}: `#endif` outside any `#if`"));
            }
        } else if directive.starts_with("// #") {
            return Err(format!("line {at}: unknown directive `{directive}`"));
        }
    }
    match open.last() {
        Some((at, _)) => Err(format!("line {at}: `#if` without `#endif`")),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::{
        FrameUniforms, GpuCurve, GpuLight, GpuMaterial, GpuObject, GpuRamp, GpuShadowCast, GpuSpotMap,
        GpuTexture, GpuWave,
    };
    use std::mem::{offset_of, size_of};

    /// Every float literal of every WGSL source fits in an `f32` exactly as written: browsers'
    /// WGSL compilers (Chrome's Tint) refuse a literal past `f32::MAX` even when it would round
    /// to it (`3.40282347e38`), where naga rounds; `f32::MAX` is written `3.4028234663852886e38`.
    #[test]
    fn float_literals_fit_in_f32_as_browsers_read_them() {
        let sources = [
            ("common", COMMON),
            ("energy", ENERGY),
            ("curve", CURVE),
            ("shading", SHADING),
            ("shading_bindings", SHADING_BINDINGS),
            ("raster", RASTER),
            ("wave", WAVE),
            ("wave_samples", WAVE_SAMPLES),
            ("wave_energy", WAVE_ENERGY),
            ("wave_overlay", WAVE_OVERLAY),
            ("shadow_lookup", SHADOW_LOOKUP),
            ("shadow_bindings", SHADOW_BINDINGS),
            ("shadow_raster", SHADOW_RASTER),
            ("soft_map", SOFT_MAP),
            ("soft", SOFT),
            ("soft_trace", SOFT_TRACE),
            ("soft_traced", SOFT_TRACED),
            ("edges", EDGES),
            ("present", PRESENT),
            ("bloom", BLOOM),
        ];
        let mut checked = 0;
        for (name, src) in sources {
            for (n, line) in src.lines().enumerate() {
                let code = line.split("//").next().unwrap_or("");
                let b = code.as_bytes();
                let mut i = 0;
                while i < b.len() {
                    let starts = b[i].is_ascii_digit()
                        && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'));
                    if !starts {
                        i += 1;
                        continue;
                    }
                    let mut j = i;
                    while j < b.len()
                        && (b[j].is_ascii_digit()
                            || b[j] == b'.'
                            || b[j] == b'e'
                            || b[j] == b'E'
                            || ((b[j] == b'-' || b[j] == b'+') && j > i && matches!(b[j - 1], b'e' | b'E')))
                    {
                        j += 1;
                    }
                    let lit = &code[i..j];
                    if lit.contains(['.', 'e', 'E']) {
                        let v: f64 =
                            lit.parse().unwrap_or_else(|e| panic!("{name}.wgsl:{}: `{lit}`: {e}", n + 1));
                        assert!(
                            v.abs() <= f64::from(f32::MAX),
                            "{name}.wgsl:{}: `{lit}` is past f32::MAX, which browsers refuse; write 3.4028234663852886e38",
                            n + 1
                        );
                        checked += 1;
                    }
                    i = j.max(i + 1);
                }
            }
        }
        assert!(checked > 100, "only {checked} float literals found: the scan is broken");
        assert!("3.40282347e38".parse::<f64>().unwrap() > f64::from(f32::MAX), "the check can fail");
    }

    fn validate(name: &str, source: &str) -> naga::Module {
        let module = naga::front::wgsl::parse_str(source)
            .unwrap_or_else(|e| panic!("{name}: WGSL parse error:\n{}", e.emit_to_string(source)));
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        );
        if let Err(e) = validator.validate(&module) {
            panic!("{name}: WGSL validation error:\n{}", e.emit_to_string(source));
        }
        module
    }

    fn modules() -> Vec<(&'static str, naga::Module)> {
        vec![
            ("raster module", validate("raster module", &compose(RASTER_PARTS))),
            ("wave module", validate("wave module", &compose(WAVE_PARTS))),
            ("wave samples module", validate("wave samples module", &compose(WAVE_SAMPLES_PARTS))),
            ("shadow module", validate("shadow module", &compose(SHADOW_PARTS))),
            ("soft map module", validate("soft map module", &compose(SOFT_MAP_PARTS))),
            ("soft module", validate("soft module", &compose(SOFT_PARTS))),
            ("soft traced module", validate("soft traced module", &compose(SOFT_TRACED_PARTS))),
            ("present module", validate("present module", &compose(PRESENT_PARTS))),
            ("edge module", validate("edge module", &compose(EDGES_PARTS))),
            ("wave overlay module", validate("wave overlay module", &compose(WAVE_OVERLAY_PARTS))),
            ("bloom module", validate("bloom module", &compose(BLOOM_PARTS))),
        ]
    }

    /// Every file's `// #if` / `// #else` / `// #endif` lines are balanced and name known
    /// features, and every combination of features composes a valid wave, wave samples and
    /// overlay module; a feature that is off leaves none of its lines.
    #[test]
    fn every_feature_combination_composes_a_valid_module() {
        for &(name, source) in FILES {
            check_directives(source).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        assert!(check_directives("// #if NOPE\n// #endif\n").is_err());
        assert!(check_directives("// #if SRGB8\n").is_err());
        assert!(check_directives("// #endif\n").is_err());
        assert!(check_directives("// #if SRGB8\n// #else\n// #else\n// #endif\n").is_err());
        let subsets: Vec<Vec<&str>> = (0..1u32 << FEATURES.len())
            .map(|m| {
                FEATURES.iter().enumerate().filter(|(i, _)| m & (1 << i) != 0).map(|(_, f)| *f).collect()
            })
            .collect();
        for on in &subsets {
            for (name, parts) in [
                ("wave", WAVE_PARTS),
                ("wave samples", WAVE_SAMPLES_PARTS),
                ("wave overlay", WAVE_OVERLAY_PARTS),
            ] {
                let source = compose_with(parts, on);
                assert_eq!(
                    source.lines().count(),
                    compose(parts).lines().count(),
                    "{name} {on:?}: line numbers kept"
                );
                validate(&format!("{name} module with {on:?}"), &source);
            }
        }
        // What each feature brings, present exactly when it is on.
        let marks = [
            ("ATTENUATION", "fn rq_attenuated("),
            ("ATTENUATION", "fn curve_piece_attenuated("),
            ("SRGB8", "fn srgb8_code("),
        ];
        for on in &subsets {
            let source = compose_with(WAVE_PARTS, on);
            for (feature, mark) in marks {
                assert_eq!(source.contains(mark), on.contains(&feature), "{mark} with {on:?}");
            }
        }
    }

    /// The builtins `dot`, `cross` and `length` round differently on different drivers (see
    /// `dot3` in common.wgsl); the shaders use the written-out twins only.
    #[test]
    fn shaders_use_the_written_out_vector_products() {
        for &(name, source) in FILES {
            for (i, line) in source.lines().enumerate() {
                let code = line.split("//").next().unwrap_or("");
                for builtin in ["dot(", "cross(", "length(", "normalize(", "distance("] {
                    let found = code
                        .match_indices(builtin)
                        .any(|(at, _)| !code[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_'));
                    assert!(
                        !found,
                        "{name}:{}: uses the builtin `{builtin}`; use dot3/cross3/length3",
                        i + 1
                    );
                }
            }
        }
    }

    #[test]
    fn every_wgsl_file_parses_and_validates() {
        // Standalone files validate alone; pass files only after their prefix.
        validate("common.wgsl", COMMON);
        validate("common.wgsl + energy.wgsl", &compose(&[COMMON, ENERGY]));
        validate("common.wgsl + energy.wgsl + curve.wgsl", &compose(&[COMMON, ENERGY, CURVE]));
        let modules = modules();
        assert_eq!(modules.len(), 11);
        // Every file on disk is listed in FILES and used by a module.
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/src/shaders");
        let mut on_disk: Vec<String> = std::fs::read_dir(dir)
            .expect("shader dir")
            .map(|e| e.expect("dir entry").file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".wgsl"))
            .collect();
        on_disk.sort();
        let mut listed: Vec<String> = FILES.iter().map(|(n, _)| n.to_string()).collect();
        listed.sort();
        assert_eq!(on_disk, listed, "src/shaders/*.wgsl and shaders::FILES differ");
        for (name, text) in FILES {
            let used = RASTER_PARTS
                .iter()
                .chain(WAVE_PARTS)
                .chain(WAVE_SAMPLES_PARTS)
                .chain(SHADOW_PARTS)
                .chain(SOFT_MAP_PARTS)
                .chain(SOFT_PARTS)
                .chain(SOFT_TRACED_PARTS)
                .chain(PRESENT_PARTS)
                .chain(EDGES_PARTS)
                .chain(WAVE_OVERLAY_PARTS)
                .chain(BLOOM_PARTS)
                .any(|p| std::ptr::eq(*p, *text));
            assert!(used, "{name} is not part of any module");
        }
    }

    #[test]
    fn broken_wgsl_is_reported_not_accepted() {
        // The validator must catch a type error in a pass (guards the test above against vacuity).
        let broken = compose(&[COMMON, "fn f() -> f32 { return vec3<f32>(1.0); }"]);
        let module = naga::front::wgsl::parse_str(&broken).expect("parses");
        let mut v = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        );
        assert!(v.validate(&module).is_err());
    }

    /// Member offsets and size of the WGSL struct `name` as naga lays it out.
    fn wgsl_layout(module: &naga::Module, name: &str) -> (Vec<(String, u32)>, u32) {
        let ty = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("struct {name} not found"))
            .1;
        match &ty.inner {
            naga::TypeInner::Struct { members, span } => {
                (members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect(), *span)
            }
            _ => panic!("{name} is not a struct"),
        }
    }

    /// The traced resolve's structs lay out as their Rust twins, and the hierarchy's as
    /// hadou-math's own (whose bytes are uploaded as they are).
    #[test]
    fn traced_structs_match_their_rust_definitions() {
        use crate::layout::{GpuBvhNode, GpuBvhTri, TracedGrid, TracedUniforms};
        use std::mem::{offset_of, size_of};
        let module = validate("soft traced module", &compose(SOFT_TRACED_PARTS));
        let field = |name: &str, offset: usize| (name.to_string(), offset as u32);
        let (members, span) = wgsl_layout(&module, "TracedUniforms");
        let rust = vec![
            field("rows", offset_of!(TracedUniforms, rows)),
            field("per_row", offset_of!(TracedUniforms, per_row)),
            field("disc", offset_of!(TracedUniforms, disc)),
            field("node_count", offset_of!(TracedUniforms, node_count)),
            field("weights", offset_of!(TracedUniforms, weights)),
        ];
        assert_eq!((members, span as usize), (rust, size_of::<TracedUniforms>()));
        assert_eq!(size_of::<TracedUniforms>() / 16 * 4 - 4, hadou_math::soft::MAX_ROWS, "a weight a row");
        let (members, span) = wgsl_layout(&module, "TracedGrid");
        let rust = vec![
            field("k", offset_of!(TracedGrid, k)),
            field("pad0", offset_of!(TracedGrid, pad)),
            field("pad1", offset_of!(TracedGrid, pad) + 4),
            field("pad2", offset_of!(TracedGrid, pad) + 8),
        ];
        assert_eq!((members, span as usize), (rust, size_of::<TracedGrid>()));
        let (members, span) = wgsl_layout(&module, "BvhNode");
        let rust = vec![
            field("lo", offset_of!(GpuBvhNode, lo)),
            field("skip", offset_of!(GpuBvhNode, skip)),
            field("hi", offset_of!(GpuBvhNode, hi)),
            field("tris", offset_of!(GpuBvhNode, tris)),
        ];
        assert_eq!((members, span as u64), (rust, hadou_math::soft::BVH_NODE_BYTES));
        assert_eq!(size_of::<GpuBvhNode>() as u64, hadou_math::soft::BVH_NODE_BYTES);
        let (members, span) = wgsl_layout(&module, "BvhTri");
        let rust = vec![
            field("a", offset_of!(GpuBvhTri, a)),
            field("b", offset_of!(GpuBvhTri, b)),
            field("c", offset_of!(GpuBvhTri, c)),
        ];
        assert_eq!((members, span as u64), (rust, hadou_math::soft::BVH_TRI_BYTES));
        assert_eq!(size_of::<GpuBvhTri>() as u64, hadou_math::soft::BVH_TRI_BYTES);
    }

    #[test]
    fn gpu_structs_match_their_rust_definitions() {
        let overlay = validate("wave overlay module", &compose(WAVE_OVERLAY_PARTS));
        let (members, span) = wgsl_layout(&overlay, "OverlayUniforms");
        let rust: Vec<(String, u32)> = [
            ("depth_model", offset_of!(crate::layout::OverlayUniforms, depth_model)),
            ("near", offset_of!(crate::layout::OverlayUniforms, near)),
            ("far", offset_of!(crate::layout::OverlayUniforms, far)),
            ("projection", offset_of!(crate::layout::OverlayUniforms, projection)),
            ("origin", offset_of!(crate::layout::OverlayUniforms, origin)),
            ("depth_span", offset_of!(crate::layout::OverlayUniforms, depth_span)),
            ("_pad", offset_of!(crate::layout::OverlayUniforms, _pad)),
            ("ortho_centre", offset_of!(crate::layout::OverlayUniforms, ortho_centre)),
            ("ortho_right", offset_of!(crate::layout::OverlayUniforms, ortho_right)),
            ("ortho_up", offset_of!(crate::layout::OverlayUniforms, ortho_up)),
        ]
        .iter()
        .map(|&(n, o)| (n.to_string(), o as u32))
        .collect();
        assert_eq!(members, rust, "OverlayUniforms member offsets");
        assert_eq!(span as usize, size_of::<crate::layout::OverlayUniforms>(), "OverlayUniforms size");
        let bloom = validate("bloom module", &compose(BLOOM_PARTS));
        let (members, span) = wgsl_layout(&bloom, "BloomUniforms");
        let rust: Vec<(String, u32)> = [
            ("a", offset_of!(crate::layout::BloomUniforms, a)),
            ("b", offset_of!(crate::layout::BloomUniforms, b)),
            ("c", offset_of!(crate::layout::BloomUniforms, c)),
            ("o", offset_of!(crate::layout::BloomUniforms, o)),
            ("params", offset_of!(crate::layout::BloomUniforms, params)),
            ("flags", offset_of!(crate::layout::BloomUniforms, flags)),
        ]
        .iter()
        .map(|&(n, o)| (n.to_string(), o as u32))
        .collect();
        assert_eq!(members, rust, "BloomUniforms member offsets");
        assert_eq!(span as usize, size_of::<crate::layout::BloomUniforms>(), "BloomUniforms size");
        let module = validate("wave module", &compose(WAVE_PARTS));
        macro_rules! check {
            ($ty:ty, $name:literal, [$($field:ident),* $(,)?]) => {{
                let (members, span) = wgsl_layout(&module, $name);
                let rust: Vec<(String, u32)> =
                    vec![$((stringify!($field).to_string(), offset_of!($ty, $field) as u32)),*];
                assert_eq!(members, rust, "{} member offsets", $name);
                assert_eq!(span as usize, size_of::<$ty>(), "{} size", $name);
            }};
        }
        check!(
            FrameUniforms,
            "FrameUniforms",
            [
                eye,
                tan_half_fov,
                right,
                aspect,
                up,
                near,
                forward,
                far,
                background,
                exposure,
                light_dir,
                tone_mode,
                light_color,
                wave_count,
                ambient,
                any_glow,
                image_size,
                tile_origin,
                tile_size,
                shadow_casts,
                map_casts,
                ndc_scale,
                ndc_offset,
                cast_count,
                map_count,
                plane_count,
                area,
                area_position,
                outline_reach,
                area_color,
                grid,
                area_axis,
                area_size,
                area_shape,
                _pad0,
                _pad1,
                _pad2,
            ]
        );
        check!(GpuSpotMap, "GpuSpotMap", [eye, tan_half, forward, near, right, size, up, _pad]);
        check!(GpuObject, "GpuObject", [model, normal_matrix, material_base, material_count, _pad]);
        check!(GpuRamp, "GpuRamp", [stops, count, kind, smoothing, _pad]);
        check!(GpuTexture, "GpuTexture", [offset, width, height, flags]);
        check!(
            GpuMaterial,
            "GpuMaterial",
            [
                base_color,
                model,
                outline_color,
                wave_blend,
                outline_width,
                shadow_mask,
                object,
                mtoon,
                base_texture,
                feature_texture,
                ramp
            ]
        );
        check!(
            GpuLight,
            "GpuLight",
            [line_kind, point_offset, point_count, inverse_square, a, b, color, ramp]
        );
        check!(GpuWave, "GpuWave", [color, kind, falloff, core_radius, attenuation, p0, p1, p2]);
        check!(
            GpuShadowCast,
            "GpuShadowCast",
            [
                k,
                opacity,
                plane_point,
                shadow,
                plane_normal,
                depth_key,
                color,
                map_size,
                map_center,
                map_scale,
                map_u,
                map_layer,
                map_v,
                map_bias,
            ]
        );
        check!(
            GpuCurve,
            "GpuCurve",
            [
                origin,
                alpha,
                axis_d,
                x_head,
                axis_y,
                attenuation,
                axis_z,
                gamma,
                s_head,
                core_floor,
                cylinder_radius,
                integrator,
                m,
                m_reduced,
                reduce,
                shape,
                order,
                points,
                point_count,
                knots,
                lo,
                hi,
                rate,
                radius,
                phase,
                y_terms,
                z_terms,
                nodes,
                node_count,
                lines,
                errors,
                level_offsets,
                levels,
                tolerance,
                att_q,
                att_floor,
                tail_radius,
                _pad0,
                _pad1,
                _pad2,
            ]
        );
    }

    #[test]
    fn constants_match() {
        use crate::layout::*;
        let module = validate("wave module", &compose(WAVE_PARTS));
        let value = |name: &str| -> u32 {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("const {name} not found"));
            match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => v,
                ref e => panic!("{name}: unexpected {e:?}"),
            }
        };
        assert_eq!(value("WAVE_SPHERE"), WAVE_SPHERE);
        assert_eq!(value("WAVE_CYLINDER"), WAVE_CYLINDER);
        assert_eq!(value("WAVE_CAPSULE"), WAVE_CAPSULE);
        assert_eq!(value("WAVE_BEAM"), WAVE_BEAM);
        assert_eq!(value("WAVE_CURVE"), WAVE_CURVE);
        assert_eq!(value("INTEGRATOR_DEFAULT"), INTEGRATOR_DEFAULT);
        assert_eq!(value("INTEGRATOR_SIMPSON"), INTEGRATOR_SIMPSON);
        assert_eq!(value("INTEGRATOR_NEAREST"), INTEGRATOR_NEAREST);
        assert_eq!(value("SHAPE_HELIX"), SHAPE_HELIX);
        assert_eq!(value("SHAPE_TRIG"), SHAPE_TRIG);
        assert_eq!(value("SHAPE_BEZIER"), SHAPE_BEZIER);
        assert_eq!(value("SHAPE_BSPLINE"), SHAPE_BSPLINE);
        assert_eq!(value("FALLOFF_FAITHFUL"), FALLOFF_FAITHFUL);
        assert_eq!(value("FALLOFF_INVERSE_SQUARE"), FALLOFF_INVERSE_SQUARE);
        assert_eq!(value("TONE_FAITHFUL"), TONE_FAITHFUL);
        assert_eq!(value("TONE_FILMIC"), TONE_FILMIC);
        assert_eq!(value("CURVE_MAX_PARTS") as usize, hadou_math::curve::MAX_ATTENUATION_PARTS);
        assert_eq!(value("HULL_BIT"), HULL_BIT);
        assert_eq!(value("MATERIAL_MASK"), MATERIAL_MASK);
        assert_eq!(value("REACH_SHIFT"), REACH_SHIFT);
        assert_eq!(value("CAST_PLANE"), CAST_PLANE);
        assert_eq!(value("SHADOW_CAST_WORDS"), SHADOW_CAST_WORDS);
        assert_eq!(value("LAMP_SEGMENT"), LAMP_SEGMENT);
        assert_eq!(value("LAMP_DISC"), LAMP_DISC);
        assert_eq!(value("LAMP_SPHERE"), LAMP_SPHERE);
        let overlay = validate("wave overlay module", &compose(WAVE_OVERLAY_PARTS));
        let overlay_value = |name: &str| -> u32 {
            let (_, c) = overlay.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).expect(name);
            match overlay.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => v,
                ref e => panic!("{name}: unexpected {e:?}"),
            }
        };
        assert_eq!(overlay_value("DEPTH_STANDARD"), DEPTH_STANDARD);
        assert_eq!(overlay_value("DEPTH_REVERSE_INFINITE"), DEPTH_REVERSE_INFINITE);
        let (_, on_plane) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some("ON_PLANE"))
            .expect("const ON_PLANE");
        match module.global_expressions[on_plane.init] {
            naga::Expression::Literal(naga::Literal::F32(v)) => assert_eq!(v, hadou_scene::ON_PLANE),
            ref e => panic!("ON_PLANE: unexpected {e:?}"),
        }
    }

    /// `load_shadow_cast` (shadow_lookup.wgsl) reads every field of `GpuShadowCast` from the word
    /// at its Rust offset.
    #[test]
    fn shadow_cast_loader_reads_the_rust_offsets() {
        use crate::layout::GpuShadowCast;
        let body = SHADOW_LOOKUP
            .split("fn load_shadow_cast")
            .nth(1)
            .and_then(|b| b.split("\n}").next())
            .expect("load_shadow_cast in shadow_lookup.wgsl");
        let mut fields = Vec::new();
        for line in body.lines().map(str::trim).filter(|l| l.starts_with("c.")) {
            let (field, rhs) = line[2..].split_once(" = ").expect("c.field = …");
            let word = match rhs.split_once("o + ") {
                Some((_, rest)) => rest.split('u').next().expect("offset").parse::<usize>().expect("number"),
                None => 0, // `data_vec3(o)`: word 0
            };
            fields.push((field.to_string(), 4 * word));
        }
        macro_rules! offsets {
            ($($field:ident),*) => { vec![$((stringify!($field).to_string(), offset_of!(GpuShadowCast, $field))),*] };
        }
        let rust = offsets!(
            k,
            opacity,
            plane_point,
            shadow,
            plane_normal,
            depth_key,
            color,
            map_size,
            map_center,
            map_scale,
            map_u,
            map_layer,
            map_v,
            map_bias
        );
        assert_eq!(fields, rust);
    }
}
