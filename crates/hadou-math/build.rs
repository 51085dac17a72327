//! `cfg(hadou_unoptimized)` where this crate is compiled at opt-level 0 (the dev profile's
//! default, also a downstream crate's debug build): there [`Lane::outlined_if_unoptimized`]
//! runs the lane kernels in frames of their own (see `src/simd/lane.rs`).

fn main() {
    println!("cargo::rustc-check-cfg=cfg(hadou_unoptimized)");
    println!("cargo::rerun-if-changed=build.rs");
    if std::env::var("OPT_LEVEL").as_deref() == Ok("0") {
        println!("cargo::rustc-cfg=hadou_unoptimized");
    }
}
