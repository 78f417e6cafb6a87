//! Reference samplers shared by the integration tests, each with its exact pdf.
#![allow(dead_code)]

use glam::{Vec2, Vec3};
use radiant_math::Frame;
use radiant_testkit::chi2::ChiSquareReport;
use std::f32::consts::PI;

/// Family-wise significance and size of the suite the tests pretend to be part of:
/// the harness will run ~100 tests, so each one is judged at Šidák's 1e-4.
pub const ALPHA: f64 = 0.01;
pub const SUITE_TESTS: u32 = 100;

/// How many standard deviations the statistic lies above its mean under the null
/// hypothesis (mean dof, variance 2 dof): a readable measure of detection margin.
pub fn sigmas(report: &ChiSquareReport) -> f64 {
    (report.statistic - report.dof as f64) / (2.0 * report.dof as f64).sqrt()
}

pub fn print_report(report: &ChiSquareReport) {
    println!(
        "{}: statistic {:.1}, dof {}, p-value {:.3e}, {:+.1} sigma, integral {:.6}, no sample {}",
        report.name,
        report.statistic,
        report.dof,
        report.p_value,
        sigmas(report),
        report.pdf_integral,
        report.no_sample
    );
}

/// Normalized cosine-power (Phong) lobe around `axis`: pdf (n+1)/(2π) cos^n.
#[derive(Clone, Copy)]
pub struct PhongLobe {
    pub frame: Frame,
    pub exponent: f32,
}

impl PhongLobe {
    pub fn new(axis: Vec3, exponent: f32) -> PhongLobe {
        PhongLobe {
            frame: Frame::from_normal(axis.normalize()),
            exponent,
        }
    }

    /// Inverts the cos θ marginal, F(cos θ) = 1 - cos^(n+1) θ.
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let cos_theta = u.x.powf(1.0 / (self.exponent + 1.0));
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        self.frame.to_world(Vec3::new(
            sin_theta * phi.cos(),
            sin_theta * phi.sin(),
            cos_theta,
        ))
    }

    pub fn pdf(&self, w: Vec3) -> f32 {
        let c = w.dot(self.frame.n).max(0.0);
        (self.exponent + 1.0) / (2.0 * PI) * c.powf(self.exponent)
    }
}

/// Isotropic Gaussian offsets by Box–Muller, dropped (None) outside `[-radius, radius]²`
/// like a pixel filter with finite support; the pdf per trial is the untruncated
/// Gaussian, which integrates to erf(radius / (σ√2))² over the rectangle.
pub fn gaussian_offset(u: Vec2, sigma: f32, radius: f32) -> Option<Vec2> {
    let r = sigma * (-2.0 * (1.0 - u.x).ln()).sqrt();
    let phi = 2.0 * PI * u.y;
    let p = Vec2::new(r * phi.cos(), r * phi.sin());
    (p.x.abs() <= radius && p.y.abs() <= radius).then_some(p)
}

pub fn gaussian_pdf(p: Vec2, sigma: f32) -> f32 {
    (-(p.length_squared()) / (2.0 * sigma * sigma)).exp() / (2.0 * PI * sigma * sigma)
}

/// Tent on [-1, 1] by inverting its CDF.
pub fn tent(u: f32) -> f32 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        1.0 - (2.0 * (1.0 - u)).sqrt()
    }
}

pub fn tent_pdf(x: f32) -> f32 {
    (1.0 - x.abs()).max(0.0)
}
