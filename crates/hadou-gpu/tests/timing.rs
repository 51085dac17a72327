//! `GpuBackend::time_frame`: the method matches the device's features and the samples are sane.

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
