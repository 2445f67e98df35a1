//! Top-view figures: the world (floor, walls, cubes, pillars) with paths and markers, drawn
//! with plotters into a PNG.

use nalgebra::Point2;
use omniloop_robot::{CellState, MapSnapshot};
use omniloop_sim::{Layout, Rgb, SolidShape};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

/// Why a figure could not be drawn or written.
#[derive(Debug, thiserror::Error)]
pub enum FigureError {
    /// The drawing's buffer does not make an image of the figure's size.
    #[error("drawing {file}: the drawing buffer does not match the image size")]
    Buffer {
        /// Target file.
        file: String,
    },
    /// A plotters call failed while drawing.
    #[error("drawing {file}: {reason}")]
    Plot {
        /// Target file.
        file: String,
        /// The cause (in the message, so not also a source: printed once).
        reason: PlotError,
    },
    /// Encoding or writing the PNG failed.
    #[error("writing {file}: {reason}")]
    Write {
        /// Target file.
        file: String,
        /// The cause (in the message, so not also a source: printed once).
        reason: image::ImageError,
    },
}

/// A plotters call that failed while drawing into an image buffer.
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
pub struct PlotError(#[from] DrawingAreaErrorKind<BitMapError>);

/// The bitmap backend's own error.
type BitMapError = <BitMapBackend<'static> as DrawingBackend>::ErrorType;

impl FigureError {
    /// The error of the figure `file` for a plotters call that failed drawing it.
    pub(crate) fn plot<E>(file: &str) -> impl Fn(E) -> FigureError + '_
    where
        PlotError: From<E>,
    {
        move |e| FigureError::Plot {
            file: file.to_string(),
            reason: PlotError::from(e),
        }
    }
}

static FONT: Once = Once::new();
const FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

pub(crate) fn register_font() {
    FONT.call_once(|| {
        // The font ships with the binary, so registering it cannot fail at run time.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_BYTES);
    });
}

/// A path to draw.
#[derive(Debug, Clone)]
pub struct PathLayer<'a> {
    /// Legend text.
    pub label: String,
    /// Colour.
    pub rgb: [u8; 3],
    /// Points in world mm.
    pub points: &'a [Point2<f64>],
    /// Draw as dots instead of a line.
    pub dots: bool,
    /// Also draw the robot's outline (`radius` mm) at every `n`-th point.
    pub discs: Option<(usize, f64)>,
}

/// A marker: a circle of given radius (mm) with a label.
#[derive(Debug, Clone)]
pub struct Marker {
    /// Centre.
    pub at: Point2<f64>,
    /// Radius in mm (drawn to scale).
    pub radius_mm: f64,
    /// Colour.
    pub rgb: [u8; 3],
    /// Text beside it (may be empty).
    pub label: String,
}

fn color(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

fn rgb(c: Rgb) -> RGBColor {
    RGBColor(c.0[0], c.0[1], c.0[2])
}

fn rect_corners(center: Point2<f64>, half: [f64; 2], angle: f64) -> Vec<(f64, f64)> {
    let (s, c) = angle.sin_cos();
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|(a, b)| {
            let x = a * half[0];
            let y = b * half[1];
            (center.x + c * x - s * y, center.y + s * x + c * y)
        })
        .collect()
}

/// The outline of a footprint (a circle as a 36-gon).
fn outline(shape: &SolidShape) -> Vec<(f64, f64)> {
    match *shape {
        SolidShape::Box {
            center_mm,
            half_extents_mm,
            angle_rad,
        } => rect_corners(center_mm, [half_extents_mm.x, half_extents_mm.y], angle_rad),
        SolidShape::Cylinder {
            center_mm,
            radius_mm,
        } => circle_points(center_mm, radius_mm, 36),
        SolidShape::Quad { corners_mm } => corners_mm.iter().map(|c| (c.x, c.y)).collect(),
    }
}

/// The bounding box of everything drawn, with a margin.
fn bounds(
    layout: &Layout,
    paths: &[PathLayer<'_>],
    markers: &[Marker],
    spots: &[Spots],
) -> (f64, f64, f64, f64) {
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for r in layout.all_floor_rects() {
        pts.extend(rect_corners(
            Point2::from(r.center_mm),
            [r.size_mm[0] / 2.0, r.size_mm[1] / 2.0],
            r.angle_deg.to_radians(),
        ));
    }
    for s in layout.solids() {
        pts.extend(outline(&s.shape));
    }
    for p in paths {
        pts.extend(p.points.iter().map(|q| (q.x, q.y)));
    }
    for m in markers {
        pts.push((m.at.x - m.radius_mm, m.at.y - m.radius_mm));
        pts.push((m.at.x + m.radius_mm, m.at.y + m.radius_mm));
    }
    for s in spots {
        pts.extend(s.points.iter().map(|q| (q.x, q.y)));
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in pts {
        if x.is_finite() && y.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x0 > x1 {
        return (-1000.0, 1000.0, -1000.0, 1000.0);
    }
    let m = 0.04 * (x1 - x0).max(y1 - y0) + 50.0;
    // Room below for the spots' legend.
    let below = if spots.is_empty() {
        0.0
    } else {
        (24.0 * spots.len() as f64 + 20.0) * (x1 - x0) / 1000.0
    };
    (x0 - m, x1 + m, y0 - m - below, y1 + m)
}

/// How a spot is marked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// A filled disc with a white rim.
    Disc,
    /// A diagonal cross.
    Cross,
}

/// Spots of one colour with one legend entry (e.g. the grid places whose error falls in one
/// band).
#[derive(Debug, Clone)]
pub struct Spots {
    /// Legend text.
    pub label: String,
    /// Colour.
    pub rgb: [u8; 3],
    /// Where, in world mm.
    pub points: Vec<Point2<f64>>,
    /// How each is marked.
    pub mark: Mark,
    /// Radius of a mark, pixels.
    pub size_px: i32,
}

/// One panel of a figure: a title, the world, paths, markers and spots.
#[derive(Debug, Clone)]
pub struct Panel<'a> {
    /// Title above the panel.
    pub title: String,
    /// The world.
    pub layout: &'a Layout,
    /// Paths.
    pub paths: Vec<PathLayer<'a>>,
    /// Markers.
    pub markers: Vec<Marker>,
    /// Spots, drawn over the rest.
    pub spots: Vec<Spots>,
    /// A map the robot built, drawn over the floor: free cells green, blocked ones red, unknown
    /// ones left clear.
    pub grid: Option<&'a MapSnapshot>,
}

type Area<'b> = DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>;

/// A panel's plotting area, in world mm.
type Plot<'b> = DrawingArea<BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A panel's chart: its axes and the series with their legend.
type PanelChart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// One panel into `area`, over `bounds` (x0, x1, y0, y1 in mm): axes, the floor, the robot's
/// map, the solids, markers, paths and spots, and their legend.
fn draw_panel(
    area: &Area<'_>,
    panel: &Panel<'_>,
    bounds: (f64, f64, f64, f64),
) -> Result<(), PlotError> {
    let (x0, x1, y0, y1) = bounds;
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 18))
        .margin_right(20)
        .x_label_area_size(50)
        .y_label_area_size(85)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x [mm]")
        .y_desc("y [mm]")
        .label_style(("sans-serif", 12))
        .draw()?;
    let plot = chart.plotting_area().clone();
    draw_floor(&plot, panel.layout, bounds)?;
    if let Some(grid) = panel.grid {
        draw_grid(&plot, grid)?;
    }
    draw_solids(&plot, panel.layout)?;
    draw_markers(&plot, &panel.markers)?;
    draw_paths(&mut chart, &panel.paths)?;
    draw_spots(&mut chart, &panel.spots)?;
    if !panel.paths.is_empty() || !panel.spots.is_empty() {
        // Spots cover the floor: their legend goes below it.
        let position = if panel.spots.is_empty() {
            SeriesLabelPosition::UpperLeft
        } else {
            SeriesLabelPosition::LowerLeft
        };
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .position(position)
            .draw()?;
    }
    Ok(())
}

/// The ground: the outside over `bounds`, the floor's rectangles (the whole panel when there
/// are none) and a field's lines.
fn draw_floor(
    plot: &Plot<'_>,
    layout: &Layout,
    bounds: (f64, f64, f64, f64),
) -> Result<(), PlotError> {
    let (x0, x1, y0, y1) = bounds;
    plot.draw(&Rectangle::new(
        [(x0, y0), (x1, y1)],
        rgb(layout.outside_rgb).filled(),
    ))?;
    let rects = layout.all_floor_rects();
    if rects.is_empty() {
        plot.draw(&Rectangle::new(
            [(x0, y0), (x1, y1)],
            rgb(layout.floor_rgb).filled(),
        ))?;
    }
    for r in rects {
        let pts = rect_corners(
            Point2::from(r.center_mm),
            [r.size_mm[0] / 2.0, r.size_mm[1] / 2.0],
            r.angle_deg.to_radians(),
        );
        plot.draw(&Polygon::new(pts, rgb(layout.floor_rgb).filled()))?;
    }
    if let Some(f) = layout.field_lines() {
        let line = rgb(layout.line_rgb).stroke_width(1);
        let (a, b) = (f.half_length_mm, f.half_width_mm);
        plot.draw(&PathElement::new(
            vec![(-a, -b), (a, -b), (a, b), (-a, b), (-a, -b)],
            line,
        ))?;
        plot.draw(&PathElement::new(vec![(0.0, -b), (0.0, b)], line))?;
        plot.draw(&PathElement::new(
            circle_points(Point2::origin(), f.centre_circle_radius_mm, 72),
            line,
        ))?;
        if f.has_defense_areas() {
            let (front, side) = (a - f.defense_area_depth_mm, 0.5 * f.defense_area_width_mm);
            for s in [1.0, -1.0] {
                let outline = vec![
                    (s * a, -side),
                    (s * front, -side),
                    (s * front, side),
                    (s * a, side),
                ];
                plot.draw(&PathElement::new(outline, line))?;
            }
        }
    }
    Ok(())
}

/// The world's solids, filled in their colour; all but cylinders edged in dark grey.
fn draw_solids(plot: &Plot<'_>, layout: &Layout) -> Result<(), PlotError> {
    for s in layout.solids() {
        let fill = rgb(s.rgb).filled();
        let edge = RGBColor(60, 60, 60).stroke_width(1);
        let pts = outline(&s.shape);
        plot.draw(&Polygon::new(pts.clone(), fill))?;
        if !matches!(s.shape, SolidShape::Cylinder { .. }) {
            let mut closed = pts;
            closed.push(closed[0]);
            plot.draw(&PathElement::new(closed, edge))?;
        }
    }
    Ok(())
}

/// The markers: circles to scale, each with its label at its upper right.
fn draw_markers(plot: &Plot<'_>, markers: &[Marker]) -> Result<(), PlotError> {
    for m in markers {
        plot.draw(&PathElement::new(
            circle_points(m.at, m.radius_mm, 48),
            color(m.rgb).stroke_width(2),
        ))?;
        if !m.label.is_empty() {
            plot.draw(&Text::new(
                m.label.clone(),
                (m.at.x + m.radius_mm, m.at.y + m.radius_mm),
                ("sans-serif", 13).into_font().color(&BLACK),
            ))?;
        }
    }
    Ok(())
}

/// The paths, as lines or dots (with the robot's outline along them when asked), each in the
/// legend.
fn draw_paths<'a, 'b: 'a>(
    chart: &mut PanelChart<'a, 'b>,
    paths: &[PathLayer<'_>],
) -> Result<(), PlotError> {
    for p in paths {
        let c = color(p.rgb);
        if let Some((every, radius)) = p.discs {
            for q in p.points.iter().step_by(every.max(1)) {
                chart.plotting_area().draw(&PathElement::new(
                    circle_points(*q, radius, 36),
                    c.stroke_width(1),
                ))?;
            }
        }
        let pts: Vec<(f64, f64)> = p.points.iter().map(|q| (q.x, q.y)).collect();
        let series = if p.dots {
            chart.draw_series(pts.iter().map(|&q| Circle::new(q, 1, c.filled())))?
        } else {
            chart.draw_series(LineSeries::new(pts, c.stroke_width(2)))?
        };
        // A path without a label stays out of the legend (many paths, one entry).
        if !p.label.is_empty() {
            series.label(p.label.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
            });
        }
    }
    Ok(())
}

/// The spots, discs (white-rimmed) or crosses, each set in the legend.
fn draw_spots<'a, 'b: 'a>(
    chart: &mut PanelChart<'a, 'b>,
    spots: &[Spots],
) -> Result<(), PlotError> {
    for spots in spots {
        let c = color(spots.rgb);
        let r = spots.size_px;
        let pts = spots.points.iter().map(|q| (q.x, q.y));
        let series = match spots.mark {
            Mark::Disc => {
                chart.draw_series(pts.clone().map(|q| Circle::new(q, r + 1, WHITE.filled())))?;
                chart.draw_series(pts.map(|q| Circle::new(q, r, c.filled())))?
            }
            Mark::Cross => chart.draw_series(pts.map(|q| Cross::new(q, r, c.stroke_width(2))))?,
        };
        let mark = spots.mark;
        series.label(spots.label.clone()).legend(move |(x, y)| {
            let at = (x + 9, y);
            match mark {
                Mark::Disc => EmptyElement::at(at) + Circle::new((0, 0), r, c.filled()),
                Mark::Cross => EmptyElement::at(at) + Circle::new((0, 0), r, c.stroke_width(2)),
            }
        });
    }
    Ok(())
}

/// The robot's map, a rectangle a run of like cells along each row.
fn draw_grid(plot: &Plot<'_>, grid: &MapSnapshot) -> Result<(), PlotError> {
    let g = &grid.geometry;
    let (ox, oy, c) = (g.origin_mm.x, g.origin_mm.y, g.cell_mm);
    for y in 0..g.height {
        let row = &grid.cells[y * g.width..(y + 1) * g.width];
        let mut x = 0;
        while x < g.width {
            let state = row[x];
            let run = row[x..].iter().take_while(|&&s| s == state).count();
            let style = match state {
                CellState::Free => Some(RGBColor(40, 200, 60).mix(0.3).filled()),
                CellState::Suspect => Some(RGBColor(240, 150, 30).mix(0.65).filled()),
                CellState::Blocked => Some(RGBColor(200, 30, 30).mix(0.65).filled()),
                CellState::Unknown => None,
            };
            if let Some(style) = style {
                let (x0, y0) = (ox + x as f64 * c, oy + y as f64 * c);
                plot.draw(&Rectangle::new(
                    [(x0, y0), (x0 + run as f64 * c, y0 + c)],
                    style,
                ))?;
            }
            x += run;
        }
    }
    Ok(())
}

fn circle_points(c: Point2<f64>, r: f64, n: usize) -> Vec<(f64, f64)> {
    (0..=n)
        .map(|k| {
            let t = k as f64 * std::f64::consts::TAU / n as f64;
            (c.x + r * t.cos(), c.y + r * t.sin())
        })
        .collect()
}

/// Draws panels side by side into a PNG; each panel is `width` pixels wide and all share the
/// bounds of everything drawn, with millimetres square.
pub fn draw_panels(file: &Path, panels: &[Panel<'_>], width: u32) -> Result<(), FigureError> {
    let name = file.display().to_string();
    render_panels(&name, panels, width)?
        .save(file)
        .map_err(|reason| FigureError::Write { file: name, reason })
}

/// [`draw_panels`] into PNG bytes; `name` names the figure in errors.
pub fn panels_png(name: &str, panels: &[Panel<'_>], width: u32) -> Result<Vec<u8>, FigureError> {
    png_bytes(name, &render_panels(name, panels, width)?)
}

/// `img` encoded as PNG; `name` names the figure in errors.
pub(crate) fn png_bytes(name: &str, img: &image::RgbImage) -> Result<Vec<u8>, FigureError> {
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(|reason| FigureError::Write {
        file: name.to_string(),
        reason,
    })?;
    Ok(bytes)
}

/// Draws panels side by side into an image (`name` names the figure in errors).
pub fn render_panels(
    name: &str,
    panels: &[Panel<'_>],
    width: u32,
) -> Result<image::RgbImage, FigureError> {
    register_font();
    let mut b = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in panels {
        let (x0, x1, y0, y1) = bounds(p.layout, &p.paths, &p.markers, &p.spots);
        b = (b.0.min(x0), b.1.max(x1), b.2.min(y0), b.3.max(y1));
    }
    let plot_w = width.saturating_sub(105).max(100);
    let plot_h = ((plot_w as f64) * (b.3 - b.2) / (b.1 - b.0))
        .round()
        .max(100.0) as u32;
    let height = plot_h + 90;
    let total_w = width * panels.len().max(1) as u32;
    let mut buf = vec![255u8; (total_w * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (total_w, height)).into_drawing_area();
        root.fill(&WHITE).map_err(FigureError::plot(name))?;
        let areas = root.split_evenly((1, panels.len().max(1)));
        for (area, panel) in areas.iter().zip(panels) {
            draw_panel(area, panel, b).map_err(FigureError::plot(name))?;
        }
        root.present().map_err(FigureError::plot(name))?;
    }
    image::RgbImage::from_raw(total_w, height, buf).ok_or_else(|| FigureError::Buffer {
        file: name.to_string(),
    })
}

/// Draws one panel into a PNG `width` pixels wide.
pub fn draw_topview(
    file: &Path,
    title: &str,
    layout: &Layout,
    paths: &[PathLayer<'_>],
    markers: &[Marker],
    width: u32,
) -> Result<(), FigureError> {
    draw_panels(
        file,
        &[Panel {
            title: title.to_string(),
            layout,
            paths: paths.to_vec(),
            markers: markers.to_vec(),
            spots: Vec::new(),
            grid: None,
        }],
        width,
    )
}
