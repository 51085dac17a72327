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

/// A rendered image as 8-bit sRGB only: what a PNG holds. The CPU backend writes it straight
/// from its colour stage, without the float colour, energy and depth buffers of [`Image`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Rgb8Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Packed `R, G, B` bytes per pixel, rows top to bottom: the mapped linear colour through
    /// the sRGB transfer, `⌊255·srgb(v) + ½⌋` ([`hadou_math::shade::linear_to_srgb8`]).
    pub rgb: Vec<u8>,
}

impl Rgb8Image {
    /// The 8-bit sRGB of `image`'s colour; `None` if a colour, energy or depth value is not
    /// finite (no NaN or infinity may reach an image).
    pub fn from_image(image: &Image) -> Option<Rgb8Image> {
        let finite = image.color.iter().all(|c| c.iter().all(|v| v.is_finite()))
            && image.energy.iter().all(|v| v.is_finite())
            && image.depth.iter().all(|v| v.is_finite());
        if !finite {
            return None;
        }
        let srgb = hadou_math::shade::srgb8_encoder();
        let rgb =
            image.color.iter().flat_map(|c| [srgb.code(c[0]), srgb.code(c[1]), srgb.code(c[2])]).collect();
        Some(Rgb8Image { width: image.width, height: image.height, rgb })
    }
}
