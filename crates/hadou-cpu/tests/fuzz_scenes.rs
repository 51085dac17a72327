//! Mutation fuzzing of the whole path from a scene file to pixels: every example scene, the
//! hand-made hostile cases of `fuzz_corpus` (curves at the corners of their parameter boxes,
//! scenes past the triangle and image limits, textured materials whose PNG carries ancillary
//! chunks, a skin whose weights overflow, every shadow kind with an `[area_light]`, tracks with
//! extreme key times, control bytes in paths, a `[bloom]` past its pixel limit and on an
//! anti-aliased frame of grazing ground, nearest-field curves past the work a pixel may cost and
//! the B-spline zigzag that once cost 1.87 million evaluations a ray), and the files they name (a few glTF files, the
//! examples' skinned and textured `hero.glb` and the animated `brace.glb`, a PNG) are mutated at random (byte flips, lines deleted, duplicated, swapped or
//! spliced in from another scene, numbers replaced by extreme values, keys swapped, truncation),
//! written to a temporary directory and loaded with `Scene::load`. Each case must not panic, must
//! finish in bounded time, and when it loads, its frames at t = 0, 0.5 and 3 rendered by the CPU
//! backend at 24×16 must hold only finite colour, energy and depth. An error is one line without
//! control characters. Before mutating, each hand-made case runs as written and must load, or
//! fail with the message its limit promises.
//!
//! `HADOU_FUZZ_CASES=N` sets the number of cases (default 1000), `HADOU_FUZZ_SEED=S` the seed
//! (printed, so a failure can be replayed; the failing case's own seed and text are reported).

mod fuzz_corpus;

use hadou_math::rng::Rng;
use hadou_scene::Scene;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Longest one case (load and three frames) may take.
const CASE_LIMIT: Duration = Duration::from_secs(5);

const EXTREMES: &[&str] = &[
    "1e308",
    "-1e308",
    "-0",
    "-0.0",
    "3e38",
    "-3e38",
    "3.4028236e38",
    "1e-45",
    "-1e-45",
    "1e-38",
    "123456789012345678901234567890",
    "-123456789012345678901234567890",
    "9223372036854775807",
    "4294967296",
    "65536",
    "16385",
    "0",
    "1",
    "-1",
    "2",
    "1e5",
    "1e6",
    "-1e6",
    "1e7",
    "179",
    "179.999",
    "180",
    "0.001",
    "1e-6",
    "1e-7",
    "nan",
    "inf",
    "0x10",
    "1_000",
];

/// Byte ranges of the numbers in `text` (ASCII digits with sign, point and exponent).
fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let starts = text[i].is_ascii_digit()
            || ((text[i] == b'-' || text[i] == b'+') && text.get(i + 1).is_some_and(u8::is_ascii_digit));
        let after_word = i > 0 && (text[i - 1].is_ascii_alphanumeric() || text[i - 1] == b'_');
        if starts && !after_word {
            let s = i;
            i += 1;
            while i < text.len()
                && (text[i].is_ascii_digit()
                    || matches!(text[i], b'.' | b'e' | b'E' | b'_')
                    || ((text[i] == b'-' || text[i] == b'+') && matches!(text[i - 1], b'e' | b'E')))
            {
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}

fn lines(text: &[u8]) -> Vec<Vec<u8>> {
    text.split(|&b| b == b'\n').map(|l| l.to_vec()).collect()
}

fn join(lines: &[Vec<u8>]) -> Vec<u8> {
    lines.join(&b'\n')
}

/// One random mutation of `text`; `donors` supply spliced-in lines.
fn mutate(rng: &mut Rng, text: &[u8], donors: &[Vec<u8>]) -> Vec<u8> {
    let mut t = text.to_vec();
    match rng.below(10) {
        0 if !t.is_empty() => {
            let i = rng.below(t.len());
            t[i] = if rng.below(2) == 0 { t[i] ^ (1 << rng.below(8)) } else { rng.next_u64() as u8 };
        }
        1 => {
            let mut l = lines(&t);
            if !l.is_empty() {
                l.remove(rng.below(l.len()));
            }
            t = join(&l);
        }
        2 => {
            let mut l = lines(&t);
            if !l.is_empty() {
                let i = rng.below(l.len());
                let line = l[i].clone();
                for _ in 0..1 + rng.below(3) {
                    l.insert(i, line.clone());
                }
            }
            t = join(&l);
        }
        3..=5 => {
            let nums = numbers(&t);
            if !nums.is_empty() {
                let (s, e) = *rng.pick(&nums);
                let v = rng.pick(EXTREMES).as_bytes();
                t.splice(s..e, v.iter().copied());
            }
        }
        6 => {
            // Swap the keys of two `key = value` lines.
            let mut l = lines(&t);
            let keyed: Vec<usize> = (0..l.len()).filter(|&i| l[i].windows(3).any(|w| w == b" = ")).collect();
            if keyed.len() >= 2 {
                let (a, b) = (*rng.pick(&keyed), *rng.pick(&keyed));
                let split = |x: &Vec<u8>| {
                    let p = x.windows(3).position(|w| w == b" = ").unwrap();
                    (x[..p].to_vec(), x[p..].to_vec())
                };
                let ((ka, va), (kb, vb)) = (split(&l[a]), split(&l[b]));
                l[a] = [kb, va].concat();
                l[b] = [ka, vb].concat();
            }
            t = join(&l);
        }
        7 => {
            let n = rng.below(t.len() + 1);
            t.truncate(n);
        }
        8 => {
            let mut l = lines(&t);
            if l.len() >= 2 {
                let (a, b) = (rng.below(l.len()), rng.below(l.len()));
                l.swap(a, b);
            }
            t = join(&l);
        }
        _ => {
            let donor = lines(rng.pick::<Vec<u8>>(donors));
            let mut l = lines(&t);
            if !donor.is_empty() {
                let line = rng.pick(&donor).clone();
                let at = rng.below(l.len() + 1);
                l.insert(at, line);
            }
            t = join(&l);
        }
    }
    t
}

fn b64(data: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let v = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for i in 0..4 {
            s.push(if i <= c.len() { A[(v >> (18 - 6 * i) & 63) as usize] as char } else { '=' });
        }
    }
    s
}

/// A triangle's positions (36 bytes) and u16 indices (6 bytes + 2 padding).
fn triangle_blob() -> Vec<u8> {
    let mut b = Vec::new();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend_from_slice(&c.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

/// glTF JSON for the triangle, one node per line so line mutations hit the structure.
fn triangle_json(uri: Option<&str>) -> String {
    let uri = uri.map_or(String::new(), |u| format!(",\"uri\":\"{u}\""));
    format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\n\"scene\":0,\n\"scenes\":[{{\"nodes\":[0]}}],\n\
         \"nodes\":[{{\"children\":[1],\"translation\":[0.5,0,0]}},\n{{\"mesh\":0,\"scale\":[2,2,2]}}],\n\
         \"meshes\":[{{\"primitives\":[{{\"attributes\":{{\"POSITION\":0}},\"indices\":1,\"mode\":4}}]}}],\n\
         \"buffers\":[{{\"byteLength\":44{uri}}}],\n\
         \"bufferViews\":[{{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36}},\n\
         {{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}}],\n\
         \"accessors\":[{{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\
         \"min\":[0,0,0],\"max\":[1,1,0]}},\n\
         {{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}}]}}\n"
    )
}

fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut js = json.as_bytes().to_vec();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    let total = 12 + 8 + js.len() + 8 + bin.len();
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(js.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&js);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out
}

const GLTF_SCENE: &str = "[image]\nwidth = 64\nheight = 48\n\n[camera]\nposition = [0.5, 0.5, 4.0]\n\
target = [0.5, 0.5, 0.0]\nfar = 50\n\n[[object]]\nname = \"m\"\nkind = \"gltf\"\npath = \"m.gltf\"\n\
position = [0.0, 0.0, 0.0]\nscale = 1.0\n\n[[wave]]\nname = \"s\"\nkind = \"sphere\"\nM = [0.5, 0.5, 1.0]\nalpha_s = 0.5\n";

fn env_u64(key: &str) -> Option<u64> {
    std::env::var(key).ok().and_then(|v| v.trim().parse().ok())
}

/// Loads and renders one case: `Ok(Ok(()))` when it loaded and rendered, `Ok(Err(message))`
/// when it failed cleanly; the outer `Err` says what went wrong.
fn run_case(path: &Path) -> Result<Result<(), String>, String> {
    let scene = match Scene::load(path) {
        Ok(s) => s,
        Err(e) => {
            let msg = e.to_string();
            if msg.is_empty() || msg.chars().any(char::is_control) {
                return Err(format!("error message is not one line of text: {msg:?}"));
            }
            return Ok(Err(msg));
        }
    };
    for t in [0.0, 0.5, 3.0] {
        let mut frame = scene.at(t);
        frame.width = 24;
        frame.height = 16;
        let img = hadou_cpu::render(&frame);
        let bad = img
            .color
            .iter()
            .flatten()
            .position(|v| !v.is_finite())
            .map(|i| ("colour", i / 4))
            .or_else(|| img.energy.iter().position(|v| !v.is_finite()).map(|i| ("energy", i)))
            .or_else(|| img.depth.iter().position(|v| !v.is_finite()).map(|i| ("depth", i)));
        if let Some((what, i)) = bad {
            return Err(format!("non-finite {what} at pixel ({}, {}) at t = {t}", i % 24, i / 24));
        }
    }
    Ok(Ok(()))
}

/// What a hand-made case must do as written: load (`None`), or fail with a message containing
/// the text.
fn seed_expectation(name: &str) -> Option<&'static str> {
    match name {
        "helix at rate -1e6" => Some("at most 128 turns"),
        "ten 1024-segment spheres" => Some("triangles"),
        "area light over a 4097×4096 image" => Some("16777216 pixels"),
        "control bytes in a path" => Some("a\\0b\\u{1b}[2J.glb"),
        "bloom over an 8193×8192 image" => Some("at most 67108864 pixels"),
        "nearest-field helices past the pixel's work" => Some("[[wave]] \"h11\" may cost"),
        _ => None,
    }
}

#[test]
fn mutated_scenes_load_or_fail_cleanly_and_render_finite() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut corpus: Vec<(String, Vec<u8>)> = std::fs::read_dir(&root)
        .expect("scenes/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap()))
        .collect();
    corpus.sort();
    assert!(corpus.len() >= 10, "example scenes not found in {}", root.display());
    corpus.push(("gltf-scene".into(), GLTF_SCENE.as_bytes().to_vec()));
    let seeds = fuzz_corpus::seeds();
    corpus.extend(seeds.iter().cloned());
    let aux = fuzz_corpus::aux_files();
    let donors: Vec<Vec<u8>> = corpus.iter().map(|c| c.1.clone()).collect();

    let blob = triangle_blob();
    let data_uri = format!("data:application/octet-stream;base64,{}", b64(&blob));
    let gltf_json = triangle_json(Some(&data_uri));
    let glb_bytes = glb(&triangle_json(None), &blob);

    let cases = env_u64("HADOU_FUZZ_CASES").unwrap_or(1000);
    let seed = env_u64("HADOU_FUZZ_SEED").unwrap_or(0x4841_444F_5546_5A5A);
    println!("fuzz: {cases} cases, HADOU_FUZZ_SEED={seed}");

    let dir = std::env::temp_dir().join(format!("hadou-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    for asset in ["crystal.glb", "hero.glb", "brace.glb"] {
        std::fs::copy(root.join("assets").join(asset), dir.join("assets").join(asset)).unwrap();
    }
    for (name, bytes) in &aux {
        std::fs::write(dir.join(name), bytes).unwrap();
    }

    // The hand-made cases as written.
    let path = dir.join("case.toml");
    for (name, text) in &seeds {
        std::fs::write(&path, text).unwrap();
        let t0 = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| run_case(&path)))
            .unwrap_or_else(|_| panic!("{name}: panicked"))
            .unwrap_or_else(|why| panic!("{name}: {why}"));
        assert!(t0.elapsed() < CASE_LIMIT, "{name}: took {:?}", t0.elapsed());
        match (seed_expectation(name), outcome) {
            (None, Err(msg)) => panic!("{name}: should load, failed: {msg}"),
            (Some(want), Ok(())) => panic!("{name}: should fail with \"{want}\", loaded"),
            (Some(want), Err(msg)) => assert!(msg.contains(want), "{name}: wanted \"{want}\" in: {msg}"),
            (None, Ok(())) => {}
        }
    }

    let started = Instant::now();
    let (mut loaded, mut failures) = (0usize, Vec::new());
    for case in 0..cases {
        let case_seed = seed ^ case.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let mut rng = Rng(case_seed);
        let (name, base) = rng.pick(&corpus).clone();
        let mut text = base;
        for _ in 0..1 + rng.below(4) {
            text = mutate(&mut rng, &text, &donors);
        }
        // The glTF the scenes may name: valid, mutated JSON, or mutated GLB.
        let (gltf_name, gltf_bytes) = match rng.below(4) {
            0 => ("m.gltf", gltf_json.as_bytes().to_vec()),
            1 | 2 => {
                let mut g = gltf_json.as_bytes().to_vec();
                for _ in 0..1 + rng.below(3) {
                    g = mutate(&mut rng, &g, &[gltf_json.as_bytes().to_vec()]);
                }
                ("m.gltf", g)
            }
            _ => {
                let mut g = glb_bytes.clone();
                for _ in 0..1 + rng.below(3) {
                    g = mutate(&mut rng, &g, std::slice::from_ref(&glb_bytes));
                }
                ("m.glb", g)
            }
        };
        if gltf_name == "m.glb" {
            text = String::from_utf8_lossy(&text).replace("m.gltf", "m.glb").into_bytes();
        }
        std::fs::write(dir.join(gltf_name), &gltf_bytes).unwrap();
        // The hand-made cases' PNG and skinned glTF: as made, or mutated.
        for (aux_name, bytes) in &aux {
            let mut b = bytes.clone();
            if rng.below(3) == 0 {
                for _ in 0..1 + rng.below(3) {
                    b = mutate(&mut rng, &b, std::slice::from_ref(bytes));
                }
            }
            std::fs::write(dir.join(aux_name), &b).unwrap();
        }
        std::fs::write(&path, &text).unwrap();

        let t0 = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| run_case(&path)));
        let took = t0.elapsed();
        let report = |why: String| {
            format!(
                "case {case} (from {name}, case seed {case_seed}, run seed {seed}): {why}\n--- scene ---\n{}\n--- {gltf_name} ---\n{}",
                String::from_utf8_lossy(&text),
                String::from_utf8_lossy(&gltf_bytes)
            )
        };
        match outcome {
            Ok(Ok(Ok(()))) => loaded += 1,
            Ok(Ok(Err(_))) => {}
            Ok(Err(why)) => failures.push(report(why)),
            Err(_) => failures.push(report("panicked".into())),
        }
        if took > CASE_LIMIT {
            failures.push(report(format!("took {took:?}, more than {CASE_LIMIT:?}")));
        }
        if failures.len() >= 5 {
            break;
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    println!("fuzz: {loaded} of {cases} cases loaded and rendered, {:?} in all", started.elapsed());
    assert!(failures.is_empty(), "{} failure(s):\n\n{}", failures.len(), failures.join("\n\n"));
}
