//! Seeded sensor noise from a counter: every pixel's and channel's Gaussian draw is a pure
//! function of (the sensor's seed, the frame number, the pixel, the channel), so frames need no
//! generator state between them, pixels can be drawn in any order or in parallel, and the GPU
//! (`trace.wgsl`) draws the same noise as the CPU, operation for operation.
//!
//! - The frame's key: `splitmix64(seed + splitmix64(frame))`, its high 32 bits (on the CPU;
//!   the GPU receives the key).
//! - Pixel `i` (row-major): `m = mix32(i)`, `h1 = mix32(m ^ key)`,
//!   `h2 = mix32(m ^ key ^ 0x9e3779b9)`, where `mix32` is Wellons' `lowbias32` integer hash.
//!   Red takes the low 16 bits of `h1`, green its high 16 bits, blue the low 16 bits of `h2`.
//! - A 16-bit index `k` is the standard normal quantile `Phi^-1((k + 0.5) / 65536)`
//!   (Acklam's rational approximation, relative error below 1.2e-9), the table scaled to unit
//!   variance: a Gaussian truncated at 4.32 sigma.
//! - The level: `clamp(floor(level + sigma * z + 0.5), 0, 255)`.

use rayon::prelude::*;
use std::sync::{Arc, Mutex, OnceLock};

/// Bits of a table index.
const TABLE_BITS: u32 = 16;

/// Number of quantiles in the Gaussian table.
pub const GAUSS_TABLE_LEN: usize = 1 << TABLE_BITS;

/// The noise of one frame of one sensor: its key and sigma (grey levels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameNoise {
    /// The frame's key (see the module's documentation).
    pub key: u32,
    /// Standard deviation, grey levels (0: no noise).
    pub sigma: f32,
}

/// Noise for one sensor: its seed and the number of the next frame.
#[derive(Debug, Clone)]
pub struct SensorNoise {
    seed: u64,
    frame: u64,
}

impl SensorNoise {
    /// A noise source seeded with `seed`, at frame 0.
    pub fn new(seed: u64) -> Self {
        Self { seed, frame: 0 }
    }

    /// The noise of the next frame at `sigma` (and counts the frame).
    pub fn next_frame(&mut self, sigma: f32) -> FrameNoise {
        let key = frame_key(self.seed, self.frame);
        self.frame += 1;
        FrameNoise { key, sigma }
    }

    /// Writes `pixels` (packed RGBA8) into `rgba` bytes with the next frame's noise of `sigma`
    /// levels on the three colour channels (alpha stays 255).
    pub fn apply(&mut self, pixels: &[u32], sigma: f32, rgba: &mut [u8]) {
        let noise = self.next_frame(sigma);
        apply(pixels, noise, rgba);
    }
}

/// The key of frame `frame` of a sensor seeded `seed`.
pub fn frame_key(seed: u64, frame: u64) -> u32 {
    (splitmix64(seed.wrapping_add(splitmix64(frame))) >> 32) as u32
}

/// SplitMix64's output function of `x` (Steele, Lea and Flood 2014).
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Wellons' `lowbias32` integer hash (the same in `trace.wgsl`).
pub fn mix32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// The three table indices (red, green, blue) of pixel `i` under `key`.
pub fn pixel_indices(i: u32, key: u32) -> [usize; 3] {
    mixed_indices(mix32(i), key)
}

/// [`pixel_indices`] from the pixel's hash `mix32(i)`, which does not change from frame to
/// frame.
fn mixed_indices(mixed: u32, key: u32) -> [usize; 3] {
    let m = mixed ^ key;
    let h1 = mix32(m);
    let h2 = mix32(m ^ 0x9e37_79b9);
    [
        (h1 & 0xffff) as usize,
        (h1 >> 16) as usize,
        (h2 & 0xffff) as usize,
    ]
}

/// A level with noise: `clamp(floor(level + sigma z + 0.5), 0, 255)` (truncating a value
/// clamped to 0..=255 is flooring it).
pub fn noisy_level(level: u8, sigma: f32, z: f32) -> u8 {
    (level as f32 + sigma * z + 0.5).clamp(0.0, 255.0) as u8
}

/// Writes `pixels` (packed RGBA8) into `rgba` bytes with `noise` on the colour channels.
pub fn apply(pixels: &[u32], noise: FrameNoise, rgba: &mut [u8]) {
    assert_eq!(rgba.len(), pixels.len() * 4);
    if noise.sigma <= 0.0 {
        for (p, out) in pixels.iter().zip(rgba.chunks_exact_mut(4)) {
            out.copy_from_slice(&p.to_le_bytes());
        }
        return;
    }
    let table = gauss_table();
    let mixed = pixel_hashes(pixels.len());
    // Every draw is a function of its pixel's index: blocks of pixels in parallel give the
    // same image as one after the other.
    const BLOCK: usize = 4096;
    let block_fn = noisy_block_fn();
    pixels
        .par_chunks(BLOCK)
        .zip(rgba.par_chunks_mut(4 * BLOCK))
        .zip(mixed.par_chunks(BLOCK))
        .for_each(|((block, out), mixed)| block_fn(block, mixed, noise, table, out));
}

/// A block of [`apply`], in the widest vector instructions this processor has: the same
/// scalar code compiled twice, chosen once at run time (the arithmetic and its order are the
/// same in both, so are the levels).
type NoisyBlock = fn(&[u32], &[u32], FrameNoise, &[f32], &mut [u8]);

fn noisy_block_fn() -> NoisyBlock {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        return |block, mixed, noise, table, out| {
            // SAFETY: AVX2 was detected on this processor just above.
            unsafe { noisy_block_avx2(block, mixed, noise, table, out) }
        };
    }
    noisy_block
}

/// [`noisy_block`] eight pixels at a time in AVX2: the hashes in 32-bit lanes, the table read
/// by eight loads, each level's `(level + sigma z) + 0.5`, clamped and truncated, as the scalar
/// code computes it (no fused multiply-add: the same roundings).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn noisy_block_avx2(
    block: &[u32],
    mixed: &[u32],
    noise: FrameNoise,
    table: &[f32],
    out: &mut [u8],
) {
    use std::arch::x86_64::*;
    assert!(table.len() >= GAUSS_TABLE_LEN && out.len() >= 4 * block.len());
    let n = block.len().min(mixed.len()) / 8 * 8;
    let mix = |mut x: __m256i| {
        x = _mm256_xor_si256(x, _mm256_srli_epi32::<16>(x));
        x = _mm256_mullo_epi32(x, _mm256_set1_epi32(0x7feb_352d));
        x = _mm256_xor_si256(x, _mm256_srli_epi32::<15>(x));
        x = _mm256_mullo_epi32(x, _mm256_set1_epi32(0x846c_a68b_u32 as i32));
        _mm256_xor_si256(x, _mm256_srli_epi32::<16>(x))
    };
    let low16 = _mm256_set1_epi32(0xffff);
    let byte = _mm256_set1_epi32(0xff);
    let (sigma, half) = (_mm256_set1_ps(noise.sigma), _mm256_set1_ps(0.5));
    let (zero, top) = (_mm256_setzero_ps(), _mm256_set1_ps(255.0));
    // SAFETY: every table index is below 65536 <= table.len(); every load and store is of
    // eight lanes inside `block`, `mixed` and `out` (i + 8 <= n, asserted lengths).
    unsafe {
        let level = |v: __m256i, k: __m256i| {
            // Eight loads, not a gather: as fast or faster (much faster on some processors).
            let mut idx = [0u32; 8];
            _mm256_storeu_si256(idx.as_mut_ptr().cast(), k);
            let z = idx.map(|k| *table.get_unchecked(k as usize));
            let z = _mm256_loadu_ps(z.as_ptr());
            let x = _mm256_add_ps(
                _mm256_add_ps(_mm256_cvtepi32_ps(v), _mm256_mul_ps(sigma, z)),
                half,
            );
            _mm256_cvttps_epi32(_mm256_min_ps(_mm256_max_ps(x, zero), top))
        };
        for i in (0..n).step_by(8) {
            let p = _mm256_loadu_si256(block.as_ptr().add(i).cast());
            let m = _mm256_xor_si256(
                _mm256_loadu_si256(mixed.as_ptr().add(i).cast()),
                _mm256_set1_epi32(noise.key as i32),
            );
            let h1 = mix(m);
            let h2 = mix(_mm256_xor_si256(
                m,
                _mm256_set1_epi32(0x9e37_79b9_u32 as i32),
            ));
            let r = level(_mm256_and_si256(p, byte), _mm256_and_si256(h1, low16));
            let g = level(
                _mm256_and_si256(_mm256_srli_epi32::<8>(p), byte),
                _mm256_srli_epi32::<16>(h1),
            );
            let b = level(
                _mm256_and_si256(_mm256_srli_epi32::<16>(p), byte),
                _mm256_and_si256(h2, low16),
            );
            let alpha = _mm256_andnot_si256(_mm256_set1_epi32(0x00ff_ffff), p);
            let v = _mm256_or_si256(
                _mm256_or_si256(r, _mm256_slli_epi32::<8>(g)),
                _mm256_or_si256(_mm256_slli_epi32::<16>(b), alpha),
            );
            _mm256_storeu_si256(out.as_mut_ptr().add(4 * i).cast(), v);
        }
    }
    noisy_block(&block[n..], &mixed[n..], noise, table, &mut out[4 * n..]);
}

/// `block`'s packed pixels, each with its draws (`mixed`: the pixels' hashes), into `out`.
#[inline(always)]
fn noisy_block(block: &[u32], mixed: &[u32], noise: FrameNoise, table: &[f32], out: &mut [u8]) {
    let level = |v: u32, k: u32| noisy_level(v as u8, noise.sigma, table[k as usize]) as u32;
    for ((&p, out), &m) in block.iter().zip(out.chunks_exact_mut(4)).zip(mixed) {
        let m = m ^ noise.key;
        let (h1, h2) = (mix32(m), mix32(m ^ 0x9e37_79b9));
        let r = level(p & 0xff, h1 & 0xffff);
        let g = level((p >> 8) & 0xff, h1 >> 16);
        let b = level((p >> 16) & 0xff, h2 & 0xffff);
        let v = r | (g << 8) | (b << 16) | (p & 0xff00_0000);
        out.copy_from_slice(&v.to_le_bytes());
    }
}

/// `mix32(i)` of every pixel index of a frame of `len` pixels, hashed once for each frame size.
fn pixel_hashes(len: usize) -> Arc<Vec<u32>> {
    static HASHES: Mutex<Vec<Arc<Vec<u32>>>> = Mutex::new(Vec::new());
    let mut cache = HASHES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(h) = cache.iter().find(|h| h.len() == len) {
        return h.clone();
    }
    let h = Arc::new((0..len as u32).map(mix32).collect::<Vec<_>>());
    if cache.len() >= 8 {
        cache.remove(0);
    }
    cache.push(h.clone());
    h
}

/// The Gaussian table: standard normal quantiles at `(k + 0.5) / 65536`, scaled to unit
/// variance (the GPU receives the same values).
pub fn gauss_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = GAUSS_TABLE_LEN;
        let q: Vec<f64> = (0..n)
            .map(|k| normal_quantile((k as f64 + 0.5) / n as f64))
            .collect();
        let var = q.iter().map(|x| x * x).sum::<f64>() / n as f64;
        let scale = 1.0 / var.sqrt();
        q.iter().map(|x| (x * scale) as f32).collect()
    })
}

/// The standard normal quantile `Phi^-1(p)` for `0 < p < 1` (Acklam's algorithm).
fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    const P_LOW: f64 = 0.02425;
    if p < P_LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vector_block_draws_the_scalar_levels() {
        // Every level, random alphas and keys, sigmas from none to a saturating one, and a
        // length that leaves a scalar tail.
        let n = 4096 + 5;
        let pixels: Vec<u32> = (0..n as u32).map(|i| mix32(i.wrapping_mul(7919))).collect();
        let mixed: Vec<u32> = (0..n as u32).map(mix32).collect();
        for (k, sigma) in [0.0f32, 0.7, 4.0, 12.5, 90.0].into_iter().enumerate() {
            let noise = FrameNoise {
                key: frame_key(3, k as u64),
                sigma,
            };
            let (mut want, mut got) = (vec![0u8; 4 * n], vec![0u8; 4 * n]);
            noisy_block(&pixels, &mixed, noise, gauss_table(), &mut want);
            noisy_block_fn()(&pixels, &mixed, noise, gauss_table(), &mut got);
            assert!(want == got, "sigma {sigma}: the vector block differs");
        }
    }

    /// A flat grey frame of `n` pixels with noise `sigma`, frame `frame` of seed `seed`, as
    /// deviations from the grey level per channel.
    fn deviations(seed: u64, frame: u64, n: usize, sigma: f32) -> Vec<[f64; 3]> {
        let pixels = vec![0xff80_8080u32; n];
        let mut rgba = vec![0u8; 4 * n];
        let noise = FrameNoise {
            key: frame_key(seed, frame),
            sigma,
        };
        apply(&pixels, noise, &mut rgba);
        rgba.chunks_exact(4)
            .map(|p| [0, 1, 2].map(|c| p[c] as f64 - 128.0))
            .collect()
    }

    fn mean_sd(v: &[f64]) -> (f64, f64) {
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        (mean, var.sqrt())
    }

    /// Pearson's correlation of two equally long samples.
    fn correlation(a: &[f64], b: &[f64]) -> f64 {
        let (ma, sa) = mean_sd(a);
        let (mb, sb) = mean_sd(b);
        let cov = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - ma) * (y - mb))
            .sum::<f64>()
            / a.len() as f64;
        cov / (sa * sb)
    }

    // Thresholds: with n = 256 x 220 x 3 = 168 960 draws, the standard error of the mean is
    // sigma / 411 and of a correlation 1 / sqrt(56 320) = 0.0042 per channel pair; the tests
    // allow 4 standard errors (a chance failure below 1e-4), and sigma within 1%.
    const N: usize = 256 * 220;

    #[test]
    fn the_table_is_a_unit_normal() {
        let t = gauss_table();
        let v: Vec<f64> = t.iter().map(|&x| x as f64).collect();
        let (mean, sd) = mean_sd(&v);
        assert!(mean.abs() < 1e-6, "mean {mean}");
        assert!((sd - 1.0).abs() < 1e-6, "sd {sd}");
        // Quantiles in order, symmetric, the tails at 4.32 sigma.
        assert!(t.windows(2).all(|w| w[0] < w[1]));
        assert!((t[0] + t[GAUSS_TABLE_LEN - 1]).abs() < 1e-5);
        assert!(
            (t[GAUSS_TABLE_LEN - 1] - 4.32).abs() < 0.01,
            "{}",
            t[GAUSS_TABLE_LEN - 1]
        );
        // 84.13% of a normal lies below +1 sigma.
        let below = t.iter().filter(|&&x| x < 1.0).count() as f64 / GAUSS_TABLE_LEN as f64;
        assert!((below - 0.8413).abs() < 0.001, "{below}");
    }

    #[test]
    fn a_frame_has_mean_zero_and_the_sigma_asked() {
        let d = deviations(3, 0, N, 4.0);
        let all: Vec<f64> = d.iter().flatten().copied().collect();
        let (mean, sd) = mean_sd(&all);
        assert!(
            mean.abs() < 4.0 * 4.0 / (all.len() as f64).sqrt(),
            "mean {mean}"
        );
        // Rounding to levels adds 1/12 of a level squared.
        let expected = (16.0f64 + 1.0 / 12.0).sqrt();
        assert!(
            (sd / expected - 1.0).abs() < 0.01,
            "sd {sd}, expected {expected}"
        );
    }

    #[test]
    fn neighbours_channels_and_frames_are_uncorrelated() {
        let limit = 4.0 / (N as f64).sqrt();
        let a = deviations(11, 5, N, 8.0);
        let b = deviations(11, 6, N, 8.0);
        let ch = |d: &[[f64; 3]], c: usize| d.iter().map(|p| p[c]).collect::<Vec<f64>>();
        for c in 0..3 {
            let x = ch(&a, c);
            // Horizontal and vertical neighbours (rows of 256 pixels).
            let r_h = correlation(&x[..N - 1], &x[1..]);
            let r_v = correlation(&x[..N - 256], &x[256..]);
            let r_f = correlation(&x, &ch(&b, c));
            let r_c = correlation(&x, &ch(&a, (c + 1) % 3));
            for (what, r) in [
                ("row", r_h),
                ("column", r_v),
                ("frame", r_f),
                ("channel", r_c),
            ] {
                assert!(r.abs() < limit, "channel {c}, {what} neighbour: r = {r}");
            }
        }
    }

    #[test]
    fn noise_is_a_pure_function_of_seed_frame_and_pixel() {
        let mut n = SensorNoise::new(7);
        let pixels = vec![0xff40_8020u32; 1000];
        let (mut a, mut b, mut c) = (vec![0u8; 4000], vec![0u8; 4000], vec![0u8; 4000]);
        n.apply(&pixels, 4.0, &mut a);
        n.apply(&pixels, 4.0, &mut b);
        assert_ne!(a, b, "a new frame, new noise");
        // Frame 1 drawn directly, without drawing frame 0 first.
        apply(
            &pixels,
            FrameNoise {
                key: frame_key(7, 1),
                sigma: 4.0,
            },
            &mut c,
        );
        assert_eq!(b, c);
        SensorNoise::new(8).apply(&pixels, 4.0, &mut c);
        assert_ne!(a, c, "another seed, other noise");
        assert!(a.chunks_exact(4).all(|p| p[3] == 255));
    }

    #[test]
    fn zero_sigma_leaves_the_image() {
        let pixels = vec![0xff10_2030u32, 0xff00_0000];
        let mut rgba = vec![0u8; 8];
        SensorNoise::new(1).apply(&pixels, 0.0, &mut rgba);
        assert_eq!(rgba, [0x30, 0x20, 0x10, 0xff, 0, 0, 0, 0xff]);
    }
}
