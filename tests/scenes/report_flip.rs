//! LDR-FLIP (`texsim::flip`, NVIDIA's reference implementation through `nv-flip`): zero for
//! identical images, growing with the difference, pooled over the mask, the 99th percentile by
//! nearest rank, the error map's size and colours.

use texsim::flip::{error_map_rgba8, flip};
use texsim::report::{Image, MASKED_RGB};

/// A 64x48 image with a smooth gradient plus `delta` (16-bit units) added to the red channel of
/// the pixels of the right half.
fn gradient(delta: u16) -> Image {
    let (w, h) = (64u32, 48u32);
    let mut img = Image::new(w, h, [0, 0, 0, 65535]);
    for y in 0..h {
        for x in 0..w {
            let r = (x * 1000 + y * 300) as u16;
            let g = (y * 1200) as u16;
            let add = if x >= w / 2 { delta } else { 0 };
            img.px[(y * w + x) as usize] = [r.saturating_add(add), g, 20000, 65535];
        }
    }
    img
}

#[test]
fn identical_images_have_zero_flip() {
    let a = gradient(0);
    let f = flip(&a, &a, None).unwrap();
    assert_eq!(f.stats.pixels, 64 * 48);
    assert_eq!(f.stats.mean, 0.0);
    assert_eq!(f.stats.p99, 0.0);
    assert_eq!(f.stats.max, 0.0);
    assert_eq!(f.map.len(), 64 * 48);
}

#[test]
fn flip_grows_with_the_difference_and_stays_in_0_1() {
    let reference = gradient(0);
    let mut last = 0.0;
    for delta in [512u16, 4096, 16384, 40000] {
        let f = flip(&gradient(delta), &reference, None).unwrap();
        assert!(
            f.stats.mean > last,
            "delta {delta}: {} <= {last}",
            f.stats.mean
        );
        assert!(f.stats.max <= 1.0 && f.stats.p99 <= f.stats.max);
        assert!(f.stats.mean <= f.stats.max);
        assert!(f.map.iter().all(|v| (0.0..=1.0).contains(v)));
        last = f.stats.mean;
    }
    // Black against white is a large perceived difference.
    let black = Image::new(32, 32, [0, 0, 0, 65535]);
    let white = Image::new(32, 32, [65535, 65535, 65535, 65535]);
    let f = flip(&black, &white, None).unwrap();
    assert!(f.stats.mean > 0.5, "{}", f.stats.mean);
}

/// The statistics pool only the masked pixels: masking the changed half leaves the error of the
/// other half (which the filters still reach near the boundary), below the whole image's.
#[test]
fn the_mask_selects_the_pooled_pixels_and_p99_is_a_nearest_rank() {
    let reference = gradient(0);
    let test = gradient(16384);
    let all = flip(&test, &reference, None).unwrap();
    let left: Vec<bool> = (0..64 * 48).map(|i| i % 64 < 32).collect();
    let f = flip(&test, &reference, Some(&left)).unwrap();
    assert_eq!(f.stats.pixels, 32 * 48);
    assert!(
        f.stats.mean < all.stats.mean / 2.0,
        "{} vs {}",
        f.stats.mean,
        all.stats.mean
    );
    let mut pooled: Vec<f32> = all
        .map
        .iter()
        .zip(&left)
        .filter(|(_, &m)| m)
        .map(|(&v, _)| v)
        .collect();
    pooled.sort_by(f32::total_cmp);
    let mean = pooled.iter().map(|&v| f64::from(v)).sum::<f64>() / pooled.len() as f64;
    assert!((f.stats.mean - mean).abs() < 1e-12);
    // 1536 pixels: rank ceil(0.99 * 1536) = 1521.
    assert_eq!(f.stats.p99, f64::from(pooled[1520]));
    let none = vec![false; 64 * 48];
    assert!(flip(&test, &reference, Some(&none)).is_none());
    assert!(flip(&test, &Image::new(8, 8, [0; 4]), None).is_none());
}

#[test]
fn error_map_is_magma_with_grey_outside_the_mask() {
    let reference = gradient(0);
    let test = gradient(40000);
    let left: Vec<bool> = (0..64 * 48).map(|i| i % 64 < 32).collect();
    let f = flip(&test, &reference, None).unwrap();
    let rgba = error_map_rgba8(&f, Some(&left));
    assert_eq!(rgba.len(), 64 * 48 * 4);
    // Right half: masked grey.
    assert_eq!(&rgba[63 * 4..63 * 4 + 3], &MASKED_RGB);
    // Far left (no error): magma's black end.
    let p = &rgba[0..3];
    assert!(p.iter().all(|&c| c < 16), "{p:?}");
    let same = flip(&reference, &reference, None).unwrap();
    let rgba = error_map_rgba8(&same, None);
    assert!(rgba.chunks_exact(4).all(|p| p[..3] == rgba[..3]));
}
