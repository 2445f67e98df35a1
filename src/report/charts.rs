//! Charts: x-y plots of lines and dots in a grid of panels, drawn with plotters into a PNG.

use super::topview::{FigureError, PlotError, png_bytes, register_font};
use plotters::prelude::*;

/// The colours of the lines of a figure, in order (Matplotlib's ten, then navy and maroon):
/// each knob of a robustness panel, each robot of a team.
pub const PALETTE: [[u8; 3]; 12] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
    [0, 0, 128],
    [128, 0, 0],
];

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Joined by a line.
    Line,
    /// A dot at each point.
    Dots,
    /// A cross at each point.
    Crosses,
}

/// One series of a chart.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text (empty: not in the legend).
    pub label: String,
    /// Colour.
    pub rgb: [u8; 3],
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub style: Style,
}

/// One panel: axes, their labels and ranges, and the series.
#[derive(Debug, Clone)]
pub struct Chart {
    /// Title above the panel.
    pub title: String,
    /// Label of the x axis.
    pub x_label: String,
    /// Label of the y axis.
    pub y_label: String,
    /// Range of the x axis.
    pub x_range: (f64, f64),
    /// Range of the y axis.
    pub y_range: (f64, f64),
    /// The series.
    pub series: Vec<Series>,
}

/// Draws `charts` into a PNG, `columns` panels a row, each `cell` pixels (width, height);
/// `name` names the figure in errors.
pub fn charts_png(
    name: &str,
    charts: &[Chart],
    columns: usize,
    cell: (u32, u32),
) -> Result<Vec<u8>, FigureError> {
    register_font();
    let columns = columns.max(1);
    let rows = charts.len().div_ceil(columns).max(1);
    let (w, h) = (cell.0 * columns as u32, cell.1 * rows as u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(FigureError::plot(name))?;
        let areas = root.split_evenly((rows, columns));
        for (area, chart) in areas.iter().zip(charts) {
            draw_chart(area, chart).map_err(FigureError::plot(name))?;
        }
        root.present().map_err(FigureError::plot(name))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).ok_or_else(|| FigureError::Buffer {
        file: name.to_string(),
    })?;
    png_bytes(name, &img)
}

/// One chart into `area`: its axes, its series and, when any is labelled, their legend.
fn draw_chart(
    area: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
    c: &Chart,
) -> Result<(), PlotError> {
    let mut chart = ChartBuilder::on(area)
        .caption(&c.title, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(52)
        .build_cartesian_2d(c.x_range.0..c.x_range.1, c.y_range.0..c.y_range.1)?;
    chart
        .configure_mesh()
        .x_desc(c.x_label.as_str())
        .y_desc(c.y_label.as_str())
        .label_style(("sans-serif", 12))
        .draw()?;
    let mut labelled = false;
    for s in &c.series {
        let colour = RGBColor(s.rgb[0], s.rgb[1], s.rgb[2]);
        let pts = s.points.iter().copied();
        let drawn = match s.style {
            Style::Line => chart.draw_series(LineSeries::new(pts, colour.stroke_width(2))),
            Style::Dots => chart.draw_series(pts.map(|p| Circle::new(p, 3, colour.filled()))),
            Style::Crosses => {
                chart.draw_series(pts.map(|p| Cross::new(p, 4, colour.stroke_width(2))))
            }
        }?;
        if !s.label.is_empty() {
            labelled = true;
            drawn.label(s.label.clone()).legend(move |(x, y)| {
                Rectangle::new([(x, y - 4), (x + 14, y + 4)], colour.filled())
            });
        }
    }
    if labelled {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 12))
            .draw()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_of_charts_is_a_png_of_the_grid_size() {
        let chart = Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            series: vec![Series {
                label: "s".into(),
                rgb: [200, 0, 0],
                points: vec![(0.1, 0.2), (0.5, 0.9)],
                style: Style::Line,
            }],
        };
        let png = charts_png(
            "t.png",
            &[chart.clone(), chart.clone(), chart],
            2,
            (300, 200),
        )
        .unwrap();
        let img = image::load_from_memory(&png).unwrap();
        assert_eq!((img.width(), img.height()), (600, 400));
    }
}
