//! The GPU passes, one file each, named like their shaders. Each owns its pipelines and bind
//! group layout, declares its shader's bindings once ([`setup::Binding`] tables, held to the WGSL
//! by the tests below), builds its bind group from inputs the caller owns (buffers, the G-buffer
//! views, the output buffer or texture) and records itself into a command encoder the caller
//! owns; none reads the whole prepared frame. The renderer (`render.rs`) owns the resources of a
//! frame and orders the passes; an engine or a web page can drive the same passes on its own
//! targets.
//!
//! Order within a frame: [`shadow_maps`] (once), with an `[area_light]` [`soft`]'s maps and the
//! whole-image classification and resolve (once), then per tile [`raster`] → [`edges`] →
//! [`plane_shadows`] → [`soft`]'s gather → [`wave`] → read-back, or [`present`] into a window's
//! texture. With a `[bloom]` the wave pass writes the linear colour, every tile's colour is
//! gathered into one image, and [`bloom`]'s chain adds the glare and maps the colour before the
//! read-back.

pub(crate) mod bloom;
pub(crate) mod edges;
pub(crate) mod plane_shadows;
pub(crate) mod present;
pub(crate) mod raster;
pub(crate) mod setup;
pub(crate) mod shadow_maps;
pub(crate) mod soft;
pub(crate) mod wave;
pub(crate) mod wave_overlay;

#[cfg(test)]
mod tests {
    use super::setup::{Binding, Kind};
    use crate::shaders;

    /// Every binding a pass declares is the WGSL variable of that name at `@group(0)
    /// @binding(n)`, of the declared kind; a pass using the whole module declares all of its
    /// bindings.
    #[test]
    fn pass_bindings_match_their_shaders() {
        let c = shaders::compose;
        let passes: [(&str, String, &[Binding], bool); 12] = [
            ("bloom", c(shaders::BLOOM_PARTS), &super::bloom::BINDINGS, true),
            ("raster", c(shaders::RASTER_PARTS), &super::raster::BINDINGS, true),
            ("edges", c(shaders::EDGES_PARTS), &super::edges::BINDINGS, true),
            ("wave", c(shaders::WAVE_PARTS), &super::wave::BINDINGS, true),
            ("wave samples", c(shaders::WAVE_SAMPLES_PARTS), &super::wave::BINDINGS, true),
            ("plane shadows", c(shaders::SHADOW_PARTS), &super::plane_shadows::BINDINGS, true),
            // vs_map reads only some of shadow_raster.wgsl's bindings.
            ("shadow maps", c(shaders::SHADOW_PARTS), &super::shadow_maps::BINDINGS, false),
            ("soft map", c(shaders::SOFT_MAP_PARTS), &super::soft::MAP_BINDINGS, true),
            ("soft", c(shaders::SOFT_PARTS), &super::soft::BINDINGS, true),
            ("present", c(shaders::PRESENT_PARTS), &super::present::BINDINGS, true),
            ("wave overlay", super::wave_overlay::source(false, true), &super::wave_overlay::BINDINGS, true),
            (
                "wave overlay, multisampled depth",
                super::wave_overlay::source(true, true),
                &super::wave_overlay::BINDINGS_MULTISAMPLED,
                true,
            ),
        ];
        for (pass, source, bindings, whole) in passes {
            let module = naga::front::wgsl::parse_str(&source).expect("the module parses");
            let (mut declared, mut found) = (0, 0);
            for (_, var) in module.global_variables.iter() {
                let Some(rb) = &var.binding else { continue };
                declared += 1;
                let name = var.name.as_deref().unwrap_or("?");
                assert_eq!(rb.group, 0, "{pass}: {name}");
                let Some(b) = bindings.iter().find(|b| b.binding == rb.binding) else {
                    assert!(!whole, "{pass}: binding {} ({name}) is not declared", rb.binding);
                    continue;
                };
                found += 1;
                assert_eq!(b.name, name, "{pass}: binding {}", rb.binding);
                let kind = match (var.space, &module.types[var.ty].inner) {
                    (naga::AddressSpace::Uniform, _) => Kind::Uniform,
                    (naga::AddressSpace::Storage { access }, _) => {
                        if access.contains(naga::StorageAccess::STORE) {
                            Kind::StorageRw
                        } else {
                            Kind::Storage
                        }
                    }
                    (
                        _,
                        &naga::TypeInner::Image {
                            class: naga::ImageClass::Sampled { kind, multi },
                            arrayed,
                            ..
                        },
                    ) => match (kind, arrayed, multi) {
                        (naga::ScalarKind::Uint, false, false) => Kind::UintTexture,
                        (naga::ScalarKind::Float, false, false) => Kind::Depth,
                        (naga::ScalarKind::Float, false, true) => Kind::DepthMultisampled,
                        (naga::ScalarKind::Float, true, false) => Kind::DepthArray,
                        other => panic!("{pass}: {name}: unexpected texture {other:?}"),
                    },
                    (
                        _,
                        &naga::TypeInner::Image {
                            class:
                                naga::ImageClass::Storage { format: naga::StorageFormat::Rgba32Uint, access },
                            arrayed: false,
                            ..
                        },
                    ) if access == naga::StorageAccess::STORE => Kind::UintStorageTexture,
                    other => panic!("{pass}: {name}: unexpected {other:?}"),
                };
                assert_eq!(b.kind, kind, "{pass}: {name}");
            }
            assert_eq!(found, bindings.len(), "{pass}: every binding it declares is in the shader");
            if whole {
                assert_eq!(declared, bindings.len(), "{pass}: every declared binding is in the shader");
            } else {
                assert!(declared > bindings.len(), "{pass}: a subset of the module's bindings");
            }
            let mut numbers: Vec<u32> = bindings.iter().map(|b| b.binding).collect();
            numbers.dedup();
            assert_eq!(numbers.len(), bindings.len(), "{pass}: no binding twice");
        }
    }

    /// The wave overlay specialises exactly the overrides its module declares, each one of the
    /// wave pass's (so one `WaveVariant` serves both).
    #[test]
    fn overlay_overrides_are_its_modules() {
        let module =
            naga::front::wgsl::parse_str(&shaders::compose(shaders::WAVE_OVERLAY_PARTS)).expect("parses");
        let mut names: Vec<&str> = module.overrides.iter().filter_map(|(_, o)| o.name.as_deref()).collect();
        names.sort_unstable();
        let mut expected = super::wave_overlay::OVERRIDES.to_vec();
        expected.sort_unstable();
        assert_eq!(names, expected);
        assert!(expected.iter().all(|n| super::wave::WaveVariant::NAMES.contains(n)));
    }
}
