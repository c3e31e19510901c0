//! Plain `[f64; 3]` helpers. States stay plain arrays so they serialize as JSON lists and copy for free.

pub type Vec3 = [f64; 3];

pub fn add(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn sub(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn scale(a: &Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

pub fn norm(a: &Vec3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Counter-clockwise rotation about the z axis (seen from above), the only rotation the augmentation uses.
pub fn rotate_z(a: &Vec3, angle: f64) -> Vec3 {
    let (s, c) = angle.sin_cos();
    [c * a[0] - s * a[1], s * a[0] + c * a[1], a[2]]
}

/// Rotation about the y axis (right-handed), used to tilt the launcher head.
pub fn rotate_y(a: &Vec3, angle: f64) -> Vec3 {
    let (s, c) = angle.sin_cos();
    [c * a[0] + s * a[2], a[1], -s * a[0] + c * a[2]]
}

/// Wraps an angle to (−π, π] so rotated launch parameters stay comparable with sampled ones.
pub fn wrap_angle(angle: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    let mut a = angle.rem_euclid(two_pi);
    if a > std::f64::consts::PI {
        a -= two_pi;
    }
    a
}
