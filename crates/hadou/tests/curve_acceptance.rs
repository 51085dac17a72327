//! The default curve integrator against faithful Simpson `m = 500` on every example curve scene
//! (`hadou::bench::ACCEPTANCE_SCENES`), measured as `hadou bench curves` measures them but on a
//! coarser pixel grid: 99th-percentile relative energy error ≤ 0.5 %, Simpson further from the
//! converged reference, and at least 10× fewer curve evaluations per pixel. (The 5× time bar is
//! measured by the bench, not by a test.)

use hadou::bench::{curve_accuracy, curve_reference, with_integrator, ACCEPTANCE_SCENES};
use hadou_math::curve::Integrator;
use hadou_scene::Scene;
use std::path::Path;

/// Pixels per side of the test grid (the bench uses 64).
const GRID: u32 = 24;

#[test]
fn default_integrator_meets_the_bars_on_every_example_scene() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut failures = Vec::new();
    for &(label, file, t) in &ACCEPTANCE_SCENES {
        let scene = Scene::load(dir.join(file)).unwrap_or_else(|e| panic!("{e}"));
        let base = scene.at(t);
        let reference = curve_reference(&base, GRID);
        assert!(reference.iter().any(|&r| r > 0.0), "{label}: the curve is not in view");
        let simpson = with_integrator(&base, Integrator::Simpson { m: 500, reduction: None });
        let (s_evals, s_p99) = curve_accuracy(&simpson, &reference, GRID);
        let (d_evals, d_p99) = curve_accuracy(&with_integrator(&base, Integrator::Default), &reference, GRID);
        println!(
            "{label}: default p99 {d_p99:.2e}, {d_evals:.1} evals; Simpson m=500 p99 {s_p99:.2e}, {s_evals:.1} evals ({:.1}×)",
            s_evals / d_evals
        );
        if !(d_p99 <= 5e-3 && s_p99 > d_p99 && s_evals >= 10.0 * d_evals) {
            failures.push(label);
        }
    }
    assert!(failures.is_empty(), "bars not met on {failures:?} (see the printed lines)");
}
