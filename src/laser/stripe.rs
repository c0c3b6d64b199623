//! Sub-pixel stripe centres, one per column (a horizontal stripe) or per
//! row (a vertical one), by the centre of gravity over a thresholded window
//! or by a ridge detector ([`super::ridge`]).
//!
//! Each scan line (column or row) is searched for its peak with a top-hat
//! response: the lightly smoothed signal minus the mean of two flanking
//! windows `max_width_px / 2 + 2` pixels away, so a light square of the
//! board's pattern (both flanks light) does not answer and its edge only by
//! half its step, the stripe (both flanks darker) by its full contrast. A
//! centre far from the median of its 25 neighbours on either side is
//! searched again near that median (the stripe is continuous). The local background
//! is the straight line through the two flanks' means. When the image with
//! the laser off is given it is subtracted first (the board's pattern and
//! the ambient light cancel). The scan axis is chosen automatically (the
//! one that finds the stripe in more lines) unless given.
//!
//! Centre of gravity: over the contiguous window around the peak where the
//! signal exceeds `background + threshold * contrast`, weights `signal -
//! that level`. Width: full width at half the contrast (linear
//! interpolation of the crossings). Quality: the peak's grey level and its
//! contrast above the background; `saturated` when a pixel of the window is
//! at 255. A centre's std is the noise (from the image's pixel-to-pixel
//! differences, a robust MAD) propagated through the estimator.

use crate::error::{Error, Result};
use crate::image::GrayImage;
use serde::{Deserialize, Serialize};

/// How the centre is found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum StripeMethod {
    /// Centre of gravity over a thresholded window.
    #[default]
    CentreOfGravity,
    /// Steger's ridge detector: Gaussian derivatives, the second
    /// derivative's extremum along the line normal.
    Ridge,
}

impl StripeMethod {
    /// The name used by the CLI and JSON (`cog`, `ridge`).
    pub fn name(self) -> &'static str {
        match self {
            StripeMethod::CentreOfGravity => "cog",
            StripeMethod::Ridge => "ridge",
        }
    }
    /// From its name; an unknown name is an error naming the choices.
    pub fn from_name(name: &str) -> Result<StripeMethod> {
        match name {
            "cog" | "centre_of_gravity" => Ok(StripeMethod::CentreOfGravity),
            "ridge" | "steger" => Ok(StripeMethod::Ridge),
            other => Err(Error::invalid(
                "extractor",
                format!("unknown extractor '{other}' (expected cog or ridge)"),
            )),
        }
    }
}

/// Which image lines are scanned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ScanAxis {
    /// One centre per column (a roughly horizontal stripe): `y_px` measured.
    Columns,
    /// One centre per row (a roughly vertical stripe): `x_px` measured.
    Rows,
}

/// Settings of [`extract_stripe`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StripeOptions {
    /// Centre of gravity or ridge (default centre of gravity).
    pub method: StripeMethod,
    /// Columns or rows; `None`: chosen from the image (default).
    pub axis: Option<ScanAxis>,
    /// Smallest contrast of a peak above its local background, grey levels
    /// (default 20); a line with less is a gap.
    pub min_contrast: f64,
    /// The centre of gravity's window level, a fraction of the contrast
    /// above the background (default 0.3).
    pub threshold: f64,
    /// Widest stripe expected, pixels (default 24): sets the flanks'
    /// distance.
    pub max_width_px: f64,
}

impl Default for StripeOptions {
    fn default() -> Self {
        StripeOptions {
            method: StripeMethod::CentreOfGravity,
            axis: None,
            min_contrast: 20.0,
            threshold: 0.3,
            max_width_px: 24.0,
        }
    }
}

/// One stripe centre.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StripePoint {
    /// Centre x, pixels (the column itself when scanning columns).
    pub x_px: f64,
    /// Centre y, pixels (the row itself when scanning rows).
    pub y_px: f64,
    /// Full width at half the contrast, pixels.
    pub width_px: f64,
    /// Brightest grey level of the peak (after the laser-off subtraction).
    pub peak: f64,
    /// Peak above the local background, grey levels.
    pub contrast: f64,
    /// Standard deviation of the centre along the scan, pixels.
    pub std_px: f64,
    /// A pixel of the window is at 255 in the stripe image.
    pub saturated: bool,
}

/// A stripe: its centres, gaps and ends.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stripe {
    /// The scanned lines.
    pub axis: ScanAxis,
    /// The extractor.
    pub method: StripeMethod,
    /// Centres in scan order.
    pub points: Vec<StripePoint>,
    /// Runs of scan lines without a centre between two found ones,
    /// `[first, last]` (column or row indices, inclusive).
    pub gaps: Vec<[usize; 2]>,
    /// The ends of each continuous piece, `[x_px, y_px]`, two per piece.
    pub ends: Vec<[f64; 2]>,
    /// The image's noise estimate, grey levels.
    pub noise_grey: f64,
    /// The ridge detector's Gaussian sigma, pixels (ridge only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ridge_sigma_px: Option<f64>,
}

/// The signal in scan order: line `i` (a column or a row), position `j`.
pub(crate) struct Scan {
    pub lines: usize,
    pub len: usize,
    pub data: Vec<f32>,
    pub raw: Vec<u8>,
    /// The laser-off image in scan order, when given.
    pub off: Option<Vec<f32>>,
}

impl Scan {
    fn new(on: &GrayImage, off: Option<&GrayImage>, axis: ScanAxis) -> Scan {
        let (w, h) = (on.width as usize, on.height as usize);
        let (lines, len) = match axis {
            ScanAxis::Columns => (w, h),
            ScanAxis::Rows => (h, w),
        };
        let mut data = vec![0f32; w * h];
        let mut raw = vec![0u8; w * h];
        let mut off_scan = off.map(|_| vec![0f32; w * h]);
        for y in 0..h {
            for x in 0..w {
                let k = y * w + x;
                let v = on.pixels[k];
                let s = v as f32 - off.map_or(0.0, |o| o.pixels[k] as f32);
                let idx = match axis {
                    ScanAxis::Columns => x * h + y,
                    ScanAxis::Rows => y * w + x,
                };
                data[idx] = s;
                raw[idx] = v;
                if let (Some(o), Some(t)) = (off, off_scan.as_mut()) {
                    t[idx] = o.pixels[k] as f32;
                }
            }
        }
        Scan {
            lines,
            len,
            data,
            raw,
            off: off_scan,
        }
    }
    pub(crate) fn line(&self, i: usize) -> &[f32] {
        &self.data[i * self.len..(i + 1) * self.len]
    }
    /// The value at line `i`, position `j`, clamped to the image.
    pub(crate) fn at(&self, i: isize, j: isize) -> f32 {
        let i = i.clamp(0, self.lines as isize - 1) as usize;
        let j = j.clamp(0, self.len as isize - 1) as usize;
        self.data[i * self.len + j]
    }
}

/// The first pass's finding in one line.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Peak {
    /// Centre of gravity, position along the line.
    pub centre: f64,
    pub std: f64,
    pub width: f64,
    pub peak: f64,
    pub contrast: f64,
    pub saturated: bool,
}

/// The stripe in `on` (with the laser-off image `off` subtracted when given).
pub fn extract_stripe(
    on: &GrayImage,
    off: Option<&GrayImage>,
    options: &StripeOptions,
) -> Result<Stripe> {
    check(on, off, options)?;
    let axis = match options.axis {
        Some(a) => a,
        None => {
            let count = |a| {
                let scan = Scan::new(on, off, a);
                let noise = noise_of(&scan);
                first_pass(&scan, options, noise).iter().flatten().count()
            };
            if count(ScanAxis::Rows) > count(ScanAxis::Columns) {
                ScanAxis::Rows
            } else {
                ScanAxis::Columns
            }
        }
    };
    let scan = Scan::new(on, off, axis);
    let noise = noise_of(&scan);
    let mut peaks = first_pass(&scan, options, noise);
    drop_isolated(&mut peaks, options.max_width_px);
    let mut ridge_sigma = None;
    if options.method == StripeMethod::Ridge {
        let mut widths: Vec<f64> = peaks.iter().flatten().map(|p| p.width).collect();
        let median = median(&mut widths).unwrap_or(2.0);
        let sigma = (median / (2.0 * 3f64.sqrt())).clamp(0.8, options.max_width_px / 2.0);
        ridge_sigma = Some(sigma);
        let kernels = super::ridge::Kernels::new(sigma);
        for (i, slot) in peaks.iter_mut().enumerate() {
            if let Some(p) = slot {
                *slot = super::ridge::refine(&scan, i, p, &kernels, noise);
            }
        }
    }
    Ok(assemble(axis, options.method, &peaks, noise, ridge_sigma))
}

fn check(on: &GrayImage, off: Option<&GrayImage>, options: &StripeOptions) -> Result<()> {
    if on.width < 8 || on.height < 8 {
        return Err(Error::invalid(
            "stripe image",
            format!("needs at least 8x8 pixels, got {}x{}", on.width, on.height),
        ));
    }
    if let Some(o) = off {
        if (o.width, o.height) != (on.width, on.height) {
            return Err(Error::invalid(
                "laser-off image",
                format!(
                    "must be the stripe image's size {}x{}, got {}x{}",
                    on.width, on.height, o.width, o.height
                ),
            ));
        }
    }
    let o = options;
    let contrast_ok = o.min_contrast.is_finite() && o.min_contrast > 0.0;
    let threshold_ok = o.threshold > 0.0 && o.threshold < 1.0;
    let width_ok = (2.0..=200.0).contains(&o.max_width_px);
    if !(contrast_ok && threshold_ok && width_ok) {
        return Err(Error::invalid(
            "stripe options",
            format!(
                "need min_contrast > 0, 0 < threshold < 1 and 2 <= max_width_px <= 200, got {}, {}, {}",
                o.min_contrast, o.threshold, o.max_width_px
            ),
        ));
    }
    Ok(())
}

/// Robust noise sigma of the signal: the MAD of neighbour differences.
fn noise_of(scan: &Scan) -> f64 {
    let mut d: Vec<f64> = Vec::with_capacity(scan.data.len() / 5 + 1);
    for i in (0..scan.lines).step_by(3) {
        let l = scan.line(i);
        for j in (1..scan.len).step_by(2) {
            d.push((l[j] - l[j - 1]).abs() as f64);
        }
    }
    median(&mut d).map_or(0.0, |m| 1.4826 * m / 2f64.sqrt())
}

pub(crate) fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    Some(*m)
}

fn first_pass(scan: &Scan, options: &StripeOptions, noise: f64) -> Vec<Option<Peak>> {
    let raw = |i: usize| &scan.raw[i * scan.len..(i + 1) * scan.len];
    // The step model across albedo edges refines the centre of gravity
    // (the ridge detector starts from the plain first pass).
    let refit = options.method == StripeMethod::CentreOfGravity;
    let off = |i: usize| {
        scan.off
            .as_ref()
            .filter(|_| refit)
            .map(|o| &o[i * scan.len..(i + 1) * scan.len])
    };
    let mut peaks: Vec<Option<Peak>> = (0..scan.lines)
        .map(|i| peak_in_line(scan.line(i), raw(i), off(i), options, noise, (0, scan.len)))
        .collect();
    // The stripe is continuous: a centre far from its neighbourhood's
    // median (a light square of the pattern outshining a dim stretch of
    // the stripe) is searched again near that median.
    let reach = options.max_width_px;
    let medians: Vec<Option<f64>> = (0..scan.lines)
        .map(|i| {
            let lo = i.saturating_sub(TRACK);
            let hi = (i + TRACK + 1).min(scan.lines);
            let mut c: Vec<f64> = peaks[lo..hi].iter().flatten().map(|p| p.centre).collect();
            if c.len() > TRACK {
                median(&mut c)
            } else {
                None
            }
        })
        .collect();
    for (i, slot) in peaks.iter_mut().enumerate() {
        let (Some(p), Some(m)) = (*slot, medians[i]) else {
            continue;
        };
        if (p.centre - m).abs() > reach {
            let lo = (m - reach).max(0.0) as usize;
            let hi = ((m + reach) as usize + 1).min(scan.len);
            *slot = peak_in_line(scan.line(i), raw(i), off(i), options, noise, (lo, hi))
                .filter(|q| (q.centre - m).abs() <= reach);
        }
    }
    peaks
}

/// Lines on either side whose centres make the neighbourhood's median.
const TRACK: usize = 25;

/// Flank length, pixels.
const FLANK: usize = 5;
/// Smallest centre std reported, pixels (a noise-free image still has
/// quantisation).
const MIN_STD_PX: f64 = 0.01;

fn peak_in_line(
    line: &[f32],
    raw: &[u8],
    off: Option<&[f32]>,
    options: &StripeOptions,
    noise: f64,
    search: (usize, usize),
) -> Option<Peak> {
    let n = line.len();
    let offset = (options.max_width_px / 2.0).ceil() as usize + 2;
    let mut prefix = vec![0f64; n + 1];
    for j in 0..n {
        prefix[j + 1] = prefix[j] + line[j] as f64;
    }
    let mean = |a: usize, b: usize| (prefix[b] - prefix[a]) / (b - a) as f64;
    let left =
        |j: usize| (j + 1 >= offset + FLANK).then(|| mean(j + 1 - offset - FLANK, j + 1 - offset));
    let right = |j: usize| (j + offset + FLANK <= n).then(|| mean(j + offset, j + offset + FLANK));
    let smooth = |j: usize| {
        let a = line[j.saturating_sub(1)] as f64;
        let c = line[(j + 1).min(n - 1)] as f64;
        0.25 * a + 0.5 * line[j] as f64 + 0.25 * c
    };
    let mut best: Option<(usize, f64)> = None;
    for j in search.0..search.1.min(n) {
        let flank = match (left(j), right(j)) {
            (Some(a), Some(b)) => 0.5 * (a + b),
            (Some(a), None) => a,
            (None, Some(b)) => b,
            (None, None) => continue,
        };
        let r = smooth(j) - flank;
        if best.map_or(true, |(_, v)| r > v) {
            best = Some((j, r));
        }
    }
    let (j0, response) = best?;
    if response < options.min_contrast {
        return None;
    }
    // The background: a line through the flanks' means.
    let half = (FLANK as f64 - 1.0) / 2.0;
    let (bl, br) = (left(j0), right(j0));
    let (pl, pr) = (
        j0 as f64 - offset as f64 - half,
        j0 as f64 + offset as f64 + half,
    );
    let bg = |j: f64| match (bl, br) {
        (Some(a), Some(b)) => a + (b - a) * (j - pl) / (pr - pl),
        (Some(a), None) => a,
        (None, Some(b)) => b,
        (None, None) => 0.0,
    };
    let lo = j0.saturating_sub(2);
    let hi = (j0 + 2).min(n - 1);
    let (jp, peak) = (lo..=hi)
        .map(|j| (j, line[j] as f64))
        .fold((j0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a });
    let contrast = peak - bg(jp as f64);
    if contrast < options.min_contrast {
        return None;
    }
    let level = |j: usize| bg(j as f64) + options.threshold * contrast;
    let above = |j: usize| line[j] as f64 - level(j);
    let (mut a, mut b) = (jp, jp);
    while a > 0 && jp - (a - 1) <= offset && above(a - 1) > 0.0 {
        a -= 1;
    }
    while b + 1 < n && (b + 1) - jp <= offset && above(b + 1) > 0.0 {
        b += 1;
    }
    let (mut sw, mut swj) = (0.0, 0.0);
    for j in a..=b {
        let w = above(j).max(0.0);
        sw += w;
        swj += w * j as f64;
    }
    if sw <= 0.0 {
        return None;
    }
    let centre = swj / sw;
    let spread: f64 = (a..=b).map(|j| (j as f64 - centre).powi(2)).sum();
    let std = (noise * spread.sqrt() / sw).max(MIN_STD_PX);
    let half_level = |j: usize| line[j] as f64 - (bg(j as f64) + 0.5 * contrast);
    let mut l = jp;
    while l > 0 && half_level(l - 1) > 0.0 && jp - l < 2 * offset {
        l -= 1;
    }
    let left_edge = if l > 0 {
        let (v0, v1) = (half_level(l - 1), half_level(l));
        l as f64 - v1 / (v1 - v0)
    } else {
        0.0
    };
    let mut r = jp;
    while r + 1 < n && half_level(r + 1) > 0.0 && r - jp < 2 * offset {
        r += 1;
    }
    let right_edge = if r + 1 < n {
        let (v0, v1) = (half_level(r), half_level(r + 1));
        r as f64 + v0 / (v0 - v1)
    } else {
        (n - 1) as f64
    };
    let p = Peak {
        centre,
        std,
        width: right_edge - left_edge,
        peak,
        contrast,
        saturated: raw[a..=b].contains(&255),
    };
    Some(match off {
        Some(off) => super::ratio::across_edge(line, raw, off, p, (a, b, jp), offset, noise),
        None => p,
    })
}

/// Drop a centre that jumps away from both of its neighbours while they agree.
fn drop_isolated(peaks: &mut [Option<Peak>], max_width: f64) {
    let limit = max_width / 2.0;
    let bad: Vec<usize> = (1..peaks.len().saturating_sub(1))
        .filter(|&i| match (peaks[i - 1], peaks[i], peaks[i + 1]) {
            (Some(a), Some(b), Some(c)) => {
                (a.centre - c.centre).abs() < limit
                    && (b.centre - a.centre).abs() > limit
                    && (b.centre - c.centre).abs() > limit
            }
            _ => false,
        })
        .collect();
    for i in bad {
        peaks[i] = None;
    }
}

fn assemble(
    axis: ScanAxis,
    method: StripeMethod,
    peaks: &[Option<Peak>],
    noise: f64,
    ridge_sigma_px: Option<f64>,
) -> Stripe {
    let xy = |i: usize, c: f64| match axis {
        ScanAxis::Columns => [i as f64, c],
        ScanAxis::Rows => [c, i as f64],
    };
    let mut points = Vec::new();
    let mut gaps = Vec::new();
    let mut ends = Vec::new();
    let mut last: Option<(usize, f64)> = None;
    for (i, p) in peaks.iter().enumerate() {
        let Some(p) = p else { continue };
        match last {
            Some((k, c)) if k + 1 < i => {
                gaps.push([k + 1, i - 1]);
                ends.push(xy(k, c));
                ends.push(xy(i, p.centre));
            }
            None => ends.push(xy(i, p.centre)),
            Some(_) => {}
        }
        last = Some((i, p.centre));
        let [x_px, y_px] = xy(i, p.centre);
        points.push(StripePoint {
            x_px,
            y_px,
            width_px: p.width,
            peak: p.peak,
            contrast: p.contrast,
            std_px: p.std,
            saturated: p.saturated,
        });
    }
    if let Some((k, c)) = last {
        ends.push(xy(k, c));
    }
    Stripe {
        axis,
        method,
        points,
        gaps,
        ends,
        noise_grey: noise,
        ridge_sigma_px,
    }
}
