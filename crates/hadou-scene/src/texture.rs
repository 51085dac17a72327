//! Texture images: decoding untrusted PNG (and JPEG) bytes into a [`Texture`] with bounded
//! memory, reading texture files named by a scene, and [`encode_png`] for tests and generated
//! assets.
//!
//! The image's header is read first and its size checked against [`TEXTURE_MAX_EDGE`],
//! [`TEXTURE_MAX_TEXELS`] and what is left of the scene's [`MAX_SCENE_TEXELS`] before any pixel
//! buffer is allocated; textures are decoded one at a time, so the peak while decoding is one
//! image's buffers on top of the textures kept. PNG text and ICC chunks are skipped unread (a
//! small compressed chunk may inflate to a gigabyte). Decoders run under [`guarded`], so a panic
//! inside one is an error, never a crash.

use crate::error::show_path;
use crate::files::read_regular_file;
use crate::frame::Texture;
use crate::guard::guarded;
use std::path::Path;

/// Largest texture file read, in bytes (256 MiB).
pub const TEXTURE_MAX_BYTES: u64 = 256 << 20;
/// Longest texture edge accepted, in texels.
pub const TEXTURE_MAX_EDGE: u32 = 16384;
/// Most texels of one texture (an 8192 × 8192 image).
pub const TEXTURE_MAX_TEXELS: u64 = 8192 * 8192;
/// Edge above which a texture is halved (box filter) at load, with a warning: textures are
/// sampled at level 0 only, and the GPU keeps every texture of a frame in one storage buffer.
pub const TEXTURE_DOWNSCALE_EDGE: u32 = 4096;
/// Most texels all the textures of one scene may keep together, after any downscale, each decoded
/// image counted once (a file named by two materials, or a glTF file used by two objects, once):
/// 31 × 2²⁰ = 32 505 856 texels, 124 MiB of RGBA8.
///
/// Why: the GPU backend packs the textures of a frame into one storage buffer binding (its
/// "shading data"), whose limit under WebGPU's default limits is 128 MiB = 134 217 728 bytes, with
/// the sRGB table (1 KiB), the curves' light polylines (at most 256 waves × 128 points × 12 bytes =
/// 384 KiB) and the shadow-cast records (at most `MAX_SHADOW_CASTERS` = 1024 casts × 96 bytes plus
/// 64 map indices: under 97 KiB). 124 MiB of texels leaves 4 MiB for those 482 KiB, so whatever a
/// scene may hold fits any adapter that meets WebGPU's defaults. Two 4096² textures (128 MiB) do
/// not fit and are refused at load.
pub const MAX_SCENE_TEXELS: u64 = 31 << 20;

/// Decodes PNG or JPEG `bytes` (recognised by their signature) into RGBA8. `warnings` receives a
/// note when the image is downscaled.
pub fn decode_texture(bytes: &[u8], name: &str, warnings: &mut Vec<String>) -> Result<Texture, String> {
    decode_texture_within(bytes, name, MAX_SCENE_TEXELS, warnings)
}

/// [`decode_texture`] for a scene with `texels_left` of its [`MAX_SCENE_TEXELS`] left: an image
/// that would keep more (after any halving) is refused from its header, before it is decoded.
pub(crate) fn decode_texture_within(
    bytes: &[u8],
    name: &str,
    texels_left: u64,
    warnings: &mut Vec<String>,
) -> Result<Texture, String> {
    let tex = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        guarded("PNG", || decode_png(bytes, name, texels_left))??
    } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        guarded("JPEG", || decode_jpeg(bytes, name, texels_left))??
    } else if bytes.is_empty() {
        return Err("the file is empty; it is not a PNG or JPEG image".into());
    } else {
        return Err("not a PNG or JPEG image (unrecognised signature)".into());
    };
    Ok(downscale(tex, warnings))
}

/// Reads and decodes the texture file at `path`, refusing one that would keep more than
/// `texels_left` texels.
pub(crate) fn load_texture_file(
    path: &Path,
    texels_left: u64,
    warnings: &mut Vec<String>,
) -> Result<Texture, String> {
    let bytes =
        read_regular_file(path, TEXTURE_MAX_BYTES).map_err(|e| format!("cannot read the file: {e}"))?;
    decode_texture_within(&bytes, &show_path(path), texels_left, warnings)
}

/// The size an image of `width × height` texels keeps after [`downscale`].
pub(crate) fn kept_size(mut width: u32, mut height: u32) -> (u32, u32) {
    while width > TEXTURE_DOWNSCALE_EDGE || height > TEXTURE_DOWNSCALE_EDGE {
        (width, height) = (width.div_ceil(2), height.div_ceil(2));
    }
    (width, height)
}

/// Checks a header's size before decoding: the per-image limits, then what is left of the
/// scene's texel budget.
fn check_size(width: u32, height: u32, texels_left: u64) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("the image is {width}×{height} texels; it has no texels"));
    }
    if width > TEXTURE_MAX_EDGE
        || height > TEXTURE_MAX_EDGE
        || width as u64 * height as u64 > TEXTURE_MAX_TEXELS
    {
        return Err(format!(
            "the image is {width}×{height} texels, larger than the limit of {TEXTURE_MAX_EDGE} per edge and \
             {TEXTURE_MAX_TEXELS} texels"
        ));
    }
    let (w, h) = kept_size(width, height);
    let kept = u64::from(w) * u64::from(h);
    if kept > texels_left {
        let halved = if (w, h) == (width, height) {
            String::new()
        } else {
            format!(" (kept at {w}×{h} after halving)")
        };
        return Err(format!(
            "the image is {width}×{height} texels{halved}: {kept} texels, more than the {texels_left} left of \
             the limit of {MAX_SCENE_TEXELS} texels for all the textures of a scene (124 MiB, what the GPU \
             backend can bind at once); use smaller or fewer textures"
        ));
    }
    Ok(())
}

fn decode_png(bytes: &[u8], name: &str, texels_left: u64) -> Result<Texture, String> {
    let bad = |e: png::DecodingError| format!("not a valid PNG image: {e}");
    // Text (tEXt, zTXt, iTXt) and ICC profile (iCCP) chunks are skipped unread: hadou uses
    // neither, and a compressed one may inflate far beyond its size in the file.
    let mut options = png::DecodeOptions::default();
    options.set_ignore_text_chunk(true);
    options.set_ignore_iccp_chunk(true);
    let mut decoder = png::Decoder::new_with_options(std::io::Cursor::new(bytes), options);
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    decoder.set_limits(png::Limits { bytes: (TEXTURE_MAX_TEXELS * 8) as usize });
    let mut reader = decoder.read_info().map_err(bad)?;
    let (w, h) = (reader.info().width, reader.info().height);
    check_size(w, h, texels_left)?;
    let size = reader.output_buffer_size().ok_or("the PNG image is too large")?;
    let mut buf = vec![0u8; size];
    let frame = reader.next_frame(&mut buf).map_err(bad)?;
    let data = &buf[..frame.buffer_size()];
    let n = w as usize * h as usize;
    let texels: Vec<[u8; 4]> = match frame.color_type {
        png::ColorType::Rgba => data.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect(),
        png::ColorType::Rgb => data.chunks_exact(3).map(|c| [c[0], c[1], c[2], 255]).collect(),
        png::ColorType::GrayscaleAlpha => data.chunks_exact(2).map(|c| [c[0], c[0], c[0], c[1]]).collect(),
        png::ColorType::Grayscale => data.iter().map(|&g| [g, g, g, 255]).collect(),
        png::ColorType::Indexed => return Err("indexed PNG was not expanded".into()),
    };
    if texels.len() != n {
        return Err(format!("the PNG image decoded to {} texels instead of {n}", texels.len()));
    }
    Ok(Texture { name: name.into(), width: w, height: h, texels })
}

fn decode_jpeg(bytes: &[u8], name: &str, texels_left: u64) -> Result<Texture, String> {
    use zune_jpeg::zune_core::bytestream::ZCursor;
    use zune_jpeg::zune_core::colorspace::ColorSpace;
    use zune_jpeg::zune_core::options::DecoderOptions;
    let bad = |e: zune_jpeg::errors::DecodeErrors| format!("not a valid JPEG image: {e:?}");
    let edge = TEXTURE_MAX_EDGE as usize;
    let options = DecoderOptions::default()
        .jpeg_set_out_colorspace(ColorSpace::RGBA)
        .set_max_width(edge)
        .set_max_height(edge);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    // The header alone first: the size is checked before any pixel buffer exists.
    decoder.decode_headers().map_err(bad)?;
    let (w, h) = decoder.dimensions().ok_or("the JPEG image has no frame header")?;
    check_size(w as u32, h as u32, texels_left)?;
    let (w, h) = (w as u32, h as u32);
    let data = decoder.decode().map_err(bad)?;
    let n = w as usize * h as usize;
    let texels: Vec<[u8; 4]> = if data.len() == 4 * n {
        data.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()
    } else if data.len() == 3 * n {
        data.chunks_exact(3).map(|c| [c[0], c[1], c[2], 255]).collect()
    } else if data.len() == n {
        data.iter().map(|&g| [g, g, g, 255]).collect()
    } else {
        return Err(format!(
            "the JPEG image decoded to {} bytes, which does not fit {w}×{h} texels",
            data.len()
        ));
    };
    Ok(Texture { name: name.into(), width: w, height: h, texels })
}

/// Halves the image (2×2 box filter in linear light) until both edges are at most
/// [`TEXTURE_DOWNSCALE_EDGE`], with a warning.
fn downscale(mut t: Texture, warnings: &mut Vec<String>) -> Texture {
    if t.width <= TEXTURE_DOWNSCALE_EDGE && t.height <= TEXTURE_DOWNSCALE_EDGE {
        return t;
    }
    let (w0, h0) = (t.width, t.height);
    let table = hadou_math::toon::srgb_table();
    let encode = |v: f32| (hadou_math::shade::linear_to_srgb(v) * 255.0 + 0.5) as u8;
    while t.width > TEXTURE_DOWNSCALE_EDGE || t.height > TEXTURE_DOWNSCALE_EDGE {
        let (w, h) = (t.width.div_ceil(2), t.height.div_ceil(2));
        let mut out = Vec::with_capacity(w as usize * h as usize);
        for y in 0..h {
            for x in 0..w {
                let mut acc = [0.0f32; 4];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let sx = (2 * x + dx).min(t.width - 1);
                    let sy = (2 * y + dy).min(t.height - 1);
                    let p = t.texels[(sy * t.width + sx) as usize];
                    for k in 0..3 {
                        acc[k] += 0.25 * table[p[k] as usize];
                    }
                    acc[3] += 0.25 * p[3] as f32;
                }
                out.push([encode(acc[0]), encode(acc[1]), encode(acc[2]), (acc[3] + 0.5) as u8]);
            }
        }
        t = Texture { width: w, height: h, texels: out, ..t };
    }
    warnings.push(format!(
        "texture {}: {w0}×{h0} texels downscaled to {}×{} (textures above {TEXTURE_DOWNSCALE_EDGE} texels per \
         edge are sampled at level 0 only)",
        t.name, t.width, t.height
    ));
    t
}

/// Encodes RGBA8 texels as a PNG file's bytes (for tests and generated assets).
pub fn encode_png(width: u32, height: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().expect("writing to a Vec cannot fail");
        w.write_image_data(texels.as_flattened()).expect("the texel count matches the size");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_and_bad_bytes() {
        let texels = [[255, 0, 0, 255], [0, 255, 0, 128], [0, 0, 255, 0], [9, 9, 9, 9]];
        let bytes = encode_png(2, 2, &texels);
        let mut warn = Vec::new();
        let t = decode_texture(&bytes, "t", &mut warn).unwrap();
        assert_eq!((t.width, t.height), (2, 2));
        assert_eq!(t.texels, texels);
        assert!(warn.is_empty());
        assert!(decode_texture(b"hello", "t", &mut warn).unwrap_err().contains("not a PNG or JPEG"));
        assert!(decode_texture(&bytes[..40], "t", &mut warn).unwrap_err().contains("PNG"));
        assert!(decode_texture(&[], "t", &mut warn).unwrap_err().contains("empty"));
    }

    #[test]
    fn huge_textures_are_refused_before_allocation_and_large_ones_halved() {
        assert!(check_size(20000, 1, MAX_SCENE_TEXELS).unwrap_err().contains("larger than the limit"));
        assert!(check_size(0, 5, MAX_SCENE_TEXELS).unwrap_err().contains("no texels"));
        assert_eq!(kept_size(8192, 8192), (4096, 4096));
        assert_eq!(kept_size(16384, 3), (4096, 1));
        let e = check_size(8192, 8192, (1 << 24) - 1).unwrap_err();
        assert!(e.contains("kept at 4096×4096") && e.contains("16777215 left"), "{e}");
        assert!(check_size(8192, 8192, 1 << 24).is_ok());
        let t = Texture { name: "big".into(), width: 4097, height: 2, texels: vec![[255; 4]; 8194] };
        let mut warn = Vec::new();
        let small = downscale(t, &mut warn);
        assert_eq!((small.width, small.height), (2049, 1));
        assert_eq!(small.texels[0], [255; 4]);
        assert!(warn[0].contains("downscaled"), "{warn:?}");
    }
}
