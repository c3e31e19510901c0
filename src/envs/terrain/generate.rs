//! Random terrain maps as thesis 5.5.1 describes them (the authors' generator is not public): a random
//! background colour, then patches placed one after another, each filled in a random colour inside a closed
//! contour of cubic Bézier curves.

use rand::Rng;
use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Transform};

use super::map::{TerrainMap, MAP_SIZE};
use crate::util::seeding::rng_for;

/// Patches per map, inclusive.
const PATCHES: (usize, usize) = (3, 8);
/// Control points on a patch contour, inclusive.
const CONTOUR_POINTS: (usize, usize) = (5, 9);
/// A patch's mean radius as a fraction of the map side.
const RADIUS: (f32, f32) = (0.05, 0.18);

fn random_color<R: Rng>(rng: &mut R) -> [u8; 3] {
    [rng.random(), rng.random(), rng.random()]
}

/// A closed, smooth blob: control points at jittered angles and radii around `center`, joined by cubic Béziers
/// whose handles follow the neighbours (a closed Catmull-Rom spline written as Béziers).
fn blob<R: Rng>(rng: &mut R, center: (f32, f32), radius: f32) -> Option<tiny_skia::Path> {
    let n = rng.random_range(CONTOUR_POINTS.0..=CONTOUR_POINTS.1);
    let step = std::f32::consts::TAU / n as f32;
    let start = rng.random_range(0.0..std::f32::consts::TAU);
    let points: Vec<(f32, f32)> = (0..n)
        .map(|i| {
            let angle = start + step * (i as f32 + rng.random_range(-0.3..0.3));
            let r = radius * rng.random_range(0.35..1.35);
            (center.0 + r * angle.cos(), center.1 + r * angle.sin())
        })
        .collect();
    let at = |i: usize| points[i % n];
    let mut builder = PathBuilder::new();
    builder.move_to(points[0].0, points[0].1);
    for i in 0..n {
        let (prev, from, to, next) = (at(i + n - 1), at(i), at(i + 1), at(i + 2));
        let c1 = (from.0 + (to.0 - prev.0) / 6.0, from.1 + (to.1 - prev.1) / 6.0);
        let c2 = (to.0 - (next.0 - from.0) / 6.0, to.1 - (next.1 - from.1) / 6.0);
        builder.cubic_to(c1.0, c1.1, c2.0, c2.1, to.0, to.1);
    }
    builder.close();
    builder.finish()
}

/// Map `index` of a set made with `seed`: the same pair always draws the same map.
pub fn generate_map(seed: u64, index: u64) -> TerrainMap {
    let mut rng = rng_for(seed, &[index]);
    let side = MAP_SIZE as u32;
    let mut canvas = Pixmap::new(side, side).expect("460 × 460 is a valid canvas");
    let [r, g, b] = random_color(&mut rng);
    canvas.fill(tiny_skia::Color::from_rgba8(r, g, b, 255));
    // Hard edges: an anti-aliased rim would blend two colours into frictions that neither patch has.
    let mut paint = Paint { anti_alias: false, ..Paint::default() };
    let patches = rng.random_range(PATCHES.0..=PATCHES.1);
    for _ in 0..patches {
        let center = (rng.random_range(0.0..side as f32), rng.random_range(0.0..side as f32));
        let radius = rng.random_range(RADIUS.0..RADIUS.1) * side as f32;
        let [r, g, b] = random_color(&mut rng);
        paint.set_color_rgba8(r, g, b, 255);
        if let Some(path) = blob(&mut rng, center, radius) {
            canvas.fill_path(&path, &paint, FillRule::Winding, Transform::identity(), None);
        }
    }
    // Opaque fills on an opaque canvas: premultiplied RGBA is plain RGBA.
    let rgb: Vec<u8> = canvas.data().chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
    TerrainMap::from_rgb(rgb, format!("map{index:03}.png")).expect("the canvas is MAP_SIZE² pixels")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn maps_are_seeded_and_hold_a_few_flat_colours() {
        let a = generate_map(1, 0);
        assert_eq!(a, generate_map(1, 0));
        assert_ne!(a.crc32, generate_map(1, 1).crc32);
        assert_ne!(a.crc32, generate_map(2, 0).crc32);
        for index in 0..10 {
            let map = generate_map(1, index);
            let colors: HashSet<&[u8]> = map.rgb().chunks_exact(3).collect();
            // Background plus up to 8 patches (some may be hidden under later ones or off the map), no blends.
            assert!((2..=1 + PATCHES.1).contains(&colors.len()), "map {index}: {} colours", colors.len());
        }
    }
}
