//! `GpuBackend::encode_wave_overlay`: the waves drawn into a colour target and against a depth
//! buffer that the test owns (as a game engine's frame owns them), compared with hadou-cpu's
//! energies for the same frame. The depth buffer holds a wall at one view depth (cleared to that
//! depth's value in each depth model), so the CPU reference is the same frame with that wall as an
//! object: per pixel the overlay must be `exposure · rgb·a·E` with `E` the CPU's energy clipped at
//! the wall, added to what the target held (or replacing it); where the depth buffer holds nothing,
//! the frame without the wall.
//!
//! Skips with a message when there is no usable adapter; fails instead under
//! `HADOU_REQUIRE_GPU=1`.

mod common;

use common::{gpu_or_skip, kamehameha_frame};
use hadou_cpu::CpuBackend;
use hadou_gpu::{DepthModel, GpuBackend, OverlayBlend, OverlayProjection, OverlayTarget};
use hadou_math::Mat4;
use hadou_scene::{Backend, Frame, Mesh, Object};
use std::sync::Arc;

const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// An `f16` (IEEE binary16) as `f32`.
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let frac = f32::from(h & 0x3ff);
    match exp {
        0 => sign * frac * 2f32.powi(-24),
        31 => sign * if frac == 0.0 { f32::INFINITY } else { f32::NAN },
        _ => sign * (1.0 + frac / 1024.0) * 2f32.powi(exp - 15),
    }
}

/// A quad facing the camera at view depth `z`, far wider than the view.
fn wall(frame: &Frame, z: f32) -> Object {
    let b = frame.camera.basis(frame.width, frame.height);
    let c = b.eye + b.forward * z;
    let (r, u) = (b.right * 500.0, b.up * 500.0);
    let corners = [c - r - u, c + r - u, c + r + u, c - r + u];
    let mesh = Mesh {
        positions: corners.iter().map(|p| [p.x, p.y, p.z]).collect(),
        normals: vec![[-b.forward.x, -b.forward.y, -b.forward.z]; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Mesh::default()
    };
    Object::new("wall", Arc::new(mesh), Mat4::IDENTITY, [0.5; 3])
}

/// Draws the overlay of `frame` into a colour target cleared to `clear` against a depth buffer
/// cleared to `depth`, and reads the colour back (RGBA per pixel).
fn overlay(
    gpu: &mut GpuBackend,
    frame: &Frame,
    depth: f32,
    model: DepthModel,
    blend: OverlayBlend,
    clear: [f64; 4],
) -> Vec<[f32; 4]> {
    overlay_samples(gpu, frame, depth, model, blend, clear, 1)
}

/// The error of `encode_wave_overlay` against a depth buffer of `samples` samples per pixel.
fn overlay_refused(gpu: &mut GpuBackend, frame: &Frame, samples: u32) -> String {
    let device = gpu.device().clone();
    let size = wgpu::Extent3d { width: frame.width, height: frame.height, depth_or_array_layers: 1 };
    let make = |format, sample_count| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size,
            mip_level_count: 1,
            sample_count,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        })
    };
    let color = make(COLOR_FORMAT, 1).create_view(&Default::default());
    let depth = make(wgpu::TextureFormat::Depth32Float, samples).create_view(&Default::default());
    let target = OverlayTarget {
        color: &color,
        color_format: COLOR_FORMAT,
        depth: &depth,
        depth_model: DepthModel::ReverseInfinite,
        depth_samples: samples,
        blend: OverlayBlend::Replace,
        origin: [0, 0],
        projection: OverlayProjection::Perspective,
    };
    let mut enc = device.create_command_encoder(&Default::default());
    gpu.encode_wave_overlay(frame, &mut enc, &target).expect_err("refused on OpenGL").to_string()
}

/// [`overlay`] against a depth buffer of `samples` samples per pixel (an MSAA engine's).
fn overlay_samples(
    gpu: &mut GpuBackend,
    frame: &Frame,
    depth: f32,
    model: DepthModel,
    blend: OverlayBlend,
    clear: [f64; 4],
    samples: u32,
) -> Vec<[f32; 4]> {
    overlay_with(gpu, frame, depth, model, blend, clear, samples, false)
}

/// [`overlay_samples`], drawn by `encode_prepared_wave_overlay` from the frame's waves prepared
/// beforehand (`layout::frame_waves`) when `prepared` is set.
#[allow(clippy::too_many_arguments)]
fn overlay_with(
    gpu: &mut GpuBackend,
    frame: &Frame,
    depth: f32,
    model: DepthModel,
    blend: OverlayBlend,
    clear: [f64; 4],
    samples: u32,
    prepared: bool,
) -> Vec<[f32; 4]> {
    overlay_at(gpu, frame, depth, model, blend, clear, samples, prepared, [0, 0])
}

/// [`overlay_with`] into textures `origin` larger than the frame in each direction, the frame
/// drawn at `origin` (a viewport's corner): the frame's pixels, read back from there.
#[allow(clippy::too_many_arguments)]
fn overlay_at(
    gpu: &mut GpuBackend,
    frame: &Frame,
    depth: f32,
    model: DepthModel,
    blend: OverlayBlend,
    clear: [f64; 4],
    samples: u32,
    prepared: bool,
    origin: [u32; 2],
) -> Vec<[f32; 4]> {
    let (w, h) = (frame.width, frame.height);
    let (tw, th) = (w + origin[0], h + origin[1]);
    let device = gpu.device().clone();
    let queue = gpu.queue().clone();
    let texture = |format, usage, sample_count| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d { width: tw, height: th, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let color =
        texture(COLOR_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC, 1);
    let depth_texture = texture(
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        samples,
    );
    let (color_view, depth_view) =
        (color.create_view(&Default::default()), depth_texture.create_view(&Default::default()));
    let mut enc = device.create_command_encoder(&Default::default());
    // The caller's own frame: its (resolved) colour and its depth, here just cleared.
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("the caller's colour"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &color_view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color { r: clear[0], g: clear[1], b: clear[2], a: clear[3] }),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("the caller's depth"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth_view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(depth),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    let target = OverlayTarget {
        color: &color_view,
        color_format: COLOR_FORMAT,
        depth: &depth_view,
        depth_model: model,
        depth_samples: samples,
        blend,
        origin,
        projection: OverlayProjection::Perspective,
    };
    if prepared {
        let waves = hadou_gpu::layout::frame_waves(frame).expect("the frame's waves");
        gpu.encode_prepared_wave_overlay(frame, &waves, &mut enc, &target)
            .expect("encode_prepared_wave_overlay");
    } else {
        gpu.encode_wave_overlay(frame, &mut enc, &target).expect("encode_wave_overlay");
    }
    let row = (8 * w).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("overlay read-back"),
        size: row as u64 * h as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            origin: wgpu::Origin3d { x: origin[0], y: origin[1], z: 0 },
            ..color.as_image_copy()
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
    queue.submit([enc.finish()]);
    buffer.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("mapping the read-back buffer"));
    device
        .poll(wgpu::PollType::Wait {
            submission_index: None,
            timeout: Some(std::time::Duration::from_secs(300)),
        })
        .expect("waiting for the GPU");
    let mapped = buffer.slice(..).get_mapped_range();
    let mut out = Vec::with_capacity(w as usize * h as usize);
    for y in 0..h as usize {
        for x in 0..w as usize {
            let at = y * row as usize + 8 * x;
            let c: [f32; 4] = std::array::from_fn(|k| {
                f16_to_f32(u16::from_le_bytes([mapped[at + 2 * k], mapped[at + 2 * k + 1]]))
            });
            out.push(c);
        }
    }
    drop(mapped);
    buffer.unmap();
    out
}

/// Holds every pixel of `got` to `base + exposure·rgb·a·E` (alpha: `alpha`), with `E` the CPU's
/// energy of `reference`, within the half float's precision and the backends' energy tolerance.
fn assert_matches(what: &str, got: &[[f32; 4]], reference: &Frame, base: [f32; 3], alpha: f32) {
    let cpu = CpuBackend::new().render(reference).expect("CPU render");
    let w = &reference.waves[0];
    let k = w.color[3] * reference.color_mapping.exposure;
    let mut worst = 0.0f32;
    let mut lit = 0;
    for (i, c) in got.iter().enumerate() {
        let e = cpu.energy[i];
        for ch in 0..3 {
            let want = base[ch] + k * w.color[ch] * e;
            let err = (c[ch] - want).abs();
            let tol = 3e-3 * want.abs() + 2e-3;
            worst = worst.max(err / tol);
            assert!(
                err <= tol,
                "{what}: pixel {i} channel {ch}: overlay {} against {want} (energy {e})",
                c[ch]
            );
        }
        assert_eq!(c[3], alpha, "{what}: pixel {i} alpha");
        lit += usize::from(e > 1e-2);
    }
    assert!(lit > got.len() / 20, "{what}: the beam is in view ({lit} lit pixels)");
    eprintln!("{what}: worst error {worst:.3} of the tolerance");
}

#[test]
fn the_overlay_is_the_waves_light_clipped_at_the_callers_depth() {
    let Some(mut gpu) = gpu_or_skip("wave overlay") else { return };
    let open = kamehameha_frame(80, 48);
    let (near, far) = (open.camera.near, open.camera.far);
    // A wall through the beam: nearer pixels keep part of its light, the rest none.
    let z = 12.5;
    let mut walled = open.clone();
    walled.objects = vec![wall(&open, z)];
    let standard = far * (z - near) / (z * (far - near));
    let base = [0.25, 0.5, 0.75];
    let clear = [0.25, 0.5, 0.75, 1.0];

    let got = overlay(&mut gpu, &open, standard, DepthModel::Standard, OverlayBlend::Add, clear);
    assert_matches("standard depth, added", &got, &walled, base, 1.0);

    let got = overlay(&mut gpu, &open, near / z, DepthModel::ReverseInfinite, OverlayBlend::Replace, clear);
    assert_matches("reverse infinite depth, replaced", &got, &walled, [0.0; 3], 0.0);

    // Cleared depth: nothing drawn, the whole ray (the frame without any object).
    let mut bare = open.clone();
    bare.objects.clear();
    let got = overlay(&mut gpu, &open, 1.0, DepthModel::Standard, OverlayBlend::Replace, clear);
    assert_matches("nothing drawn (standard)", &got, &bare, [0.0; 3], 0.0);
    let got = overlay(&mut gpu, &open, 0.0, DepthModel::ReverseInfinite, OverlayBlend::Replace, clear);
    assert_matches("nothing drawn (reverse)", &got, &bare, [0.0; 3], 0.0);

    // An MSAA engine's depth buffer (4 samples; its first is read): the same light. On OpenGL
    // (which read it as empty) it is refused with an error instead.
    if gpu.adapter_info().backend == wgpu::Backend::Gl {
        let message = overlay_refused(&mut gpu, &open, 4);
        assert!(message.contains("multisampled") && message.contains("OpenGL"), "{message}");
    } else {
        let got = overlay_samples(
            &mut gpu,
            &open,
            near / z,
            DepthModel::ReverseInfinite,
            OverlayBlend::Replace,
            clear,
            4,
        );
        assert_matches("reverse infinite depth, 4 samples, replaced", &got, &walled, [0.0; 3], 0.0);
    }

    // The wall must matter, or the test could not fail on the clipping.
    let mut cpu = CpuBackend::new();
    let (a, b) = (cpu.render(&walled).unwrap(), cpu.render(&bare).unwrap());
    assert!(a.energy.iter().zip(&b.energy).any(|(x, y)| (x - y).abs() > 0.1 * y.abs() + 1e-2));
}

/// A caller that prepares the frame's waves once (hadou-bevy: once per frame for every view and
/// for its materials' wave lights) gets the very pixels of the overlay that prepares them itself,
/// curves included; waves prepared for another frame are refused.
#[test]
fn prepared_waves_draw_the_same_overlay() {
    let Some(mut gpu) = gpu_or_skip("prepared wave overlay") else { return };
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let scene = hadou_scene::Scene::load(scenes.join("fig4-2-bspline.toml")).expect("the example scene");
    let mut frame = scene.at(0.5);
    (frame.width, frame.height) = (48, 32);
    let mut with_beam = kamehameha_frame(48, 32);
    with_beam.waves.extend(frame.waves.iter().cloned());
    assert!(with_beam.waves.iter().any(|w| w.shape.curve().is_some()), "a curved wave is drawn");
    let clear = [0.0, 0.0, 0.0, 1.0];
    let (model, blend) = (DepthModel::Standard, OverlayBlend::Replace);
    let own = overlay_with(&mut gpu, &with_beam, 1.0, model, blend, clear, 1, false);
    let prepared = overlay_with(&mut gpu, &with_beam, 1.0, model, blend, clear, 1, true);
    assert!(own.iter().any(|p| p[0] > 0.0), "the overlay draws light");
    assert_eq!(own, prepared, "the prepared overlay's pixels");

    let device = gpu.device().clone();
    let (color, depth) = targets(&device, &with_beam);
    let target = OverlayTarget {
        color: &color,
        color_format: COLOR_FORMAT,
        depth: &depth,
        depth_model: model,
        depth_samples: 1,
        blend,
        origin: [0, 0],
        projection: OverlayProjection::Perspective,
    };
    let other = hadou_gpu::layout::frame_waves(&frame).expect("the other frame's waves");
    let mut enc = device.create_command_encoder(&Default::default());
    let message = gpu
        .encode_prepared_wave_overlay(&with_beam, &other, &mut enc, &target)
        .expect_err("waves of another frame")
        .to_string();
    assert!(message.contains("prepared waves"), "{message}");
}

/// A colour target and a single-sample depth buffer of `frame`'s size, as views.
fn targets(device: &wgpu::Device, frame: &Frame) -> (wgpu::TextureView, wgpu::TextureView) {
    let size = wgpu::Extent3d { width: frame.width, height: frame.height, depth_or_array_layers: 1 };
    let make = |format| {
        device
            .create_texture(&wgpu::TextureDescriptor {
                label: None,
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&Default::default())
    };
    (make(COLOR_FORMAT), make(wgpu::TextureFormat::Depth32Float))
}

/// A frame drawn into a viewport whose corner is not the target's (split screen, picture in
/// picture: `OverlayTarget::origin`) gets the very pixels it gets at the target's corner, clipped
/// at the same depth; on every backend.
#[test]
fn a_viewport_away_from_the_corner_draws_the_same_waves() {
    let Some(mut gpu) = gpu_or_skip("wave overlay in a viewport") else { return };
    let frame = kamehameha_frame(40, 24);
    let (near, z) = (frame.camera.near, 12.5);
    let clear = [0.0, 0.0, 0.0, 1.0];
    let (model, blend) = (DepthModel::ReverseInfinite, OverlayBlend::Replace);
    let corner = overlay_at(&mut gpu, &frame, near / z, model, blend, clear, 1, false, [0, 0]);
    let moved = overlay_at(&mut gpu, &frame, near / z, model, blend, clear, 1, true, [13, 7]);
    assert!(corner.iter().any(|p| p[0] > 0.0), "the overlay draws light");
    // Not a picture that is the same everywhere: a shifted one would differ.
    assert!(corner.iter().any(|p| p != &corner[0]));
    assert_eq!(corner, moved, "the frame's pixels at (13, 7)");
}
