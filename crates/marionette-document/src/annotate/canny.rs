//! The edges of a picture as ControlNet's canny preprocessor finds them: `cv2.Canny(rgb,
//! low, high)` on the picture's RGB (aperture 3, the L1 gradient), reproduced step for step
//! so that the pixels are OpenCV's: 3 × 3 Sobel derivatives with the border replicated, in
//! each pixel the channel of the largest |dx| + |dy|, non-maximum suppression along the
//! gradient's direction in OpenCV's fixed point (tan 22.5° as 13573 / 2¹⁵), then hysteresis
//! from the pixels above `high` through the 8-connected ones above `low`.

use image::{GrayImage, Luma, RgbImage};
use serde::{Deserialize, Serialize};

/// The canny preprocessor's two thresholds on the L1 gradient (ControlNet's defaults:
/// 100 and 200); a pixel above `high` starts an edge, one above `low` continues it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Canny {
    pub low: f64,
    pub high: f64,
}

impl Default for Canny {
    fn default() -> Self {
        Self { low: 100.0, high: 200.0 }
    }
}

impl std::str::FromStr for Canny {
    type Err = String;

    /// `LOW,HIGH`: two numbers from 0 to 1020 (the largest L1 gradient of 8-bit pixels).
    fn from_str(s: &str) -> Result<Self, String> {
        let expected = || format!("expected LOW,HIGH (100,200), each 0 to 1020, found {s:?}");
        let (low, high) = s.split_once(',').ok_or_else(expected)?;
        let number = |t: &str| t.trim().parse::<f64>().ok().filter(|v| (0.0..=1020.0).contains(v));
        let (Some(low), Some(high)) = (number(low), number(high)) else { return Err(expected()) };
        Ok(Self { low, high })
    }
}

/// OpenCV's `CANNY_SHIFT` and tan 22.5° in that fixed point.
const SHIFT: u32 = 15;
const TAN_22: i64 = 13573;

/// The edges of `picture` (255 on an edge, 0 elsewhere), as `cv2.Canny` draws them.
pub fn edges(picture: &RgbImage, canny: Canny) -> GrayImage {
    let (w, h) = (picture.width() as usize, picture.height() as usize);
    let (low, high) = if canny.low > canny.high { (canny.high, canny.low) } else { (canny.low, canny.high) };
    let (low, high) = (low.floor() as i32, high.floor() as i32);
    let gradient = strongest_gradient(picture);
    // OpenCV's map, with a border of "not an edge": 0 may be an edge, 1 is not, 2 is.
    let stride = w + 2;
    let mut map = vec![1u8; stride * (h + 2)];
    let mut stack = Vec::new();
    let magnitude = |x: isize, y: isize| -> i32 {
        let inside = (0..w as isize).contains(&x) && (0..h as isize).contains(&y);
        if inside { gradient[y as usize * w + x as usize].2 } else { 0 }
    };
    for y in 0..h {
        for x in 0..w {
            let (dx, dy, m) = gradient[y * w + x];
            let cell = (y + 1) * stride + x + 1;
            if m <= low || !is_local_maximum(dx, dy, m, |ox, oy| magnitude(x as isize + ox, y as isize + oy)) {
                continue;
            }
            if m > high {
                map[cell] = 2;
                stack.push(cell);
            } else {
                map[cell] = 0;
            }
        }
    }
    follow_edges(&mut map, stride, stack);
    GrayImage::from_fn(w as u32, h as u32, |x, y| {
        Luma([if map[(y as usize + 1) * stride + x as usize + 1] == 2 { 255 } else { 0 }])
    })
}

/// Whether `m` is the largest along the gradient (dx, dy), as OpenCV compares: strictly
/// above the neighbour behind, at least the one ahead, except on the diagonals (strictly
/// above both). `at(ox, oy)` is the magnitude at that offset, 0 outside the picture.
fn is_local_maximum(dx: i16, dy: i16, m: i32, at: impl Fn(isize, isize) -> i32) -> bool {
    let x = i64::from(dx).abs();
    let y = i64::from(dy).abs() << SHIFT;
    let tan_22x = x * TAN_22;
    if y < tan_22x {
        return m > at(-1, 0) && m >= at(1, 0);
    }
    let tan_67x = tan_22x + (x << (SHIFT + 1));
    if y > tan_67x {
        return m > at(0, -1) && m >= at(0, 1);
    }
    let s = if (dx ^ dy) < 0 { -1 } else { 1 };
    m > at(-s, -1) && m > at(s, 1)
}

/// Hysteresis: every "may be" cell 8-connected to an edge becomes edge.
fn follow_edges(map: &mut [u8], stride: usize, mut stack: Vec<usize>) {
    let around = [1, stride - 1, stride, stride + 1];
    while let Some(cell) = stack.pop() {
        for next in around.iter().flat_map(|&d| [cell - d, cell + d]) {
            if map[next] == 0 {
                map[next] = 2;
                stack.push(next);
            }
        }
    }
}

/// Per pixel, the Sobel derivatives (dx, dy) and L1 magnitude of the channel whose
/// magnitude is largest (the first such in R, G, B order).
fn strongest_gradient(picture: &RgbImage) -> Vec<(i16, i16, i32)> {
    let (w, h) = (picture.width() as i64, picture.height() as i64);
    let at = |x: i64, y: i64, c: usize| {
        i32::from(picture.get_pixel(x.clamp(0, w - 1) as u32, y.clamp(0, h - 1) as u32).0[c])
    };
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let mut best = (0i16, 0i16, -1i32);
            for c in 0..3 {
                let p = |ox: i64, oy: i64| at(x + ox, y + oy, c);
                let dx = (p(1, -1) - p(-1, -1)) + 2 * (p(1, 0) - p(-1, 0)) + (p(1, 1) - p(-1, 1));
                let dy = (p(-1, 1) - p(-1, -1)) + 2 * (p(0, 1) - p(0, -1)) + (p(1, 1) - p(1, -1));
                let m = dx.abs() + dy.abs();
                if m > best.2 {
                    best = (dx as i16, dy as i16, m);
                }
            }
            out.push(best);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertical step from black to grey: one edge column, on the last dark pixel, which
    /// OpenCV's comparison (strictly above the left, at least the right) picks of the two
    /// equal magnitudes either side of the step.
    #[test]
    fn a_step_gives_one_column_of_edge() {
        let picture = RgbImage::from_fn(8, 6, |x, _| image::Rgb(if x < 4 { [0; 3] } else { [200; 3] }));
        let edges = edges(&picture, Canny::default());
        for y in 0..6 {
            let row: Vec<u8> = (0..8).map(|x| edges.get_pixel(x, y).0[0]).collect();
            assert_eq!(row, [0, 0, 0, 255, 0, 0, 0, 0], "row {y}");
        }
    }

    #[test]
    fn a_flat_picture_has_no_edges_and_thresholds_parse() {
        let picture = RgbImage::from_pixel(5, 5, image::Rgb([90, 10, 200]));
        assert!(edges(&picture, Canny::default()).pixels().all(|p| p.0[0] == 0));
        assert_eq!("50, 150".parse::<Canny>(), Ok(Canny { low: 50.0, high: 150.0 }));
        assert!("50".parse::<Canny>().unwrap_err().contains("expected LOW,HIGH"));
        assert!("50,2000".parse::<Canny>().is_err());
    }
}
