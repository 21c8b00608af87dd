//! PNG pictures of a run: a vertical slice of a cell field through the column axis, and a time
//! trace (pressure drop or bed height). Simple on purpose: a colour map, axes, and numeric labels
//! in a 3×5 pixel font.

use super::png::Image;
use crate::grid::CylGrid;

const WHITE: [u8; 3] = [255, 255, 255];
const BLACK: [u8; 3] = [0, 0, 0];
const BLUE: [u8; 3] = [31, 119, 180];
const RED: [u8; 3] = [214, 39, 40];

/// Viridis-like colour map, t in [0, 1] (5 stops of matplotlib's viridis, linearly interpolated).
pub fn colour(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] =
        [[68.0, 1.0, 84.0], [59.0, 82.0, 139.0], [33.0, 145.0, 140.0], [94.0, 201.0, 98.0], [253.0, 231.0, 37.0]];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let mut c = [0u8; 3];
    for (n, v) in c.iter_mut().enumerate() {
        *v = (STOPS[i][n] * (1.0 - f) + STOPS[i + 1][n] * f).round() as u8;
    }
    c
}

/// The field on the vertical plane y = 0 through the axis (x from −R to R, z upward), with a
/// colour bar labelled by `lo` and `hi` (values outside are clamped).
pub fn axial_slice(grid: &CylGrid, field: &[f64], lo: f64, hi: f64) -> Image {
    let px_per_m = (240.0 / (2.0 * grid.radius)).min(720.0 / grid.height);
    let w = ((2.0 * grid.radius * px_per_m).round() as usize).max(8);
    let h = ((grid.height * px_per_m).round() as usize).max(8);
    let (margin, bar) = (10usize, 40usize);
    let mut img = Image::new(w + 2 * margin + bar + 30, h + 2 * margin, WHITE);
    for py in 0..h {
        let z = (h - py) as f64 / px_per_m - 0.5 / px_per_m;
        for px in 0..w {
            let x = -grid.radius + (px as f64 + 0.5) / px_per_m;
            // A hair off the plane so that points on a cell boundary pick one side consistently.
            let v = field[grid.locate(x, 1e-9 * grid.radius, z)];
            img.set((px + margin) as i64, (py + margin) as i64, colour((v - lo) / (hi - lo)));
        }
    }
    let bx = (w + 2 * margin) as i64;
    for py in 0..h {
        let c = colour(1.0 - py as f64 / (h - 1) as f64);
        img.fill_rect(bx, (py + margin) as i64, 10, 1, c);
    }
    text(&mut img, bx + 13, margin as i64, &short(hi), BLACK);
    text(&mut img, bx + 13, (h + margin) as i64 - 5, &short(lo), BLACK);
    img
}

/// A line plot of y against t with labelled axis ends.
pub fn trace(t: &[f64], y: &[f64]) -> Image {
    trace_marked(t, y, None, None)
}

/// `trace` with a red horizontal line at y = `level` and a red vertical line at t = `at`
/// (each labelled; the axes widen to hold them).
pub fn trace_marked(t: &[f64], y: &[f64], level: Option<f64>, at: Option<f64>) -> Image {
    let (w, h, left, bottom, top, right) = (640i64, 400i64, 60i64, 30i64, 15i64, 20i64);
    let mut img = Image::new(w as usize, h as usize, WHITE);
    let (pw, ph) = (w - left - right, h - top - bottom);
    img.line((left, top), (left, top + ph), BLACK);
    img.line((left, top + ph), (left + pw, top + ph), BLACK);
    let pts: Vec<(f64, f64)> =
        t.iter().zip(y).filter(|(a, b)| a.is_finite() && b.is_finite()).map(|(a, b)| (*a, *b)).collect();
    if pts.is_empty() {
        return img;
    }
    let (t0, t1) = span(pts.iter().map(|p| p.0).chain(at.filter(|a| a.is_finite())));
    let (y0, y1) = span(pts.iter().map(|p| p.1).chain(level.filter(|l| l.is_finite())));
    let to_px = |(a, b): (f64, f64)| {
        (
            left + ((a - t0) / (t1 - t0) * pw as f64).round() as i64,
            top + ph - ((b - y0) / (y1 - y0) * ph as f64).round() as i64,
        )
    };
    if let Some(l) = level.filter(|l| l.is_finite()) {
        let (_, yy) = to_px((t0, l));
        img.line((left, yy), (left + pw, yy), RED);
        text(&mut img, left + pw - 40, yy - 8, &short(l), RED);
    }
    if let Some(a) = at.filter(|a| a.is_finite()) {
        let (xx, _) = to_px((a, y0));
        img.line((xx, top), (xx, top + ph), RED);
        text(&mut img, xx + 3, top + ph - 12, &short(a), RED);
    }
    for pair in pts.windows(2) {
        img.line(to_px(pair[0]), to_px(pair[1]), BLUE);
    }
    for p in &pts {
        let (x, yy) = to_px(*p);
        img.fill_rect(x - 1, yy - 1, 3, 3, BLUE);
    }
    text(&mut img, 4, top, &short(y1), BLACK);
    text(&mut img, 4, top + ph - 5, &short(y0), BLACK);
    text(&mut img, left, top + ph + 8, &short(t0), BLACK);
    text(&mut img, left + pw - 40, top + ph + 8, &short(t1), BLACK);
    img
}

/// Range of the values, widened when flat so the plot has a height.
fn span(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    if hi - lo > 1e-12 * hi.abs().max(1e-300) {
        (lo, hi)
    } else {
        (lo - 0.5 - 0.01 * lo.abs(), hi + 0.5 + 0.01 * hi.abs())
    }
}

fn short(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e5) {
        format!("{x:.3e}")
    } else {
        format!("{x:.4}")
    }
}

/// 3×5 glyphs for digits, '.', '-', 'e' (each row 3 bits, top first).
fn glyph(c: char) -> [u8; 5] {
    match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '.' => [0, 0, 0, 0, 2],
        '-' => [0, 0, 7, 0, 0],
        'e' => [0, 7, 7, 4, 7],
        _ => [0; 5],
    }
}

/// Draw text at (x, y) (top-left), one pixel per font bit.
pub fn text(img: &mut Image, x: i64, y: i64, s: &str, c: [u8; 3]) {
    for (n, ch) in s.chars().enumerate() {
        let g = glyph(ch);
        for (row, bits) in g.iter().enumerate() {
            for col in 0..3 {
                if bits & (4 >> col) != 0 {
                    img.set(x + 4 * n as i64 + col, y + row as i64, c);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marked_trace_draws_the_level_and_the_mark_where_they_belong() {
        // y = t over [0, 10]; level 5 and mark 2.5 sit at known fractions of the plot box
        let t: Vec<f64> = (0..=10).map(|k| k as f64).collect();
        let img = trace_marked(&t, &t, Some(5.0), Some(2.5));
        let (left, top, pw, ph) = (60usize, 15usize, 560usize, 355usize);
        let y_level = top + ph - (0.5 * ph as f64).round() as usize;
        let x_mark = left + (0.25 * pw as f64).round() as usize;
        assert_eq!(img.get(left + pw - 60, y_level), RED, "level line");
        assert_eq!(img.get(x_mark, top + 5), RED, "mark line");
        assert_ne!(img.get(left + pw - 60, y_level - 20), RED);
        // without marks the same pixels stay clear
        let plain = trace(&t, &t);
        assert_ne!(plain.get(left + pw - 60, y_level), RED);
        assert_ne!(plain.get(x_mark, top + 5), RED);
    }
}
