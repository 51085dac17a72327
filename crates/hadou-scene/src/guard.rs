//! Third-party parsers (toml, gltf) run on untrusted bytes. Their inputs are checked first so that
//! they should not panic, but should one still panic, [`guarded`] turns it into an error message,
//! and the panic's own report is kept off stderr (the user sees one clean error line).

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    /// Set while this thread runs a guarded call.
    static GUARDED: Cell<bool> = const { Cell::new(false) };
}

static HOOK: Once = Once::new();

/// Installs (once per process) a panic hook that stays silent for panics inside [`guarded`] on
/// the same thread and hands every other panic to the hook that was installed before.
fn install_hook() {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !GUARDED.with(Cell::get) {
                previous(info);
            }
        }));
    });
}

/// Runs `f`; a panic inside it becomes `Err("… (internal error in the <what> parser: …)")`.
pub(crate) fn guarded<T>(what: &str, f: impl FnOnce() -> T) -> Result<T, String> {
    install_hook();
    let was = GUARDED.with(|g| g.replace(true));
    let r = catch_unwind(AssertUnwindSafe(f));
    GUARDED.with(|g| g.set(was));
    r.map_err(|payload| {
        let detail = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".into());
        format!("the {what} parser failed on this input ({detail})")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_in_a_guarded_call_becomes_an_error() {
        let e = guarded("test", || -> u32 { panic!("boom") }).unwrap_err();
        assert!(e.contains("test parser") && e.contains("boom"), "{e}");
        assert_eq!(guarded("test", || 7), Ok(7));
        // The flag is reset afterwards, so later panics elsewhere are reported normally.
        assert!(!GUARDED.with(Cell::get));
    }
}
