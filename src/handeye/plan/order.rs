//! The visiting order of planned poses: a short open tour from the robot's
//! current pose, nearest neighbour then 2-opt, on a move cost of flange
//! travel plus rotation (`|dt| + ROTATION_LEVER_M * angle`: a radian of
//! wrist rotation costs like 0.3 m of travel).

use crate::handeye::Pose;

/// Metres of travel one radian of rotation is worth in the move cost.
pub const ROTATION_LEVER_M: f64 = 0.3;

/// Cost of moving from `a` to `b`.
pub fn move_cost(a: &Pose, b: &Pose) -> f64 {
    let dt = (b.translation.vector - a.translation.vector).norm();
    let angle = (a.rotation.inverse() * b.rotation).angle();
    dt + ROTATION_LEVER_M * angle
}

fn tour_cost(start: &Pose, poses: &[Pose], tour: &[usize]) -> f64 {
    let mut cost = 0.0;
    let mut at = start;
    for &k in tour {
        cost += move_cost(at, &poses[k]);
        at = &poses[k];
    }
    cost
}

/// The order (indices into `poses`) of a short open tour from `start`.
pub fn short_tour(start: &Pose, poses: &[Pose]) -> Vec<usize> {
    let n = poses.len();
    let mut left: Vec<usize> = (0..n).collect();
    let mut tour = Vec::with_capacity(n);
    let mut at = *start;
    while !left.is_empty() {
        let (pos, _) = left
            .iter()
            .enumerate()
            .map(|(pos, &k)| (pos, move_cost(&at, &poses[k])))
            .fold((0, f64::INFINITY), |b, c| if c.1 < b.1 { c } else { b });
        let k = left.remove(pos);
        at = poses[k];
        tour.push(k);
    }
    // 2-opt: reverse a stretch while that shortens the tour.
    let mut best = tour_cost(start, poses, &tour);
    let mut improved = true;
    while improved {
        improved = false;
        for i in 0..n {
            for j in i + 1..n {
                tour[i..=j].reverse();
                let c = tour_cost(start, poses, &tour);
                if c + 1e-12 < best {
                    best = c;
                    improved = true;
                } else {
                    tour[i..=j].reverse();
                }
            }
        }
    }
    tour
}

/// Flange travel (m) along `poses` in order from `start`.
pub fn tour_travel_m(start: &Pose, poses: &[Pose]) -> f64 {
    let mut at = start;
    let mut d = 0.0;
    for p in poses {
        d += (p.translation.vector - at.translation.vector).norm();
        at = p;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn points_on_a_line_are_visited_in_order() {
        let start = Pose::identity();
        let xs = [0.5, 0.1, 0.4, 0.2, 0.3];
        let poses: Vec<Pose> = xs.iter().map(|&x| Pose::translation(x, 0.0, 0.0)).collect();
        let tour = short_tour(&start, &poses);
        assert_eq!(tour, vec![1, 3, 4, 2, 0]);
        let ordered: Vec<Pose> = tour.iter().map(|&k| poses[k]).collect();
        assert!((tour_travel_m(&start, &ordered) - 0.5).abs() < 1e-12);
    }
}
