//! `GpuBackend::time_frame`: the method matches the device's features, the samples are sane, and
//! with timestamps the frame splits into its passes.

mod common;

use common::*;
use hadou_gpu::TimingMethod;

#[test]
fn time_frame_reports_its_method_and_positive_times() {
    let Some(mut gpu) = gpu_or_skip("time_frame") else { return };
    let frame = kamehameha_frame(256, 192);
    let t = gpu.time_frame(&frame, 3).expect("timing");
    let expected = if gpu.has_timestamps() { TimingMethod::GpuTimestamps } else { TimingMethod::WallClock };
    assert_eq!(t.method, expected);
    assert_eq!(t.per_iteration_ms.len(), 3);
    assert_eq!(t.tiles, 1);
    assert!(t.per_iteration_ms.iter().all(|&ms| ms > 0.0 && ms.is_finite()), "{t:?}");
    assert!(t.min_ms <= t.median_ms && t.median_ms <= t.per_iteration_ms.iter().cloned().fold(0.0, f64::max));
    eprintln!("{}: {:?}, median {:.3} ms ({:.0} fps)", gpu.adapter_name(), t.method, t.median_ms, t.fps());
    assert!(gpu.time_frame(&frame, 0).is_err());
}

/// The names of `t`'s passes, in order.
fn names(t: &hadou_gpu::FrameTiming) -> Vec<&str> {
    t.passes.iter().map(|p| p.name.as_str()).collect()
}

/// With timestamps every pass of the frame is timed (shadow maps, raster, plane shadows, wave,
/// a `[bloom]`'s glare chain) and, in one iteration, the passes sum to no more than the frame; without them (some GL drivers) there is no
/// split. A frame with nothing to draw skips the raster pass.
#[test]
fn time_frame_splits_the_frame_into_its_passes() {
    let Some(mut gpu) = gpu_or_skip("time_frame passes") else { return };
    let (_, shadows) = example_frames(|name| name == "shadow-uneven.toml").remove(0);
    let mut waves_only = kamehameha_frame(64, 48);
    waves_only.objects.clear();
    let (_, mut glare) = example_frames(|name| name == "glare-kamehameha.toml").remove(0);
    assert!(glare.bloom.is_some());
    (glare.width, glare.height) = (160, 120);
    let cases = [
        (kamehameha_frame(200, 150), vec!["raster", "wave"]),
        (shadows, vec!["shadow maps", "raster", "edges", "plane shadows", "wave"]),
        (waves_only, vec!["wave"]),
        // The glare chain after the tiles, inside the frame's time.
        (glare, vec!["raster", "wave", "bloom"]),
    ];
    for (frame, expected) in cases {
        let t = gpu.time_frame(&frame, 1).expect("timing");
        if !gpu.has_timestamps() {
            assert_eq!(t.method, TimingMethod::WallClock);
            assert!(t.passes.is_empty(), "no timestamps, no passes: {t:?}");
            continue;
        }
        assert_eq!(t.method, TimingMethod::GpuTimestamps);
        assert_eq!(names(&t), expected, "{t:?}");
        assert!(t.passes.iter().all(|p| p.median_ms >= 0.0 && p.median_ms.is_finite()), "{t:?}");
        let sum: f64 = t.passes.iter().map(|p| p.median_ms).sum();
        assert!(sum <= t.median_ms * (1.0 + 1e-9), "passes {sum} ms > frame {} ms: {t:?}", t.median_ms);
        assert!(t.passes.iter().any(|p| p.name == "wave" && p.median_ms > 0.0), "{t:?}");
        if frame.bloom.is_some() {
            assert!(t.passes.iter().any(|p| p.name == "bloom" && p.median_ms > 0.0), "{t:?}");
        }
        // Several iterations: each pass's median is within the frame's.
        let t = gpu.time_frame(&frame, 3).expect("timing");
        let max = t.per_iteration_ms.iter().cloned().fold(0.0, f64::max);
        assert!(t.passes.iter().all(|p| p.median_ms <= max), "{t:?}");
    }
}

/// A frame with an `[area_light]` is timed by the wall clock (its soft shadows are prepared
/// with it), split into the soft preparation and the tiles, on any adapter: each part positive,
/// and in every iteration together no more than the frame.
#[test]
fn time_frame_times_an_area_light_frame_by_the_wall_clock() {
    let Some(mut gpu) = gpu_or_skip("time_frame area light") else { return };
    let (_, mut frame) = example_frames(|name| name == "soft-gradient.toml").remove(0);
    assert!(frame.area_light.is_some());
    frame.width = 96;
    frame.height = 72;
    let t = gpu.time_frame(&frame, 2).expect("timing");
    assert_eq!(t.method, TimingMethod::WallClock);
    assert_eq!(names(&t), [hadou_gpu::SOFT_PREPARATION, hadou_gpu::SOFT_TILES]);
    assert!(t.passes.iter().all(|p| p.median_ms > 0.0 && p.median_ms.is_finite()), "{t:?}");
    assert_eq!(t.per_iteration_ms.len(), 2);
    assert!(t.per_iteration_ms.iter().all(|&ms| ms > 0.0 && ms.is_finite()), "{t:?}");
    // The parts' medians, each at most the slowest frame; their sum at most the two frames.
    let slowest = t.per_iteration_ms.iter().copied().fold(0.0, f64::max);
    assert!(t.passes.iter().all(|p| p.median_ms <= slowest), "{t:?}");
    let sum: f64 = t.passes.iter().map(|p| p.median_ms).sum();
    assert!(sum <= t.per_iteration_ms.iter().sum::<f64>(), "{t:?}");
}

/// `time_wave_overlay` times the overlay pass alone (wall clock): one sample per iteration, each
/// finite and positive; zero iterations and an invalid frame are errors, not panics.
#[test]
fn time_wave_overlay_reports_positive_times_and_refuses_nonsense() {
    let Some(mut gpu) = gpu_or_skip("time_wave_overlay") else { return };
    let frame = kamehameha_frame(160, 120);
    let t = gpu.time_wave_overlay(&frame, 3).expect("timing");
    assert_eq!(t.method, TimingMethod::WallClock);
    assert_eq!(t.per_iteration_ms.len(), 3);
    assert!(t.per_iteration_ms.iter().all(|&ms| ms > 0.0 && ms.is_finite()), "{t:?}");
    assert!(t.min_ms <= t.median_ms && t.passes.is_empty(), "{t:?}");
    eprintln!("{}: overlay median {:.3} ms", gpu.adapter_name(), t.median_ms);
    assert!(gpu.time_wave_overlay(&frame, 0).is_err());
    let mut bad = frame.clone();
    bad.width = 0;
    assert!(gpu.time_wave_overlay(&bad, 1).is_err());
}
