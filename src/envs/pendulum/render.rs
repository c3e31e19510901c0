//! Pendulum frames as gym's classic-control viewer draws them, which is what DLGPD learned from: a 500 × 500
//! window over [−2.2, 2.2]², white background, the pole a capsule of length 1 and width 0.2 in
//! (0.8, 0.3, 0.3) rotated by θ + π/2 (θ = 0 points up, θ grows counter-clockwise), a black axle of radius
//! 0.05; no anti-aliasing (OpenGL filled polygons), circles as 30-gons. The frame is then resized to 64 × 64.

use fast_image_resize::images::Image;
use fast_image_resize::{FilterType, PixelType, ResizeAlg, ResizeOptions, Resizer};
use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Transform};

pub const RENDER_SIZE: u32 = 500;
pub const WORLD_BOUND: f64 = 2.2;
/// Side of the frames the model sees.
pub const FRAME_SIZE: u32 = 64;
/// Bytes of one RGB frame.
pub const FRAME_BYTES: usize = (FRAME_SIZE * FRAME_SIZE * 3) as usize;

const POLE_LENGTH: f32 = 1.0;
const POLE_WIDTH: f32 = 0.2;
const AXLE_RADIUS: f32 = 0.05;
const POLE_RGB: [u8; 3] = [204, 77, 77];
/// gym's `make_circle` resolution.
const CIRCLE_SEGMENTS: usize = 30;

/// Renders frames; keeps its canvases so that rendering a dataset allocates once.
pub struct PendulumRenderer {
    canvas: Pixmap,
    resizer: Resizer,
    full_rgb: Vec<u8>,
}

impl Default for PendulumRenderer {
    fn default() -> Self {
        Self::new()
    }
}

/// A closed polygon approximating a circle, as gym builds it.
fn circle(builder: &mut PathBuilder, cx: f32, cy: f32, r: f32) {
    for i in 0..CIRCLE_SEGMENTS {
        let a = 2.0 * std::f32::consts::PI * i as f32 / CIRCLE_SEGMENTS as f32;
        let (x, y) = (cx + r * a.cos(), cy + r * a.sin());
        if i == 0 {
            builder.move_to(x, y);
        } else {
            builder.line_to(x, y);
        }
    }
    builder.close();
}

impl PendulumRenderer {
    pub fn new() -> Self {
        PendulumRenderer {
            canvas: Pixmap::new(RENDER_SIZE, RENDER_SIZE).expect("a 500 × 500 canvas is a valid size"),
            resizer: Resizer::new(),
            full_rgb: vec![0; (RENDER_SIZE * RENDER_SIZE * 3) as usize],
        }
    }

    /// World (y up) → canvas pixels (y down, origin top left), the flip gym applies to its window capture.
    fn world_to_canvas() -> Transform {
        let scale = RENDER_SIZE as f32 / (2.0 * WORLD_BOUND as f32);
        Transform::from_row(scale, 0.0, 0.0, -scale, WORLD_BOUND as f32 * scale, WORLD_BOUND as f32 * scale)
    }

    /// The 500 × 500 RGB render of angle `theta`, row-major from the top-left corner.
    pub fn render_full(&mut self, theta: f64) -> &[u8] {
        self.canvas.fill(tiny_skia::Color::WHITE);
        let world = Self::world_to_canvas();
        let rotation = (theta + std::f64::consts::FRAC_PI_2) as f32;
        let pole = world.pre_concat(Transform::from_rotate(rotation.to_degrees()));
        let mut paint = Paint { anti_alias: false, ..Paint::default() };

        let half = POLE_WIDTH / 2.0;
        let mut builder = PathBuilder::new();
        builder.move_to(0.0, -half);
        builder.line_to(POLE_LENGTH, -half);
        builder.line_to(POLE_LENGTH, half);
        builder.line_to(0.0, half);
        builder.close();
        circle(&mut builder, 0.0, 0.0, half);
        circle(&mut builder, POLE_LENGTH, 0.0, half);
        let rod = builder.finish().expect("the capsule path is non-empty");
        paint.set_color_rgba8(POLE_RGB[0], POLE_RGB[1], POLE_RGB[2], 255);
        self.canvas.fill_path(&rod, &paint, FillRule::Winding, pole, None);

        let mut builder = PathBuilder::new();
        circle(&mut builder, 0.0, 0.0, AXLE_RADIUS);
        let axle = builder.finish().expect("the axle path is non-empty");
        paint.set_color_rgba8(0, 0, 0, 255);
        self.canvas.fill_path(&axle, &paint, FillRule::Winding, world, None);

        // Opaque drawing on an opaque canvas: the premultiplied RGBA is plain RGBA.
        for (rgb, rgba) in self.full_rgb.chunks_exact_mut(3).zip(self.canvas.data().chunks_exact(4)) {
            rgb.copy_from_slice(&rgba[..3]);
        }
        &self.full_rgb
    }

    /// The 64 × 64 RGB frame of angle `theta` (bilinear resize of the full render).
    pub fn frame(&mut self, theta: f64) -> Vec<u8> {
        self.render_full(theta);
        let source = Image::from_slice_u8(RENDER_SIZE, RENDER_SIZE, &mut self.full_rgb, PixelType::U8x3)
            .expect("the buffer holds 500 × 500 RGB pixels");
        let mut out = Image::new(FRAME_SIZE, FRAME_SIZE, PixelType::U8x3);
        let options = ResizeOptions::new().resize_alg(ResizeAlg::Convolution(FilterType::Bilinear));
        self.resizer.resize(&source, &mut out, &options).expect("both images are RGB u8");
        out.into_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixel(rgb: &[u8], size: u32, x: u32, y: u32) -> [u8; 3] {
        let i = ((y * size + x) * 3) as usize;
        [rgb[i], rgb[i + 1], rgb[i + 2]]
    }

    /// Canvas pixel of a world point.
    fn at(x: f64, y: f64) -> (u32, u32) {
        let s = RENDER_SIZE as f64 / (2.0 * WORLD_BOUND);
        (((x + WORLD_BOUND) * s) as u32, ((WORLD_BOUND - y) * s) as u32)
    }

    #[test]
    fn the_pole_points_up_at_zero_and_turns_counter_clockwise() {
        let mut r = PendulumRenderer::new();
        let full = r.render_full(0.0).to_vec();
        let (x, y) = at(0.0, 0.6);
        assert_eq!(pixel(&full, RENDER_SIZE, x, y), POLE_RGB, "pole above the axle");
        let (x, y) = at(0.0, -0.6);
        assert_eq!(pixel(&full, RENDER_SIZE, x, y), [255; 3], "nothing below");
        let (x, y) = at(0.0, 0.0);
        assert_eq!(pixel(&full, RENDER_SIZE, x, y), [0; 3], "black axle at the origin");
        // θ = π/2: counter-clockwise from up is left.
        let full = r.render_full(std::f64::consts::FRAC_PI_2).to_vec();
        let (x, y) = at(-0.6, 0.0);
        assert_eq!(pixel(&full, RENDER_SIZE, x, y), POLE_RGB);
        let (x, y) = at(0.6, 0.0);
        assert_eq!(pixel(&full, RENDER_SIZE, x, y), [255; 3]);
        // The rounded tip reaches 1.1 from the axle, nothing beyond.
        let (x, y) = at(-1.07, 0.0);
        assert_eq!(pixel(&full, RENDER_SIZE, x, y), POLE_RGB);
        let (x, y) = at(-1.15, 0.0);
        assert_eq!(pixel(&full, RENDER_SIZE, x, y), [255; 3]);
    }

    #[test]
    fn frames_are_small_deterministic_and_differ_by_angle() {
        let mut r = PendulumRenderer::new();
        let a = r.frame(0.3);
        assert_eq!(a.len(), FRAME_BYTES);
        assert_eq!(a, PendulumRenderer::new().frame(0.3));
        let b = r.frame(0.3 + std::f64::consts::PI);
        assert_ne!(a, b);
        // Mostly background, some pole colour: the red channel stays high where green drops.
        let reddish = a.chunks_exact(3).filter(|p| p[0] > 150 && p[1] < 150).count();
        assert!((20..600).contains(&reddish), "{reddish} reddish pixels");
        // θ and θ + 2π draw the same frame.
        assert_eq!(r.frame(0.3 + 2.0 * std::f64::consts::PI), r.frame(0.3));
    }
}
