//! What every GIF writer of the workspace shares (`hadou render -o x.gif`, the viewer's export,
//! the web page's): the frame size limit, the quantiser's speed and the frames' delays.

/// The most pixels of a GIF frame: 16,777,216 (4096²). A GIF frame is quantised whole (NeuQuant
/// needs all its colours at once), which costs about 5 bytes a pixel on top of the rendered bands
/// (80 MB at this limit, 1.3 GB at 16384²); larger animations are written as a PNG sequence,
/// band by band.
pub const GIF_MAX_PIXELS: u64 = 1 << 24;

/// Checks a GIF frame size against [`GIF_MAX_PIXELS`]; the message names the size, callers
/// prefix where it came from.
pub fn check_gif_size(width: u32, height: u32) -> Result<(), String> {
    let n = u64::from(width) * u64::from(height);
    if n > GIF_MAX_PIXELS {
        return Err(format!(
            "a GIF frame is at most {GIF_MAX_PIXELS} pixels (4096²; each frame is quantised whole); \
             {width}×{height} is {n} pixels: choose a smaller size, or write a PNG sequence (an output \
             directory ending in `/`), which has no such limit"
        ));
    }
    Ok(())
}

/// NeuQuant's speed for GIF quantisation (1 = best, 30 = fastest; 10 is the crate's advised
/// compromise).
pub const GIF_QUANT_SPEED: i32 = 10;

/// The GIF delay of the `k`-th frame of an animation (k = 0 for its first frame), in the GIF's
/// unit of 1/100 s.
///
/// Rounding: frame `k` is shown from `round(100·k/fps)` to `round(100·(k+1)/fps)` centiseconds
/// (halves away from zero), so delays alternate between the two nearest whole centiseconds and
/// the animation's total length stays within 5 ms of `frames / fps` (24 fps: 4, 4, 5, 4, 4, 4 cs,
/// repeating, 25 cs per 6 frames). Above 50 fps every delay is 2 cs (the animation plays at 50 fps,
/// slower than asked), because browsers show 0 or 1 cs delays as 10 cs. Delays beyond 655.35 s
/// (`fps` below about 0.0015) are capped at `u16::MAX`.
pub fn gif_delay_cs(fps: f32, k: u32) -> u16 {
    let fps = f64::from(fps);
    if fps >= 50.0 {
        return 2;
    }
    let at = |k: u32| (100.0 * f64::from(k) / fps).round();
    (at(k + 1) - at(k)).clamp(2.0, f64::from(u16::MAX)) as u16
}
