//! Grey planes of the forward camera's images and bilinear reading of them.

use image::{ImageBuffer, Luma, RgbaImage};

/// A grey image of `f32` levels.
pub type Grey = ImageBuffer<Luma<f32>, Vec<f32>>;

/// The luminance of an RGBA image (ITU-R BT.601 weights), as a [`Grey`] plane.
pub fn grey(image: &RgbaImage) -> Grey {
    Grey::from_fn(image.width(), image.height(), |x, y| {
        let p = image.get_pixel(x, y).0;
        Luma([crate::resection::stripes::luminance(&p)])
    })
}

/// The level of `img` at `(x, y)` (pixel centres at integers) by bilinear interpolation, the
/// border pixels continued outward.
pub fn bilinear(img: &Grey, x: f64, y: f64) -> f32 {
    let (w, h) = (img.width() as i64, img.height() as i64);
    let x = x.clamp(0.0, (w - 1) as f64);
    let y = y.clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (x.floor() as i64, y.floor() as i64);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    let p = |xx: i64, yy: i64| img.get_pixel(xx as u32, yy as u32).0[0];
    let top = p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx;
    let bottom = p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx;
    top * (1.0 - fy) + bottom * fy
}
