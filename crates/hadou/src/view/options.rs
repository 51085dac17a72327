//! What `hadou view` was asked to do ([`ViewOptions`]) and how it fails ([`ViewError`], with the
//! message for a machine without a display).

use hadou_view::viewer::BackendKind;
use std::path::PathBuf;

/// What `hadou view` was asked to do.
#[derive(Clone, Debug, Default)]
pub struct ViewOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// A script to run (see `hadou_view::script`).
    pub script: Option<PathBuf>,
    /// Write the viewport here and exit (after the script, if any).
    pub screenshot: Option<PathBuf>,
    /// Start at this time.
    pub time: Option<f32>,
    /// Force a backend (else chosen automatically).
    pub backend: Option<BackendKind>,
    /// Print the frame-time figures as JSON on exit.
    pub stats: bool,
}

/// A failure with its exit code (2: bad input; 1: everything else).
#[derive(Debug)]
pub struct ViewError {
    /// Exit code.
    pub code: u8,
    /// The message.
    pub message: String,
}

pub(super) fn fail(code: u8, message: impl Into<String>) -> ViewError {
    ViewError { code, message: message.into() }
}

/// The message when there is no display to open a window on.
pub fn no_display_message(detail: &str) -> String {
    format!(
        "hadou view needs a display, and none could be opened ({detail}). On Linux it uses the X11 \
         server named by DISPLAY or the Wayland compositor named by WAYLAND_DISPLAY; neither is usable \
         here. Run it in a desktop session, or under a virtual X server: `xvfb-run -a hadou view SCENE`; \
         without a window, `hadou render SCENE -o out.png` writes the same image (`--frames A..B` for \
         an animation) and `hadou probe` reads single pixels"
    )
}
