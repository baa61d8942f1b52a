//! SVG plots (plotters' SVG backend: text is laid out by the browser, so no
//! font files are needed). Every plot has a title and axis labels with
//! units; logarithmic axes are drawn on the base-10 logarithm of the data
//! with tick labels in the data's own values.

use crate::error::{Error, Result};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

fn plot_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::csv(path, format!("SVG drawing failed: {e}"))
}

/// A named curve for [`line_plot`].
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// Points `(x, y)`, finite.
    pub points: Vec<(f64, f64)>,
}

/// How the axes of a line plot map data to the page.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scale {
    /// Both axes linear.
    #[default]
    Linear,
    /// Logarithmic y (points with y <= 0 are left out).
    LogY,
    /// Both axes logarithmic (points with x <= 0 or y <= 0 left out).
    LogLog,
}

impl Scale {
    fn log_x(self) -> bool {
        self == Scale::LogLog
    }
    fn log_y(self) -> bool {
        self != Scale::Linear
    }
}

/// Axis labels (with units) and title of a line plot.
pub struct Axes<'a> {
    /// Title.
    pub title: &'a str,
    /// x label, with its unit.
    pub x: &'a str,
    /// y label, with its unit.
    pub y: &'a str,
    /// Linear or logarithmic axes.
    pub scale: Scale,
}

/// `v` on a logarithmic axis: its base-10 logarithm (positive finite
/// values only).
fn log_of(v: f64) -> Option<f64> {
    (v > 0.0 && v.is_finite()).then(|| v.log10())
}

/// Tick label of a value drawn at `v` on a log axis: `10^v`.
fn log_tick(v: &f64) -> String {
    format!("{:.0e}", 10f64.powf(*v))
}

/// Does a linear axis over `[lo, hi]` need scientific tick labels
/// (plotters' default writes `0.0` for every tick of a range like 0 to
/// 9e-6 J)? When its largest magnitude is below 1e-2 or above 1e5.
fn needs_sci(lo: f64, hi: f64) -> bool {
    let m = lo.abs().max(hi.abs());
    m > 0.0 && !(1e-2..1e5).contains(&m)
}

/// Scientific tick label with three significant digits: `9.14e-6`.
fn sci_tick(v: &f64) -> String {
    format!("{v:.2e}")
}

/// The curves' points as drawn: logarithms where the axis is logarithmic,
/// non-finite and non-positive-on-log points left out.
fn drawn_points(curves: &[Curve], scale: Scale) -> Vec<Vec<(f64, f64)>> {
    let map = |v: f64, log: bool| {
        if log {
            log_of(v)
        } else {
            v.is_finite().then_some(v)
        }
    };
    curves
        .iter()
        .map(|c| {
            c.points
                .iter()
                .filter_map(|&(x, y)| Some((map(x, scale.log_x())?, map(y, scale.log_y())?)))
                .collect()
        })
        .collect()
}

/// The smallest box `(x0, x1, y0, y1)` around the drawn points, when
/// there is one.
fn bounds(drawn: &[Vec<(f64, f64)>]) -> Option<(f64, f64, f64, f64)> {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in drawn.iter().flatten() {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    (x0.is_finite() && y0.is_finite()).then_some((x0, x1, y0, y1))
}

/// The axes every line and scatter plot draws on: white page, title, the
/// data box `bounds` padded by 5 % of its range (half its magnitude, at
/// least 0.5, where the range vanishes), the axis labels and the tick
/// labels: `10^v` on a logarithmic axis, scientific on a linear y axis
/// whose values need it ([`needs_sci`]) and on such an x axis when
/// `sci_x`.
fn frame<'a, 'b>(
    root: &'b DrawingArea<SVGBackend<'a>, Shift>,
    path: &Path,
    axes: &Axes,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    sci_x: bool,
) -> Result<ChartContext<'b, SVGBackend<'a>, Cartesian2d<RangedCoordf64, RangedCoordf64>>> {
    let pad = |a: f64, b: f64| {
        if b > a {
            0.05 * (b - a)
        } else {
            0.5 * a.abs().max(1.0)
        }
    };
    let (px, py) = (pad(x0, x1), pad(y0, y1));
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let mut chart = ChartBuilder::on(root)
        .caption(axes.title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0 - px..x1 + px, y0 - py..y1 + py)
        .map_err(|e| plot_err(path, e))?;
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(axes.x).y_desc(axes.y);
    if axes.scale.log_x() {
        mesh.x_label_formatter(&log_tick);
    } else if sci_x && needs_sci(x0, x1) {
        mesh.x_label_formatter(&sci_tick);
    }
    if axes.scale.log_y() {
        mesh.y_label_formatter(&log_tick);
    } else if needs_sci(y0, y1) {
        mesh.y_label_formatter(&sci_tick);
    }
    mesh.draw().map_err(|e| plot_err(path, e))?;
    Ok(chart)
}

/// Draw curves into an SVG (legend; linear or logarithmic axes).
pub fn line_plot(path: &Path, axes: &Axes, curves: &[Curve]) -> Result<()> {
    draw_lines(path, axes, curves, None)
}

/// [`line_plot`] of curves whose values were raised to a positive `floor`
/// (a gap that reached zero, shown on a log axis): where a curve reaches
/// the floor, a hollow downward triangle in its colour, and the legend
/// says `≤ <floor> (floor)`, so a floor is not read as convergence to it.
pub fn line_plot_floored(path: &Path, axes: &Axes, curves: &[Curve], floor: f64) -> Result<()> {
    draw_lines(path, axes, curves, Some(floor))
}

/// [`line_plot`], with the points at `floor` marked when given.
fn draw_lines(path: &Path, axes: &Axes, curves: &[Curve], floor: Option<f64>) -> Result<()> {
    let drawn = drawn_points(curves, axes.scale);
    let Some(bounds) = bounds(&drawn) else {
        return Ok(());
    };
    let root = SVGBackend::new(path, (800, 500)).into_drawing_area();
    let mut chart = frame(&root, path, axes, bounds, false)?;
    for (i, (c, pts)) in curves.iter().zip(drawn).enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(pts, color.stroke_width(2)))
            .map_err(|e| plot_err(path, e))?
            .label(c.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    if let Some(floor) = floor {
        mark_floor(path, &mut chart, curves, axes.scale, floor)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| plot_err(path, e))?;
    root.present().map_err(|e| plot_err(path, e))
}

/// A set of points for [`scatter_plot`]: markers, or a line through the
/// points in their order.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points `(x, y)`; non-finite ones are left out.
    pub points: Vec<(f64, f64)>,
    /// Draw a line through the points instead of markers.
    pub line: bool,
}

/// Draw point sets (a distinct colour each: the first as rings, the
/// others as dots; line series in grey) on linear axes with a legend, e.g. Pareto fronts in objective
/// space.
pub fn scatter_plot(path: &Path, axes: &Axes, series: &[Series]) -> Result<()> {
    let pts: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .copied()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect()
        })
        .collect();
    let Some(bounds) = bounds(&pts) else {
        return Ok(());
    };
    let root = SVGBackend::new(path, (800, 600)).into_drawing_area();
    let mut chart = frame(&root, path, axes, bounds, true)?;
    let mut colour = 0;
    for (s, p) in series.iter().zip(pts) {
        if s.line {
            let grey = RGBColor(150, 150, 150);
            chart
                .draw_series(LineSeries::new(p, grey.stroke_width(1)))
                .map_err(|e| plot_err(path, e))?
                .label(s.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], grey.stroke_width(1))
                });
        } else {
            // The first marker series as rings around the others' dots,
            // so that points on top of each other stay visible.
            let c = Palette99::pick(colour).to_rgba();
            let style = if colour == 0 {
                c.stroke_width(2)
            } else {
                c.filled()
            };
            let r = if colour == 0 { 5 } else { 3 };
            colour += 1;
            chart
                .draw_series(p.into_iter().map(|q| Circle::new(q, r, style)))
                .map_err(|e| plot_err(path, e))?
                .label(s.label.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), r, style));
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| plot_err(path, e))?;
    root.present().map_err(|e| plot_err(path, e))
}

/// Hollow triangles on the points where a curve comes down to `floor`
/// (the first of each run of points at or below it), and one legend entry
/// for them (none when no point is there).
fn mark_floor<DB: DrawingBackend>(
    path: &Path,
    chart: &mut ChartContext<DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    curves: &[Curve],
    scale: Scale,
    floor: f64,
) -> Result<()> {
    let at_floor: Vec<Curve> = curves
        .iter()
        .map(|c| Curve {
            label: String::new(),
            points: (c.points.iter().enumerate())
                .filter(|&(k, p)| p.1 <= floor && (k == 0 || c.points[k - 1].1 > floor))
                .map(|(_, &p)| p)
                .collect(),
        })
        .collect();
    if at_floor.iter().all(|c| c.points.is_empty()) {
        return Ok(());
    }
    for (i, pts) in drawn_points(&at_floor, scale).into_iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(pts.into_iter().map(|p| {
                EmptyElement::at(p) + PathElement::new(down_triangle(0, 0), color.stroke_width(2))
            }))
            .map_err(|e| plot_err(path, e))?;
    }
    chart
        .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
        .map_err(|e| plot_err(path, e))?
        .label(format!("≤ {floor:.0e} (floor)"))
        .legend(|(x, y)| PathElement::new(down_triangle(x + 10, y), BLACK.stroke_width(2)));
    Ok(())
}

/// Outline of a downward triangle (`≤`) around the pixel `(x, y)`.
fn down_triangle(x: i32, y: i32) -> Vec<(i32, i32)> {
    vec![(x - 7, y - 5), (x + 7, y - 5), (x, y + 7), (x - 7, y - 5)]
}

/// A heat map: a regular grid of values, cells that violate constraints,
/// and marked points.
pub struct HeatMap<'a> {
    /// Title.
    pub title: &'a str,
    /// Second line under the title (empty: none), e.g. the values of the
    /// variables a slice holds fixed.
    pub subtitle: &'a str,
    /// Axis names (with units).
    pub names: (&'a str, &'a str),
    /// What the colours show (with its unit), written on the colour scale.
    pub value_label: &'a str,
    /// Grid coordinates along x (`nx`) and y (`ny`), increasing.
    pub xs: &'a [f64],
    /// Grid coordinates along y.
    pub ys: &'a [f64],
    /// Values, `values[i * ny + j]` at `(xs[i], ys[j])`.
    pub values: &'a [f64],
    /// Infeasible cells (same indexing), drawn greyed.
    pub infeasible: &'a [bool],
    /// Marked points: label, points, colour index.
    pub marks: Vec<(String, Vec<(f64, f64)>)>,
}

/// How a heat map's values become colours: the colour coordinate `c(v)`
/// runs linearly along the colour bar from `lo` (bottom) to `hi` (top).
#[derive(Debug, Clone, Copy, PartialEq)]
struct ColourScale {
    /// `c = log10(max(v, floor))` when `Some(floor)`, else `c = v`.
    log_floor: Option<f64>,
    /// Bottom of the bar, `c` of the smallest value.
    lo: f64,
    /// Top of the bar, `c` of the largest value.
    hi: f64,
    /// Are some values below the log floor (drawn in the bottom colour)?
    clipped: bool,
}

/// Decades of a logarithmic colour scale below its largest value.
const LOG_DECADES: f64 = 3.0;

impl ColourScale {
    /// The scale for values in `[vmin, vmax]`: logarithmic when they are
    /// non-negative and span more than two decades (tall peaks beside the
    /// basins), with a floor at the power of ten [`LOG_DECADES`] decades
    /// below the largest; linear otherwise.
    fn new(vmin: f64, vmax: f64) -> ColourScale {
        if vmin >= 0.0 && vmax > 100.0 * vmin {
            let floor = 10f64.powf(vmax.log10().floor() - LOG_DECADES).max(vmin);
            return ColourScale {
                log_floor: Some(floor),
                lo: floor.log10(),
                hi: vmax.log10(),
                clipped: vmin < floor,
            };
        }
        let (lo, hi) = if vmax > vmin {
            (vmin, vmax)
        } else {
            (vmin - 0.5, vmin + 0.5)
        };
        ColourScale {
            log_floor: None,
            lo,
            hi,
            clipped: false,
        }
    }

    /// The colour coordinate of `v`.
    fn coord(&self, v: f64) -> f64 {
        match self.log_floor {
            Some(floor) => v.max(floor).log10(),
            None => v,
        }
    }

    /// Position of `v` on the ramp, in `[0, 1]`.
    fn position(&self, v: f64) -> f64 {
        (self.coord(v) - self.lo) / (self.hi - self.lo)
    }

    /// The colour bar's label: what `c` is, from the values' label.
    fn label(&self, value_label: &str) -> String {
        match self.log_floor {
            Some(floor) if self.clipped => {
                format!("log10 of {value_label}; values below {floor:.0e} in the bottom colour")
            }
            Some(_) => format!("log10 of {value_label}"),
            None => value_label.to_string(),
        }
    }
}

/// The colour scale of a heat map in `area`: the ramp from `scale.lo`
/// (bottom) to `scale.hi` (top) on a linear axis of the colour coordinate,
/// evenly spaced round ticks, and `label`.
fn colour_bar<DB: DrawingBackend>(
    path: &Path,
    area: &DrawingArea<DB, plotters::coord::Shift>,
    label: &str,
    scale: &ColourScale,
) -> Result<()> {
    let mut bar = ChartBuilder::on(area)
        .margin_top(10)
        .margin_bottom(50)
        .margin_right(5)
        .y_label_area_size(95)
        .build_cartesian_2d(0.0..1.0, scale.lo..scale.hi)
        .map_err(|e| plot_err(path, e))?;
    let mut mesh = bar.configure_mesh();
    mesh.disable_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 14))
        .y_labels(8);
    if scale.log_floor.is_none() && needs_sci(scale.lo, scale.hi) {
        mesh.y_label_formatter(&sci_tick);
    }
    mesh.draw().map_err(|e| plot_err(path, e))?;
    const STEPS: usize = 200;
    let at = |k: usize| scale.lo + (scale.hi - scale.lo) * k as f64 / STEPS as f64;
    bar.draw_series((0..STEPS).map(|k| {
        let t = (k as f64 + 0.5) / STEPS as f64;
        Rectangle::new([(0.0, at(k)), (1.0, at(k + 1))], ramp(t).filled())
    }))
    .map_err(|e| plot_err(path, e))?;
    Ok(())
}

/// Colour for `t` in `[0, 1]` (a viridis-like ramp: dark blue, teal, yellow).
fn ramp(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let s = t.clamp(0.0, 1.0) * 4.0;
    let i = (s.floor() as usize).min(3);
    let w = s - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: f64, q: f64| (p + w * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// `c` greyed: two thirds of the way to light grey (infeasible cells).
fn greyed(c: RGBColor) -> RGBColor {
    let grey = |u: u8| ((u as f64 + 2.0 * 200.0) / 3.0) as u8;
    RGBColor(grey(c.0), grey(c.1), grey(c.2))
}

/// Draw a heat map SVG. The colour follows `f` on a linear scale, or
/// `log10 f` when the values are non-negative and span more than two
/// decades (the basins stay visible next to tall peaks; values below
/// `10^(⌊log10 max⌋ − 3)` share the bottom colour); the colour
/// bar says which. Infeasible cells are greyed and, when there are any,
/// named in the legend.
pub fn heat_map(path: &Path, map: &HeatMap) -> Result<()> {
    let (nx, ny) = (map.xs.len(), map.ys.len());
    if nx < 2 || ny < 2 || map.values.len() != nx * ny {
        return Err(plot_err(path, "grid needs at least 2 x 2 values"));
    }
    let vmin = map.values.iter().copied().fold(f64::INFINITY, f64::min);
    let vmax = map.values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let scale = ColourScale::new(vmin, vmax);
    let half = |c: &[f64], i: usize| {
        let lo = if i == 0 {
            c[0]
        } else {
            0.5 * (c[i - 1] + c[i])
        };
        let hi = if i + 1 == c.len() {
            c[i]
        } else {
            0.5 * (c[i] + c[i + 1])
        };
        (lo, hi)
    };
    let root = SVGBackend::new(path, (900, 700)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let mut root = root
        .titled(map.title, ("sans-serif", 20))
        .map_err(|e| plot_err(path, e))?;
    if !map.subtitle.is_empty() {
        root = root
            .titled(map.subtitle, ("sans-serif", 14))
            .map_err(|e| plot_err(path, e))?;
    }
    let (root, bar) = root.split_horizontally(760);
    colour_bar(path, &bar, &scale.label(map.value_label), &scale)?;
    let mut chart = ChartBuilder::on(&root)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(map.xs[0]..map.xs[nx - 1], map.ys[0]..map.ys[ny - 1])
        .map_err(|e| plot_err(path, e))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(map.names.0)
        .y_desc(map.names.1)
        .draw()
        .map_err(|e| plot_err(path, e))?;
    let mut cells = Vec::with_capacity(nx * ny);
    let mut any_infeasible = false;
    for i in 0..nx {
        for j in 0..ny {
            let mut c = ramp(scale.position(map.values[i * ny + j]));
            if map.infeasible.get(i * ny + j).copied().unwrap_or(false) {
                c = greyed(c);
                any_infeasible = true;
            }
            let ((x0, x1), (y0, y1)) = (half(map.xs, i), half(map.ys, j));
            cells.push(Rectangle::new([(x0, y0), (x1, y1)], c.filled()));
        }
    }
    chart.draw_series(cells).map_err(|e| plot_err(path, e))?;
    let colors = [RED, WHITE, MAGENTA, CYAN];
    for (k, (label, pts)) in map.marks.iter().enumerate() {
        let color = colors[k % colors.len()];
        chart
            .draw_series(pts.iter().map(|&p| Cross::new(p, 7, color.stroke_width(3))))
            .map_err(|e| plot_err(path, e))?
            .label(label.clone())
            .legend(move |(x, y)| Cross::new((x + 8, y), 5, color.stroke_width(3)));
    }
    if any_infeasible {
        // A legend entry only: no cell is drawn by this series.
        let swatch = greyed(ramp(0.5));
        chart
            .draw_series(std::iter::empty::<Rectangle<(f64, f64)>>())
            .map_err(|e| plot_err(path, e))?
            .label("grey: infeasible (some g > 0)")
            .legend(move |(x, y)| {
                Rectangle::new([(x + 2, y - 6), (x + 14, y + 6)], swatch.filled())
            });
    }
    if !map.marks.is_empty() || any_infeasible {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| plot_err(path, e))?;
    }
    root.present().map_err(|e| plot_err(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_values_get_scientific_ticks() {
        assert!(needs_sci(0.0, 9.1e-6) && needs_sci(-2e5, 0.0));
        assert!(!needs_sci(3.09, 3.12) && !needs_sci(-0.05, 1.0) && !needs_sci(0.0, 0.0));
        // A strain energy of a few µJ: ticks in its own values, not `0.0`.
        let dir = std::env::temp_dir().join(format!("plyscape-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("u.svg");
        let axes = Axes {
            title: "U",
            x: "t [s]",
            y: "U [J]",
            scale: Scale::Linear,
        };
        let points = (0..=10)
            .map(|k| (0.1 * k as f64, 1e-6 * k as f64))
            .collect();
        line_plot(
            &path,
            &axes,
            &[Curve {
                label: "U".into(),
                points,
            }],
        )
        .unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("5.00e-6"), "{svg}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn colour_scale_is_log_only_over_decades() {
        // Himmelblau's range: log10 f, floor three decades below 10^2.
        let s = ColourScale::new(0.0, 890.0);
        assert!((s.log_floor.unwrap() - 0.1).abs() < 1e-17);
        assert!(s.clipped && (s.lo + 1.0).abs() < 1e-15 && s.hi == 890f64.log10());
        assert_eq!((s.position(0.0), s.position(890.0)), (0.0, 1.0));
        assert!((s.position(10.0) - 2.0 / (1.0 + 890f64.log10())).abs() < 1e-14);
        assert!(s
            .label("f [-]")
            .starts_with("log10 of f [-]; values below 1e-1"));
        // Within two decades: linear in f, labelled with f itself.
        let s = ColourScale::new(1.0, 50.0);
        assert_eq!((s.log_floor, s.lo, s.hi), (None, 1.0, 50.0));
        assert_eq!((s.position(25.5), s.label("f [-]")), (0.5, "f [-]".into()));
        // Positive, above the floor: log10 f, nothing clipped.
        let s = ColourScale::new(20.0, 1e4);
        assert_eq!((s.lo, s.clipped), (20f64.log10(), false));
        assert_eq!(s.label("f [-]"), "log10 of f [-]");
        // Negative values: linear.
        assert_eq!(ColourScale::new(-1.0, 1e6).log_floor, None);
    }

    #[test]
    fn floor_and_infeasible_cells_are_named() {
        let dir = std::env::temp_dir().join(format!("plyscape-floor-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let axes = Axes {
            title: "gap",
            x: "calls [-]",
            y: "gap [-]",
            scale: Scale::LogLog,
        };
        let curve = |ys: &[f64]| Curve {
            label: "c".into(),
            points: ys
                .iter()
                .enumerate()
                .map(|(k, &y)| (k as f64 + 1.0, y))
                .collect(),
        };
        let path = dir.join("floor.svg");
        line_plot_floored(&path, &axes, &[curve(&[1.0, 1e-3, 1e-12, 1e-12])], 1e-12).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("≤ 1e-12 (floor)"), "{svg}");
        line_plot_floored(&path, &axes, &[curve(&[1.0, 1e-3])], 1e-12).unwrap();
        assert!(!std::fs::read_to_string(&path).unwrap().contains("(floor)"));
        let (xs, ys) = ([0.0, 1.0], [0.0, 1.0]);
        let map = |infeasible: &'static [bool]| HeatMap {
            title: "t",
            subtitle: "held at x3 = 0.5",
            names: ("x1 [-]", "x2 [-]"),
            value_label: "f [-]",
            xs: &xs,
            ys: &ys,
            values: &[1.0, 2.0, 3.0, 4.0],
            infeasible,
            marks: Vec::new(),
        };
        let path = dir.join("map.svg");
        heat_map(&path, &map(&[false, true, false, false])).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("grey: infeasible") && svg.contains("held at x3 = 0.5"));
        heat_map(&path, &map(&[false; 4])).unwrap();
        assert!(!std::fs::read_to_string(&path)
            .unwrap()
            .contains("infeasible"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn ramp_ends() {
        assert_eq!(ramp(0.0), RGBColor(68, 1, 84));
        assert_eq!(ramp(1.0), RGBColor(253, 231, 37));
    }
}
