use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Mask, compressed};

/// Pixels of a mask given as rows of '#' (inside) and '.'.
fn pixels(rows: &[&str]) -> (usize, usize, Vec<bool>) {
    let inside = rows
        .iter()
        .flat_map(|r| r.bytes().map(|b| b == b'#'))
        .collect();
    (rows[0].len(), rows.len(), inside)
}

/// The even-odd fill of `polygon` at each pixel's centre of a `width`×`height` image, in exact
/// integer arithmetic (the bridges, walked both ways, must cancel even through a centre).
fn fill(polygon: &[f64], width: usize, height: usize) -> Vec<bool> {
    // doubled coordinates: corners even, centres odd
    let corners: Vec<(i64, i64)> = polygon
        .chunks(2)
        .map(|c| (2 * c[0] as i64, 2 * c[1] as i64))
        .collect();
    let mut inside = vec![false; width * height];
    for (k, cell) in inside.iter_mut().enumerate() {
        let (px, py) = (2 * (k % width) as i64 + 1, 2 * (k / width) as i64 + 1);
        for (i, &a) in corners.iter().enumerate() {
            let b = corners[(i + 1) % corners.len()];
            let ((x0, y0), (x1, y1)) = if a.1 <= b.1 { (a, b) } else { (b, a) };
            // the edge spans the centre's row and passes right of the centre
            if y0 < py && py < y1 && (px - x0) * (y1 - y0) < (py - y0) * (x1 - x0) {
                *cell = !*cell;
            }
        }
    }
    inside
}

#[test]
fn a_masks_polygon_fills_exactly_its_pixels_holes_and_touching_corners_too() {
    let (w, h, ring) = pixels(&[
        "#......", "..####.", "..#.##.", "..####.", "..####.", "......#",
    ]);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let random: Vec<(usize, usize, Vec<bool>)> = (0..200)
        .map(|k| {
            let (w, h) = (1 + k % 23, 1 + k % 17);
            (w, h, (0..w * h).map(|_| rng.random_bool(0.55)).collect())
        })
        .collect();
    for (w, h, inside) in std::iter::once((w, h, ring)).chain(random) {
        let mask = Mask {
            width: w,
            height: h,
            inside: &inside,
        };
        let Some(polygon) = mask.polygon() else {
            assert!(!inside.contains(&true));
            continue;
        };
        assert!(polygon.iter().all(|v| v.fract() == 0.0), "{polygon:?}");
        assert_eq!(fill(&polygon, w, h), inside, "{w}×{h}: {polygon:?}");
    }
}

#[test]
fn runs_and_their_compression_are_pycocotools() {
    let (w, h, inside) = pixels(&[
        "#......", "..####.", "..#.##.", "..####.", "..####.", "......#",
    ]);
    let mask = Mask {
        width: w,
        height: h,
        inside: &inside,
    };
    // pycocotools.mask.encode of the same mask
    let runs = mask.runs_in(0, 0, w, h);
    assert_eq!(runs.iter().sum::<u32>() as usize, w * h);
    assert_eq!(compressed(&runs), "01<3FMO112004M");
    assert_eq!(mask.area(), 17);
    assert_eq!(mask.bbox(), Some([0, 0, 7, 6]));
    // a 25×280 block at (5, 10) of a 40×300 image, a 2×20 hole in it, placed as a window
    let (bw, bh) = (25, 280);
    let inside: Vec<bool> = (0..bw * bh)
        .map(|k| {
            let (x, y) = (5 + k % bw, 10 + k / bw);
            !((10..12).contains(&x) && (100..120).contains(&y))
        })
        .collect();
    let window = Mask {
        width: bw,
        height: bh,
        inside: &inside,
    };
    assert_eq!(
        compressed(&window.runs_in(5, 10, 40, 300)),
        "V_1h8d000000000RJ0`20`M0`20^30000000000000000000000000000000000^m2"
    );
}
