//! Diffuse area lights: a shape that emits radiance `l` from its front side (or both
//! sides). A quadric or curved patch is one light; an emitting triangle mesh is one
//! light as a whole (a parallelogram when it is a quad), sampled with one 2D sample
//! stratified over the whole emitter. Were each triangle its own light, a separate 1D
//! choice among them would break the 2D stratification of the point on the emitter: on
//! the Cornell box's quad light that costs 3.2× the direct-light variance of sampling
//! the quad as one patch.
//!
//! With an image (`filename`) the radiance at a point is `l` times the image at the
//! point's (u, v), the same (u, v) a ray hitting the point sees: samples carry them.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::emission_image::EmissionImage;
use super::{LightHit, LightLeSample, LightLiSample, LightPoint, LightSampleContext};
use crate::geometry::bilinear::BilinearPatch;
use crate::geometry::disk::Disk;
use crate::geometry::ray::gamma;
use crate::geometry::ray::transform_point_with_error;
use crate::geometry::sample::{AreaSample, area_pdf_to_solid_angle};
use crate::geometry::sphere::Sphere;
use crate::geometry::triangle::sample_triangle;
use radiant_math::color::Rgb;
use radiant_math::{Distribution1D, Frame, PI, Transform, sampling};

#[derive(Clone, Debug)]
pub enum LightShape {
    /// A triangle in render space; `n` is the oriented front normal.
    Triangle { p: [Vec3; 3], n: Vec3, area: f32 },
    /// A planar parallelogram `p + s e1 + t e2`, (s, t) in [0,1]² (a quad mesh of two
    /// triangles): the sample maps to it linearly, so every stratum of the 2D sample is a
    /// parallelogram of the same share of the area.
    Parallelogram {
        p: Vec3,
        e1: Vec3,
        e2: Vec3,
        n: Vec3,
        area: f32,
    },
    /// Several triangles emitting as one light, sampled uniformly by area.
    Mesh(Box<EmittingMesh>),
    /// A sphere placed by a similarity transform (solid angles are preserved).
    Sphere {
        sphere: Sphere,
        render_from_object: Transform,
        reverse: bool,
    },
    /// A curved bilinear patch in render space; `orientation` −1 flips ∂p/∂u × ∂p/∂v.
    Bilinear {
        patch: BilinearPatch,
        orientation: f32,
    },
    /// A disk placed by a similarity transform; `scale2` is the area scale factor. Its
    /// render-space front normal (reversed where the shape says so) and area density
    /// are the same for every point, so they are kept rather than transformed at each
    /// sample ([`LightShape::disk`]).
    Disk {
        disk: Disk,
        render_from_object: Transform,
        scale2: f32,
        normal: Vec3,
        pdf: f32,
    },
}

impl LightShape {
    /// The disk `disk` placed by `render_from_object`, facing the other way with `reverse`.
    pub fn disk(disk: Disk, render_from_object: Transform, reverse: bool) -> LightShape {
        let scale2 = similarity_scale2(&render_from_object);
        let sample = disk.sample_area(Vec2::ZERO);
        let AreaSample { n: normal, pdf, .. } =
            to_render(sample, &render_from_object, reverse, scale2);
        LightShape::Disk {
            disk,
            render_from_object,
            scale2,
            normal,
            pdf,
        }
    }
}

/// The triangles of an emitting mesh and the choice among them by area. One 2D sample
/// places a point on the whole mesh: its first coordinate picks a triangle through the
/// area CDF and, rescaled to [0,1) within that triangle's share, is reused with the
/// second to place the point in it — consecutive strata of the sample stay adjacent
/// pieces of the emitter (the inversion method; Pharr, Jakob & Humphreys, *PBR* 4th
/// ed., sec. A.4.2).
#[derive(Clone, Debug)]
pub struct EmittingMesh {
    /// Render-space vertices of each triangle.
    pub triangles: Vec<[Vec3; 3]>,
    /// Oriented front normal of each triangle.
    pub normals: Vec<Vec3>,
    /// Triangle choice in proportion to area.
    pub by_area: Distribution1D,
    /// Total area.
    pub area: f32,
    /// Surface (u, v) at the vertices of each triangle, for a light with an image;
    /// empty otherwise.
    pub uvs: Vec<[Vec2; 3]>,
}

impl EmittingMesh {
    /// The mesh of `triangles` with front normals `normals`; every triangle must have a
    /// positive area. `uvs` is empty, or the (u, v) of each triangle's vertices.
    pub fn new(triangles: Vec<[Vec3; 3]>, normals: Vec<Vec3>, uvs: Vec<[Vec2; 3]>) -> EmittingMesh {
        assert!(uvs.is_empty() || uvs.len() == triangles.len());
        let areas: Vec<f32> = triangles
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
            .collect();
        let area = areas.iter().map(|&a| a as f64).sum::<f64>() as f32;
        EmittingMesh {
            triangles,
            normals,
            by_area: Distribution1D::new(&areas),
            area,
            uvs,
        }
    }
}

/// The parallelogram two triangles form, as (corner, edge, edge), when they share an
/// edge as its diagonal and their other corners mirror each other through its middle.
pub fn parallelogram_of(a: [Vec3; 3], b: [Vec3; 3]) -> Option<(Vec3, Vec3, Vec3)> {
    let shared: Vec<Vec3> = a.iter().copied().filter(|p| b.contains(p)).collect();
    let [s0, s1] = shared[..] else {
        return None;
    };
    let x = *a.iter().find(|p| !b.contains(p))?;
    let y = *b.iter().find(|p| !a.contains(p))?;
    let (e1, e2) = (s0 - x, s1 - x);
    // The fourth corner must be x + e1 + e2, to round-off.
    let tolerance = 1e-5 * (e1.length() + e2.length());
    ((x + e1 + e2 - y).length() <= tolerance).then_some((x, e1, e2))
}

#[derive(Clone, Debug)]
pub struct AreaLight {
    pub shape: LightShape,
    /// The radiance; with `image`, the factor the image is multiplied by.
    pub l: Rgb,
    pub two_sided: bool,
    /// Emission varying over the surface (pbrt-v4's `filename`). Triangles of a light
    /// with an image are always a [`LightShape::Mesh`] with its `uvs`.
    pub image: Option<Arc<EmissionImage>>,
}

/// A point sampled on the light with its surface (u, v) (zero when the light has no
/// image, which is the only reader).
struct EmitterSample {
    area: AreaSample,
    uv: Vec2,
}

impl AreaLight {
    pub fn area(&self) -> f32 {
        match &self.shape {
            LightShape::Triangle { area, .. } | LightShape::Parallelogram { area, .. } => *area,
            LightShape::Mesh(m) => m.area,
            LightShape::Sphere {
                sphere,
                render_from_object,
                ..
            } => sphere.area() * similarity_scale2(render_from_object),
            LightShape::Disk { disk, scale2, .. } => disk.area() * scale2,
            LightShape::Bilinear { patch, .. } => patch.area(),
        }
    }

    pub fn power(&self) -> Rgb {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        self.mean_radiance() * (PI * self.area() * sides)
    }

    /// The radiance averaged over the surface's (u, v): `l`, or `l` times the image's
    /// mean (exact for the uniform parameterisations of triangles, quads and disks
    /// with the default uvs; a fair weight for light selection otherwise).
    pub fn mean_radiance(&self) -> Rgb {
        match &self.image {
            None => self.l,
            Some(img) => self.l * img.mean(),
        }
    }

    /// Radiance leaving a point with front normal `n` and surface parameters `uv` in
    /// direction `w`.
    pub fn radiance(&self, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        if !(self.two_sided || n.dot(w) > 0.0) {
            return Rgb::BLACK;
        }
        match &self.image {
            None => self.l,
            Some(img) => self.l * img.lookup(uv),
        }
    }

    /// A point on the light sampled uniformly by render-space area, with its (u, v).
    #[inline(always)]
    fn sample_area(&self, u: Vec2) -> Option<EmitterSample> {
        let with_uv = self.image.is_some();
        let plain = |area: AreaSample| EmitterSample {
            area,
            uv: Vec2::ZERO,
        };
        Some(match &self.shape {
            LightShape::Triangle { p, n, area } => {
                let s = sample_triangle(p[0], p[1], p[2], u)?;
                plain(AreaSample {
                    p: s.p,
                    p_error: s.p_error,
                    n: *n,
                    pdf: 1.0 / area,
                })
            }
            LightShape::Parallelogram { p, e1, e2, n, area } => {
                let q = *p + *e1 * u.x + *e2 * u.y;
                // Two products and two sums per coordinate.
                let p_error = gamma(4) * (p.abs() + (*e1 * u.x).abs() + (*e2 * u.y).abs());
                plain(AreaSample {
                    p: q,
                    p_error,
                    n: *n,
                    pdf: 1.0 / area,
                })
            }
            LightShape::Mesh(m) => {
                let (i, _, rest) = m.by_area.sample(u.x);
                let t = m.triangles[i];
                let ut = Vec2::new(rest, u.y);
                let s = sample_triangle(t[0], t[1], t[2], ut)?;
                let uv = match m.uvs.get(i) {
                    Some(tuv) if with_uv => {
                        // The barycentrics `sample_triangle` placed the point at.
                        let b = sampling::uniform_triangle(ut);
                        tuv[0] * b[0] + tuv[1] * b[1] + tuv[2] * b[2]
                    }
                    _ => Vec2::ZERO,
                };
                EmitterSample {
                    area: AreaSample {
                        p: s.p,
                        p_error: s.p_error,
                        n: m.normals[i],
                        pdf: 1.0 / m.area,
                    },
                    uv,
                }
            }
            LightShape::Sphere {
                sphere,
                render_from_object,
                reverse,
            } => {
                let s = sphere.sample_area(u);
                EmitterSample {
                    uv: if with_uv { sphere.uv(s.p) } else { Vec2::ZERO },
                    area: to_render(
                        s,
                        render_from_object,
                        *reverse,
                        similarity_scale2(render_from_object),
                    ),
                }
            }
            LightShape::Disk {
                disk,
                render_from_object,
                normal,
                pdf,
                ..
            } => {
                let q = disk.sample_area(u).p;
                let (p, p_error) = transform_point_with_error(render_from_object, q, Vec3::ZERO);
                EmitterSample {
                    uv: if with_uv { disk.uv(q) } else { Vec2::ZERO },
                    area: AreaSample {
                        p,
                        p_error,
                        n: *normal,
                        pdf: *pdf,
                    },
                }
            }
            LightShape::Bilinear { patch, orientation } => {
                let s = patch.sample_area(u)?;
                EmitterSample {
                    // The patch is sampled in its own (u, v).
                    uv: u,
                    area: AreaSample {
                        n: s.n * *orientation,
                        ..s
                    },
                }
            }
        })
    }

    /// A point on the light seen from `ctx`: spheres sample the cone they subtend (far
    /// less variance than area sampling), everything else samples area, converted to
    /// solid angle.
    #[inline]
    pub fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightLiSample> {
        let p = ctx.p;
        let (p_light, pdf, uv) = match &self.shape {
            LightShape::Sphere {
                sphere,
                render_from_object,
                reverse,
            } => {
                let inv = render_from_object.inverse();
                let s = sphere.sample_solid_angle(inv.point(p), u)?;
                let mut n = render_from_object.normal(s.n).normalize();
                if *reverse {
                    n = -n;
                }
                let (q, q_error) = transform_point_with_error(render_from_object, s.p, s.p_error);
                let uv = if self.image.is_some() {
                    sphere.uv(s.p)
                } else {
                    Vec2::ZERO
                };
                (LightPoint::new(q, q_error, n), s.pdf, uv)
            }
            _ => {
                let EmitterSample { area: s, uv } = self.sample_area(u)?;
                (
                    LightPoint::new(s.p, s.p_error, s.n),
                    area_pdf_to_solid_angle(s.pdf, p, s.p, s.n),
                    uv,
                )
            }
        };
        let (q, n) = (p_light.p, p_light.n);
        if pdf <= 0.0 || !pdf.is_finite() {
            return None;
        }
        let wi = (q - p).normalize_or_zero();
        let li = self.radiance(n, uv, -wi);
        if li.is_black() || wi == Vec3::ZERO {
            return None;
        }
        Some(LightLiSample {
            li,
            wi,
            pdf,
            p_light,
            delta: false,
            at_infinity: false,
        })
    }

    /// Solid-angle density of `sample_li` from `ctx` for the direction that meets the
    /// light at `hit`.
    pub fn pdf_li(&self, ctx: &LightSampleContext, hit: &LightHit) -> f32 {
        let (p, q, n) = (ctx.p, hit.p, hit.n);
        match &self.shape {
            LightShape::Sphere {
                sphere,
                render_from_object,
                ..
            } => {
                let inv = render_from_object.inverse();
                sphere.pdf_solid_angle(inv.point(p), inv.point(q))
            }
            LightShape::Bilinear { patch, .. } => {
                area_pdf_to_solid_angle(patch.pdf_area(hit.uv), p, q, n)
            }
            _ => area_pdf_to_solid_angle(1.0 / self.area(), p, q, n),
        }
    }

    /// A photon ray: position by area (uniform, or uniform in (u,v) on a curved patch),
    /// cosine-distributed direction on the emitting side(s), the side chosen with
    /// probability 1/2 when both emit. Its power is L π / pdf_pos per side — the
    /// light's whole power when the position is uniform.
    pub fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<LightLeSample> {
        let EmitterSample { area: s, uv } = self.sample_area(u_pos)?;
        let le = match &self.image {
            None => self.l,
            Some(img) => self.l * img.lookup(uv),
        };
        let (mut u, mut n) = (u_dir, s.n);
        let mut sides = 1.0;
        if self.two_sided {
            sides = 2.0;
            // Reuse the first dimension to pick the side.
            if u.x < 0.5 {
                u.x *= 2.0;
            } else {
                u.x = 2.0 * u.x - 1.0;
                n = -n;
            }
            u.x = u.x.min(radiant_math::ONE_MINUS_EPSILON);
        }
        let local = sampling::cosine_hemisphere(u);
        let d = Frame::from_normal(n).to_world(local);
        Some(LightLeSample {
            ray: LightPoint::new(s.p, s.p_error, n).spawn_ray(d),
            n,
            pdf_pos: s.pdf,
            pdf_dir: sampling::cosine_hemisphere_pdf(local.z) / sides,
            le,
            power: le * (PI * sides / s.pdf),
        })
    }
}

/// Area scale factor of a similarity transform: |det|^(2/3).
fn similarity_scale2(xf: &Transform) -> f32 {
    glam::Mat3::from_mat4(xf.m)
        .determinant()
        .abs()
        .powf(2.0 / 3.0)
}

fn to_render(s: AreaSample, xf: &Transform, reverse: bool, scale2: f32) -> AreaSample {
    let mut n = xf.normal(s.n).normalize();
    if reverse {
        n = -n;
    }
    let (p, p_error) = transform_point_with_error(xf, s.p, s.p_error);
    AreaSample {
        p,
        p_error,
        n,
        pdf: s.pdf / scale2,
    }
}
