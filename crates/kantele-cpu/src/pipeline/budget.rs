//! A frame's time and cancellation budget: checked between chunks of the geometry stages and
//! between triangles of the raster stage, so a frame with far too much work stops soon after
//! its deadline (or after the caller raises its cancellation flag) instead of running for
//! minutes.

use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::time::{Duration, Instant};

use kantele_rules::stats::FrameStop;

/// Triangles a tile rasterizes between two budget checks (a few hundred microseconds of work
/// at most, for triangles covering the whole tile).
pub(super) const TRIANGLES_PER_CHECK: usize = 16;

/// The budget of one frame. Once exhausted it stays exhausted (the first reason is kept).
pub(super) struct FrameBudget<'a> {
    deadline: Option<Instant>,
    timeout: Option<Duration>,
    cancel: Option<&'a AtomicBool>,
    /// 0 while running, else the `FrameStop` code that stopped the frame.
    stopped: AtomicU8,
}

const RUNNING: u8 = 0;
const CANCELLED: u8 = 1;
const TIMED_OUT: u8 = 2;

impl<'a> FrameBudget<'a> {
    /// A budget of `timeout` from `start` (none: no deadline) and an optional flag the caller
    /// sets to cancel.
    pub(super) fn new(
        start: Instant,
        timeout: Option<Duration>,
        cancel: Option<&'a AtomicBool>,
    ) -> Self {
        Self {
            deadline: timeout.and_then(|t| start.checked_add(t)),
            timeout,
            cancel,
            stopped: AtomicU8::new(RUNNING),
        }
    }

    /// Whether the frame must stop now. Cheap when there is no budget; otherwise one atomic
    /// load and, with a deadline, one clock read.
    #[inline]
    pub(super) fn exhausted(&self) -> bool {
        if self.deadline.is_none() && self.cancel.is_none() {
            return false;
        }
        if self.stopped.load(Ordering::Relaxed) != RUNNING {
            return true;
        }
        let reason = if self.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            CANCELLED
        } else if self.deadline.is_some_and(|d| Instant::now() >= d) {
            TIMED_OUT
        } else {
            return false;
        };
        // Keep the first reason if two threads see different ones.
        let _ =
            self.stopped
                .compare_exchange(RUNNING, reason, Ordering::Relaxed, Ordering::Relaxed);
        true
    }

    /// Why the frame stopped early, if it did.
    pub(super) fn stop(&self) -> Option<FrameStop> {
        match self.stopped.load(Ordering::Relaxed) {
            CANCELLED => Some(FrameStop::Cancelled),
            TIMED_OUT => Some(FrameStop::TimedOut {
                budget: self.timeout.unwrap_or_default(),
            }),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_budget_never_stops_and_a_raised_flag_stops_for_good() {
        let start = Instant::now();
        assert!(!FrameBudget::new(start, None, None).exhausted());
        let flag = AtomicBool::new(false);
        let budget = FrameBudget::new(start, Some(Duration::from_secs(3600)), Some(&flag));
        assert!(!budget.exhausted());
        assert_eq!(budget.stop(), None);
        flag.store(true, Ordering::Relaxed);
        assert!(budget.exhausted());
        flag.store(false, Ordering::Relaxed);
        assert!(budget.exhausted());
        assert_eq!(budget.stop(), Some(FrameStop::Cancelled));
    }

    #[test]
    fn a_passed_deadline_reports_its_budget() {
        let budget = FrameBudget::new(Instant::now(), Some(Duration::ZERO), None);
        assert!(budget.exhausted());
        assert_eq!(
            budget.stop(),
            Some(FrameStop::TimedOut {
                budget: Duration::ZERO
            })
        );
    }
}
