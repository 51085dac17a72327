//! The window and its GPU state ([`Gfx`]): the winit window, the wgpu surface and the one device
//! that draws egui into it and, on an adapter that can run hadou, renders the GPU backend's
//! viewport; the backend the viewport starts with; one egui frame drawn and presented.

use super::options::{fail, no_display_message, ViewError};
use hadou_gpu::wgpu;
use hadou_gpu::GpuBackend;
use hadou_view::viewer::{BackendKind, Viewer};
use std::sync::Arc;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

/// The window's GPU state.
pub(super) struct Gfx {
    pub(super) window: Arc<Window>,
    pub(super) surface: wgpu::Surface<'static>,
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    pub(super) config: wgpu::SurfaceConfiguration,
    pub(super) egui_renderer: egui_wgpu::Renderer,
    pub(super) egui_state: egui_winit::State,
    /// The GPU backend on the window's device (when the adapter can run hadou).
    pub(super) gpu: Option<GpuBackend>,
    pub(super) gpu_texture: Option<egui::TextureId>,
    /// The CPU backend's image texture.
    pub(super) cpu_texture: Option<(wgpu::Texture, egui::TextureId, [u32; 2])>,
    pub(super) adapter_software: bool,
    pub(super) adapter_name: String,
    /// The last size the surface was configured at without an error (the fallback).
    good: [u32; 2],
    /// Frames in a row that had no surface texture to draw into.
    misses: u32,
    /// Set when the surface gave no texture for [`MAX_MISSES`] frames in a row: drawing stops
    /// until the surface is configured again (a resize), so a broken surface does not spin.
    broken: bool,
}

/// What drawing one frame came to.
pub(super) enum Drawn {
    /// Drawn and presented.
    Presented,
    /// Not drawn: the surface had no texture this time (occluded, timed out, or configured again
    /// to try the next frame).
    Skipped,
    /// The surface gave no texture for [`MAX_MISSES`] frames in a row, even configured again;
    /// nothing is drawn until it is configured again. The message says why.
    Failed(String),
}

/// Frames in a row without a surface texture before drawing stops.
const MAX_MISSES: u32 = 3;

impl Gfx {
    /// Opens the window on `viewer`'s scene, its surface and device, and the GPU backend on that
    /// device where the adapter can run it; returns them with the backend the viewport starts with
    /// (`forced` by `--backend`, else chosen here), which `viewer`'s statistics name. `scripted`
    /// runs present without waiting for the display where they can.
    pub(super) fn open(
        event_loop: &ActiveEventLoop,
        viewer: &mut Viewer,
        egui_ctx: &egui::Context,
        scripted: bool,
        forced: Option<BackendKind>,
    ) -> Result<(Gfx, BackendKind), ViewError> {
        let scene = viewer.scene();
        let (w, h) = (scene.width(), scene.height());
        let title = format!("hadou — {}", viewer.doc.path().display());
        let size = winit::dpi::LogicalSize::new((w + 380).clamp(640, 1800), (h + 130).clamp(420, 1200));
        let attrs = Window::default_attributes().with_title(title).with_inner_size(size);
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| fail(1, no_display_message(&format!("cannot create a window: {e}"))))?,
        );
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
            Box::new(event_loop.owned_display_handle()),
        ));
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| fail(1, format!("cannot draw into the window: {e}")))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
        }))
        .map_err(|e| fail(1, format!("no GPU adapter can draw into the window: {e}")))?;
        let info = adapter.get_info();
        let hadou_ok = hadou_gpu::check_adapter(&adapter);
        let desc = match hadou_ok {
            Ok(()) => hadou_gpu::device_descriptor(&adapter),
            Err(_) => wgpu::DeviceDescriptor {
                label: Some("hadou view"),
                required_limits: wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits()),
                ..Default::default()
            },
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&desc))
            .map_err(|e| fail(1, format!("cannot open the GPU device for the window: {e}")))?;
        let caps = surface.get_capabilities(&adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| fail(1, "the window's surface offers no pixel format"))?;
        let present_mode = if scripted && caps.present_modes.contains(&wgpu::PresentMode::Immediate) {
            wgpu::PresentMode::Immediate
        } else {
            wgpu::PresentMode::AutoVsync
        };
        let inner = window.inner_size();
        let max = device.limits().max_texture_dimension_2d;
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: inner.width.clamp(1, max),
            height: inner.height.clamp(1, max),
            present_mode,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        if inner.width > 0 && inner.height > 0 {
            configure_scoped(&surface, &device, &config)
                .map_err(|e| fail(1, format!("cannot draw into the window: {e}")))?;
        }
        let egui_renderer = egui_wgpu::Renderer::new(&device, format, egui_wgpu::RendererOptions::default());
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        let gpu = match hadou_ok {
            Ok(()) => match GpuBackend::from_device(&adapter, device.clone(), queue.clone()) {
                Ok(g) => Some(g),
                Err(e) => {
                    viewer.complain(format!("the GPU backend cannot start on {}: {e}", info.name));
                    None
                }
            },
            Err(e) => {
                viewer.say(format!("GPU backend unavailable: {e}"));
                None
            }
        };
        let software = info.device_type == wgpu::DeviceType::Cpu;
        let (backend, note) = match (forced, &gpu) {
            (Some(BackendKind::Gpu), None) => {
                return Err(fail(
                    2,
                    format!(
                        "--backend gpu: the window's adapter {} cannot run hadou's GPU backend",
                        info.name
                    ),
                ))
            }
            (Some(b), _) => (b, "chosen with --backend".to_string()),
            (None, None) => (BackendKind::Cpu, "auto: no usable GPU backend".into()),
            (None, Some(_)) if software => (
                BackendKind::Cpu,
                format!("auto: {} is a software rasterizer; the CPU backend is faster", info.name),
            ),
            (None, Some(_)) => (BackendKind::Gpu, format!("auto: hardware GPU {}", info.name)),
        };
        viewer.stats.backend = Some(backend);
        viewer.stats.backend_note = note;
        viewer.stats.adapter = format!("{} ({:?})", info.name, info.backend);
        let good = [config.width, config.height];
        let gfx = Gfx {
            window,
            surface,
            device,
            queue,
            config,
            egui_renderer,
            egui_state,
            gpu,
            gpu_texture: None,
            cpu_texture: None,
            adapter_software: software,
            adapter_name: info.name.clone(),
            good,
            misses: 0,
            broken: false,
        };
        Ok((gfx, backend))
    }

    /// The largest edge a surface may have on this device.
    pub(super) fn max_edge(&self) -> u32 {
        self.device.limits().max_texture_dimension_2d
    }

    /// The size the surface is configured at.
    pub(super) fn size(&self) -> [u32; 2] {
        [self.config.width, self.config.height]
    }

    /// The last size the surface was configured at without an error.
    pub(super) fn last_good(&self) -> [u32; 2] {
        self.good
    }

    /// Configures the surface at `w × h` pixels (both > 0; the caller has checked them against
    /// [`Gfx::max_edge`] and the scene's limits). An error the device reports (out of memory, a
    /// size the surface refuses) configures it back at the last size that worked and is returned.
    pub(super) fn configure(&mut self, w: u32, h: u32) -> Result<(), String> {
        let max = self.max_edge();
        if w == 0 || h == 0 || w > max || h > max {
            return Err(format!("the window's surface cannot be {w}×{h} pixels (1..={max} on this adapter)"));
        }
        self.config.width = w;
        self.config.height = h;
        self.misses = 0;
        self.broken = false;
        match configure_scoped(&self.surface, &self.device, &self.config) {
            Ok(()) => {
                self.good = [w, h];
                Ok(())
            }
            Err(e) => {
                let [gw, gh] = self.good;
                self.config.width = gw;
                self.config.height = gh;
                let back = match configure_scoped(&self.surface, &self.device, &self.config) {
                    Ok(()) => format!("it stays {gw}×{gh}"),
                    Err(e2) => {
                        self.broken = true;
                        format!("nor at {gw}×{gh} ({e2})")
                    }
                };
                Err(format!("the window's surface cannot be configured at {w}×{h} pixels ({e}); {back}"))
            }
        }
    }

    /// Runs one egui frame of `ui` and presents it on the window's surface. When the surface has
    /// no texture to draw into it is configured again for the next frame; after [`MAX_MISSES`]
    /// frames in a row without one (or when it cannot be configured) drawing stops with
    /// [`Drawn::Failed`] until [`Gfx::configure`] is called again.
    pub(super) fn draw(&mut self, egui_ctx: &egui::Context, ui: impl FnMut(&mut egui::Ui)) -> Drawn {
        if self.broken {
            return Drawn::Skipped;
        }
        let raw = self.egui_state.take_egui_input(&self.window);
        let out = egui_ctx.run_ui(raw, ui);
        // egui wants another pass at once (after input, while it animates): one more frame.
        if out.viewport_output.get(&egui::ViewportId::ROOT).is_some_and(|v| v.repaint_delay.is_zero()) {
            self.window.request_redraw();
        }
        self.egui_state.handle_platform_output(&self.window, out.platform_output);
        let jobs = egui_ctx.tessellate(out.shapes, out.pixels_per_point);
        for (id, delta) in &out.textures_delta.set {
            self.egui_renderer.update_texture(&self.device, &self.queue, *id, delta);
        }
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: out.pixels_per_point,
        };
        let mut drawn = Drawn::Presented;
        let surface_texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => {
                self.misses = 0;
                Some(t)
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                drawn = Drawn::Skipped;
                None
            }
            other => {
                self.misses += 1;
                let configured = configure_scoped(&self.surface, &self.device, &self.config);
                drawn = match configured {
                    Err(e) => Drawn::Failed(format!(
                        "the window's surface gave no texture ({other:?}) and cannot be configured \
                         again at {}×{} pixels: {e}",
                        self.config.width, self.config.height
                    )),
                    Ok(()) if self.misses >= MAX_MISSES => Drawn::Failed(format!(
                        "the window's surface gave no texture at {}×{} pixels {MAX_MISSES} frames in a \
                         row ({other:?})",
                        self.config.width, self.config.height
                    )),
                    Ok(()) => Drawn::Skipped,
                };
                if matches!(drawn, Drawn::Failed(_)) {
                    self.broken = true;
                }
                None
            }
        };
        if let Some(st) = surface_texture {
            let view = st.texture.create_view(&Default::default());
            let mut enc = self.device.create_command_encoder(&Default::default());
            let extra =
                self.egui_renderer.update_buffers(&self.device, &self.queue, &mut enc, &jobs, &screen);
            {
                let pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("egui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color { r: 0.05, g: 0.05, b: 0.06, a: 1.0 }),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                let mut pass = pass.forget_lifetime();
                self.egui_renderer.render(&mut pass, &jobs, &screen);
            }
            self.queue.submit(extra.into_iter().chain([enc.finish()]));
            self.window.pre_present_notify();
            st.present();
        }
        for id in &out.textures_delta.free {
            self.egui_renderer.free_texture(id);
        }
        drawn
    }
}

/// Configures `surface` inside error scopes, so that an error the device reports (out of memory, a
/// configuration the surface refuses) comes back here instead of going to the device's handler.
fn configure_scoped(
    surface: &wgpu::Surface<'_>,
    device: &wgpu::Device,
    config: &wgpu::SurfaceConfiguration,
) -> Result<(), String> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    surface.configure(device, config);
    // Popped in reverse order of pushing; wgpu-core pops at once (no wait).
    let errors = [
        pollster::block_on(validation.pop()),
        pollster::block_on(internal.pop()),
        pollster::block_on(oom.pop()),
    ];
    match errors.into_iter().flatten().next() {
        Some(e) => Err(e.to_string()),
        None => Ok(()),
    }
}
