//! Which pairs of poses a motion test compares: every pair for small sets,
//! else a bounded number per pose, so that tests comparing the rotation
//! angles of motions (the hand-eye pairing proof, the rig's frame check)
//! stay linear in the number of poses.

/// The poses `j > i` whose motion from pose `i` is compared, out of `n`:
/// all of them when `n <= 2 * max_per_pose + 1`, else the next
/// `max_per_pose / 2` and as many spread over the rest.
pub fn motion_partners(i: usize, n: usize, max_per_pose: usize) -> Vec<usize> {
    if n <= 2 * max_per_pose + 1 {
        return (i + 1..n).collect();
    }
    let half = max_per_pose / 2;
    let mut js: Vec<usize> = (1..=half).map(|k| i + k).collect();
    let stride = n / (half + 1);
    js.extend((1..=half).map(|k| i + k * stride));
    js.retain(|&j| j < n);
    js.dedup();
    js
}
