//! The page's GIF export: frames handed in one at a time (the page renders one per browser
//! frame, so a long export never freezes the tab), quantised and written into memory as
//! `hadou render -o x.gif` writes them (`hadou_scene::gif_delay_cs`, `GIF_QUANT_SPEED`), then
//! handed to the user as a download.

use hadou_scene::{check_gif_size, gif_delay_cs, GIF_QUANT_SPEED};

/// A GIF being written in memory.
pub struct GifExport {
    encoder: gif::Encoder<Vec<u8>>,
    size: [u16; 2],
    fps: f32,
    frames: std::ops::Range<u32>,
    done: u32,
}

impl GifExport {
    /// A GIF of `width × height` frames `frames` at `fps`, or why not (the GIF frame limit).
    pub fn new(width: u32, height: u32, frames: std::ops::Range<u32>, fps: f32) -> Result<GifExport, String> {
        check_gif_size(width, height)?;
        let (Ok(w), Ok(h)) = (u16::try_from(width), u16::try_from(height)) else {
            return Err(format!("{width}×{height} is too large for a GIF (65535 at most)"));
        };
        if frames.is_empty() {
            return Err("no frames to export".into());
        }
        if !(fps.is_finite() && fps > 0.0) {
            return Err(format!("fps {fps}: expected a positive number"));
        }
        let mut encoder = gif::Encoder::new(Vec::new(), w, h, &[]).map_err(|e| e.to_string())?;
        encoder.set_repeat(gif::Repeat::Infinite).map_err(|e| e.to_string())?;
        Ok(GifExport { encoder, size: [w, h], fps, frames, done: 0 })
    }

    /// The frame number to render next, `None` when every frame is in.
    pub fn next_frame(&self) -> Option<u32> {
        let f = self.frames.start + self.done;
        (f < self.frames.end).then_some(f)
    }

    /// The scene time of frame `f`.
    pub fn time_of(&self, f: u32) -> f32 {
        f as f32 / self.fps
    }

    /// `(done, total)` frames.
    pub fn progress(&self) -> (u32, u32) {
        (self.done, self.frames.len() as u32)
    }

    /// Adds the next frame's sRGB RGBA bytes.
    pub fn push(&mut self, mut rgba: Vec<u8>) -> Result<(), String> {
        let [w, h] = self.size;
        if rgba.len() != 4 * w as usize * h as usize {
            return Err(format!("a frame of {} bytes for a {w}×{h} GIF", rgba.len()));
        }
        let mut frame = gif::Frame::from_rgba_speed(w, h, &mut rgba, GIF_QUANT_SPEED);
        frame.delay = gif_delay_cs(self.fps, self.done);
        self.encoder.write_frame(&frame).map_err(|e| e.to_string())?;
        self.done += 1;
        Ok(())
    }

    /// The finished file's bytes.
    pub fn finish(self) -> Result<Vec<u8>, String> {
        self.encoder.into_inner().map_err(|e| e.to_string())
    }
}

/// `rgba` (sRGB bytes, `width × height`) as a PNG file: what a screenshot downloads.
pub fn png_bytes(rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let mut w = enc.write_header().map_err(|e| e.to_string())?;
        w.write_image_data(rgba).map_err(|e| e.to_string())?;
        w.finish().map_err(|e| e.to_string())?;
    }
    Ok(out)
}
