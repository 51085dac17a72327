//! `hadou probe`: one pixel's opaque result and every wave's energy there ([`probe`]), through the
//! same set-up, opaque pass and batched wave code as the render, so it reports exactly what the
//! render drew.

use crate::opaque::{OpaqueBuffers, NONE};
use crate::render::opaque_pass;
use crate::setup::FrameSetup;
use crate::waves::{self, WavePass};
use hadou_scene::Frame;

/// What `hadou probe` reports about one pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    /// Pixel x.
    pub x: u32,
    /// Pixel y (0 = top row).
    pub y: u32,
    /// Each wave's name, integrated energy and integrand evaluations, in scene order.
    pub waves: Vec<WaveProbe>,
    /// Final linear RGBA.
    pub color: [f32; 4],
    /// Eye distance to the visible surface or the far plane.
    pub depth: f32,
    /// Name of the visible object, if any.
    pub object: Option<String>,
    /// Name of the `[[shadow]]` darkening the pixel, if any.
    pub shadow: Option<String>,
    /// With an `[area_light]`, the pixel's soft-shadow visibility (0 umbra … 1 lit) where a
    /// surface is visible.
    pub soft: Option<f32>,
}

impl Probe {
    /// The probe in one line, as the viewer's status shows it: each wave's energy and
    /// evaluations, the colour, the depth and the object.
    pub fn summary(&self) -> String {
        let waves: Vec<String> = self
            .waves
            .iter()
            .map(|w| format!("{} E={:.4} ({} evals)", w.name, w.energy, w.evaluations))
            .collect();
        format!(
            "pixel ({}, {}): {} · rgb [{:.3}, {:.3}, {:.3}] · depth {:.3}{}",
            self.x,
            self.y,
            if waves.is_empty() { "no waves".to_string() } else { waves.join(", ") },
            self.color[0],
            self.color[1],
            self.color[2],
            self.depth,
            self.object.as_ref().map(|o| format!(" · object {o}")).unwrap_or_default()
        )
    }
}

/// One wave's contribution at a probed pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct WaveProbe {
    /// Wave name.
    pub name: String,
    /// Integrated energy `I`.
    pub energy: f32,
    /// Integrand evaluations (closed-form pieces for analytic shapes).
    pub evaluations: u32,
}

/// Probes one pixel: renders the opaque pass and evaluates every wave there, at the pixel's centre
/// and one sample (`frame.samples` is not used: the pixel of the frame at `samples = 1`). `None`
/// if the pixel is outside the image.
pub fn probe(frame: &Frame, x: u32, y: u32) -> Option<Probe> {
    if x >= frame.width || y >= frame.height {
        return None;
    }
    let setup = FrameSetup::new(frame);
    // The probed row alone (the opaque pass decides each pixel independently), or every row when
    // the area light's penumbra search needs them.
    let mut opaque = OpaqueBuffers::default();
    let oy0 = opaque_pass(frame, &setup, 1, y as usize..y as usize + 1, &mut opaque);
    let i = (y as usize - oy0) * frame.width as usize + x as usize;
    let surface = Some(opaque.surface[i]).filter(|d| d.is_finite());
    let mut light = [0.0f32; 3];
    let mut out = Vec::new();
    let pass = WavePass::new(frame, &setup.basis, &setup.curves);
    let (energies, depth) = pass.pixel_energies(x as usize, y as f32, surface);
    for (wave, (e, n)) in frame.waves.iter().zip(energies) {
        waves::accumulate(&mut light, wave, e);
        out.push(WaveProbe { name: wave.name.clone(), energy: e, evaluations: n });
    }
    Some(Probe {
        x,
        y,
        waves: out,
        color: waves::compose(frame, opaque.color[i], light),
        depth,
        object: frame.objects.get(opaque.object[i] as usize).map(|o| o.name.clone()),
        shadow: frame.shadows.get(opaque.shadow[i] as usize).map(|s| s.name.clone()),
        soft: opaque.visibility.get(i).copied().filter(|_| surface.is_some() && opaque.object[i] != NONE),
    })
}
