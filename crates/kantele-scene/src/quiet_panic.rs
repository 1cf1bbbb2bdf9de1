//! `catch_unwind` without the panic message on stderr: a panic inside a dependency becomes one
//! error line printed by the caller, not three lines and a backtrace.
//!
//! The process-wide panic hook is wrapped once: panics on a thread that is inside [`catch`] are
//! silent, panics anywhere else still go to the previous hook.

use std::cell::{Cell, RefCell};
use std::panic::{self, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    /// How many [`catch`] calls are active on this thread.
    static SILENCED: Cell<u32> = const { Cell::new(0) };
    /// Source file of the last panic caught on this thread (for the fuzz targets, which tell
    /// a dependency's panic from one in Kantele's own code).
    static LAST_CAUGHT_FILE: RefCell<Option<String>> = const { RefCell::new(None) };
}

static INSTALL: Once = Once::new();

fn install_hook() {
    INSTALL.call_once(|| {
        let previous = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            if SILENCED.with(Cell::get) == 0 {
                previous(info);
            } else {
                let file = info.location().map(|l| l.file().to_string());
                LAST_CAUGHT_FILE.with(|f| *f.borrow_mut() = file);
            }
        }));
    });
}

/// The source file of the last panic [`catch`] caught on this thread, if any.
pub fn last_caught_file() -> Option<String> {
    LAST_CAUGHT_FILE.with(|f| f.borrow().clone())
}

/// Runs `f`; a panic inside it is caught silently and returned as its message.
pub fn catch<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    install_hook();
    SILENCED.with(|s| s.set(s.get() + 1));
    let result = panic::catch_unwind(AssertUnwindSafe(f));
    SILENCED.with(|s| s.set(s.get() - 1));
    result.map_err(|panic| {
        panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown error".to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_its_message() {
        assert_eq!(catch(|| 7), Ok(7));
        let caught = catch(|| -> u32 { panic!("boom {}", 42) });
        assert_eq!(caught, Err("boom 42".to_string()));
        assert!(last_caught_file().is_some_and(|f| f.ends_with("quiet_panic.rs")));
        // The counter is balanced again after a caught panic.
        SILENCED.with(|s| assert_eq!(s.get(), 0));
    }
}
