//! MToon materials of VRM files → [`Mtoon`] (`gltf_material` resolves their textures).
//!
//! - VRM 1.0: a material's `extensions.VRMC_materials_mtoon` object, every field of
//!   `VRMC_materials_mtoon` 1.0 ([`read_mtoon10`]); emission is the glTF material's own
//!   `emissiveFactor` / `emissiveTexture`.
//! - VRM 0.x: `extensions.VRM.materialProperties[i]` of the file, for glTF material `i`, when its
//!   `shader` is `"VRM/MToon"` ([`read_mtoon0`]), converted to the 1.0 parameters as the VRM
//!   migration does: colours `_Color`, `_ShadeColor`, `_RimColor`, `_OutlineColor` are sRGB-encoded
//!   (decoded here), `_EmissionColor` linear; the 0.x step `smoothstep(shift, lerp(1, shift,
//!   toony), N·L)` becomes the 1.0 step of the same range (toony `(2 − (max − min))/2`, shift
//!   `−(max + min)/2`, both clamped); `_IndirectLightIntensity` → `giEqualization = 1 − it`;
//!   `_OutlineWidth` is in centimetres (world mode: `× 0.01` metres; screen mode: `× 0.01` of the
//!   screen height); `_OutlineColorMode` 0 (fixed colour) → lighting mix 0; `_UvAnimRotation` is
//!   in turns per second (`× 2π`); `_SphereAdd` is the matcap (additive, white factor); the UV
//!   animation mask reads the red channel.
//!
//! Values out of the specification's range are clamped to it; a value of the wrong type is an
//! error naming the material and the key; unknown keys and features hadou does not draw are
//! warnings.

use crate::frame::{Mtoon, OutlineWidthMode};
use serde_json::Value;

/// A texture reference read from raw JSON: texture index and TEXCOORD set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct TexInfo {
    /// Index into the file's `textures`.
    pub index: usize,
    /// TEXCOORD set.
    pub tex_coord: u32,
}

/// The textures an MToon material names, for `gltf_material` to load into its [`Mtoon`].
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct MtoonTextures {
    pub shade: Option<TexInfo>,
    pub shift: Option<TexInfo>,
    pub rim: Option<TexInfo>,
    pub matcap: Option<TexInfo>,
    pub outline_width: Option<TexInfo>,
    pub uv_mask: Option<TexInfo>,
    /// VRM 0.x `_EmissionMap` (1.0 materials use the glTF `emissiveTexture`).
    pub emissive: Option<TexInfo>,
    /// VRM 0.x `_MainTex`, used when the glTF material has no `baseColorTexture`.
    pub base: Option<TexInfo>,
}

/// Reads a `textureInfo` object (`{"index": N, "texCoord": M}`) at `what`.
pub(crate) fn tex_info(v: &Value, what: &str, n_tex: usize) -> Result<TexInfo, String> {
    let index = v
        .get("index")
        .and_then(Value::as_u64)
        .ok_or_else(|| format!("{what} must be an object with a non-negative integer `index`"))?;
    tex_index(index, what, n_tex)?;
    let tex_coord = match v.get("texCoord") {
        None => 0,
        Some(t) => {
            t.as_u64()
                .filter(|&t| t < 16)
                .ok_or_else(|| format!("{what}.texCoord must be an integer from 0 to 15"))? as u32
        }
    };
    Ok(TexInfo { index: index as usize, tex_coord })
}

fn tex_index(index: u64, what: &str, n_tex: usize) -> Result<(), String> {
    if index >= n_tex as u64 {
        return Err(format!(
            "{what} refers to texture {index}, but the file has {n_tex} texture entries (0-based)"
        ));
    }
    Ok(())
}

/// A finite number at `v[key]`, `default` when absent.
pub(crate) fn number(v: &Value, key: &str, default: f32, what: &str) -> Result<f32, String> {
    match v.get(key) {
        None => Ok(default),
        Some(x) => x
            .as_f64()
            .map(|x| x as f32)
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{what}.{key} must be a finite number")),
    }
}

/// `v[key]` as `[f32; 3]` (at least three finite numbers), `default` when absent.
pub(crate) fn color3(v: &Value, key: &str, default: [f32; 3], what: &str) -> Result<[f32; 3], String> {
    let Some(x) = v.get(key) else { return Ok(default) };
    let arr = x.as_array().filter(|a| a.len() >= 3);
    let vals: Option<Vec<f32>> = arr
        .map(|a| a[..3].iter().map(|c| c.as_f64().map(|c| c as f32).filter(|c| c.is_finite())).collect())
        .and_then(|v: Option<Vec<f32>>| v);
    vals.map(|v| [v[0], v[1], v[2]])
        .ok_or_else(|| format!("{what}.{key} must be an array of 3 or 4 finite numbers"))
}

fn optional_tex(v: &Value, key: &str, what: &str, n_tex: usize) -> Result<Option<TexInfo>, String> {
    v.get(key).map(|t| tex_info(t, &format!("{what}.{key}"), n_tex)).transpose()
}

fn non_negative(c: [f32; 3]) -> [f32; 3] {
    c.map(|x| x.max(0.0))
}

/// The keys of `VRMC_materials_mtoon` 1.0.
const KEYS_10: &[&str] = &[
    "specVersion",
    "transparentWithZWrite",
    "renderQueueOffsetNumber",
    "shadeColorFactor",
    "shadeMultiplyTexture",
    "shadingShiftFactor",
    "shadingShiftTexture",
    "shadingToonyFactor",
    "giEqualizationFactor",
    "matcapFactor",
    "matcapTexture",
    "parametricRimColorFactor",
    "rimMultiplyTexture",
    "rimLightingMixFactor",
    "parametricRimFresnelPowerFactor",
    "parametricRimLiftFactor",
    "outlineWidthMode",
    "outlineWidthFactor",
    "outlineWidthMultiplyTexture",
    "outlineColorFactor",
    "outlineLightingMixFactor",
    "uvAnimationMaskTexture",
    "uvAnimationScrollXSpeedFactor",
    "uvAnimationScrollYSpeedFactor",
    "uvAnimationRotationSpeedFactor",
    "extensions",
    "extras",
];

/// Reads a `VRMC_materials_mtoon` 1.0 object; `what` names the material (`material 3`), `name`
/// its display name for warnings. Textures are left to the caller ([`MtoonTextures`]); the
/// emission is not part of the extension.
pub(crate) fn read_mtoon10(
    ext: &Value,
    what: &str,
    name: &str,
    n_tex: usize,
    warnings: &mut Vec<String>,
) -> Result<(Mtoon, MtoonTextures), String> {
    let what = format!("{what} (VRMC_materials_mtoon)");
    let obj = ext.as_object().ok_or_else(|| format!("{what} must be an object"))?;
    for key in obj.keys() {
        if !KEYS_10.contains(&key.as_str()) {
            warnings.push(format!(
                "material `{name}` ({what}): unknown key `{}` is ignored",
                crate::error::escape_controls(key)
            ));
        }
    }
    let d = Mtoon::default();
    let shift_tex = match ext.get("shadingShiftTexture") {
        Some(t) => {
            let w = format!("{what}.shadingShiftTexture");
            Some((tex_info(t, &w, n_tex)?, number(t, "scale", 1.0, &w)?))
        }
        None => None,
    };
    let mode = match ext.get("outlineWidthMode") {
        None => OutlineWidthMode::None,
        Some(v) => match v.as_str() {
            Some("none") => OutlineWidthMode::None,
            Some("worldCoordinates") => OutlineWidthMode::World,
            Some("screenCoordinates") => OutlineWidthMode::Screen,
            _ => {
                return Err(format!(
                    "{what}.outlineWidthMode must be one of \"none\", \"worldCoordinates\", \"screenCoordinates\""
                ))
            }
        },
    };
    if let Some(v) = ext.get("transparentWithZWrite") {
        let b = v.as_bool().ok_or_else(|| format!("{what}.transparentWithZWrite must be true or false"))?;
        if b {
            warnings.push(format!(
                "material `{name}` ({what}): transparentWithZWrite is ignored (hadou draws surfaces opaque)"
            ));
        }
    }
    if let Some(v) = ext.get("renderQueueOffsetNumber") {
        let n = v.as_i64().ok_or_else(|| format!("{what}.renderQueueOffsetNumber must be an integer"))?;
        if n != 0 {
            warnings.push(format!(
                "material `{name}` ({what}): renderQueueOffsetNumber is ignored (hadou draws surfaces opaque)"
            ));
        }
    }
    let m = Mtoon {
        shade_color: non_negative(color3(ext, "shadeColorFactor", d.shade_color, &what)?),
        shading_shift: number(ext, "shadingShiftFactor", d.shading_shift, &what)?.clamp(-1.0, 1.0),
        shift_texture_scale: shift_tex.map_or(1.0, |t| t.1),
        toony: number(ext, "shadingToonyFactor", d.toony, &what)?.clamp(0.0, 1.0),
        gi_equalization: number(ext, "giEqualizationFactor", d.gi_equalization, &what)?.clamp(0.0, 1.0),
        matcap_color: non_negative(color3(ext, "matcapFactor", d.matcap_color, &what)?),
        rim_color: non_negative(color3(ext, "parametricRimColorFactor", d.rim_color, &what)?),
        rim_lighting_mix: number(ext, "rimLightingMixFactor", d.rim_lighting_mix, &what)?.clamp(0.0, 1.0),
        rim_fresnel_power: number(ext, "parametricRimFresnelPowerFactor", d.rim_fresnel_power, &what)?
            .clamp(0.0, 100.0),
        rim_lift: number(ext, "parametricRimLiftFactor", d.rim_lift, &what)?.clamp(-1.0, 2.0),
        outline_mode: mode,
        outline_width: number(ext, "outlineWidthFactor", d.outline_width, &what)?.max(0.0),
        outline_color: non_negative(color3(ext, "outlineColorFactor", d.outline_color, &what)?),
        outline_lighting_mix: number(ext, "outlineLightingMixFactor", d.outline_lighting_mix, &what)?
            .clamp(0.0, 1.0),
        uv_mask_channel: 2,
        uv_scroll: [
            number(ext, "uvAnimationScrollXSpeedFactor", 0.0, &what)?,
            number(ext, "uvAnimationScrollYSpeedFactor", 0.0, &what)?,
        ],
        uv_rotation: number(ext, "uvAnimationRotationSpeedFactor", 0.0, &what)?,
        ..d
    };
    let tex = MtoonTextures {
        shade: optional_tex(ext, "shadeMultiplyTexture", &what, n_tex)?,
        shift: shift_tex.map(|t| t.0),
        rim: optional_tex(ext, "rimMultiplyTexture", &what, n_tex)?,
        matcap: optional_tex(ext, "matcapTexture", &what, n_tex)?,
        outline_width: optional_tex(ext, "outlineWidthMultiplyTexture", &what, n_tex)?,
        uv_mask: optional_tex(ext, "uvAnimationMaskTexture", &what, n_tex)?,
        emissive: None,
        base: None,
    };
    Ok((m, tex))
}

/// sRGB-encoded → linear (the sRGB transfer function).
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The 1.0 `(shadingToonyFactor, shadingShiftFactor)` of a 0.x `(_ShadeToony, _ShadeShift)`: the
/// 0.x step runs from `shift` to `lerp(1, shift, toony)`; the 1.0 step over
/// `[−1 + toony', 1 − toony']` shifted by `shift'` covers the same range when
/// `toony' = (2 − (max − min))/2` and `shift' = −(max + min)/2` (clamped to [0, 1], [−1, 1]).
pub(crate) fn migrate_toony_shift(toony0: f32, shift0: f32) -> (f32, f32) {
    let (lo, hi) = (shift0, 1.0 + (shift0 - 1.0) * toony0);
    (((2.0 - (hi - lo)) * 0.5).clamp(0.0, 1.0), (-(hi + lo) * 0.5).clamp(-1.0, 1.0))
}

/// The float, colour and texture properties of VRM 0.x's MToon that hadou reads; others warn.
const FLOATS_0: &[&str] = &[
    "_ShadeShift",
    "_ShadeToony",
    "_IndirectLightIntensity",
    "_RimLightingMix",
    "_RimFresnelPower",
    "_RimLift",
    "_OutlineWidthMode",
    "_OutlineWidth",
    "_OutlineColorMode",
    "_OutlineLightingMix",
    "_UvAnimScrollX",
    "_UvAnimScrollY",
    "_UvAnimRotation",
];
/// Properties without a visible effect in hadou's opaque drawing (render state, editor state).
const QUIET_0: &[&str] = &[
    "_Cutoff",
    "_BlendMode",
    "_CullMode",
    "_OutlineCullMode",
    "_SrcBlend",
    "_DstBlend",
    "_ZWrite",
    "_AlphaToMask",
    "_DebugMode",
    "_MToonVersion",
    "_OutlineScaledMaxDistance",
    "_LightColorAttenuation",
    "_BumpScale",
    "_ReceiveShadowRate",
    "_ShadingGradeRate",
];
const TEXTURES_0: &[&str] = &[
    "_MainTex",
    "_ShadeTexture",
    "_RimTexture",
    "_SphereAdd",
    "_EmissionMap",
    "_OutlineWidthTexture",
    "_UvAnimMaskTexture",
];

/// A VRM 0.x MToon material: its parameters, its textures, and its base colour `_Color`.
pub(crate) type Mtoon0 = (Mtoon, MtoonTextures, Option<[f32; 3]>);

/// Reads VRM 0.x `materialProperties[i]` (shader `"VRM/MToon"`; other shaders give `Ok(None)`),
/// converted to 1.0 parameters (see the module docs). Returns the MToon, its textures and the
/// base colour `_Color` when given.
pub(crate) fn read_mtoon0(
    props: &Value,
    what: &str,
    name: &str,
    n_tex: usize,
    warnings: &mut Vec<String>,
) -> Result<Option<Mtoon0>, String> {
    let what = format!("{what} (VRM materialProperties)");
    if !props.is_object() {
        return Err(format!("{what} must be an object"));
    }
    match props.get("shader").map(Value::as_str) {
        Some(Some("VRM/MToon")) => {}
        Some(Some(_)) | None => return Ok(None),
        Some(None) => return Err(format!("{what}.shader must be a string")),
    }
    let group = |key: &str| -> Result<&serde_json::Map<String, Value>, String> {
        static EMPTY: std::sync::OnceLock<serde_json::Map<String, Value>> = std::sync::OnceLock::new();
        match props.get(key) {
            None => Ok(EMPTY.get_or_init(serde_json::Map::new)),
            Some(v) => v.as_object().ok_or_else(|| format!("{what}.{key} must be an object")),
        }
    };
    let floats = group("floatProperties")?;
    let vectors = group("vectorProperties")?;
    let textures = group("textureProperties")?;
    let fw = format!("{what}.floatProperties");
    let f = |key: &str, default: f32| -> Result<f32, String> {
        match floats.get(key) {
            None => Ok(default),
            Some(x) => x
                .as_f64()
                .map(|x| x as f32)
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{fw}.{key} must be a finite number")),
        }
    };
    let vw = format!("{what}.vectorProperties");
    let v = |key: &str, srgb: bool| -> Result<Option<[f32; 3]>, String> {
        let Some(x) = vectors.get(key) else { return Ok(None) };
        let c = color3(&serde_json::json!({ key: x }), key, [0.0; 3], &vw)?;
        Ok(Some(non_negative(if srgb { c.map(srgb_to_linear) } else { c })))
    };
    let tw = format!("{what}.textureProperties");
    let t = |key: &str| -> Result<Option<TexInfo>, String> {
        let Some(x) = textures.get(key) else { return Ok(None) };
        let index = x.as_u64().ok_or_else(|| format!("{tw}.{key} must be a non-negative integer"))?;
        tex_index(index, &format!("{tw}.{key}"), n_tex)?;
        Ok(Some(TexInfo { index: index as usize, tex_coord: 0 }))
    };
    for key in floats.keys() {
        if !FLOATS_0.contains(&key.as_str()) && !QUIET_0.contains(&key.as_str()) {
            warnings.push(format!(
                "material `{name}` ({what}): MToon property `{}` is ignored",
                crate::error::escape_controls(key)
            ));
        }
    }
    for key in textures.keys() {
        if !TEXTURES_0.contains(&key.as_str()) {
            warnings.push(format!(
                "material `{name}` ({what}): MToon texture `{}` is ignored",
                crate::error::escape_controls(key)
            ));
        }
    }
    let (toony, shift) = migrate_toony_shift(f("_ShadeToony", 0.9)?, f("_ShadeShift", 0.0)?);
    let width = f("_OutlineWidth", 0.5)?.max(0.0) * 0.01;
    let mode = match f("_OutlineWidthMode", 0.0)?.round() as i32 {
        1 => OutlineWidthMode::World,
        2 => OutlineWidthMode::Screen,
        _ => OutlineWidthMode::None,
    };
    let fixed_outline = f("_OutlineColorMode", 0.0)?.round() as i32 == 0;
    let d = Mtoon::default();
    let sphere = t("_SphereAdd")?;
    let m = Mtoon {
        shade_color: v("_ShadeColor", true)?.unwrap_or([0.97, 0.81, 0.86].map(srgb_to_linear)),
        shading_shift: shift,
        toony,
        gi_equalization: (1.0 - f("_IndirectLightIntensity", 0.1)?).clamp(0.0, 1.0),
        rim_color: v("_RimColor", true)?.unwrap_or([0.0; 3]),
        rim_lighting_mix: f("_RimLightingMix", 0.0)?.clamp(0.0, 1.0),
        rim_fresnel_power: f("_RimFresnelPower", 1.0)?.clamp(0.0, 100.0),
        rim_lift: f("_RimLift", 0.0)?.clamp(-1.0, 2.0),
        matcap_color: [1.0; 3],
        outline_mode: mode,
        outline_width: width,
        outline_color: v("_OutlineColor", true)?.unwrap_or([0.0; 3]),
        outline_lighting_mix: if fixed_outline {
            0.0
        } else {
            f("_OutlineLightingMix", 1.0)?.clamp(0.0, 1.0)
        },
        uv_mask_channel: 0,
        uv_scroll: [f("_UvAnimScrollX", 0.0)?, f("_UvAnimScrollY", 0.0)?],
        uv_rotation: f("_UvAnimRotation", 0.0)? * std::f32::consts::TAU,
        emissive: v("_EmissionColor", false)?.unwrap_or([0.0; 3]),
        ..d
    };
    let tex = MtoonTextures {
        shade: t("_ShadeTexture")?,
        shift: None,
        rim: t("_RimTexture")?,
        matcap: sphere,
        outline_width: t("_OutlineWidthTexture")?,
        uv_mask: t("_UvAnimMaskTexture")?,
        emissive: t("_EmissionMap")?,
        base: t("_MainTex")?,
    };
    Ok(Some((m, tex, v("_Color", true)?)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn migration_keeps_the_step_range() {
        // 0.x defaults (toony 0.9, shift 0): the step from 0 to 0.1 → toony 0.95, shift −0.05.
        let (t, s) = migrate_toony_shift(0.9, 0.0);
        assert!((t - 0.95).abs() < 1e-6 && (s + 0.05).abs() < 1e-6, "{t} {s}");
        // Lambert-like (0, 0): from 0 to 1 → toony 0.5, shift −0.5.
        let (t, s) = migrate_toony_shift(0.0, 0.0);
        assert!((t - 0.5).abs() < 1e-6 && (s + 0.5).abs() < 1e-6, "{t} {s}");
        // The 1.0 step range [−1 + t − s, 1 − t − s] is the 0.x range [shift, lerp(1, shift, toony)].
        let (t, s) = migrate_toony_shift(0.3, -0.4);
        let (lo, hi) = (-0.4, 1.0 + (-0.4 - 1.0) * 0.3);
        assert!((-1.0 + t - s - lo).abs() < 1e-6 && (1.0 - t - s - hi).abs() < 1e-6);
    }

    #[test]
    fn srgb_decoding_matches_the_transfer_function() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
    }
}
