//! The slow-client budget of `robocal serve`: at most a few connections may
//! be slow at once, so a flood of slow clients cannot hold every worker.

use std::sync::atomic::{AtomicUsize, Ordering};

/// The slots of the slow-client budget (see [`super::http::Limits::slow_slots`]).
pub(super) struct SlowBudget {
    pub(super) in_use: AtomicUsize,
    pub(super) max: usize,
}

/// One connection's claim on the [`SlowBudget`]: taken at most once, when
/// the client first turns out slow, and given back when the connection ends.
pub(super) struct Slowness<'a> {
    budget: &'a SlowBudget,
    pub(super) held: bool,
}

impl<'a> Slowness<'a> {
    pub(super) fn new(budget: &'a SlowBudget) -> Self {
        Slowness {
            budget,
            held: false,
        }
    }

    /// Whether this connection may be slow: it holds a slot, or takes one.
    pub(super) fn allow(&mut self) -> bool {
        if !self.held {
            self.held = self
                .budget
                .in_use
                .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| {
                    (n < self.budget.max).then_some(n + 1)
                })
                .is_ok();
        }
        self.held
    }
}

impl Drop for Slowness<'_> {
    fn drop(&mut self) {
        if self.held {
            self.budget.in_use.fetch_sub(1, Ordering::SeqCst);
        }
    }
}
