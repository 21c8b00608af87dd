//! PNG figures of a run, drawn with plotters into an RGB buffer and encoded by `png`: a cell field
//! on the vertical plane through the column axis (axes in mm, the snapshot time in the title, a
//! colour bar with ticks and the quantity with its unit), and a time trace (pressure drop or bed
//! height) with titled axes. Text is DejaVu Sans, embedded (the `dejavu` crate, drawn by
//! ab_glyph), so no system font library is needed.

use super::png::Image;
use crate::grid::CylGrid;
use plotters::coord::ReverseCoordTranslate;
use plotters::prelude::*;
use plotters::style::FontStyle;

const BLUE: RGBColor = RGBColor(31, 119, 180);
/// The colour of marked levels and times.
pub const MARK: [u8; 3] = [214, 39, 40];

/// A drawing that failed (it never should: the canvas is memory and the font is embedded).
#[derive(Debug, Clone, PartialEq)]
pub struct PlotError(pub String);

impl std::fmt::Display for PlotError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot draw the figure: {}", self.0)
    }
}
impl std::error::Error for PlotError {}

fn fail<E: std::fmt::Debug>(e: E) -> PlotError {
    PlotError(format!("{e:?}"))
}

/// The embedded font, registered once as plotters' "sans-serif".
fn font() -> Result<(), PlotError> {
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular()).is_ok()
    });
    ok.then_some(()).ok_or_else(|| PlotError("the embedded DejaVu Sans font does not load".into()))
}

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

fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// What a field picture shows: its title, the quantity with its unit (the colour bar's label) and
/// the colour range (values outside are clamped).
#[derive(Clone, Debug)]
pub struct FieldLabels<'a> {
    /// E.g. "voidage at t = 0.0500 s".
    pub title: &'a str,
    /// E.g. "voidage ε [-]", "gauge pressure p − p_out [Pa]".
    pub quantity: &'a str,
    pub lo: f64,
    pub hi: f64,
}

/// The titles of a trace: the figure's and its axes'.
#[derive(Clone, Debug)]
pub struct TraceLabels<'a> {
    pub title: &'a str,
    /// E.g. "time t [s]".
    pub x: &'a str,
    /// E.g. "bed pressure drop ΔP [Pa]".
    pub y: &'a str,
}

/// A tick label on an axis from `lo` to `hi`: as many decimals as the span needs (about one
/// more digit than the ticks' step), or powers of ten for very large or very small axes.
fn tick(v: f64, lo: f64, hi: f64) -> String {
    let (span, size) = ((hi - lo).abs(), lo.abs().max(hi.abs()));
    if size >= 1e5 || (size > 0.0 && size < 1e-3) {
        return format!("{v:.2e}");
    }
    let decimals = if span > 0.0 {
        let order = span.log10().floor();
        let mantissa = span / 10f64.powf(order);
        (1.0 - order + if mantissa < 2.0 { 1.0 } else { 0.0 }).clamp(0.0, 6.0) as usize
    } else {
        2
    };
    format!("{v:.decimals$}")
}

/// An RGB canvas for plotters, returned as an `Image`.
fn canvas(
    w: u32,
    h: u32,
    draw: impl FnOnce(DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> Result<(), PlotError>,
) -> Result<Image, PlotError> {
    font()?;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        draw(root.clone())?;
        root.present().map_err(fail)?;
    }
    Ok(Image { width: w as usize, height: h as usize, rgb: buf.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect() })
}

/// The field on the vertical plane y = 0 through the axis (x from −R to R, z upward, both in mm),
/// beside a colour bar from `lo` to `hi` with ticks.
pub fn axial_slice(grid: &CylGrid, field: &[f64], labels: &FieldLabels) -> Result<Image, PlotError> {
    let (lo, hi) = if labels.hi > labels.lo { (labels.lo, labels.hi) } else { (labels.lo - 0.5, labels.lo + 0.5) };
    let (r_mm, h_mm) = (1e3 * grid.radius, 1e3 * grid.height);
    // The plot keeps the column's aspect, within 160–360 px across and up to 720 px high.
    let px_per_mm = (360.0 / (2.0 * r_mm)).min(720.0 / h_mm);
    let plot_w = ((2.0 * r_mm * px_per_mm).round() as u32).clamp(160, 360);
    let plot_h = ((h_mm * px_per_mm).round() as u32).clamp(160, 720);
    let (left, bottom, top, right, bar_w) = (78u32, 55u32, 50u32, 20u32, 160u32);
    let (w, h) = (left + plot_w + right + bar_w, top + plot_h + bottom);
    canvas(w, h, |root| {
        root.fill(&WHITE).map_err(fail)?;
        let (main, bar) = root.split_horizontally(left + plot_w + right);
        let mut chart = ChartBuilder::on(&main)
            .caption(labels.title, ("sans-serif", 17))
            .margin_top(10)
            .margin_left(8)
            .margin_right(right)
            .x_label_area_size(bottom - 10)
            .y_label_area_size(left)
            .build_cartesian_2d(-r_mm..r_mm, 0.0..h_mm)
            .map_err(fail)?;
        let area = chart.plotting_area();
        let (xs, ys) = area.get_pixel_range();
        let pixels = area.strip_coord_spec();
        let spec = chart.as_coord_spec();
        for py in ys.clone() {
            for px in xs.clone() {
                let Some((x_mm, z_mm)) = spec.reverse_translate((px, py)) else { continue };
                // A hair off the plane so that points on a cell boundary pick one side consistently.
                let v = field[grid.locate(1e-3 * x_mm, 1e-9 * grid.radius, 1e-3 * z_mm)];
                // A cell without a value (NaN: e.g. never visited by a particle) stays white.
                if v.is_nan() {
                    continue;
                }
                let c = rgb(colour((v - lo) / (hi - lo)));
                pixels.draw_pixel((px - xs.start, py - ys.start), &c).map_err(fail)?;
            }
        }
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x [mm]")
            .y_desc("height above the distributor z [mm]")
            .x_labels(if plot_w < 220 { 3 } else { 5 })
            .y_labels(8)
            .x_label_formatter(&|v| tick(*v, -r_mm, r_mm))
            .y_label_formatter(&|v| tick(*v, 0.0, h_mm))
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 14))
            .draw()
            .map_err(fail)?;
        colour_bar(&bar, labels.quantity, lo, hi, top, bottom)
    })
}

/// A vertical colour bar for [lo, hi] with ticks and the quantity's label on its right.
fn colour_bar(
    area: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
    quantity: &str,
    lo: f64,
    hi: f64,
    top: u32,
    bottom: u32,
) -> Result<(), PlotError> {
    let mut bar = ChartBuilder::on(area)
        .margin_top(top)
        .margin_bottom(bottom)
        .margin_left(10)
        .margin_right(12)
        .set_label_area_size(LabelAreaPosition::Right, 100)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(fail)?;
    let (xs, ys) = bar.plotting_area().get_pixel_range();
    let strip = bar.plotting_area().strip_coord_spec();
    let n = (ys.end - ys.start).max(2);
    for (k, py) in ys.clone().enumerate() {
        let c = rgb(colour(1.0 - k as f64 / (n - 1) as f64));
        for px in xs.clone() {
            strip.draw_pixel((px - xs.start, py - ys.start), &c).map_err(fail)?;
        }
    }
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(7)
        .y_label_formatter(&|v| tick(*v, lo, hi))
        .y_desc(quantity)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .draw()
        .map_err(fail)?;
    Ok(())
}

/// A line plot of y against t with titled axes.
pub fn trace(t: &[f64], y: &[f64], labels: &TraceLabels) -> Result<Image, PlotError> {
    trace_marked(t, y, None, None, labels)
}

/// `trace` with a red horizontal line at y = `level` and a red vertical line at t = `at`
/// (each labelled with its value; the axes widen to hold them).
pub fn trace_marked(
    t: &[f64],
    y: &[f64],
    level: Option<f64>,
    at: Option<f64>,
    labels: &TraceLabels,
) -> Result<Image, PlotError> {
    let pts: Vec<(f64, f64)> =
        t.iter().zip(y).filter(|(a, b)| a.is_finite() && b.is_finite()).map(|(a, b)| (*a, *b)).collect();
    let (level, at) = (level.filter(|l| l.is_finite()), at.filter(|a| a.is_finite()));
    let (t0, t1) = span(pts.iter().map(|p| p.0).chain(at));
    let (y0, y1) = span(pts.iter().map(|p| p.1).chain(level));
    let (y0, y1) = (y0 - 0.05 * (y1 - y0), y1 + 0.05 * (y1 - y0));
    canvas(800, 480, |root| {
        root.fill(&WHITE).map_err(fail)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(labels.title, ("sans-serif", 18))
            .margin(12)
            .margin_right(32)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(t0..t1, y0..y1)
            .map_err(fail)?;
        chart
            .configure_mesh()
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(215, 215, 215))
            .x_desc(labels.x)
            .y_desc(labels.y)
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&|v| tick(*v, t0, t1))
            .y_label_formatter(&|v| tick(*v, y0, y1))
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 14))
            .draw()
            .map_err(fail)?;
        let mark = rgb(MARK);
        let note = ("sans-serif", 13).into_font().color(&mark);
        if let Some(l) = level {
            chart
                .draw_series(std::iter::once(PathElement::new(vec![(t0, l), (t1, l)], mark.stroke_width(2))))
                .map_err(fail)?;
            let at_t = t0 + 0.02 * (t1 - t0);
            chart.draw_series(std::iter::once(Text::new(tick(l, y0, y1), (at_t, l), note.clone()))).map_err(fail)?;
        }
        if let Some(a) = at {
            chart
                .draw_series(std::iter::once(PathElement::new(vec![(a, y0), (a, y1)], mark.stroke_width(2))))
                .map_err(fail)?;
            let at_y = y0 + 0.06 * (y1 - y0);
            chart.draw_series(std::iter::once(Text::new(tick(a, t0, t1), (a, at_y), note))).map_err(fail)?;
        }
        chart.draw_series(LineSeries::new(pts.iter().copied(), BLUE.stroke_width(2))).map_err(fail)?;
        chart.draw_series(pts.iter().map(|p| Circle::new(*p, 2, BLUE.filled()))).map_err(fail)?;
        Ok(())
    })
}

/// Range of the values, widened when flat (or empty) so the plot has a height.
fn span(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    if !lo.is_finite() || !hi.is_finite() {
        (0.0, 1.0)
    } else if hi - lo > 1e-12 * hi.abs().max(1e-300) {
        (lo, hi)
    } else {
        (lo - 0.5 - 0.01 * lo.abs(), hi + 0.5 + 0.01 * hi.abs())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count(img: &Image, c: [u8; 3]) -> usize {
        img.rgb.iter().filter(|p| **p == c).count()
    }

    /// Pixels of a dark grey or black, as text and axes are drawn.
    fn dark_in(img: &Image, rows: std::ops::Range<usize>, cols: std::ops::Range<usize>) -> usize {
        rows.flat_map(|y| cols.clone().map(move |x| (x, y)))
            .filter(|&(x, y)| img.get(x, y).iter().all(|&v| v < 110))
            .count()
    }

    #[test]
    fn marked_trace_draws_the_level_and_the_mark_and_titles_its_axes() {
        // y = t over [0, 10]; the level at 5 is a horizontal red line, the mark at 2.5 a vertical one
        let t: Vec<f64> = (0..=10).map(|k| k as f64).collect();
        let labels = TraceLabels { title: "a straight line", x: "time t [s]", y: "y [Pa]" };
        let img = trace_marked(&t, &t, Some(5.0), Some(2.5), &labels).unwrap();
        assert_eq!((img.width, img.height), (800, 480));
        let red_rows: Vec<usize> =
            (0..img.height).filter(|&y| (0..img.width).filter(|&x| img.get(x, y) == MARK).count() > 300).collect();
        let red_cols: Vec<usize> =
            (0..img.width).filter(|&x| (0..img.height).filter(|&y| img.get(x, y) == MARK).count() > 200).collect();
        assert!(!red_rows.is_empty() && !red_cols.is_empty(), "a red level line and a red mark line");
        // the level sits halfway up the y range and the mark a quarter across the t range
        let (row, col) = (red_rows[0] as f64, red_cols[0] as f64);
        assert!((row / img.height as f64 - 0.5).abs() < 0.12, "level row {row}");
        assert!((col / img.width as f64 - 0.35).abs() < 0.12, "mark column {col}");
        let plain = trace(&t, &t, &labels).unwrap();
        assert_eq!(count(&plain, MARK), 0, "no marks, no red");
        // the title (top band) and the axis titles (left and bottom bands) are drawn text
        assert!(dark_in(&img, 0..35, 250..550) > 50, "title text");
        assert!(dark_in(&img, 440..480, 300..500) > 30, "x axis title");
        assert!(dark_in(&img, 150..330, 0..30) > 30, "y axis title");
    }

    #[test]
    fn axial_slice_has_the_field_a_colour_bar_with_its_whole_map_and_labels() {
        let grid = CylGrid::new(0.022, 0.06, 0.0044, 0.005, 3);
        // ε = 0.4 in the bottom layer, 1 above
        let field: Vec<f64> =
            (0..grid.num_cells()).map(|c| if c < grid.cells_per_layer() { 0.4 } else { 1.0 }).collect();
        let labels = FieldLabels { title: "voidage at t = 0.0100 s", quantity: "voidage ε [-]", lo: 0.4, hi: 1.0 };
        let img = axial_slice(&grid, &field, &labels).unwrap();
        let (top, bottom) = (count(&img, colour(1.0)), count(&img, colour(0.0)));
        assert!(top > 20_000, "ε = 1 fills most of the plane ({top} px)");
        assert!(bottom > 1_000, "the bottom layer shows ε = 0.4 ({bottom} px)");
        assert!(top > 5 * bottom, "one layer of twelve is packed");
        // the colour bar holds the map from end to end
        assert!(count(&img, colour(0.5)) > 5, "mid-map colours (bar)");
        // title and tick labels are text
        assert!(dark_in(&img, 0..40, 0..img.width) > 50, "title text");
        assert!(dark_in(&img, 0..img.height, img.width - 120..img.width) > 100, "colour-bar ticks and label");
    }

    #[test]
    fn ticks_carry_the_decimals_their_span_needs() {
        assert_eq!(tick(0.35, 0.3, 1.0), "0.35");
        assert_eq!(tick(120.0, 0.0, 600.0), "120");
        assert_eq!(tick(-105.5, -106.1, -104.4), "-105.50");
        assert_eq!(tick(0.0015, 0.0, 0.002), "0.0015");
        assert_eq!(tick(250000.0, 0.0, 1e6), "2.50e5");
        assert_eq!(tick(5e-4, 0.0, 8e-4), "5.00e-4");
    }
}
