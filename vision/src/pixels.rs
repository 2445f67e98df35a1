//! Frames between pixel layouts: an RGBA image as packed RGB bytes (what NumPy, ROS 2's `rgb8`
//! and OpenCV take) and packed RGB bytes as an opaque RGBA image (what every stage here reads).
//!
//! The loops run once a frame on every frame handed across a language boundary; they live here,
//! optimised with the rest of the vision code, rather than in the bindings' glue.

use image::RgbaImage;

/// The image's pixels as packed RGB bytes, row-major, `width * height * 3` long (the alpha
/// channel dropped).
pub fn rgb_bytes(img: &RgbaImage) -> Vec<u8> {
    let mut rgb = vec![0u8; img.as_raw().len() / 4 * 3];
    for (out, px) in rgb.chunks_exact_mut(3).zip(img.as_raw().chunks_exact(4)) {
        out.copy_from_slice(&px[..3]);
    }
    rgb
}

/// Packed RGB bytes, row-major, as an opaque RGBA image; `None` unless `rgb` holds exactly
/// `width * height * 3` bytes.
pub fn rgba_from_rgb(width: u32, height: u32, rgb: &[u8]) -> Option<RgbaImage> {
    let pixels = (width as usize).checked_mul(height as usize)?;
    if rgb.len() != pixels.checked_mul(3)? {
        return None;
    }
    let mut rgba = vec![255u8; pixels * 4];
    for (out, px) in rgba.chunks_exact_mut(4).zip(rgb.chunks_exact(3)) {
        out[..3].copy_from_slice(px);
    }
    RgbaImage::from_raw(width, height, rgba)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb_and_back_keeps_every_pixel_and_makes_it_opaque() {
        let img = RgbaImage::from_fn(5, 3, |x, y| {
            image::Rgba([x as u8 * 40, y as u8 * 70, (x + y) as u8, 255])
        });
        let rgb = rgb_bytes(&img);
        assert_eq!(rgb.len(), 5 * 3 * 3);
        // Row 1, column 2: offset (1 * 5 + 2) * 3.
        assert_eq!(&rgb[21..24], &[80, 70, 3]);
        assert_eq!(rgba_from_rgb(5, 3, &rgb), Some(img));
        let translucent = RgbaImage::from_pixel(2, 2, image::Rgba([9, 8, 7, 0]));
        let opaque = rgba_from_rgb(2, 2, &rgb_bytes(&translucent)).unwrap();
        assert!(opaque.pixels().all(|p| p.0 == [9, 8, 7, 255]));
    }

    #[test]
    fn bytes_that_do_not_fill_the_shape_give_no_image() {
        assert_eq!(rgba_from_rgb(2, 2, &[0; 11]), None);
        assert_eq!(rgba_from_rgb(2, 2, &[0; 13]), None);
        assert_eq!(rgba_from_rgb(u32::MAX, u32::MAX, &[]), None);
    }
}
