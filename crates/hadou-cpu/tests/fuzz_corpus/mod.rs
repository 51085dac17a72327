//! The fuzz test's hand-made corpus: the hostile cases that once crashed, spun or took gigabytes
//! (each now loads within its limits or fails with a message), and the files they name. Each
//! seed runs once as written, then is mutated like the example scenes.

/// The files the seeds name, written beside them: a textured material's PNG carrying ancillary
/// chunks (text, an ICC profile), and a skinned glTF triangle whose first vertex's weights
/// overflow when summed.
pub fn aux_files() -> Vec<(&'static str, Vec<u8>)> {
    vec![("tex.png", png_with_chunks()), ("skin.gltf", skinned_triangle_gltf().into_bytes())]
}

/// `(name, scene text)` for each hostile case.
pub fn seeds() -> Vec<(String, Vec<u8>)> {
    let head = "[image]\nwidth = 64\nheight = 48\n\n[camera]\nposition = [0, 1, 6]\ntarget = [0, 0, 0]\n\n";
    let mut out: Vec<(String, String)> = vec![
        (
            // A helix at the corner of its box (128 turns, slope 8e4): its work per ray stays
            // bounded.
            "helix at its turn and slope limits".into(),
            format!(
                "{head}[[wave]]\nname = \"h\"\nkind = \"helix\"\nO = [-2, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n\
                 radius = 400\nrate = -201\nlength = 4\n"
            ),
        ),
        (
            // Past them: once hours for a 32×24 image, now refused.
            "helix at rate -1e6".into(),
            format!(
                "{head}[[wave]]\nname = \"h\"\nkind = \"helix\"\nO = [-2, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n\
                 radius = 1e6\nrate = -1e6\nlength = 4\n"
            ),
        ),
        (
            // 64 harmonics, the most a sum may have (about 20 turns of the fastest: the cost of the
            // turn limit's corner, ~3 ms a ray, is crates/hadou-math/tests/curve_cost.rs's to check;
            // three frames of it here would outlast a case's time limit on a loaded machine).
            "trigonometric sum of 64 terms".into(),
            format!(
                "{head}[[wave]]\nname = \"t\"\nkind = \"trig\"\nO = [-2, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n\
                 rate = -0.5\nlength = 4\ny_terms = [{t}]\nz_terms = [{t}]\n",
                t = (0..64).map(|i| format!("[4, {}]", if i % 2 == 0 { -4 } else { 4 })).collect::<Vec<_>>().join(", ")
            ),
        ),
        (
            "B-spline of 512 points".into(),
            format!(
                "{head}[[wave]]\nname = \"b\"\nkind = \"bspline\"\nO = [-2, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n\
                 points = [{}]\n",
                (0..512).map(|i| format!("[{}, {}]", i % 3, (i * 7) % 5)).collect::<Vec<_>>().join(", ")
            ),
        ),
        (
            // 10.5 M triangles with no file at all: past the triangle limit, refused.
            "ten 1024-segment spheres".into(),
            format!(
                "{head}{}",
                (0..10)
                    .map(|i| format!("[[object]]\nname = \"s{i}\"\nkind = \"sphere\"\nsegments = 1024\nposition = [{i}, 0, 0]\n\n"))
                    .collect::<String>()
            ),
        ),
        (
            "textured toon materials with keys".into(),
            format!(
                "{head}[[material]]\nname = \"m\"\nmodel = \"toon\"\nbase_texture = \"tex.png\"\n\
                 feature_texture = \"tex.png\"\ntexture_wrap = \"mirror\"\noutline = true\nwave_blend = 0.5\n\n\
                 [[object]]\nname = \"ball\"\nkind = \"sphere\"\nmaterial = \"m\"\n\n\
                 [[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [1, 1, 1]\nalpha_s = 0.5\n\n\
                 [[track]]\ntarget = \"material.m.wave_blend\"\nkeys = [[0, 0], [1e-30, 1], [3, 0.5]]\n"
            ),
        ),
        (
            "skin whose weights overflow".into(),
            format!(
                "{head}[[object]]\nname = \"s\"\nkind = \"gltf\"\npath = \"skin.gltf\"\n\n\
                 [[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [0.5, 0.5, 1]\nalpha_s = 0.5\n"
            ),
        ),
        (
            // Past the `[area_light]`'s image limit by one row: refused.
            "area light over a 4097×4096 image".into(),
            "[image]\nwidth = 4097\nheight = 4096\n\n[camera]\nposition = [0, 2, 6]\ntarget = [0, 0, 0]\n\n\
             [[object]]\nname = \"floor\"\nkind = \"plane\"\n\n[[object]]\nname = \"box\"\nkind = \"box\"\n\
             position = [0, 1, 0]\n\n[area_light]\nposition = [0, 4, 0]\nsize = 0.5\ntarget = [0, 0, 0]\n"
                .into(),
        ),
        (
            "area light and every shadow kind".into(),
            format!(
                "{head}[[object]]\nname = \"floor\"\nkind = \"plane\"\nposition = [0, -1, 0]\n\n\
                 [[object]]\nname = \"box\"\nkind = \"box\"\n\n\
                 [[wave]]\nname = \"w\"\nkind = \"beam\"\nM = [-3, 1, 0]\nD = [1, 0, 0]\nlength = 4\n\
                 alpha_s = 0.1\nalpha_c = 0.1\n\n\
                 [[shadow]]\nname = \"sun\"\nkind = \"sun\"\nmethod = \"plane\"\ncasters = [\"box\"]\n\
                 receivers = [\"floor\"]\n\n\
                 [[shadow]]\nname = \"map\"\nkind = \"sun\"\nmethod = \"map\"\nmap_size = 64\n\
                 casters = [\"box\"]\nreceivers = [\"floor\"]\n\n\
                 [[shadow]]\nname = \"wave\"\nkind = \"wave\"\nmethod = \"map\"\n\
                 casters = [\"box\"]\nreceivers = [\"floor\"]\n\n\
                 [area_light]\nposition = [0, 4, 0]\nsize = 0.5\ntarget = [0, 0, 0]\n"
            ),
        ),
        (
            "tracks with extreme key times".into(),
            format!(
                "{head}[[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [0, 0, 0]\nalpha_s = 0.5\n\n\
                 [[track]]\ntarget = \"wave.w.M\"\nkeys = [[0, [0, 0, 0]], [1e-38, [1e6, 0, 0]], [1e6, [-1e6, 0, 0]]]\n\n\
                 [[track]]\ntarget = \"camera.fov\"\ninterpolation = \"smooth\"\nkeys = [{}]\n",
                (0..5000).map(|i| format!("[{i}, {}]", 1 + i % 170)).collect::<Vec<_>>().join(", ")
            ),
        ),
        (
            // Issue 41: a [bloom] past the glare's 8192² pixels, refused at the [bloom].
            "bloom over an 8193×8192 image".into(),
            "[image]\nwidth = 8193\nheight = 8192\n\n[[object]]\nname = \"box\"\nkind = \"box\"\n\n[bloom]\n".into(),
        ),
        (
            // Issue 41: a [bloom] on an anti-aliased frame over ground seen at a grazing angle
            // (every pixel a silhouette); loads, renders within its budget.
            "bloom, 16 samples, grazing ground".into(),
            "[image]\nwidth = 64\nheight = 48\nsamples = 16\n\n[camera]\nposition = [0, 0.05, 6]\n\
             target = [0, 0, -50]\n\n[[object]]\nname = \"ground\"\nkind = \"plane\"\nsize = [400, 400]\n\n\
             [[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [0, 0.5, 0]\nalpha_s = 5\n\n\
             [bloom]\nintensity = 16\nradius = 1\nstreak = 16\nstreak_length = 4\nthreshold = 0\n"
                .into(),
        ),
        (
            // Issue 41: nearest-field helices past the work a pixel may cost at 16 samples (the
            // twelfth passes it).
            "nearest-field helices past the pixel's work".into(),
            format!(
                "[image]\nwidth = 48\nheight = 32\nsamples = 16\n\n{}",
                (0..12)
                    .map(|i| format!(
                        "[[wave]]\nname = \"h{i}\"\nkind = \"helix\"\nO = [-0.5, {i}, 0]\nD = [1, 0, 0]\n\
                         alpha = 1\nradius = 1\nrate = 804\nlength = 1\nfield = \"nearest\"\n\n"
                    ))
                    .collect::<String>()
            ),
        ),
        (
            // Issue 41: the zigzag the nearest field once spent 1.87 million evaluations a ray on
            // (a 512-point order-2 B-spline seen down its axis), now at most 742 217.
            "nearest-field B-spline zigzag down its axis".into(),
            format!(
                "[image]\nwidth = 48\nheight = 32\n\n[camera]\nposition = [-8, 0.3, 0.05]\ntarget = [10, 0, 0]\n\
                 fov = 30\n\n[[wave]]\nname = \"z\"\nkind = \"bspline\"\nO = [-5, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n\
                 gamma = 10\norder = 2\nfield = \"nearest\"\npoints = [{}]\n",
                (0..512)
                    .map(|i| format!("[{}, {}]", if i % 2 == 1 { 0.5 } else { -0.5 }, ((i / 2) % 2) as f32 * 0.5 - 0.25))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ),
        (
            "control bytes in a path".into(),
            format!("{head}[[object]]\nname = \"g\"\nkind = \"gltf\"\npath = \"a\\u0000b\\u001b[2J.glb\"\n"),
        ),
    ];
    out.retain(|(_, t)| !t.is_empty());
    out.into_iter().map(|(n, t)| (n, t.into_bytes())).collect()
}

/// CRC-32 (ISO 3309, as PNG uses) of `data`.
fn crc32(data: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in data {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

/// A PNG chunk: length, type, data, CRC.
fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let mut crc_input = kind.to_vec();
    crc_input.extend_from_slice(data);
    out.extend_from_slice(&crc32(&crc_input).to_be_bytes());
    out
}

/// A 4×4 checker PNG with a `tEXt` and an `iCCP` chunk (an uncompressed-looking profile the
/// decoder must skip) after its header.
fn png_with_chunks() -> Vec<u8> {
    let texels: Vec<[u8; 4]> = (0..16)
        .map(|i| if (i + i / 4) % 2 == 0 { [255, 255, 255, 255] } else { [20, 20, 40, 255] })
        .collect();
    let png = hadou_scene::encode_png(4, 4, &texels);
    // Signature (8) + IHDR chunk (25).
    let (head, rest) = png.split_at(33);
    let mut out = head.to_vec();
    out.extend(chunk(b"tEXt", b"Comment\0hadou fuzz corpus"));
    // Profile name, NUL, compression method 0, then a zlib stream of stored blocks.
    let mut iccp = b"icc\0\0".to_vec();
    iccp.extend_from_slice(&[0x78, 0x01, 0x01, 0x04, 0x00, 0xFB, 0xFF, 0, 0, 0, 0, 0x00, 0x04, 0x00, 0x01]);
    out.extend(chunk(b"iCCP", &iccp));
    out.extend_from_slice(rest);
    out
}

/// A skinned triangle (one joint) as glTF JSON with its buffer in a data URI; vertex 0's weights
/// are `[3e38, 3e38, 0, 0]`, whose sum overflows f32.
fn skinned_triangle_gltf() -> String {
    let mut b = Vec::new();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend_from_slice(&c.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b.extend_from_slice(&[0u8; 12]);
    for w in [[3e38f32, 3e38, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]] {
        for x in w {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    let uri = format!("data:application/octet-stream;base64,{}", super::b64(&b));
    format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\n\"scene\":0,\n\"scenes\":[{{\"nodes\":[0,1]}}],\n\
         \"nodes\":[{{\"mesh\":0,\"skin\":0}},\n{{\"name\":\"joint\",\"translation\":[0,0.5,0]}}],\n\
         \"skins\":[{{\"joints\":[1]}}],\n\
         \"meshes\":[{{\"primitives\":[{{\"attributes\":{{\"POSITION\":0,\"JOINTS_0\":2,\"WEIGHTS_0\":3}},\"indices\":1}}]}}],\n\
         \"buffers\":[{{\"byteLength\":{},\"uri\":\"{uri}\"}}],\n\
         \"bufferViews\":[{{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36}},\n\
         {{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}},\n\
         {{\"buffer\":0,\"byteOffset\":44,\"byteLength\":12}},\n\
         {{\"buffer\":0,\"byteOffset\":56,\"byteLength\":48}}],\n\
         \"accessors\":[{{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\
         \"min\":[0,0,0],\"max\":[1,1,0]}},\n\
         {{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}},\n\
         {{\"bufferView\":2,\"componentType\":5121,\"count\":3,\"type\":\"VEC4\"}},\n\
         {{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"}}]}}\n",
        b.len()
    )
}
