//! Ctrl-C and SIGTERM as a flag: the CPU backend watches it inside a frame (the frame stops
//! within a fraction of a second), the command checks it between passes and frames, drops the
//! frame in flight (its temporaries are removed by `OutputSet`'s drop) and exits with 130.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::Result;

/// Exit status after an interrupt (128 + SIGINT).
pub const EXIT_INTERRUPTED: u8 = 130;

/// The error that stops a command after an interrupt; `main` maps it to [`EXIT_INTERRUPTED`].
#[derive(Debug)]
pub struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("interrupted; the image in flight was dropped")
    }
}

impl std::error::Error for Interrupted {}

/// Set once SIGINT or SIGTERM arrived.
#[derive(Clone, Debug)]
pub struct InterruptFlag(Arc<AtomicBool>);

impl InterruptFlag {
    /// Installs the handlers (the process no longer dies on the signal: it must check).
    pub fn install() -> Result<Self> {
        let flag = Arc::new(AtomicBool::new(false));
        for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            signal_hook::flag::register(signal, flag.clone())?;
        }
        Ok(Self(flag))
    }

    /// The flag itself, for a backend to cancel the frame in flight
    /// ([`kantele::backend::Backend::set_cancel_flag`]).
    pub fn flag(&self) -> Arc<AtomicBool> {
        self.0.clone()
    }

    /// `Err(Interrupted)` once a signal arrived.
    pub fn check(&self) -> Result<()> {
        if self.0.load(Ordering::SeqCst) {
            return Err(Interrupted.into());
        }
        Ok(())
    }
}
