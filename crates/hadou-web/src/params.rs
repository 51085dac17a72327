//! The page's URL parameters: `?scene=kamehameha&time=1.5&width=320&height=180&test=1&backend=webgl`.
//! A bad value is a message in the page, never a blank page.

/// Which graphics API the page asks the browser for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ApiChoice {
    /// WebGPU where the browser has it (the GPU backend draws), else WebGL2.
    Auto,
    /// WebGL2 only (`backend=webgl`): the CPU backend draws, WebGL2 shows its image and the UI.
    WebGl,
    /// WebGPU only (`backend=webgpu`): no fallback.
    WebGpu,
}

/// The parameters read from the URL's query.
#[derive(Clone, Debug, PartialEq)]
pub struct PageParams {
    /// The preset to open (`scene=NAME`, without `.toml`); the page's default preset when absent.
    pub scene: Option<String>,
    /// Scene time in seconds (`time=T`).
    pub time: Option<f32>,
    /// Image width override (`width=W`).
    pub width: Option<u32>,
    /// Image height override (`height=H`).
    pub height: Option<u32>,
    /// Test mode (`test=1`): render the frame once, read it back and write it into the page.
    pub test: bool,
    /// `backend=auto|webgpu|webgl`.
    pub api: ApiChoice,
}

impl PageParams {
    /// The URL's size, as overrides of the scene's frame.
    pub fn overrides(&self) -> hadou_scene::FrameOverrides {
        hadou_scene::FrameOverrides { width: self.width, height: self.height, samples: None }
    }
}

impl Default for PageParams {
    fn default() -> Self {
        PageParams { scene: None, time: None, width: None, height: None, test: false, api: ApiChoice::Auto }
    }
}

/// Reads `query` (`location.search`, with or without its `?`). Unknown keys are refused with the
/// keys there are; every problem found is listed, one message each.
pub fn parse_query(query: &str) -> Result<PageParams, Vec<String>> {
    let mut p = PageParams::default();
    let mut errors = Vec::new();
    let query = query.strip_prefix('?').unwrap_or(query);
    for pair in query.split('&').filter(|s| !s.is_empty()) {
        let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
        let (key, value) = (decode(key), decode(value));
        let shown = hadou_scene::escape_controls(&value);
        match key.as_str() {
            "scene" => p.scene = Some(value.strip_suffix(".toml").unwrap_or(&value).to_string()),
            "time" => match value.parse::<f32>() {
                Ok(t) if t.is_finite() && t >= 0.0 => p.time = Some(t),
                _ => {
                    errors.push(format!("time=`{shown}`: expected a number of seconds ≥ 0, such as time=1.5"))
                }
            },
            "width" | "height" => match value.parse::<u32>() {
                Ok(n) if (1..=hadou_scene::MAX_IMAGE_EDGE).contains(&n) => {
                    if key == "width" {
                        p.width = Some(n)
                    } else {
                        p.height = Some(n)
                    }
                }
                _ => errors.push(format!(
                    "{key}=`{shown}`: expected a whole number of pixels in 1..={}",
                    hadou_scene::MAX_IMAGE_EDGE
                )),
            },
            "test" => match value.as_str() {
                "1" | "true" | "" => p.test = true,
                "0" | "false" => p.test = false,
                _ => errors.push(format!("test=`{shown}`: expected test=1")),
            },
            "backend" => match value.as_str() {
                "auto" => p.api = ApiChoice::Auto,
                "webgpu" => p.api = ApiChoice::WebGpu,
                "webgl" | "webgl2" => p.api = ApiChoice::WebGl,
                _ => errors.push(format!("backend=`{shown}`: expected auto, webgpu or webgl")),
            },
            other => errors.push(format!(
                "unknown URL parameter `{}`; the page reads scene, time, width, height, test and backend",
                hadou_scene::escape_controls(other)
            )),
        }
    }
    if errors.is_empty() {
        Ok(p)
    } else {
        Err(errors)
    }
}

/// Percent-decoding with `+` as a space; invalid escapes stay as written.
fn decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'+' => out.push(b' '),
            b'%' if i + 2 < b.len() => {
                let hex = |c: u8| (c as char).to_digit(16);
                match (hex(b[i + 1]), hex(b[i + 2])) {
                    (Some(h), Some(l)) => {
                        out.push((h * 16 + l) as u8);
                        i += 3;
                        continue;
                    }
                    _ => out.push(b'%'),
                }
            }
            c => out.push(c),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}
