//! What the page's script hands in between the viewer's frames (a chosen preset, dropped files)
//! and what it tells the viewer once (the WebGPU adapter's name), kept until the viewer's next
//! frame takes it.

use crate::dropped::DropBatch;
use std::cell::RefCell;

/// What the page's script handed in since the viewer's last frame.
#[derive(Default)]
pub(super) struct Inbox {
    /// The batch being dropped (between `drop_begin` and `drop_end`).
    pub(super) dropping: Option<DropBatch>,
    /// Batches complete.
    pub(super) dropped: Vec<DropBatch>,
    /// A preset chosen in the page's list.
    pub(super) preset: Option<String>,
    /// The viewer's egui context, to wake it.
    pub(super) ctx: Option<egui::Context>,
}

thread_local! {
    /// The browser's WebGPU adapter in words, from the page's script.
    pub(super) static WEBGPU_ADAPTER: RefCell<String> = const { RefCell::new(String::new()) };
    pub(super) static INBOX: RefCell<Inbox> = RefCell::new(Inbox::default());
}

pub(super) fn wake() {
    INBOX.with(|i| {
        if let Some(ctx) = &i.borrow().ctx {
            ctx.request_repaint();
        }
    });
}
