//! One stable sort for the whole crate.
//!
//! `slice::sort_by` is instantiated once per element type and comparator
//! (about 6 KB of wasm each, 90 KB over the crate). Here the sorting itself
//! is one non-generic merge sort of indices through a `dyn` comparator; per
//! element type only a tiny permutation step remains. Meant for the small
//! lists of the solvers and reports (tens to a few thousand items).

use std::cmp::Ordering;

/// Indices `0..n` in stable order under `cmp` (bottom-up merge sort, runs
/// of 8 by insertion).
fn stable_order(n: usize, cmp: &dyn Fn(usize, usize) -> Ordering) -> Vec<usize> {
    const RUN: usize = 8;
    let mut a: Vec<usize> = (0..n).collect();
    for chunk in a.chunks_mut(RUN) {
        for i in 1..chunk.len() {
            let mut j = i;
            while j > 0 && cmp(chunk[j - 1], chunk[j]) == Ordering::Greater {
                chunk.swap(j - 1, j);
                j -= 1;
            }
        }
    }
    let mut b = vec![0usize; n];
    let mut width = RUN;
    while width < n {
        for (src, dst) in a.chunks(2 * width).zip(b.chunks_mut(2 * width)) {
            let (left, right) = src.split_at(width.min(src.len()));
            let (mut i, mut j) = (0, 0);
            for d in dst.iter_mut() {
                let take_left = j >= right.len()
                    || (i < left.len() && cmp(left[i], right[j]) != Ordering::Greater);
                if take_left {
                    *d = left[i];
                    i += 1;
                } else {
                    *d = right[j];
                    j += 1;
                }
            }
        }
        std::mem::swap(&mut a, &mut b);
        width *= 2;
    }
    a
}

/// Reorder `v` so that `v[k]` becomes the old `v[order[k]]` (`order` a
/// permutation of `0..v.len()`).
fn permute<T>(v: &mut [T], order: &[usize]) {
    let mut done = vec![false; v.len()];
    for start in 0..v.len() {
        if done[start] {
            continue;
        }
        let mut j = start;
        loop {
            done[j] = true;
            let k = order[j];
            if k == start {
                break;
            }
            v.swap(j, k);
            j = k;
        }
    }
}

/// Stable sort of `v` by `cmp`, like `slice::sort_by`. Short lists (the
/// detector's neighbour queries sort a few items per call) are sorted in
/// place by insertion, without allocating.
pub fn sort_by<T>(v: &mut [T], cmp: impl Fn(&T, &T) -> Ordering) {
    const SHORT: usize = 16;
    if v.len() <= SHORT {
        for i in 1..v.len() {
            let mut j = i;
            while j > 0 && cmp(&v[j - 1], &v[j]) == Ordering::Greater {
                v.swap(j - 1, j);
                j -= 1;
            }
        }
        return;
    }
    let order = stable_order(v.len(), &|i, j| cmp(&v[i], &v[j]));
    permute(v, &order);
}

/// Ascending `f64::total_cmp` order (NaN last), like
/// `v.sort_by(f64::total_cmp)`.
pub fn sort_f64(v: &mut [f64]) {
    sort_by(v, f64::total_cmp);
}

/// The `k`-th largest value of `v` (0-based; `k < v.len()`, no NaN), by
/// quickselect with a three-way partition; `v` is reordered. One
/// non-generic function instead of `select_nth_unstable_by`'s instantiation.
pub fn kth_largest_f32(v: &mut [f32], k: usize) -> f32 {
    let (mut lo, mut hi) = (0, v.len() - 1);
    loop {
        if lo == hi {
            return v[lo];
        }
        let (a, b, c) = (v[lo], v[lo + (hi - lo) / 2], v[hi]);
        let pivot = a.max(b).min(a.min(b).max(c)); // median of three
                                                   // [lo, gt_end) > pivot, [gt_end, i) == pivot, [lt_start, hi] < pivot.
        let (mut gt_end, mut i, mut lt_start) = (lo, lo, hi + 1);
        while i < lt_start {
            if v[i] > pivot {
                v.swap(gt_end, i);
                gt_end += 1;
                i += 1;
            } else if v[i] < pivot {
                lt_start -= 1;
                v.swap(i, lt_start);
            } else {
                i += 1;
            }
        }
        if k < gt_end {
            hi = gt_end - 1;
        } else if k < lt_start {
            return pivot;
        } else {
            lo = lt_start;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn same_order_as_the_standard_stable_sort() {
        let mut state = 12345u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as u32
        };
        for n in [0usize, 1, 2, 7, 8, 9, 16, 17, 31, 64, 100, 257, 1000] {
            // Few distinct keys, so that stability matters.
            let items: Vec<(u32, usize)> = (0..n).map(|i| (next() % 7, i)).collect();
            let mut ours = items.clone();
            sort_by(&mut ours, |a, b| a.0.cmp(&b.0));
            let mut std_sorted = items.clone();
            std_sorted.sort_by(|a, b| a.0.cmp(&b.0));
            assert_eq!(ours, std_sorted, "n = {n}");
        }
        for n in [1usize, 2, 3, 10, 101, 1000] {
            // Repeated values and sorted runs, the quickselect's hard cases.
            let values: Vec<f32> = (0..n)
                .map(|i| (next() % 13) as f32 + if i % 3 == 0 { 0.5 } else { 0.0 })
                .collect();
            let mut sorted = values.clone();
            sorted.sort_by(|a, b| b.total_cmp(a));
            for k in [0, n / 3, n / 2, n - 1] {
                let mut v = values.clone();
                assert_eq!(kth_largest_f32(&mut v, k), sorted[k], "n = {n}, k = {k}");
                let mut ascending = sorted.clone();
                ascending.reverse();
                assert_eq!(
                    kth_largest_f32(&mut ascending, k),
                    sorted[k],
                    "sorted input, n = {n}, k = {k}"
                );
            }
        }
        let mut v = vec![3.0, f64::NAN, -1.0, 2.5, -0.0, 0.0];
        sort_f64(&mut v);
        assert_eq!(&v[..5], &[-1.0, -0.0, 0.0, 2.5, 3.0]);
        assert!(v[5].is_nan());
    }
}
