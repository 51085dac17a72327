//! `hadou bench`: rendering speed in the layout of the thesis's tables (002 §4, SPEC.md §1.5).
//!
//! The scenes are built from scene-file text, so the bench measures exactly what users render.
//! Every table — [`analytic_table`], [`curve_table`], [`toon_table`], [`soft_table`] and
//! [`limit_table`] — is a [`Report`] of [`Table`]s: rows of named cells, printed as aligned text
//! ([`Report::to_text`]) or as JSON ([`Report::to_json`]). Frames are timed by a [`Timer`]:
//! [`time_cpu`] for the CPU backend, the `hadou` binary's own for the GPU.

mod analytic;
mod curve_accuracy;
mod curves;
mod limit;
mod soft;
mod table;
mod timing;
mod toon;

pub use analytic::{analytic_frame, analytic_scene, analytic_table, ANALYTIC_SHAPES};
pub use curve_accuracy::{curve_accuracy, curve_reference, with_integrator, ACCURACY_GRID};
pub use curves::{curve_integrators, curve_table, AcceptanceRow, ACCEPTANCE_SCENES, CURVE_SCENES};
pub use limit::{limit_table, plain_beam_loop};
pub use soft::{
    soft_disc_radius, soft_errors, soft_table, truth_map, SoftOptions, REFERENCE_PIXELS, REFERENCE_SAMPLES,
    SOFT_METHODS, SOFT_SCENE, TRACED_SHAPES, TRUTH_MAP, TRUTH_SAMPLES,
};
pub use table::{rows_json, Align, Cell, Column, Report, Row, Table};
pub use timing::{median, median_ms, rgb8_output_ms, time_cpu, Timer, Timing};
pub use toon::{
    plain_materials, toon_table, without_mtoon, GLARE_SCENE, MTOON_SCENE, SHADOW_SCENE, TOON_SCENE,
};
