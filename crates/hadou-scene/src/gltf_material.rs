//! glTF materials, textures, samplers and images → [`Material`]s (see `gltf_load` for the rest).
//!
//! - `pbrMetallicRoughness.baseColorFactor` (rgb) → [`Material::base_color`], `baseColorTexture`
//!   → [`Material::base_texture`] with the sampler's `wrapS`/`wrapT` and `magFilter`.
//! - `KHR_materials_unlit` → [`ShadingModel::Unlit`]; `VRMC_materials_mtoon` (VRM 1.0) →
//!   [`Material::mtoon`] (see `gltf_mtoon`, also for VRM 0.x), with a two-band
//!   [`ShadingModel::Toon`] ramp as its approximation (see [`ramp_of`]); otherwise
//!   [`ShadingModel::Diffuse`].
//! - hadou's feature texture (000 §2.2) lives in the material's extras:
//!   `"extras": {"hadou": {"featureTexture": {"index": N, "texCoord": M}}}` (`texCoord` optional,
//!   0 by default) → [`Material::feature_texture`].
//!
//! Images come from a bufferView or a URI (base64 data URI, or a file inside the asset root; both
//! read by `gltf_uri`) and are decoded once each (PNG or JPEG, recognised by their bytes), only
//! when a material uses them, one at a time, against what is left of the scene's
//! [`MAX_SCENE_TEXELS`](crate::texture::MAX_SCENE_TEXELS). Every index read here is checked
//! against the array it points into first.

use crate::error::escape_controls;
use crate::frame::{Filter, Material, Mtoon, Ramp, ShadingModel, Texture, TextureRef, Wrap};
use crate::gltf_mtoon::{color3, read_mtoon0, read_mtoon10, tex_info, MtoonTextures, TexInfo};
use crate::gltf_uri::resolve_uri;
use crate::texture::decode_texture_within;
use serde_json::Value;
use std::path::Path;
use std::sync::Arc;

/// The glTF extensions hadou maps (a file may list them in `extensionsRequired`).
/// `VRMC_vrm` (VRM 1.0) and `VRM` (VRM 0.x) are the avatar extensions of `.vrm` files; of them
/// hadou reads the MToon materials (`gltf_mtoon`).
pub(crate) const SUPPORTED_EXTENSIONS: &[&str] =
    &["KHR_materials_unlit", "VRMC_materials_mtoon", "VRMC_vrm", "VRM"];

/// The materials of a file and the TEXCOORD set each one's textures read.
pub(crate) struct Materials {
    /// One per glTF material, in order, then the default material for primitives without one.
    pub list: Vec<Material>,
    /// Per glTF material: the TEXCOORD set its textures use, `None` when it has no texture.
    pub uv_set: Vec<Option<u32>>,
}

impl Materials {
    /// Slot of a primitive's material (`None` → the appended default).
    pub fn slot(&self, material: Option<usize>) -> u32 {
        material.unwrap_or(self.list.len() - 1) as u32
    }
}

/// Where images come from: the loaded buffers and where external files may be read.
pub(crate) struct ImageSource<'a> {
    /// Buffer data, by buffer index.
    pub buffers: &'a [Vec<u8>],
    /// Directory of the glTF file.
    pub dir: &'a Path,
    /// External files must resolve inside this directory tree.
    pub root: &'a Path,
}

/// The two-band toon ramp that approximates an MToon material of base colour `base` for
/// renderers that do not draw MToon (hadou-bevy's material): MToon shades with
/// `linearstep(−1 + toony, 1 − toony, N·L + shift)` between the shade colour and the base colour,
/// so the band threshold is `−shift` (clamped to [−1, 1]), the step width `(1 − toony)·2` (clamped
/// to [0, 2]) and the shade band the per-channel multiplier `shade / base` (1 where the base
/// channel is 0, clamped to [0, 4]).
fn ramp_of(shade: [f32; 3], shift: f32, toony: f32, base: [f32; 3]) -> Ramp {
    let mult: [f32; 3] =
        std::array::from_fn(|i| if base[i] > 0.0 { (shade[i] / base[i]).clamp(0.0, 4.0) } else { 1.0 });
    Ramp::two_band((-shift).clamp(-1.0, 1.0), mult, ((1.0 - toony) * 2.0).clamp(0.0, 2.0))
}

/// The glTF material's `emissiveFactor` (black when absent).
fn m_emissive_factor(rm: &Value, what: &str) -> Result<[f32; 3], String> {
    color3(rm, "emissiveFactor", [0.0; 3], what)
}

fn m_emissive(c: [f32; 3]) -> [f32; 3] {
    c.map(|x| x.max(0.0))
}

/// VRM 0.x's `extensions.VRM.materialProperties[i]`, if the file has one.
fn vrm0_properties(raw: &Value, i: usize) -> Option<&Value> {
    raw.get("extensions")?.get("VRM")?.get("materialProperties")?.as_array()?.get(i)
}

/// Sampler wrap mode → [`Wrap`] (`None`, and unknown values, are REPEAT, glTF's default).
fn wrap_of(mode: gltf::texture::WrappingMode) -> Wrap {
    use gltf::texture::WrappingMode as W;
    match mode {
        W::ClampToEdge => Wrap::Clamp,
        W::MirroredRepeat => Wrap::Mirror,
        W::Repeat => Wrap::Repeat,
    }
}

/// Loads every material of the file, decoding the images they use; their texels are taken from
/// `texels_left` (the scene's texture budget).
pub(crate) fn load_materials(
    gltf: &gltf::Gltf,
    raw: &Value,
    src: &ImageSource<'_>,
    bytes_left: &mut u64,
    texels_left: &mut u64,
    warnings: &mut Vec<String>,
) -> Result<Materials, String> {
    let doc = gltf.document.as_json();
    let n_tex = doc.textures.len();
    let raw_mats = raw.get("materials").and_then(Value::as_array).map_or(&[][..], |v| v.as_slice());
    let mut images: Vec<Option<Arc<Texture>>> = vec![None; doc.images.len()];
    let mut list = Vec::with_capacity(doc.materials.len() + 1);
    let mut uv_set = Vec::with_capacity(doc.materials.len());
    for (i, m) in doc.materials.iter().enumerate() {
        let what = format!("material {i}");
        let rm = raw_mats.get(i).unwrap_or(&Value::Null);
        let name = rm
            .get("name")
            .and_then(Value::as_str)
            .filter(|s| !s.is_empty())
            .map_or_else(|| format!("material {i}"), |s| escape_controls(s).into_owned());
        let pbr = &m.pbr_metallic_roughness;
        let f = pbr.base_color_factor.0;
        if f.iter().any(|c| !c.is_finite()) {
            return Err(format!("{what}: baseColorFactor must be finite numbers"));
        }
        let base_color = [f[0], f[1], f[2]].map(|c| c.max(0.0));
        let mut mat = Material { name: name.clone(), ..Material::diffuse(base_color) };

        let base = pbr
            .base_color_texture
            .as_ref()
            .map(|t| TexInfo { index: t.index.value(), tex_coord: t.tex_coord });
        let feature =
            match rm.get("extras").and_then(|e| e.get("hadou")).and_then(|h| h.get("featureTexture")) {
                Some(v) => Some(tex_info(v, &format!("{what} (extras.hadou.featureTexture)"), n_tex)?),
                None => None,
            };
        let exts = rm.get("extensions");
        if exts.and_then(|e| e.get("KHR_materials_unlit")).is_some() {
            mat.model = ShadingModel::Unlit;
        }
        let mut base = base;
        let mut mtoon: Option<(Mtoon, MtoonTextures)> = None;
        if let Some(mt) = exts.and_then(|e| e.get("VRMC_materials_mtoon")) {
            if !mt.is_object() {
                return Err(format!("{what}: VRMC_materials_mtoon must be an object"));
            }
            let (mut m, mut t) = read_mtoon10(mt, &what, &name, n_tex, warnings)?;
            m.emissive = m_emissive(m_emissive_factor(rm, &what)?);
            t.emissive = match rm.get("emissiveTexture") {
                Some(v) => Some(tex_info(v, &format!("{what}.emissiveTexture"), n_tex)?),
                None => None,
            };
            mtoon = Some((m, t));
        } else if let Some(props) = vrm0_properties(raw, i) {
            if let Some((m, t, color)) = read_mtoon0(props, &what, &name, n_tex, warnings)? {
                if let Some(c) = color {
                    mat.base_color = c;
                }
                if base.is_none() {
                    base = t.base;
                }
                mtoon = Some((m, t));
            }
        }
        if let Some((m, _)) = &mtoon {
            mat.model = ShadingModel::Toon;
            mat.ramp = ramp_of(m.shade_color, m.shading_shift, m.toony, mat.base_color);
        }

        let mut sets: Vec<u32> = Vec::new();
        let mt = mtoon.as_ref().map(|m| m.1).unwrap_or_default();
        let slots =
            [base, feature, mt.shade, mt.shift, mt.rim, mt.matcap, mt.outline_width, mt.uv_mask, mt.emissive];
        let mut refs: [Option<TextureRef>; 9] = Default::default();
        for (slot, info) in slots.into_iter().enumerate() {
            let Some(info) = info else { continue };
            let tex = gltf
                .textures()
                .nth(info.index)
                .ok_or_else(|| format!("{what}: texture {} is missing", info.index))?;
            let image = tex.source().index();
            let texture = match &images[image] {
                Some(t) => t.clone(),
                None => {
                    let t = load_image(gltf, image, src, bytes_left, *texels_left, warnings).map_err(
                        |e| match rm.get("name").and_then(Value::as_str) {
                            Some(n) if !n.is_empty() => format!("material `{name}` ({what}): {e}"),
                            _ => format!("{what}: {e}"),
                        },
                    )?;
                    *texels_left -= t.texels.len() as u64;
                    let t = Arc::new(t);
                    images[image] = Some(t.clone());
                    t
                }
            };
            let s = tex.sampler();
            let filter = match s.mag_filter() {
                Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
                _ => Filter::Linear,
            };
            let r = TextureRef { image: texture, wrap: [wrap_of(s.wrap_s()), wrap_of(s.wrap_t())], filter };
            refs[slot] = Some(r);
            // The matcap is sampled at the view-space normal, not at a TEXCOORD set.
            if slot != 5 {
                sets.push(info.tex_coord);
            }
        }
        let [base_t, feature_t, shade_t, shift_t, rim_t, matcap_t, width_t, mask_t, emissive_t] = refs;
        mat.base_texture = base_t;
        mat.feature_texture = feature_t;
        if let Some((mut m, _)) = mtoon {
            m.shade_texture = shade_t;
            m.shift_texture = shift_t;
            m.rim_texture = rim_t;
            m.matcap_texture = matcap_t;
            m.outline_width_texture = width_t;
            m.uv_mask_texture = mask_t;
            m.emissive_texture = emissive_t;
            if m.outline_mode != crate::frame::OutlineWidthMode::None && m.outline_width > 0.0 {
                mat.outline = Some(crate::frame::Outline { width: m.outline_width, color: m.outline_color });
            }
            mat.mtoon = Some(Arc::new(m));
        }
        let set = match sets.as_slice() {
            [] => None,
            [a, rest @ ..] => {
                if rest.iter().any(|s| s != a) {
                    warnings.push(format!(
                        "material `{name}` ({what}): its textures use different TEXCOORD sets; all of them are \
                         sampled with the base texture's set TEXCOORD_{a}"
                    ));
                }
                Some(*a)
            }
        };
        list.push(mat);
        uv_set.push(set);
    }
    list.push(Material::diffuse([1.0; 3]));
    Ok(Materials { list, uv_set })
}

/// The bytes of image `index`, decoded, if it keeps at most `texels_left` texels.
fn load_image(
    gltf: &gltf::Gltf,
    index: usize,
    src: &ImageSource<'_>,
    bytes_left: &mut u64,
    texels_left: u64,
    warnings: &mut Vec<String>,
) -> Result<Texture, String> {
    // The JSON itself, not the gltf crate's `Image::source`, which requires a `mimeType` with a
    // bufferView (the bytes are sniffed here instead).
    let doc = gltf.document.as_json();
    let image = doc.images.get(index).ok_or_else(|| format!("image {index} is missing"))?;
    let fail = |e: String| format!("image {index}: {e}");
    let (bytes, name) = match (&image.buffer_view, &image.uri) {
        (Some(v), _) => {
            let view = &doc.buffer_views[v.value()];
            let buffer = view.buffer.value();
            let data = src.buffers.get(buffer).map_or(&[][..], |b| b.as_slice());
            let offset = view.byte_offset.map_or(0, |o| o.0) as usize;
            let end = offset.checked_add(view.byte_length.0 as usize);
            let bytes = end.and_then(|e| data.get(offset..e)).ok_or_else(|| {
                fail(format!("bufferView {} reads past the end of buffer {buffer}", v.value()))
            })?;
            (bytes.to_vec(), format!("image {index} (bufferView {})", v.value()))
        }
        (None, Some(uri)) => {
            let bytes = resolve_uri(uri, src.dir, src.root, *bytes_left).map_err(fail)?;
            *bytes_left = bytes_left.saturating_sub(bytes.len() as u64);
            let shown = if uri.starts_with("data:") {
                "data URI".to_string()
            } else {
                format!("`{}`", escape_controls(uri))
            };
            (bytes, format!("image {index} ({shown})"))
        }
        (None, None) => return Err(fail("it has neither a `bufferView` nor a `uri`".into())),
    };
    decode_texture_within(&bytes, &name, texels_left, warnings).map_err(|e| format!("{name}: {e}"))
}

/// Checks the raw JSON indices this module reads beyond what `check_indices` covers (the feature
/// texture of the extras, the MToon properties), so errors name the material before any image is
/// decoded.
pub(crate) fn check_raw(raw: &Value, n_tex: usize) -> Result<(), String> {
    let mats = raw.get("materials").and_then(Value::as_array).map_or(&[][..], |v| v.as_slice());
    let mut scratch = Vec::new();
    for (i, m) in mats.iter().enumerate() {
        let what = format!("material {i}");
        if let Some(v) = m.get("extras").and_then(|e| e.get("hadou")).and_then(|h| h.get("featureTexture")) {
            tex_info(v, &format!("{what} (extras.hadou.featureTexture)"), n_tex)?;
        }
        if let Some(mt) = m.get("extensions").and_then(|e| e.get("VRMC_materials_mtoon")) {
            read_mtoon10(mt, &what, &what, n_tex, &mut scratch)?;
        } else if let Some(props) = vrm0_properties(raw, i) {
            read_mtoon0(props, &what, &what, n_tex, &mut scratch)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mtoon_ramp_clamps_its_inputs() {
        let ext = serde_json::json!({"shadeColorFactor": [1.0, 0.5, 0.3], "shadingShiftFactor": -3.0,
                                     "shadingToonyFactor": -2.0});
        let (m, _) = read_mtoon10(&ext, "m", "m", 0, &mut Vec::new()).unwrap();
        assert_eq!((m.shading_shift, m.toony), (-1.0, 0.0));
        let r = ramp_of(m.shade_color, m.shading_shift, m.toony, [0.1, 0.0, 0.6]);
        assert_eq!(r.stops[0].1, [4.0, 1.0, 0.5]);
        assert_eq!(r.stops[1].0, 1.0);
        assert_eq!(r.kind, hadou_math::toon::RampKind::Bands { smoothing: 2.0 });
        let mut w = Vec::new();
        let e = read_mtoon10(&serde_json::json!({"shadingShiftFactor": "up"}), "material 2", "x", 0, &mut w)
            .unwrap_err();
        assert!(e.contains("material 2 (VRMC_materials_mtoon).shadingShiftFactor"), "{e}");
    }
}
