//! The co-observation graph of a rig: which cameras saw the board in the
//! same frames, whether that connects every camera, and the spanning tree
//! of the best-connected pairs that the initialisation chains.

use crate::error::{Error, Result};

/// `counts[i][j]`: frames seen by both camera i and camera j (the
/// diagonal: frames seen by camera i), from each camera's frame list.
pub fn co_observation_counts(frames_of_camera: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let n = frames_of_camera.len();
    let mut counts = vec![vec![0; n]; n];
    for i in 0..n {
        for j in 0..n {
            counts[i][j] = frames_of_camera[i]
                .iter()
                .filter(|f| frames_of_camera[j].contains(f))
                .count();
        }
    }
    counts
}

/// The connected groups of cameras (indices, ascending), in the order of
/// their first camera.
pub fn connected_groups(counts: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let n = counts.len();
    let mut group_of: Vec<Option<usize>> = vec![None; n];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for start in 0..n {
        if group_of[start].is_some() {
            continue;
        }
        let g = groups.len();
        let mut members = vec![start];
        group_of[start] = Some(g);
        let mut next = 0;
        while next < members.len() {
            let i = members[next];
            next += 1;
            for j in 0..n {
                if group_of[j].is_none() && counts[i][j] > 0 {
                    group_of[j] = Some(g);
                    members.push(j);
                }
            }
        }
        members.sort_unstable();
        groups.push(members);
    }
    groups
}

/// The error for cameras in more than one group, naming the groups.
pub fn disconnected_error(groups: &[Vec<usize>], names: &[String]) -> Error {
    let spelled: Vec<String> = groups
        .iter()
        .map(|g| {
            let members: Vec<&str> = g.iter().map(|&i| names[i].as_str()).collect();
            format!("{{{}}}", members.join(", "))
        })
        .collect();
    let listed = match spelled.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => spelled.join(""),
    };
    Error::degenerate(format!(
        "cameras are not connected by shared board views: {listed}; add frames where a camera \
         of each group sees the board"
    ))
}

/// A maximum spanning tree of the co-observation counts grown from `root`
/// (Prim's algorithm): each step adds the camera that shares the most
/// frames with one already in the tree (ties: lowest indices). Edges are
/// `[parent, child]` in the order added; an error names the groups when
/// the graph is not connected.
pub fn spanning_tree(
    counts: &[Vec<usize>],
    root: usize,
    names: &[String],
) -> Result<Vec<[usize; 2]>> {
    let groups = connected_groups(counts);
    if groups.len() > 1 {
        return Err(disconnected_error(&groups, names));
    }
    let n = counts.len();
    let mut in_tree = vec![false; n];
    in_tree[root] = true;
    let mut edges = Vec::with_capacity(n.saturating_sub(1));
    for _ in 1..n {
        let mut best: Option<(usize, [usize; 2])> = None;
        for parent in (0..n).filter(|&p| in_tree[p]) {
            for child in (0..n).filter(|&c| !in_tree[c]) {
                let c = counts[parent][child];
                if c > 0 && best.map_or(true, |(b, _)| c > b) {
                    best = Some((c, [parent, child]));
                }
            }
        }
        let Some((_, edge)) = best else {
            // Unreachable for a connected graph; kept as an error, not a panic.
            return Err(disconnected_error(&groups, names));
        };
        in_tree[edge[1]] = true;
        edges.push(edge);
    }
    Ok(edges)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn names(n: usize) -> Vec<String> {
        (0..n).map(|i| format!("cam{i}")).collect()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn the_tree_takes_the_best_connected_pairs() {
        // cam0-cam1 share 5 frames, cam1-cam2 4, cam0-cam2 1, cam2-cam3 2.
        let frames = vec![
            vec![0, 1, 2, 3, 4, 9],
            vec![0, 1, 2, 3, 4, 5, 6, 7, 8],
            vec![5, 6, 7, 8, 9, 10, 11],
            vec![10, 11, 12],
        ];
        let counts = co_observation_counts(&frames);
        assert_eq!(counts[0], vec![6, 5, 1, 0]);
        assert_eq!(counts[2][1], 4);
        let tree = spanning_tree(&counts, 0, &names(4)).expect("connected");
        assert_eq!(tree, vec![[0, 1], [1, 2], [2, 3]]);
        // Grown from another root, the same edges come out reversed where needed.
        let tree = spanning_tree(&counts, 3, &names(4)).expect("connected");
        assert_eq!(tree, vec![[3, 2], [2, 1], [1, 0]]);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn disconnected_cameras_are_named_by_group() {
        let frames = vec![vec![0, 1], vec![1, 2], vec![3], vec![3, 4], vec![7]];
        let counts = co_observation_counts(&frames);
        let err = spanning_tree(&counts, 0, &names(5)).unwrap_err();
        assert_eq!(
            err.to_string(),
            "cameras are not connected by shared board views: {cam0, cam1}, {cam2, cam3} and \
             {cam4}; add frames where a camera of each group sees the board"
        );
    }
}
