//! The memory `robocal detect` may hold over all its threads at once.
//!
//! Each image reserves, before its file is read, what it will hold: the
//! file, the decoder's peak ([`robocal::image::decode_peak`], from the
//! header in the file's first bytes) and the detector's working memory
//! ([`DETECT_BYTES_PER_PIXEL`]). A thread whose reservation does not fit
//! waits until others finish, so threads x per-image peak never exceeds
//! [`DETECT_MEMORY_BUDGET`]; one image larger than the whole budget runs
//! alone (it is within the decoder's own limits).

use std::sync::{Condvar, Mutex};

/// The budget of all detection threads together, in bytes: 2 GiB (twice
/// the decoder's limit for one image, so two large images run at once).
pub const DETECT_MEMORY_BUDGET: u64 = 2 << 30;

/// The detectors' working memory beyond the grey image, in bytes a pixel:
/// the pyramid, gradients and labels of the circle searches, the largest
/// (docs/bounds.md: 1.2 bytes a pixel measured on 99 MP, rounded up).
pub const DETECT_BYTES_PER_PIXEL: u64 = 2;

/// Reservations against a total.
pub struct MemoryBudget {
    total: u64,
    used: Mutex<u64>,
    freed: Condvar,
}

/// Held while an image is processed; gives its bytes back when dropped.
pub struct Reservation<'a> {
    budget: &'a MemoryBudget,
    bytes: u64,
}

impl MemoryBudget {
    /// A budget of `total` bytes.
    pub fn new(total: u64) -> Self {
        MemoryBudget {
            total,
            used: Mutex::new(0),
            freed: Condvar::new(),
        }
    }

    /// Wait until `bytes` (at most the whole budget) fit, and hold them.
    pub fn reserve(&self, bytes: u64) -> Reservation<'_> {
        let bytes = bytes.min(self.total);
        // A poisoned lock only means another thread panicked while holding
        // it; the count itself is always consistent (one add, one subtract).
        let mut used = self.used.lock().unwrap_or_else(|e| e.into_inner());
        while *used + bytes > self.total {
            used = self.freed.wait(used).unwrap_or_else(|e| e.into_inner());
        }
        *used += bytes;
        Reservation {
            budget: self,
            bytes,
        }
    }
}

impl Drop for Reservation<'_> {
    fn drop(&mut self) {
        let mut used = self.budget.used.lock().unwrap_or_else(|e| e.into_inner());
        *used -= self.bytes;
        self.budget.freed.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU64, Ordering};

    #[test]
    fn reservations_never_exceed_the_total() {
        let budget = MemoryBudget::new(100);
        let held = AtomicU64::new(0);
        let peak = AtomicU64::new(0);
        std::thread::scope(|s| {
            for i in 0..8u64 {
                let (budget, held, peak) = (&budget, &held, &peak);
                s.spawn(move || {
                    for _ in 0..20 {
                        // 30 to 170 bytes: the last ones are over the total
                        // and run alone.
                        let want = 30 + 20 * i;
                        let r = budget.reserve(want);
                        let now = held.fetch_add(r.bytes, Ordering::SeqCst) + r.bytes;
                        peak.fetch_max(now, Ordering::SeqCst);
                        std::thread::yield_now();
                        held.fetch_sub(r.bytes, Ordering::SeqCst);
                    }
                });
            }
        });
        assert!(peak.load(Ordering::SeqCst) <= 100, "peak {peak:?} bytes");
        assert_eq!(*budget.used.lock().unwrap(), 0);
    }
}
