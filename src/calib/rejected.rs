//! What the robust option rejected, said once for the whole calibration:
//! how many points, in which views, and where in the image (the border,
//! where a lens model that does not fit shows first, or spread out).

use super::report::ViewReport;
use serde::{Deserialize, Serialize};

/// A point counts as "near the border" within this fraction of the image
/// width (height) from its left or right (top or bottom) edge.
const BORDER_FRACTION: f64 = 0.1;
/// At most this many views are named in the summary sentence.
const NAMED_VIEWS: usize = 5;

/// Points the robust option rejected in one view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RejectedInView {
    /// The view's name.
    pub name: String,
    /// Points rejected in it.
    pub count: usize,
}

/// The points the robust option rejected, over all views.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RejectedPoints {
    /// Points rejected.
    pub count: usize,
    /// Points detected (used plus rejected).
    pub of_points: usize,
    /// Views with at least one rejected point, most rejections first.
    pub views: Vec<RejectedInView>,
    /// Rejected points within 10 % of the image size from an edge.
    pub near_border: usize,
    /// The same in one sentence (CLI standard error, the page).
    pub summary: String,
}

/// The summary of the views' outliers (`x_px`, `y_px` filled) for an image
/// of `size` px.
pub fn rejected_points(views: &[ViewReport], size: (u32, u32)) -> RejectedPoints {
    let (w, h) = (f64::from(size.0), f64::from(size.1));
    let near = |x: f64, y: f64| {
        x < BORDER_FRACTION * w
            || x > (1.0 - BORDER_FRACTION) * w
            || y < BORDER_FRACTION * h
            || y > (1.0 - BORDER_FRACTION) * h
    };
    let count: usize = views.iter().map(|v| v.outliers.len()).sum();
    let of_points = count + views.iter().map(|v| v.n_points).sum::<usize>();
    let near_border = views
        .iter()
        .flat_map(|v| &v.outliers)
        .filter(|o| near(o.x_px, o.y_px))
        .count();
    let mut with: Vec<RejectedInView> = views
        .iter()
        .filter(|v| !v.outliers.is_empty())
        .map(|v| RejectedInView {
            name: v.name.clone(),
            count: v.outliers.len(),
        })
        .collect();
    // Insertion order kept among equals: most rejections first.
    let mut sorted: Vec<RejectedInView> = Vec::with_capacity(with.len());
    for v in with.drain(..) {
        let at = sorted
            .iter()
            .position(|s| s.count < v.count)
            .unwrap_or(sorted.len());
        sorted.insert(at, v);
    }
    let summary = summary(count, of_points, &sorted, views.len(), near_border);
    RejectedPoints {
        count,
        of_points,
        views: sorted,
        near_border,
        summary,
    }
}

fn summary(
    count: usize,
    of_points: usize,
    views: &[RejectedInView],
    n_views: usize,
    near_border: usize,
) -> String {
    if count == 0 {
        return format!("robust loss: no point rejected (of {of_points})");
    }
    let percent = 100.0 * count as f64 / of_points.max(1) as f64;
    let mut named: Vec<String> = views
        .iter()
        .take(NAMED_VIEWS)
        .map(|v| format!("{} ({})", v.name, v.count))
        .collect();
    if views.len() > NAMED_VIEWS {
        named.push(format!("{} more", views.len() - NAMED_VIEWS));
    }
    let place = if near_border * 2 > count {
        format!(
            "; {near_border} of them near the image border, where a lens model that does not fit shows first: try another model if the border points are good"
        )
    } else {
        format!("; {near_border} of them near the image border")
    };
    format!(
        "robust loss: {count} of {of_points} points rejected ({percent:.1} %), in {} of {n_views} views: {}{place}",
        views.len(),
        named.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calib::report::Outlier;
    use crate::geometry::{Pose, PoseJson};

    fn view(name: &str, n_points: usize, at: &[(f64, f64)]) -> ViewReport {
        ViewReport {
            name: name.into(),
            rms_px: 0.1,
            n_points,
            camera_from_target: PoseJson::from(&Pose::identity()),
            outliers: at
                .iter()
                .enumerate()
                .map(|(index, &(x_px, y_px))| Outlier {
                    index,
                    id: index,
                    residual_px: 2.0,
                    x_px,
                    y_px,
                    reason: String::new(),
                })
                .collect(),
            residuals_px: vec![],
        }
    }

    #[test]
    fn counts_views_and_the_border() {
        // 1000 x 800 px: the border band is x < 100 or > 900, y < 80 or > 720.
        let views = [
            view("a.png", 50, &[(500.0, 400.0)]),
            view("b.png", 48, &[(20.0, 400.0), (500.0, 790.0)]),
            view("c.png", 54, &[]),
        ];
        let r = rejected_points(&views, (1000, 800));
        assert_eq!((r.count, r.of_points, r.near_border), (3, 155, 2));
        let named: Vec<(&str, usize)> =
            r.views.iter().map(|v| (v.name.as_str(), v.count)).collect();
        assert_eq!(named, [("b.png", 2), ("a.png", 1)]);
        assert_eq!(
            r.summary,
            "robust loss: 3 of 155 points rejected (1.9 %), in 2 of 3 views: b.png (2), a.png (1); 2 of them near the image border, where a lens model that does not fit shows first: try another model if the border points are good"
        );
    }

    #[test]
    fn says_when_nothing_was_rejected() {
        let r = rejected_points(&[view("a.png", 54, &[])], (640, 480));
        assert_eq!(r.summary, "robust loss: no point rejected (of 54)");
        assert!(r.views.is_empty());
    }
}
