//! The maths of 003's soft shadows (SPEC.md §4), by concept: `penumbra` (the two shadow-map
//! positions, the penumbra's brightness from the distances to the nearest umbra and lit pixels
//! with SPEC's corrected ratio, standard bilinear interpolation of a coarse grid with SPEC's
//! corrected weights, a pixel's class), `distance` (the exact Euclidean distance transform that
//! gives every pixel those distances in linear time), `search` (how far and on which surface a
//! penumbra pixel looks) and `spot_map` (a shadow map's perspective frame and its fitting to what
//! can be shadowed in view), and for the traced resolve `lamp` (the lamp's shape, what a receiver
//! sees of it, the light it adds), `bvh` (the casters' triangles in a flattened hierarchy) and
//! `topology` (how those triangles share corners and edges and which bound closed solids).
//! Every item is re-exported here: `hadou_math::soft::SpotMap`, ….

mod bvh;
mod distance;
mod lamp;
mod penumbra;
mod search;
mod spot_map;
mod topology;

pub use bvh::*;
pub use distance::*;
pub use lamp::*;
pub use penumbra::*;
pub use search::*;
pub use spot_map::*;
pub use topology::*;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3f;

    /// Brute force: the nearest feature pixel by trying them all.
    fn brute(feature: &[bool], w: usize, h: usize) -> Vec<f32> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                feature
                    .iter()
                    .enumerate()
                    .filter(|(_, &f)| f)
                    .map(|(j, _)| {
                        let (u, v) = ((j % w) as i64, (j / w) as i64);
                        ((x - u).pow(2) + (y - v).pow(2)) as f32
                    })
                    .fold(FAR, f32::min)
            })
            .collect()
    }

    #[test]
    fn distance_transform_is_exact_on_random_masks() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for case in 0..60 {
            let (w, h) = (1 + (next() % 23) as usize, 1 + (next() % 19) as usize);
            let density = [1u64, 5, 30, 90][case % 4];
            let mask: Vec<bool> = (0..w * h).map(|_| next() % 100 < density).collect();
            assert_eq!(distance_transform(&mask, w, h), brute(&mask, w, h), "case {case}: {w}×{h}");
        }
    }

    #[test]
    fn empty_and_full_masks() {
        assert!(distance_transform(&[false; 12], 4, 3).iter().all(|&d| d == FAR));
        assert!(distance_transform(&[true; 12], 4, 3).iter().all(|&d| d == 0.0));
    }

    #[test]
    fn brightness_runs_dark_to_light_and_never_nan() {
        assert_eq!(penumbra_brightness(0.0, 5.0), 0.0);
        assert_eq!(penumbra_brightness(5.0, 0.0), 1.0);
        assert_eq!(penumbra_brightness(1.0, 3.0), 0.25);
        assert_eq!(penumbra_brightness(0.0, 0.0), 0.5);
        assert_eq!(penumbra_brightness(f32::INFINITY, 2.0), 1.0);
        assert_eq!(penumbra_brightness(2.0, f32::INFINITY), 0.0);
        assert_eq!(penumbra_brightness(f32::INFINITY, f32::INFINITY), 0.5);
    }

    #[test]
    fn bilinear_weights_are_the_standard_ones() {
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 0.0, 0.0), 1.0);
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 1.0, 0.0), 2.0);
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 0.0, 1.0), 3.0);
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 1.0, 1.0), 4.0);
        assert_eq!(bilinear(0.0, 4.0, 0.0, 4.0, 0.25, 0.7), 1.0);
    }

    #[test]
    fn light_pair_straddles_the_light_along_g_to_l() {
        let (l1, l2) = light_pair(Vec3f::new(0.0, 4.0, 0.0), Vec3f::ZERO, 0.5).unwrap();
        assert_eq!(l1, Vec3f::new(0.0, 4.5, 0.0));
        assert_eq!(l2, Vec3f::new(0.0, 3.5, 0.0));
        assert!(light_pair(Vec3f::ZERO, Vec3f::ZERO, 1.0).is_none());
    }

    #[test]
    fn envelope_argmin_is_a_nearest_feature() {
        let f = [FAR, 0.0, FAR, FAR, 4.0, FAR, 0.0, FAR];
        let (mut out, mut arg) = ([0.0f32; 8], [0u32; 8]);
        Envelope::new(8).transform(&f, &mut out, &mut arg);
        for q in 0..8 {
            let best = (0..8)
                .filter(|&p| f[p] != FAR)
                .map(|p| (q as f32 - p as f32).powi(2) + f[p])
                .fold(FAR, f32::min);
            assert_eq!(out[q], best, "q = {q}");
            let p = arg[q] as usize;
            assert_eq!((q as f32 - p as f32).powi(2) + f[p], best, "q = {q}: argmin {p}");
        }
        let mut none = [0u32; 3];
        Envelope::new(1).transform(&[FAR; 3], &mut [0.0; 3], &mut none);
        assert_eq!(none, [u32::MAX; 3]);
    }

    #[test]
    fn spot_map_encloses_the_corners_and_biases_by_texels() {
        let corners = [Vec3f::new(-4.0, 0.0, -4.0), Vec3f::new(4.0, 0.0, 4.0), Vec3f::new(4.0, 2.0, -4.0)];
        let m = SpotMap::look(Vec3f::new(0.0, 6.0, 0.0), Vec3f::ZERO, &corners);
        for c in corners {
            let v = m.to_view(c);
            assert!(v.x.abs() <= v.z * m.tan_half && v.y.abs() <= v.z * m.tan_half, "{v:?}");
        }
        // A floor point facing the light looks up a texel inside the map; the underside does not.
        let (x, y, z) = m.lookup(Vec3f::new(1.0, 0.0, 1.0), Vec3f::Y, 512).unwrap();
        assert!((0..512).contains(&x) && (0..512).contains(&y) && z > 5.9, "{x} {y} {z}");
        assert!(m.lookup(Vec3f::new(1.0, 0.0, 1.0), -Vec3f::Y, 512).is_none());
        // Within the bias a surface does not shadow itself; a caster a metre nearer does.
        assert!(!m.occludes(z - 0.5 * m.texel(z, 512), z, 512));
        assert!(m.occludes(z - 1.0, z, 512));
        // A light inside the objects' bounds takes the widest frustum.
        let wide = SpotMap::look(Vec3f::new(0.0, 1.0, 0.0), Vec3f::ZERO, &corners);
        assert_eq!(wide.tan_half, SPOT_MAX_TAN);
    }

    #[test]
    fn segment_brightness_is_the_visible_fraction_of_the_segment_light() {
        // Lights spread evenly along the axis from A₁ = 5 to A₂ = 3 (D = 4, l = 1): each throws an
        // edge's shadow at 1/a; a receiver point at image fraction s of the band between the
        // shadows of L₁ and L₂ sees exactly the lights whose shadow edge lies short of it.
        let (d, l) = (4.0f64, 1.0f64);
        let k = segment_ratio(l as f32, d as f32);
        assert!((f64::from(k) - 5.0 / 3.0).abs() < 1e-6);
        for j in 0..=20 {
            let s = j as f64 / 20.0;
            let x = 1.0 / (d + l) + s * (1.0 / (d - l) - 1.0 / (d + l));
            let m = 200_000;
            let seen = (0..m)
                .filter(|&i| {
                    let a = (d + l) - (i as f64 + 0.5) / m as f64 * 2.0 * l;
                    1.0 / a < x
                })
                .count() as f64
                / m as f64;
            let got = f64::from(segment_brightness(s as f32, (1.0 - s) as f32, k));
            assert!((got - seen).abs() < 2e-5, "s = {s}: {got} against {seen}");
        }
        // k = 1 is 003's ratio bit for bit; the ends and the degenerate cases stay finite.
        for (d1, d2) in [(0.0, 0.0), (1.0, 3.0), (2.5, 0.5), (FAR, 2.0), (2.0, FAR), (FAR, FAR)] {
            assert_eq!(segment_brightness(d1, d2, 1.0).to_bits(), penumbra_brightness(d1, d2).to_bits());
            for k in [1.0, 1.7, 1e6] {
                let v = segment_brightness(d1, d2, k);
                assert!((0.0..=1.0).contains(&v), "{d1} {d2} {k}: {v}");
            }
        }
        assert_eq!(segment_brightness(0.0, 4.0, 3.0), 0.0);
        assert_eq!(segment_brightness(4.0, 0.0, 3.0), 1.0);
        for (l, d) in [(0.0, 1.0), (-1.0, 1.0), (1.0, 1.0), (2.0, 1.0), (f32::NAN, 1.0), (1.0, f32::INFINITY)]
        {
            let k = segment_ratio(l, d);
            assert!((1.0..=1e6).contains(&k), "l = {l}, d = {d}: {k}");
        }
    }

    #[test]
    fn implied_disc_matches_the_band_width_of_the_two_maps() {
        // Edge at r = 0.5 off the axis at D = 4, receiver at D_r = 6, l = 0.5: the two shadows of
        // the edge are 2·l·r·(D_r − D)/(D² − l²) apart, a disc of radius R gives 2·R·(D_r − D)/D.
        let (l, r, d, dr) = (0.5f32, 0.5f32, 4.0f32, 6.0f32);
        let two_maps = r * ((dr - l) / (d - l) - (dr + l) / (d + l));
        let disc = 2.0 * implied_disc_radius(l, r, d) * (dr - d) / d;
        assert!((two_maps - disc).abs() < 1e-6, "{two_maps} vs {disc}");
        assert_eq!(implied_disc_radius(2.0, 1.0, 1.0), 2.0);
    }

    #[test]
    fn classes_follow_the_two_verdicts() {
        assert_eq!(Class::of(true, true), Class::Umbra);
        assert_eq!(Class::of(true, false), Class::Penumbra);
        assert_eq!(Class::of(false, true), Class::Penumbra);
        assert_eq!(Class::of(false, false), Class::Lit);
        assert!(same_surface(Vec3f::ZERO, Vec3f::Y, Vec3f::new(3.0, 0.5, 0.0)));
        assert!(!same_surface(Vec3f::ZERO, Vec3f::Y, Vec3f::new(1.0, 1.0, 0.0)));
    }

    #[test]
    fn caster_box_blocks_exactly_the_segments_that_enter_it_before_their_end() {
        // A box rotated about y, 2 × 1 × 0.5, corner at (1, 0, −1).
        let (c, sn) = (0.6f32, 0.8f32);
        let edges = [
            Vec3f::new(2.0 * c, 0.0, -2.0 * sn),
            Vec3f::new(0.0, 1.0, 0.0),
            Vec3f::new(0.5 * sn, 0.0, 0.5 * c),
        ];
        let origin = Vec3f::new(1.0, 0.0, -1.0);
        let b = CasterBox::from_edges(origin, edges).unwrap();
        let inside = |q: Vec3f| b.local(q).iter().all(|&u| (0.0..=1.0).contains(&u));
        assert!(inside(origin + (edges[0] + edges[1] + edges[2]) * 0.5));
        assert!(!inside(origin - edges[2] * 0.01));
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 8.0 - 4.0
        };
        let (mut hit, mut miss) = (0, 0);
        for _ in 0..3000 {
            let (e, p) = (Vec3f::new(next(), next(), next()), Vec3f::new(next(), next() * 0.3 + 0.5, next()));
            // Samples along the segment up to 1 − FIT_MARGIN with a safety band either side.
            let samples: Vec<bool> =
                (0..=4000).map(|j| inside(e + (p - e) * (j as f32 / 4000.0 * 0.99))).collect();
            let brute_in = samples.iter().any(|&x| x);
            let got = b.blocks(e, p);
            if brute_in {
                assert!(got, "{e:?} → {p:?} passes through the box");
                hit += 1;
            } else if !(0..=200).any(|j| inside(e + (p - e) * (0.99 + j as f32 * 0.0001 / 2.0))) {
                // Clear of the box to the end as well: never counted.
                assert!(!got, "{e:?} → {p:?} misses the box");
                miss += 1;
            }
        }
        assert!(hit > 100 && miss > 100, "{hit} hits, {miss} misses");
        // A point on the box's face, lit from outside: the segment enters it only at the point.
        let face = origin + edges[0] * 0.5 + edges[1] * 0.5;
        assert!(!b.blocks(face - edges[2] * 4.0, face));
        assert!(b.blocks(face - edges[2] * 4.0, face + edges[2] * 0.5));
        // A parallel segment beside a face, and flat or infinite edges.
        assert!(!b.blocks(Vec3f::new(1.0, 2.0, -1.0), Vec3f::new(3.0, 2.0, -1.0)));
        assert!(CasterBox::from_edges(origin, [edges[0], edges[0], edges[2]]).is_none());
        assert!(CasterBox::from_edges(origin, [edges[0] * f32::INFINITY, edges[1], edges[2]]).is_none());
    }

    #[test]
    fn fit_window_keys_keep_the_order_and_the_fitted_map_covers_the_window() {
        let vals = [-5.0f32, -1.5, -1e-30, -0.0, 0.0, 1e-30, 0.25, 3.0, 5.6];
        for w in vals.windows(2) {
            assert!(FitWindow::key(w[0]) <= FitWindow::key(w[1]), "{} {}", w[0], w[1]);
            assert_eq!(FitWindow::value(FitWindow::key(w[1])).to_bits(), w[1].to_bits());
        }
        let corners = [Vec3f::new(-4.0, 0.0, -4.0), Vec3f::new(4.0, 0.0, 4.0), Vec3f::new(4.0, 2.0, -4.0)];
        let map = SpotMap::look(Vec3f::new(0.0, 6.0, 0.0), Vec3f::ZERO, &corners);
        assert_eq!(map.fitted(&FitWindow::EMPTY, 512).tan_half, SPOT_MIN_TAN);
        // Points off the axis: the fitted (off-axis) map looks every one of them up inside, one
        // texel's normal offset included, and is far narrower than the map.
        let pts = [Vec3f::new(1.0, 0.0, 1.2), Vec3f::new(1.6, 0.0, 0.9), Vec3f::new(1.3, 0.4, 1.5)];
        let mut w = FitWindow::default();
        for p in pts {
            w.add(map.fit_coords(p).unwrap());
        }
        let fit = map.fitted(&w, 512);
        assert!(fit.tan_half < 0.2 * map.tan_half, "{} against {}", fit.tan_half, map.tan_half);
        for p in pts {
            for n in
                [Vec3f::Y, Vec3f::new(-0.6, 0.8, 0.0), Vec3f::new(0.0, 0.8, -0.6), Vec3f::new(0.6, 0.8, 0.0)]
            {
                let (x, y, _) = fit.lookup(p, n, 512).unwrap();
                assert!((0..512).contains(&x) && (0..512).contains(&y), "{p:?} {n:?}: {x} {y}");
            }
        }
        // The same depth and texel size as an on-axis map of that width: only the centre moves.
        let v = fit.to_view(pts[0]);
        assert!((v.z - map.to_view(pts[0]).z).abs() < 1e-5);
        // A window as wide as the map keeps the map.
        let mut all = FitWindow::default();
        all.add([-map.tan_half, -map.tan_half]);
        all.add([map.tan_half, map.tan_half]);
        assert_eq!(map.fitted(&all, 512), map);
        // Narrowing by less than FIT_GAIN keeps the map; by more, fits it.
        let window = |f: f32| {
            let mut w = FitWindow::default();
            w.add([-f * map.tan_half, -f * map.tan_half]);
            w.add([f * map.tan_half, f * map.tan_half]);
            w
        };
        assert_eq!(map.fitted(&window(0.6), 512), map);
        let narrow = map.fitted(&window(0.4), 512);
        assert!(narrow.tan_half < FIT_GAIN * map.tan_half && narrow.tan_half > 0.4 * map.tan_half);
        assert_eq!(w.union(FitWindow::EMPTY), w);
    }

    #[test]
    fn the_prepared_fit_test_gathers_the_same_window_as_the_rule() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        // A small box near the point of interest, a long wall past the light (reaching behind it:
        // an unbounded rectangle) and a tilted slab.
        let boxes = [
            CasterBox::from_edges(
                Vec3f::new(-0.3, 0.0, -0.3),
                [Vec3f::X * 0.6, Vec3f::Y * 1.5, Vec3f::Z * 0.6],
            ),
            CasterBox::from_edges(
                Vec3f::new(-4.0, 0.0, -2.0),
                [Vec3f::X * 8.0, Vec3f::Y * 4.0, Vec3f::Z * 0.2],
            ),
            CasterBox::from_edges(
                Vec3f::new(1.0, 0.5, 1.0),
                [Vec3f::new(0.8, 0.3, 0.0), Vec3f::new(0.0, 0.1, 0.9), Vec3f::new(0.05, 0.4, -0.02)],
            ),
        ]
        .map(Option::unwrap);
        let corners: Vec<Vec3f> = boxes
            .iter()
            .flat_map(|b| {
                (0..8).map(move |i| {
                    let u = |k: usize| (i >> k & 1) as f32;
                    b.origin + b.edges[0] * u(0) + b.edges[1] * u(1) + b.edges[2] * u(2)
                })
            })
            .collect();
        for eye in [Vec3f::new(2.5, 1.8, 1.0), Vec3f::new(0.5, 3.0, 2.0)] {
            let map = SpotMap::look(eye, Vec3f::new(0.0, 0.7, 0.0), &corners);
            for set in 0..3 {
                let test = FitTest::new(&map, &boxes[..=set]);
                let (mut rule, mut fast) = (FitWindow::EMPTY, FitWindow::EMPTY);
                for _ in 0..4000 {
                    let p = Vec3f::new(next() * 10.0 - 5.0, next() * 4.0, next() * 6.0 - 3.0);
                    rule.add_point(&map, &boxes[..=set], p);
                    test.add(&mut fast, p);
                }
                assert_ne!(rule, FitWindow::EMPTY);
                assert_eq!(rule, fast, "eye {eye:?}, boxes 0..={set}");
            }
        }
    }
}
