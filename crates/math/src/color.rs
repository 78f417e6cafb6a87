//! Linear RGB radiometric quantities (radiance, power, albedo), one f32 per channel.
//!
//! radiant renders in linear RGB (no spectral sampling): every emitted, reflected or
//! measured quantity is an [`Rgb`] triple. Display transforms (sRGB, exposure) live in
//! `image::png` and are applied only when writing an 8-bit file.

use std::ops::{Add, AddAssign, Div, DivAssign, Index, Mul, MulAssign, Sub};

/// A linear RGB triple.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rgb {
    pub r: f32,
    pub g: f32,
    pub b: f32,
}

impl Rgb {
    pub const BLACK: Rgb = Rgb::splat(0.0);
    pub const WHITE: Rgb = Rgb::splat(1.0);

    pub const fn new(r: f32, g: f32, b: f32) -> Self {
        Rgb { r, g, b }
    }
    pub const fn splat(v: f32) -> Self {
        Rgb { r: v, g: v, b: v }
    }
    pub fn from_array(a: [f32; 3]) -> Self {
        Rgb::new(a[0], a[1], a[2])
    }
    pub fn to_array(self) -> [f32; 3] {
        [self.r, self.g, self.b]
    }
    pub fn is_black(self) -> bool {
        self.r == 0.0 && self.g == 0.0 && self.b == 0.0
    }
    pub fn is_finite(self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }
    pub fn max_component(self) -> f32 {
        self.r.max(self.g).max(self.b)
    }
    pub fn min_component(self) -> f32 {
        self.r.min(self.g).min(self.b)
    }
    /// Arithmetic mean of the channels (used for power-proportional choices).
    pub fn average(self) -> f32 {
        (self.r + self.g + self.b) / 3.0
    }
    /// Relative luminance Y of linear sRGB/Rec.709 primaries.
    pub fn luminance(self) -> f32 {
        0.2126 * self.r + 0.7152 * self.g + 0.0722 * self.b
    }
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Rgb::new(f(self.r), f(self.g), f(self.b))
    }
    pub fn clamp_min(self, v: f32) -> Self {
        self.map(|c| c.max(v))
    }
}

impl Index<usize> for Rgb {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        match i {
            0 => &self.r,
            1 => &self.g,
            2 => &self.b,
            _ => panic!("Rgb channel index {i} out of range"),
        }
    }
}

impl Add for Rgb {
    type Output = Rgb;
    fn add(self, o: Rgb) -> Rgb {
        Rgb::new(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}
impl AddAssign for Rgb {
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}
impl Sub for Rgb {
    type Output = Rgb;
    fn sub(self, o: Rgb) -> Rgb {
        Rgb::new(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}
impl Mul for Rgb {
    type Output = Rgb;
    fn mul(self, o: Rgb) -> Rgb {
        Rgb::new(self.r * o.r, self.g * o.g, self.b * o.b)
    }
}
impl MulAssign for Rgb {
    fn mul_assign(&mut self, o: Rgb) {
        *self = *self * o;
    }
}
impl Mul<f32> for Rgb {
    type Output = Rgb;
    fn mul(self, s: f32) -> Rgb {
        Rgb::new(self.r * s, self.g * s, self.b * s)
    }
}
impl Mul<Rgb> for f32 {
    type Output = Rgb;
    fn mul(self, c: Rgb) -> Rgb {
        c * self
    }
}
impl MulAssign<f32> for Rgb {
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}
impl Div<f32> for Rgb {
    type Output = Rgb;
    fn div(self, s: f32) -> Rgb {
        let inv = 1.0 / s;
        self * inv
    }
}
impl DivAssign<f32> for Rgb {
    fn div_assign(&mut self, s: f32) {
        *self = *self / s;
    }
}
