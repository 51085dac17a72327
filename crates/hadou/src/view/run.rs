//! Opening the viewer: the scene, the script and the screenshot's path are read and checked
//! before any window opens (bad input is exit 2 with its position); then winit's event loop runs
//! the [`App`] until the window closes or the script ends.

use super::app::{App, Wake};
use super::cpu_worker::CpuWorker;
use super::options::{fail, no_display_message, ViewError, ViewOptions};
use crate::output;
use hadou_view::document::Document;
use hadou_view::script;
use hadou_view::viewer::Viewer;
use winit::event_loop::EventLoop;

/// Opens the viewer on `opts.scene` and runs until the window closes (or the script ends).
pub fn run(opts: ViewOptions) -> Result<(), ViewError> {
    let doc = Document::open(&opts.scene).map_err(|e| fail(2, e.to_string()))?;
    let script = match &opts.script {
        Some(p) => {
            let bytes = hadou_scene::read_regular_file(p, 1 << 20)
                .map_err(|e| fail(2, format!("{}: cannot read the script: {e}", p.display())))?;
            let text = String::from_utf8(bytes).map_err(|e| {
                let at = e.utf8_error().valid_up_to();
                fail(2, format!("{}: the script is not UTF-8 text (byte {at})", p.display()))
            })?;
            Some((script::parse(&text, p).map_err(|e| fail(2, e))?, p.clone()))
        }
        None => None,
    };
    for p in opts.screenshot.iter() {
        output::check_writable(p).map_err(|e| fail(2, e.to_string()))?;
    }
    #[cfg(all(unix, not(target_os = "macos")))]
    if std::env::var_os("DISPLAY").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none() {
        return Err(fail(1, no_display_message("DISPLAY and WAYLAND_DISPLAY are both unset")));
    }
    let event_loop = EventLoop::<Wake>::with_user_event()
        .build()
        .map_err(|e| fail(1, no_display_message(&e.to_string())))?;
    let mut viewer = Viewer::new(doc);
    if let Some(t) = opts.time {
        viewer.timeline.time = t;
    }
    // The render thread wakes the event loop when a frame is done (the loop sleeps meanwhile).
    let proxy = event_loop.create_proxy();
    let wake = move || {
        let _ = proxy.send_event(Wake);
    };
    let cpu =
        CpuWorker::start(wake).map_err(|e| fail(1, format!("cannot start the CPU render thread: {e}")))?;
    let mut app = App::new(viewer, opts, script, cpu);
    event_loop.run_app(&mut app).map_err(|e| fail(1, format!("the window's event loop failed: {e}")))?;
    if let Some(e) = app.fatal.take() {
        return Err(e);
    }
    if app.opts.stats {
        println!("{}", app.stats_json());
    }
    Ok(())
}
