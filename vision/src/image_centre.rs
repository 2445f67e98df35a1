//! Where a mirror camera's image is centred, from the image itself: the mirror shows the robot's
//! own top and the camera (a dark disc) about the mirror's axis, so a mirror shifted off its
//! place moves that disc with the rest of its image.

use image::RgbaImage;

/// The centre of the dark disc about `guess` in `img`: the centroid of the pixels within
/// `radius_px` of the estimate whose brightest channel is at most `max_level`, the window
/// moved to the centroid and the centroid taken again (twice), so that a disc a few pixels off
/// `guess` is measured whole. `None` when fewer than `min_pixels` pixels are that dark.
pub fn dark_disc_centre(
    img: &RgbaImage,
    guess: [f64; 2],
    radius_px: f64,
    max_level: u8,
    min_pixels: usize,
) -> Option<[f64; 2]> {
    let mut centre = guess;
    for _ in 0..3 {
        centre = dark_centroid(img, centre, radius_px, max_level, min_pixels)?;
    }
    Some(centre)
}

/// The centroid (pixel centres) of the dark pixels within `radius_px` of `c`.
fn dark_centroid(
    img: &RgbaImage,
    c: [f64; 2],
    radius_px: f64,
    max_level: u8,
    min_pixels: usize,
) -> Option<[f64; 2]> {
    let (w, h) = (img.width() as f64, img.height() as f64);
    let v0 = (c[1] - radius_px).floor().clamp(0.0, h) as u32;
    let v1 = (c[1] + radius_px).ceil().clamp(0.0, h) as u32;
    let u0 = (c[0] - radius_px).floor().clamp(0.0, w) as u32;
    let u1 = (c[0] + radius_px).ceil().clamp(0.0, w) as u32;
    let (mut n, mut su, mut sv) = (0usize, 0.0, 0.0);
    for v in v0..v1 {
        for u in u0..u1 {
            let (x, y) = (f64::from(u) + 0.5, f64::from(v) + 0.5);
            if (x - c[0]).hypot(y - c[1]) > radius_px {
                continue;
            }
            let p = img.get_pixel(u, v).0;
            if p[0].max(p[1]).max(p[2]) <= max_level {
                n += 1;
                su += x;
                sv += y;
            }
        }
    }
    (n >= min_pixels.max(1)).then(|| [su / n as f64, sv / n as f64])
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    fn disc(centre: [f64; 2], r: f64) -> RgbaImage {
        RgbaImage::from_fn(120, 100, |u, v| {
            let d = (f64::from(u) + 0.5 - centre[0]).hypot(f64::from(v) + 0.5 - centre[1]);
            if d <= r {
                Rgba([20, 22, 25, 255])
            } else {
                Rgba([40, 140, 60, 255])
            }
        })
    }

    #[test]
    fn finds_a_disc_moved_off_the_guess() {
        let img = disc([63.3, 48.6], 20.0);
        let c = dark_disc_centre(&img, [60.0, 50.0], 26.0, 64, 50).unwrap();
        assert!(
            (c[0] - 63.3).abs() < 0.1 && (c[1] - 48.6).abs() < 0.1,
            "{c:?}"
        );
    }

    #[test]
    fn no_disc_no_centre() {
        let img = RgbaImage::from_pixel(50, 50, Rgba([40, 140, 60, 255]));
        assert_eq!(dark_disc_centre(&img, [25.0, 25.0], 10.0, 64, 10), None);
    }
}
