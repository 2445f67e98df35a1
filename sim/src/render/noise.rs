//! Seeded sensor noise: Gaussian, per channel per pixel, drawn from a `rand` generator.
//!
//! Drawing ~170 000 normal deviates per 256 x 220 frame would cost more than tracing it, so a
//! table of 2^18 standard normal deviates is drawn once from the seeded generator and every
//! frame reads it from a fresh random offset with a fresh random odd stride (a full-period walk
//! through the table). Everything comes from the seed: the same seed gives the same noise.

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;

const TABLE_BITS: u32 = 18;

/// Noise for one sensor.
#[derive(Debug)]
pub struct SensorNoise {
    table: Vec<f32>,
    rng: StdRng,
}

impl SensorNoise {
    /// A noise source seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        let mut rng = StdRng::seed_from_u64(seed);
        let table = (0..1usize << TABLE_BITS)
            .map(|_| rng.sample::<f32, _>(StandardNormal))
            .collect();
        Self { table, rng }
    }

    /// Writes `pixels` (packed RGBA8) into `rgba` bytes, adding noise of `sigma` levels to the
    /// three colour channels (alpha stays 255), rounded and clamped to 0..255.
    pub fn apply(&mut self, pixels: &[u32], sigma: f32, rgba: &mut [u8]) {
        assert_eq!(rgba.len(), pixels.len() * 4);
        if sigma <= 0.0 {
            for (p, out) in pixels.iter().zip(rgba.chunks_exact_mut(4)) {
                out.copy_from_slice(&p.to_le_bytes());
            }
            return;
        }
        let mask = (1usize << TABLE_BITS) - 1;
        let start = self.rng.random_range(0..=mask);
        let stride = self.rng.random_range(0..=mask) | 1;
        let table = &self.table;
        // Draw n of the frame (pixel n / 3, channel n % 3) reads entry start + n stride of
        // the walk: blocks of pixels start where the walk is at their first draw, so drawing
        // them in parallel gives the same image as one after the other.
        const BLOCK: usize = 4096;
        pixels
            .par_chunks(BLOCK)
            .zip(rgba.par_chunks_mut(4 * BLOCK))
            .enumerate()
            .for_each(|(b, (block, out))| {
                let mut idx = (start + (3 * b * BLOCK % (mask + 1)) * stride) & mask;
                for (p, out) in block.iter().zip(out.chunks_exact_mut(4)) {
                    let bytes = p.to_le_bytes();
                    for c in 0..3 {
                        let v = bytes[c] as f32 + sigma * table[idx];
                        idx = (idx + stride) & mask;
                        // Truncating a value clamped to 0..=255 is flooring it: no libm call.
                        out[c] = (v + 0.5).clamp(0.0, 255.0) as u8;
                    }
                    out[3] = bytes[3];
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_drawn_in_parallel_continue_the_one_walk() {
        // Three blocks and a part: every draw must be where one sequential walk puts it.
        let pixels: Vec<u32> = (0..10_000u32)
            .map(|i| 0xff00_0000 | (i.wrapping_mul(2_654_435_761) >> 8))
            .collect();
        let mut noise = SensorNoise::new(9);
        // The same seed: the same table and the same generator, drawn by hand below.
        let mut rng = SensorNoise::new(9).rng;
        let mut got = vec![0u8; 40_000];
        noise.apply(&pixels, 5.0, &mut got);
        let mask = (1usize << TABLE_BITS) - 1;
        let mut idx = rng.random_range(0..=mask);
        let stride = rng.random_range(0..=mask) | 1;
        for (p, out) in pixels.iter().zip(got.chunks_exact(4)) {
            let bytes = p.to_le_bytes();
            for c in 0..3 {
                let v = bytes[c] as f32 + 5.0 * noise.table[idx];
                idx = (idx + stride) & mask;
                assert_eq!(out[c], (v + 0.5).floor().clamp(0.0, 255.0) as u8);
            }
        }
    }

    #[test]
    fn noise_has_the_requested_sigma_and_is_seeded() {
        let pixels = vec![0xff80_8080u32; 20_000];
        let mut a = vec![0u8; 80_000];
        let mut b = vec![0u8; 80_000];
        SensorNoise::new(3).apply(&pixels, 4.0, &mut a);
        SensorNoise::new(3).apply(&pixels, 4.0, &mut b);
        assert_eq!(a, b);
        let mut c = vec![0u8; 80_000];
        SensorNoise::new(4).apply(&pixels, 4.0, &mut c);
        assert_ne!(a, c);
        let vals: Vec<f64> = a
            .chunks_exact(4)
            .flat_map(|p| p[..3].iter().map(|&v| v as f64 - 128.0))
            .collect();
        let mean = vals.iter().sum::<f64>() / vals.len() as f64;
        let sd = (vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / vals.len() as f64).sqrt();
        assert!(mean.abs() < 0.1, "mean {mean}");
        // Rounding adds 1/12 of a level squared.
        assert!((sd - (16.0f64 + 1.0 / 12.0).sqrt()).abs() < 0.1, "sd {sd}");
        assert!(a.chunks_exact(4).all(|p| p[3] == 255));
    }

    #[test]
    fn consecutive_frames_differ() {
        let pixels = vec![0xff80_8080u32; 1000];
        let mut n = SensorNoise::new(1);
        let mut a = vec![0u8; 4000];
        let mut b = vec![0u8; 4000];
        n.apply(&pixels, 4.0, &mut a);
        n.apply(&pixels, 4.0, &mut b);
        assert_ne!(a, b);
    }
}
