//! The [`Backend`] trait both renderers implement, and [`RenderError`], why one could not render.

use crate::frame::Frame;
use crate::image::{Image, Rgb8Image};

/// A renderer: turns a [`Frame`] into an [`Image`].
pub trait Backend {
    /// Short name (`"cpu"`, `"gpu"`).
    fn name(&self) -> &str;
    /// Renders one frame.
    fn render(&mut self, frame: &Frame) -> Result<Image, RenderError>;
    /// Renders only the rows `rows` of `frame` (0 = top), as a `frame.width × rows.len()` image
    /// whose pixels equal those rows of [`Backend::render`]'s image. Large outputs are rendered
    /// band by band with it, so memory follows the band, not the image. The default renders the
    /// whole frame and crops; both backends override it with real partial rendering.
    fn render_rows(&mut self, frame: &Frame, rows: std::ops::Range<u32>) -> Result<Image, RenderError> {
        let full = self.render(frame)?;
        Ok(full.crop_rows(rows))
    }
    /// Whether this backend can draw `frame` at all, asked before anything is allocated or
    /// written (a device limit the frame's size or parameters exceed): `Err` is the reason,
    /// naming the limit and what fits. The default accepts every frame.
    fn check_frame(&self, frame: &Frame) -> Result<(), String> {
        let _ = frame;
        Ok(())
    }
    /// The rows `rows` of `frame` as 8-bit sRGB only (what a PNG holds): the same bytes as
    /// [`Rgb8Image::from_image`] of [`Backend::render_rows`]'s image. The default converts that
    /// image (refusing one with a non-finite value); the CPU backend overrides it with a colour
    /// stage that writes the bytes directly and no float buffers.
    fn render_rows_rgb8(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
    ) -> Result<Rgb8Image, RenderError> {
        let image = self.render_rows(frame, rows)?;
        Rgb8Image::from_image(&image).ok_or_else(|| {
            RenderError::Other("internal error: the renderer produced a non-finite value".into())
        })
    }
}

/// Why a backend could not render.
#[derive(Debug)]
pub enum RenderError {
    /// No usable device (e.g. no GPU adapter).
    NoDevice(String),
    /// The device was lost or ran out of memory.
    Device(String),
    /// Host memory for a buffer that grows with the image could not be reserved (what did not
    /// fit, and how much): the render stops cleanly instead of aborting. A frame too large for
    /// the documented limits is refused before it starts ([`crate::check_image_size_with`]); this
    /// is a machine with less memory than they assume.
    Memory(String),
    /// Anything else, with a message for the user.
    Other(String),
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenderError::NoDevice(m) => write!(f, "no usable device: {m}"),
            RenderError::Device(m) => write!(f, "device error: {m}"),
            RenderError::Memory(m) => write!(f, "out of memory: {m}"),
            RenderError::Other(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for RenderError {}
