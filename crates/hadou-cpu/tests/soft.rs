//! Soft shadows from the `[area_light]` on the CPU reference (003, SPEC.md §4): the classes agree
//! with exact shadow rays to `L₁` and `L₂`, the exact resolve equals a brute-force nearest search
//! under the same rules and the faithful resolve at `N = 1`, the faithful grid pixels carry the
//! searched values, the depth-aware search changes the failure case it is for, the light adds its
//! term only where visible, and nothing is ever NaN.

use hadou_cpu::soft::{
    classify, disc_radius, edge_errors, fitted_maps, pcss, soft_input, truth, visibility, SoftInput,
    SpotDepth,
};
use hadou_math::soft::{same_surface, segment_brightness, Class, FitWindow, SEARCH_RADIUS};
use hadou_math::{Vec3, Vec3f};
use hadou_scene::{AreaLight, Frame, Penumbra, Scene, SoftResolve};
use std::path::Path;

fn scene_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// Example scene `name` at time `t`, `size²` pixels.
fn example(name: &str, t: f32, size: u32) -> Frame {
    let s = Scene::load(scene_dir().join(name)).unwrap_or_else(|e| panic!("{e}"));
    let mut f = s.at(t);
    f.width = size;
    f.height = size;
    // Pixel by pixel against the soft-shadow stage's own per-pixel results: one sample each.
    f.samples = 1;
    f
}

fn soft_scenes() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(scene_dir())
        .expect("scenes/")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with("soft-") && n.ends_with(".toml"))
        .collect();
    v.sort();
    assert!(v.len() >= 6, "the soft-* example scenes: {v:?}");
    v
}

fn classes(f: &Frame, input: &SoftInput) -> Vec<Class> {
    let light = f.area_light.as_ref().expect("area light");
    let maps = fitted_maps(light, input).map(|m| SpotDepth::render(f, &light.casters, &m, light.map_size));
    classify(&maps, input)
}

/// Brute force of the resolve's definition: the nearest pixel of class `want` within
/// `SEARCH_RADIUS` (on the same surface when depth-aware), by trying every pixel.
fn brute_nearest(input: &SoftInput, class: &[Class], i: usize, want: Class, aware: bool) -> f32 {
    let w = input.width as i64;
    let (x, y) = (i as i64 % w, i as i64 / w);
    let p = input.points[i].expect("penumbra pixels have points");
    let mut best = f32::INFINITY;
    for (j, c) in class.iter().enumerate() {
        if *c != want {
            continue;
        }
        let (u, v) = (j as i64 % w, j as i64 / w);
        let d2 = ((u - x).pow(2) + (v - y).pow(2)) as f32;
        if d2 > (SEARCH_RADIUS * SEARCH_RADIUS) as f32 || d2 >= best {
            continue;
        }
        if aware && !input.points[j].is_some_and(|q| same_surface(p.world, p.normal, q.world)) {
            continue;
        }
        best = d2;
    }
    best
}

#[test]
fn exact_resolve_is_the_brute_force_nearest_search_and_faithful_n1() {
    for name in soft_scenes() {
        for (aware, penumbra) in
            [(true, Penumbra::Segment), (false, Penumbra::Segment), (true, Penumbra::Linear)]
        {
            let mut f = example(&name, 0.0, 72);
            let light = f.area_light.as_mut().unwrap();
            light.depth_aware = aware;
            light.penumbra = penumbra;
            let light = light.clone();
            let k = light.penumbra_ratio();
            assert_eq!(k > 1.0, penumbra == Penumbra::Segment, "{name}: k = {k}");
            let input = soft_input(&f).unwrap();
            let class = classes(&f, &input);
            let exact = visibility(&f, &light, &input, SoftResolve::Exact);
            let n1 = visibility(&f, &light, &input, SoftResolve::Faithful { n: 1 });
            assert_eq!(exact, n1, "{name}: exact ≠ faithful N = 1");
            let mut penumbra = 0;
            for (i, c) in class.iter().enumerate() {
                let want = match c {
                    Class::Penumbra => {
                        penumbra += 1;
                        let d1 = brute_nearest(&input, &class, i, Class::Umbra, aware);
                        let d2 = brute_nearest(&input, &class, i, Class::Lit, aware);
                        segment_brightness(d1.sqrt(), d2.sqrt(), k)
                    }
                    Class::Lit => 1.0,
                    _ => 0.0,
                };
                assert_eq!(exact[i], want, "{name} (depth-aware {aware}): pixel {i}");
            }
            assert!(penumbra > 0 || name.contains("small"), "{name}: no penumbra at 72²");
        }
    }
}

#[test]
fn faithful_grid_pixels_carry_the_searched_values() {
    let f = example("soft-gradient.toml", 0.0, 96);
    let light = f.area_light.clone().unwrap();
    let input = soft_input(&f).unwrap();
    let exact = visibility(&f, &light, &input, SoftResolve::Exact);
    for n in [3usize, 5, 10] {
        let v = visibility(&f, &light, &input, SoftResolve::Faithful { n: n as u32 });
        let mut differs = 0;
        for (i, (&a, &b)) in v.iter().zip(&exact).enumerate() {
            let (x, y) = (i % 96, i / 96);
            if x % n == 0 && y % n == 0 {
                assert_eq!(a, b, "N = {n}: grid pixel ({x}, {y})");
            }
            assert!((0.0..=1.0).contains(&a), "N = {n}: {a}");
            differs += usize::from(a != b);
        }
        assert!(differs > 0, "N = {n} interpolates: some off-grid pixel must differ from the exact value");
    }
}

/// Whether the segment from `p` to `l` passes through the axis-aligned box `lo..hi`.
fn blocked(p: Vec3f, l: Vec3f, lo: Vec3f, hi: Vec3f) -> bool {
    let d = l - p;
    let (mut t0, mut t1) = (1e-4f32, 1.0f32);
    for k in 0..3 {
        let (o, dk, a, b) = match k {
            0 => (p.x, d.x, lo.x, hi.x),
            1 => (p.y, d.y, lo.y, hi.y),
            _ => (p.z, d.z, lo.z, hi.z),
        };
        if dk.abs() < 1e-12 {
            if o < a || o > b {
                return false;
            }
        } else {
            let (u, v) = ((a - o) / dk, (b - o) / dk);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
    }
    t0 <= t1
}

#[test]
fn classes_agree_with_exact_shadow_rays_to_the_two_map_positions() {
    // The pillar (a box 0.5 × 1.6 × 0.5 standing at the origin) shadows the floor: a floor pixel
    // is umbra when both segments to L₁ and L₂ hit the box, penumbra when one does.
    let f = example("soft-gradient.toml", 0.0, 128);
    let light = f.area_light.clone().unwrap();
    let (l1, l2) = (light.maps[0].eye, light.maps[1].eye);
    let (lo, hi) = (Vec3::new(-0.25, 0.0, -0.25), Vec3::new(0.25, 1.6, 0.25));
    let input = soft_input(&f).unwrap();
    let class = classes(&f, &input);
    let (mut floor, mut agree, mut counts) = (0, 0, [0usize; 4]);
    for (p, c) in input.points.iter().zip(&class) {
        let Some(p) = p else { continue };
        if p.world.y.abs() > 1e-3 || p.world.x.abs().max(p.world.z.abs()) < 0.3 {
            continue;
        }
        floor += 1;
        let want = Class::of(blocked(p.world, l1, lo, hi), blocked(p.world, l2, lo, hi));
        agree += usize::from(want == *c);
        counts[want as usize] += 1;
    }
    assert!(counts[1] > 100 && counts[2] > 100 && counts[3] > 100, "umbra, penumbra, lit: {counts:?}");
    // Disagreements are pixels within a map texel of a shadow edge (the maps' resolution and bias).
    assert!(agree as f64 >= 0.985 * floor as f64, "{agree} of {floor} floor pixels agree");
}

#[test]
fn the_nearer_map_casts_the_larger_shadow_and_the_penumbra_widens_away_from_the_pillar() {
    let f = example("soft-gradient.toml", 0.0, 160);
    let input = soft_input(&f).unwrap();
    let class = classes(&f, &input);
    // Floor pixels by distance from the pillar's footprint: the penumbra's share grows.
    let (mut near, mut far) = ([0usize; 2], [0usize; 2]);
    for (p, c) in input.points.iter().zip(&class) {
        let Some(p) = p else { continue };
        if p.world.y.abs() > 1e-3 || *c == Class::Lit {
            continue;
        }
        let r = p.world.x.abs().max(p.world.z.abs());
        let bucket = if r < 0.8 {
            &mut near
        } else if r > 1.6 {
            &mut far
        } else {
            continue;
        };
        bucket[usize::from(*c == Class::Penumbra)] += 1;
    }
    let share = |b: [usize; 2]| b[1] as f64 / (b[0] + b[1]).max(1) as f64;
    assert!(share(far) > 2.0 * share(near), "penumbra share near {near:?} far {far:?}");
}

#[test]
fn depth_aware_search_removes_the_halo_of_an_object_in_front() {
    let aware = example("soft-in-front.toml", 0.0, 256);
    let naive = example("soft-in-front-naive.toml", 0.0, 256);
    assert!(aware.area_light.as_ref().unwrap().depth_aware);
    assert!(!naive.area_light.as_ref().unwrap().depth_aware);
    let input = soft_input(&aware).unwrap();
    let va = visibility(&aware, aware.area_light.as_ref().unwrap(), &input, SoftResolve::Exact);
    let vn = visibility(&naive, naive.area_light.as_ref().unwrap(), &input, SoftResolve::Exact);
    // The naive search lets the crate's pixels stand in for the floor's: floor penumbra pixels
    // next to the crate's outline come out lighter or darker (003 Fig. 4.6).
    let changed = va
        .iter()
        .zip(&vn)
        .zip(&input.points)
        .filter(|((a, n), p)| p.is_some_and(|p| p.world.y.abs() < 1e-3) && (**n - **a).abs() > 0.05)
        .count();
    assert!(changed > 20, "{changed} floor pixels change with the depth-aware search");
}

#[test]
fn the_light_adds_its_term_where_visible_and_images_stay_finite() {
    for name in soft_scenes() {
        for t in [0.0, 1.0, 2.0] {
            let f = example(&name, t, 64);
            let img = hadou_cpu::render(&f);
            assert!(img.color.iter().flatten().all(|c| c.is_finite()), "{name} at {t}");
            let dark = hadou_cpu::render(&Frame { area_light: None, ..f.clone() });
            let input = soft_input(&f).unwrap();
            let light = f.area_light.as_ref().unwrap();
            let v = visibility(&f, light, &input, light.resolve);
            for (i, p) in input.points.iter().enumerate() {
                let Some(p) = p else { continue };
                for k in 0..3 {
                    let want = dark.color[i][k] + v[i] * p.term[k];
                    // Colour mapping is monotone: the umbra gets nothing, the rest no less.
                    if v[i] == 0.0 || p.term[k] == 0.0 {
                        assert_eq!(img.color[i][k], dark.color[i][k], "{name} pixel {i}");
                    } else {
                        assert!(img.color[i][k] >= dark.color[i][k], "{name} pixel {i}: {want}");
                    }
                }
            }
        }
    }
}

#[test]
fn references_are_bounded_and_truth_tends_to_the_hard_shadow() {
    let f = example("soft-gradient.toml", 0.0, 64);
    let light = f.area_light.clone().unwrap();
    let input = soft_input(&f).unwrap();
    let p = pcss(&f, &light, &input, 0.1);
    assert!(p.iter().all(|v| (0.0..=1.0).contains(v)));
    let t = truth(&f, &light, &input, 0.1, 16, 512);
    assert!(t.iter().all(|v| (0.0..=1.0).contains(v)));
    assert!(t.iter().any(|&v| v > 0.0 && v < 1.0), "a disc light has a penumbra");
    // A disc of radius 0 is the point light at L: every point fully lit or fully dark.
    let hard = truth(&f, &light, &input, 0.0, 4, 512);
    assert!(hard.iter().all(|&v| v == 0.0 || v == 1.0));
}

/// The segment brightness (hadou's default with the exact resolve) stands closer to a true disc
/// light than 003's linear ratio on the same classes and distances: its mean error over the
/// shadow-edge pixels is lower, and it brightens the penumbra (the lights between `L₁` and `L₂`
/// throw their shadows nearer `L₁`'s, the umbra's edge).
#[test]
fn segment_brightness_is_closer_to_a_disc_light_than_the_linear_ratio() {
    let f = example("soft-gradient.toml", 0.0, 160);
    let light = f.area_light.clone().unwrap();
    let input = soft_input(&f).unwrap();
    // The disc `hadou bench shadows` measures against, and its error.
    let t = truth(&f, &light, &input, disc_radius(&f).unwrap(), 64, 640);
    let visible: Vec<bool> = input.points.iter().map(Option::is_some).collect();
    let error = |penumbra: Penumbra| {
        let v = visibility(&f, &AreaLight { penumbra, ..light.clone() }, &input, SoftResolve::Exact);
        (edge_errors(&v, &t, &visible).0, v)
    };
    let (segment, vs) = error(Penumbra::Segment);
    let (linear, vl) = error(Penumbra::Linear);
    eprintln!("mean error against the disc: segment {segment:.4}, linear {linear:.4}");
    assert!(segment < 0.97 * linear, "segment {segment} against linear {linear}");
    let brighter = vs.iter().zip(&vl).filter(|(a, b)| a > b).count();
    let darker = vs.iter().zip(&vl).filter(|(a, b)| a < b).count();
    assert!(brighter > 100 && darker == 0, "{brighter} brighter, {darker} darker");
}

/// How far the wall's shadow in `a` lies from the one in `b`, in pixels: for every pixel of the
/// wall's lit face (`z = −1.3`) of soft-plaster, the least `d` such that a wall pixel of the other
/// image within `d` rows and columns has a visibility within `TOL` of its own (up to 64), the
/// largest of these both ways. A stair step `n` pixels wide needs about `n` there.
fn wall_shift(input: &SoftInput, a: &[f32], b: &[f32]) -> usize {
    const TOL: f32 = 0.1;
    const K: i64 = 64;
    let (w, h) = (input.width as i64, input.height as i64);
    let on_wall =
        |i: usize| input.points[i].is_some_and(|p| (p.world.z + 1.3).abs() < 1e-3 && p.normal.z > 0.99);
    let one_way = |a: &[f32], b: &[f32]| {
        let mut worst = 0;
        for i in (0..a.len()).filter(|&i| on_wall(i) && (a[i] - b[i]).abs() > TOL) {
            let (x, y) = (i as i64 % w, i as i64 / w);
            let near = |d: i64| {
                (-d..=d).flat_map(|dy| (-d..=d).map(move |dx| (dx, dy))).any(|(dx, dy)| {
                    let (u, v) = (x + dx, y + dy);
                    u >= 0 && v >= 0 && u < w && v < h && {
                        let j = (v * w + u) as usize;
                        on_wall(j) && (a[i] - b[j]).abs() <= TOL
                    }
                })
            };
            worst = worst.max((1..=K).find(|&d| near(d)).unwrap_or(K + 1) as usize);
        }
        worst
    };
    one_way(a, b).max(one_way(b, a))
}

#[test]
fn a_large_caster_leaves_the_wall_shadow_as_fine_as_the_figure_alone_gives() {
    // soft-plaster's 8 m wall casts too (every non-plane object does by default) and stands 2 m
    // from the lamp: fitted to everything, the maps spread their texels over a frustum of tan 80°
    // and the figure's shadow on the wall comes out stair-stepped. Fitted to the visible points a
    // caster lies in front of, the wall's own face needs none of them: the shadow on the wall
    // lies within 2 pixels of the one with the figure alone casting.
    let size = 256;
    let path = scene_dir().join("soft-plaster.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let figure_only = text.replace("target = \"figure\"\n", "target = \"figure\"\ncasters = \"figure\"\n");
    assert_ne!(text, figure_only);
    let frame = |text: &str| {
        let mut f = Scene::parse(text, &path).unwrap_or_else(|e| panic!("{e}")).at(1.5);
        (f.width, f.height) = (size, size);
        f
    };
    let (all, alone) = (frame(&text), frame(&figure_only));
    assert_eq!(all.area_light.as_ref().unwrap().casters.len(), 2, "the figure and the wall cast");
    assert_eq!(alone.area_light.as_ref().unwrap().casters.len(), 1);
    let input = soft_input(&all).unwrap();
    let vis = |f: &Frame| visibility(f, f.area_light.as_ref().unwrap(), &input, SoftResolve::Exact);
    let (a, b) = (vis(&all), vis(&alone));
    let penumbra = (0..a.len()).filter(|&i| a[i] > 0.05 && a[i] < 0.95).count();
    assert!(penumbra > 500, "{penumbra} penumbra pixels");
    let shift = wall_shift(&input, &a, &b);
    assert!(shift <= 2, "the wall shadow lies up to {shift} px from the figure-only one at {size}²");
    // The wall's box lies in front of no visible point: the maps are fitted to the figure's
    // shadow as tightly as with the figure alone (which keeps 003's frustum, barely wider).
    let fit = fitted_maps(all.area_light.as_ref().unwrap(), &input);
    for (f, alone) in fit.iter().zip(&alone.area_light.as_ref().unwrap().maps) {
        assert!(
            f.tan_half < alone.tan_half && f.tan_half > 0.8 * alone.tan_half,
            "{} against {}",
            f.tan_half,
            alone.tan_half
        );
    }
    // Both maps are fitted far inside the frustum that encloses the wall.
    for (fit, full) in fitted_maps(all.area_light.as_ref().unwrap(), &input)
        .iter()
        .zip(&all.area_light.as_ref().unwrap().maps)
    {
        assert!(fit.tan_half < 0.25 * full.tan_half, "{} against {}", fit.tan_half, full.tan_half);
    }
}

#[test]
fn fitted_maps_are_the_rule_over_every_visible_point() {
    // The prepared test and the coarse first pass change nothing: the maps are those of the
    // windows FitWindow::add_point gathers over every visible point, on every soft-* scene.
    let mut fitted = 0;
    for name in soft_scenes() {
        for t in [0.0, 1.0, 2.0] {
            let f = example(&name, t, 96);
            let light = f.area_light.as_ref().unwrap();
            let input = soft_input(&f).unwrap();
            let want = [0, 1].map(|k| {
                let mut w = FitWindow::EMPTY;
                for p in input.points.iter().flatten() {
                    w.add_point(&light.maps[k], &light.caster_boxes, p.world);
                }
                light.maps[k].fitted(&w, light.map_size)
            });
            let got = fitted_maps(light, &input);
            assert_eq!(got, want, "{name} at {t}");
            fitted += got.iter().zip(&light.maps).filter(|(a, b)| a != b).count();
        }
    }
    assert!(fitted >= 6, "{fitted} maps narrowed (soft-plaster's at least)");
}
