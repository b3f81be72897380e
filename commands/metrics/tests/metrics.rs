//! The metrics against values computed by hand on tiny images, region
//! restriction, non-finite values, error maps and heat maps.

use glam::{DVec3, Vec3};
use glint_metrics::*;

/// Test and reference, 2 × 2, row-major from the top-left. They differ at (0, 1)
/// by −0.125 in R, and at (1, 1) by +1 in R and −1 in B.
fn pair() -> ([Vec3; 4], [Vec3; 4]) {
    let test = [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::splat(0.5),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, 1.0, 0.0),
    ];
    let reference = [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::splat(0.5),
        Vec3::new(0.125, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 1.0),
    ];
    (test, reference)
}

fn view(pixels: &[Vec3]) -> ImageView<'_> {
    ImageView::new(2, pixels.len() as u32 / 2, pixels).unwrap()
}

const FULL: Region = Region {
    x0: 0,
    y0: 0,
    x1: 2,
    y1: 2,
};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

#[test]
fn means_mse_rmse_and_rel_mse_match_hand_computed_values() {
    let (t, r) = pair();
    let (t, r) = (view(&t), view(&r));
    assert_eq!(
        channel_means(t, FULL).unwrap(),
        DVec3::new(0.875, 0.375, 0.125)
    );
    assert_eq!(
        channel_means(r, FULL).unwrap(),
        DVec3::new(0.65625, 0.375, 0.375)
    );
    // Squared differences: 0.125², 1, 1 over 4 pixels × 3 channels.
    let expected_mse = (0.125f64.powi(2) + 2.0) / 12.0;
    assert!(close(mse(t, r, FULL).unwrap(), expected_mse));
    assert!(close(rmse(t, r, FULL).unwrap(), expected_mse.sqrt()));
    // (x − r)² / (r + 0.01)²: 0.015625 / 0.135² once (r = 0.125), 1 / 1.01² twice (r = 1).
    let expected_rel = (0.015625 / (0.135 * 0.135) + 2.0 / (1.01 * 1.01)) / 12.0;
    assert!(
        close(rel_mse(t, r, FULL).unwrap(), expected_rel),
        "{}",
        rel_mse(t, r, FULL).unwrap()
    );
}

#[test]
fn relative_mse_divides_by_the_reference_not_the_test() {
    let (a, b) = ([Vec3::splat(2.0); 2], [Vec3::splat(1.0); 2]);
    let region = Region::full(2, 1);
    assert!(close(
        rel_mse(view(&a), view(&b), region).unwrap(),
        1.0 / (1.01 * 1.01)
    ));
    assert!(close(
        rel_mse(view(&b), view(&a), region).unwrap(),
        1.0 / (2.01 * 2.01)
    ));
    // MSE and RMSE are symmetric.
    assert_eq!(
        mse(view(&a), view(&b), region).unwrap(),
        mse(view(&b), view(&a), region).unwrap()
    );
}

#[test]
fn max_difference_finds_the_largest_channel_and_its_pixel() {
    let (t, r) = pair();
    // R and B at (1, 1) both differ by 1: the first in reading order (R) wins.
    assert_eq!(
        max_difference(view(&t), view(&r), FULL).unwrap(),
        MaxDifference {
            value: 1.0,
            x: 1,
            y: 1,
            channel: 0
        }
    );
    let mut t2 = t;
    t2[1].y = -3.0; // (1, 0), G: |−3 − 0.5| = 3.5
    let m = max_difference(view(&t2), view(&r), FULL).unwrap();
    assert_eq!(
        (m.value, m.x, m.y, m.channel, m.channel_name()),
        (3.5, 1, 0, 1, "G")
    );
    // Identical images: 0 at the region's first pixel.
    let same = max_difference(view(&r), view(&r), Region::parse("1,1,2,2").unwrap()).unwrap();
    assert_eq!((same.value, same.x, same.y, same.channel), (0.0, 1, 1, 0));
}

#[test]
fn a_region_restricts_every_metric() {
    let (t, r) = pair();
    let (t, r) = (view(&t), view(&r));
    let top = Region::parse("0,0,2,1").unwrap();
    assert_eq!(mse(t, r, top).unwrap(), 0.0);
    assert_eq!(rel_mse(t, r, top).unwrap(), 0.0);
    assert_eq!(max_difference(t, r, top).unwrap().value, 0.0);
    assert_eq!(channel_means(t, top).unwrap(), DVec3::new(0.75, 0.25, 0.25));
    let lower_left = Region::parse("0,1,1,2").unwrap();
    assert!(close(mse(t, r, lower_left).unwrap(), 0.015625 / 3.0));
    assert!(close(
        rel_mse(t, r, lower_left).unwrap(),
        0.015625 / (0.135 * 0.135) / 3.0
    ));
    let m = max_difference(t, r, lower_left).unwrap();
    assert_eq!((m.value, m.x, m.y, m.channel), (0.125, 0, 1, 0));
}

#[test]
fn comparison_gathers_every_metric() {
    let (t, r) = pair();
    let (t, r) = (view(&t), view(&r));
    let c = compare(t, r, FULL).unwrap();
    assert_eq!(c.means_test, channel_means(t, FULL).unwrap());
    assert_eq!(c.means_reference, channel_means(r, FULL).unwrap());
    assert_eq!(c.rmse, rmse(t, r, FULL).unwrap());
    assert_eq!(c.rel_mse, rel_mse(t, r, FULL).unwrap());
    assert_eq!(c.flip, flip(t, r).unwrap().mean(FULL).unwrap());
    assert_eq!(c.max_difference, max_difference(t, r, FULL).unwrap());
    assert!(c.flip > 0.0 && c.flip <= 1.0);
    let same = compare(r, r, FULL).unwrap();
    assert_eq!(
        (
            same.rmse,
            same.rel_mse,
            same.flip,
            same.max_difference.value
        ),
        (0.0, 0.0, 0.0, 0.0)
    );
}

#[test]
fn non_finite_values_are_reported_not_hidden() {
    let (_, r) = pair();
    let mut t = r;
    t[2].y = f32::NAN;
    let (tv, rv) = (view(&t), view(&r));
    assert!(mse(tv, rv, FULL).unwrap().is_nan());
    assert!(rmse(tv, rv, FULL).unwrap().is_nan());
    assert!(rel_mse(tv, rv, FULL).unwrap().is_nan());
    assert!(channel_means(tv, FULL).unwrap().y.is_nan());
    assert_eq!(non_finite_count(tv, FULL).unwrap(), 1);
    let m = max_difference(tv, rv, FULL).unwrap();
    assert!(m.value.is_nan());
    assert_eq!((m.x, m.y, m.channel), (0, 1, 1));
    // Outside the region, it is not seen.
    assert_eq!(mse(tv, rv, Region::parse("0,0,2,1").unwrap()).unwrap(), 0.0);

    t[2].y = f32::INFINITY;
    let tv = view(&t);
    assert_eq!(mse(tv, rv, FULL).unwrap(), f64::INFINITY);
    assert!(rel_mse(tv, rv, FULL).unwrap().is_infinite());
    assert_eq!(max_difference(tv, rv, FULL).unwrap().value, f32::INFINITY);
    assert_eq!(non_finite_count(tv, FULL).unwrap(), 1);

    // The same non-finite value on both sides differs by 0: an image measures 0
    // against itself, whatever it holds.
    assert_eq!(mse(tv, tv, FULL).unwrap(), 0.0);
    assert_eq!(rel_mse(tv, tv, FULL).unwrap(), 0.0);
    assert_eq!(max_difference(tv, tv, FULL).unwrap().value, 0.0);
    let mut nan = r;
    nan[0] = Vec3::NAN;
    assert_eq!(mse(view(&nan), view(&nan), FULL).unwrap(), 0.0);
    assert_eq!(rel_mse(view(&nan), view(&nan), FULL).unwrap(), 0.0);
    assert_eq!(
        rel_mse_map(view(&nan), view(&nan)).unwrap().values,
        vec![0.0; 4]
    );
    assert_eq!(
        max_difference(view(&nan), view(&nan), FULL).unwrap().value,
        0.0
    );
    // +∞ against −∞ is an infinite difference.
    let (plus, minus) = ([Vec3::INFINITY; 2], [Vec3::NEG_INFINITY; 2]);
    assert_eq!(
        max_difference(view(&plus), view(&minus), Region::full(2, 1))
            .unwrap()
            .value,
        f32::INFINITY
    );
    // FLIP sees the 8-bit sRGB encoding: NaN as 0, so NaN against black is 0.
    let (black, nans) = ([Vec3::ZERO; 4], [Vec3::NAN; 4]);
    assert_eq!(
        flip(view(&nans), view(&black)).unwrap().mean(FULL).unwrap(),
        0.0
    );
}

#[test]
fn rel_mse_map_holds_each_pixels_mean_over_channels() {
    let (t, r) = pair();
    let map = rel_mse_map(view(&t), view(&r)).unwrap();
    assert_eq!((map.width, map.height), (2, 2));
    assert_eq!(&map.values[..2], &[0.0, 0.0]);
    assert_eq!(map.value(0, 1), (0.015625 / (0.135 * 0.135) / 3.0) as f32);
    assert_eq!(map.value(1, 1), (2.0 / (1.01 * 1.01) / 3.0) as f32);
    assert!((map.mean(FULL).unwrap() - rel_mse(view(&t), view(&r), FULL).unwrap()).abs() < 1e-7);
    assert_eq!(map.max(FULL).unwrap(), map.value(1, 1));
    assert_eq!(map.max(Region::parse("0,0,2,1").unwrap()).unwrap(), 0.0);
}

#[test]
fn error_map_statistics_cover_only_the_region() {
    let map = ErrorMap {
        width: 3,
        height: 2,
        values: vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0],
    };
    assert_eq!(map.mean(Region::full(3, 2)).unwrap(), 2.5);
    assert_eq!(map.max(Region::full(3, 2)).unwrap(), 5.0);
    let right = Region::parse("1,0,3,2").unwrap();
    assert_eq!(map.mean(right).unwrap(), 3.0);
    assert_eq!(map.max(Region::parse("0,0,2,2").unwrap()).unwrap(), 4.0);
    let mut with_nan = map.clone();
    with_nan.values[1] = f32::NAN;
    assert!(with_nan.max(Region::full(3, 2)).unwrap().is_nan());
    assert!(with_nan.mean(Region::full(3, 2)).unwrap().is_nan());
    assert_eq!(
        with_nan.max(Region::parse("2,0,3,2").unwrap()).unwrap(),
        5.0
    );
}

/// Every refusal is an error with its reason, never a panic.
#[test]
fn what_does_not_fit_is_an_error_not_a_panic() {
    let (a, b) = ([Vec3::ZERO; 4], [Vec3::ZERO; 2]);
    let (a, b) = (view(&a), view(&b));
    let message = |e: MetricsError| e.to_string();
    let mismatch = "the images differ in size: 2x2 and 2x1";
    assert_eq!(
        rmse(a, b, Region::full(2, 1)).map_err(message),
        Err(mismatch.into())
    );
    assert_eq!(rel_mse_map(a, b).map_err(message), Err(mismatch.into()));
    assert_eq!(flip(a, b).map_err(message), Err(mismatch.into()));
    let outside = Region::parse("0,0,3,1").unwrap();
    let err = rel_mse(a, a, outside).unwrap_err().to_string();
    assert_eq!(err, "the region 0,0,3,1 reaches outside the 2x2 image");
    assert!(channel_means(a, outside).is_err() && non_finite_count(a, outside).is_err());
    assert!(max_difference(a, a, outside).is_err());
    let short = ImageView::new(2, 2, &[Vec3::ZERO; 3])
        .unwrap_err()
        .to_string();
    assert_eq!(short, "an image of 2x2 pixels needs 4 values, it has 3");
    let empty = ImageView::new(0, 0, &[]).unwrap();
    assert_eq!(flip(empty, empty), Err(MetricsError::Empty(0, 0)));
    let map = ErrorMap {
        width: 2,
        height: 2,
        values: vec![0.0; 3],
    };
    assert!(map.mean(FULL).is_err() && map.max(FULL).is_err() && heatmap(&map, 1.0).is_err());
}

#[test]
fn heatmap_uses_magma_from_black_to_light_yellow() {
    let lut = magma();
    // Magma starts near black and ends in a light yellow.
    assert!(lut[0].iter().all(|&c| c < 10));
    assert!(lut[255][0] > 240 && lut[255][1] > 240 && lut[255][2] > 150);
    let map = ErrorMap {
        width: 5,
        height: 1,
        values: vec![0.0, 0.5, 1.0, 7.0, f32::NAN],
    };
    assert_eq!(
        heatmap(&map, 1.0).unwrap(),
        vec![lut[0], lut[128], lut[255], lut[255], lut[255]]
    );
    // value / scale: 0.5 / 2 = 0.25 -> entry round(63.75) = 64.
    assert_eq!(heatmap(&map, 2.0).unwrap()[1], lut[64]);
}

#[test]
fn heatmap_refuses_a_scale_that_is_not_positive_and_finite() {
    let map = ErrorMap {
        width: 1,
        height: 1,
        values: vec![0.0],
    };
    for scale in [0.0, -1.0, f32::INFINITY] {
        assert_eq!(heatmap(&map, scale), Err(MetricsError::Scale(scale)));
    }
    assert!(heatmap(&map, f32::NAN).is_err());
}

#[test]
fn save_heatmap_writes_a_png_and_nothing_on_failure() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("heat.png");
    let rgb = vec![
        [255, 0, 0],
        [0, 255, 0],
        [0, 0, 255],
        [9, 9, 9],
        [1, 2, 3],
        [4, 5, 6],
    ];
    save_heatmap(&path, 3, 2, &rgb).unwrap();
    let film = glint_camera::Film::load(&path).unwrap();
    assert_eq!((film.resolution().x, film.resolution().y), (3, 2));
    assert_eq!(film.to_srgb8()[..9], [255, 0, 0, 0, 255, 0, 0, 0, 255]);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    let missing = dir.path().join("no-such-dir").join("heat.png");
    let error = save_heatmap(&missing, 3, 2, &rgb).unwrap_err();
    assert!(
        error.starts_with(&format!("{}: cannot write the heat map", missing.display())),
        "{error}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    let short = save_heatmap(&path, 3, 3, &rgb).unwrap_err();
    assert!(short.ends_with("needs 9 values, it has 6"), "{short}");
    assert_eq!(glint_camera::Film::load(&path).unwrap().resolution().y, 2);
}
