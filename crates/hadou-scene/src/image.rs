//! [`Image`]: what every backend returns.

/// A rendered frame: linear colour, summed wave energy and eye distance per pixel, row-major from
/// the top-left. Every value is finite.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Final linear RGBA after colour mapping (what PNG encodes after the sRGB curve).
    pub color: Vec<[f32; 4]>,
    /// Sum over waves of the integrated energy `I` (before colour and mapping).
    pub energy: Vec<f32>,
    /// Distance from the eye to the visible surface along the pixel's ray, or to the far plane
    /// where nothing is drawn.
    pub depth: Vec<f32>,
}

impl Image {
    /// A `width × height` image filled with zeros.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self { width, height, color: vec![[0.0; 4]; n], energy: vec![0.0; n], depth: vec![0.0; n] }
    }

    /// The rows `rows` (clamped to the image) as a new image of the same width.
    pub fn crop_rows(&self, rows: std::ops::Range<u32>) -> Image {
        let (y0, y1) =
            (rows.start.min(self.height), rows.end.min(self.height).max(rows.start.min(self.height)));
        let w = self.width as usize;
        let span = y0 as usize * w..y1 as usize * w;
        Image {
            width: self.width,
            height: y1 - y0,
            color: self.color[span.clone()].to_vec(),
            energy: self.energy[span.clone()].to_vec(),
            depth: self.depth[span].to_vec(),
        }
    }

    /// Index of pixel `(x, y)`.
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }
}
