//! The lens system laid out on the optical axis, and exact f64 ray tracing through it:
//! spherical (or flat) interfaces, Snell refraction, clipping at every aperture and total internal
//! reflection, as in Kolb, Mitchell & Hanrahan (1995), section 3.

use super::{LensError, LensPrescription};
use radiant_math::DVec3;

/// One interface placed in lens space (mm; rear vertex at z = 0, +z towards the scene).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interface {
    /// Axial position of the vertex.
    pub vertex_z: f64,
    /// Radius of curvature in the file's convention (positive: centre towards the film); 0 = flat.
    pub radius: f64,
    /// Clear aperture radius (half the file's diameter; the stop's may be overridden).
    pub aperture_radius: f64,
    /// Refractive index on the scene side (the medium in front of the interface).
    pub index_scene_side: f64,
    /// Refractive index on the film side (the file's index column).
    pub index_film_side: f64,
}

impl Interface {
    /// Axial position of the sphere's centre (meaningless for flat interfaces).
    pub fn center_z(&self) -> f64 {
        self.vertex_z - self.radius
    }

    /// Axial position of the surface at height `h` from the axis (h ≤ |radius|).
    pub fn sag_z(&self, h: f64) -> f64 {
        if self.radius == 0.0 {
            return self.vertex_z;
        }
        let r = self.radius;
        // Vertex minus the sag towards the centre; written as h²/(|r| + sqrt(r² − h²)) to avoid
        // cancellation for shallow surfaces.
        let sag = h * h / (r.abs() + (r * r - h * h).max(0.0).sqrt());
        self.vertex_z - r.signum() * sag
    }
}

/// Whether tracing stops rays at aperture rims (rendering) or lets them through (construction
/// rays such as the chief ray or the thick-lens rays, which are defined without apertures).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ApertureClipping {
    Clip,
    Ignore,
}

/// A ray in lens space (mm); `dir` is unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensRay {
    /// Start point.
    pub origin: DVec3,
    /// Unit direction.
    pub dir: DVec3,
}

/// Why a ray did not make it through the lens (surface numbers count from the front element).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceFailure {
    /// Outside the clear aperture of this surface.
    Blocked { surface: usize },
    /// Totally internally reflected at this surface.
    TotalInternalReflection { surface: usize },
    /// Does not intersect this surface at all (or only behind the ray).
    Missed { surface: usize },
}

/// A lens prescription laid out on the axis, ready for exact tracing.
#[derive(Clone, Debug)]
pub struct LensSystem {
    /// The prescription's name (file), for messages.
    pub name: String,
    interfaces: Vec<Interface>,
    stop: usize,
    file_stop_diameter: f64,
}

impl LensSystem {
    /// Lays out a validated prescription; the last thickness is ignored (the film distance
    /// replaces it).
    pub fn new(prescription: &LensPrescription) -> Result<LensSystem, LensError> {
        prescription.validate()?;
        let surfaces = &prescription.surfaces;
        let n = surfaces.len();
        let mut interfaces = Vec::with_capacity(n);
        let mut z = 0.0;
        for i in (0..n).rev() {
            if i + 1 < n {
                z += surfaces[i].thickness;
            }
            let index_scene_side = if i == 0 { 1.0 } else { surfaces[i - 1].index };
            interfaces.push(Interface {
                vertex_z: z,
                radius: surfaces[i].radius,
                aperture_radius: 0.5 * surfaces[i].aperture_diameter,
                index_scene_side,
                index_film_side: surfaces[i].index,
            });
        }
        interfaces.reverse();
        let stop = prescription.stop_index().ok_or_else(|| LensError::NoStop {
            file: prescription.name.clone(),
        })?;
        let file_stop_diameter = surfaces[stop].aperture_diameter;
        Ok(LensSystem {
            name: prescription.name.clone(),
            interfaces,
            stop,
            file_stop_diameter,
        })
    }

    /// Sets the stop diameter (mm). A request wider than the file's stop is clamped to it (the
    /// lens barrel cannot open further) and a warning is returned; non-positive is an error.
    pub fn set_stop_diameter(&mut self, diameter_mm: f64) -> Result<Option<String>, LensError> {
        if !(diameter_mm > 0.0 && diameter_mm.is_finite()) {
            return Err(LensError::InvalidParameter(format!(
                "{}: aperture diameter must be positive and finite, got {diameter_mm} mm",
                self.name
            )));
        }
        let mut warning = None;
        let mut d = diameter_mm;
        // Scene files store f32: a diameter equal to the stop's up to f32 rounding is the stop.
        if d > self.file_stop_diameter * (1.0 + 1e-6) {
            warning = Some(format!(
                "{}: aperture diameter {diameter_mm} mm is larger than the lens's stop ({} mm); clamped",
                self.name, self.file_stop_diameter
            ));
        }
        d = d.min(self.file_stop_diameter);
        self.interfaces[self.stop].aperture_radius = 0.5 * d;
        Ok(warning)
    }

    /// Interfaces from the front element to the rear.
    pub fn interfaces(&self) -> &[Interface] {
        &self.interfaces
    }

    /// Index of the aperture stop among [`LensSystem::interfaces`].
    pub fn stop_index(&self) -> usize {
        self.stop
    }

    /// Current stop diameter (mm).
    pub fn stop_diameter(&self) -> f64 {
        2.0 * self.interfaces[self.stop].aperture_radius
    }

    /// The stop diameter written in the file (mm).
    pub fn file_stop_diameter(&self) -> f64 {
        self.file_stop_diameter
    }

    /// Axial distance from the front vertex to the rear vertex (mm).
    pub fn total_track(&self) -> f64 {
        self.interfaces[0].vertex_z
    }

    /// Clear aperture radius of the rear element (mm).
    pub fn rear_aperture_radius(&self) -> f64 {
        self.interfaces[self.interfaces.len() - 1].aperture_radius
    }

    /// The rear interface.
    pub fn rear(&self) -> &Interface {
        &self.interfaces[self.interfaces.len() - 1]
    }

    /// Traces a ray from the film side out through the front element.
    pub fn trace_to_scene(
        &self,
        ray: LensRay,
        clipping: ApertureClipping,
    ) -> Result<LensRay, TraceFailure> {
        self.trace_to_scene_recording(ray, clipping, 0, |_| {})
    }

    /// Traces a ray from the film side through the interfaces from the rear down to and including
    /// `last` (front element = 0), calling `record` with each intersection point.
    pub fn trace_to_scene_recording(
        &self,
        mut ray: LensRay,
        clipping: ApertureClipping,
        last: usize,
        mut record: impl FnMut(DVec3),
    ) -> Result<LensRay, TraceFailure> {
        for i in (last..self.interfaces.len()).rev() {
            ray = self.cross(i, ray, true, clipping)?;
            record(ray.origin);
        }
        Ok(ray)
    }

    /// Traces a ray from the scene side in through every interface, ending at the rear one.
    pub fn trace_to_film(
        &self,
        mut ray: LensRay,
        clipping: ApertureClipping,
    ) -> Result<LensRay, TraceFailure> {
        for i in 0..self.interfaces.len() {
            ray = self.cross(i, ray, false, clipping)?;
        }
        Ok(ray)
    }

    /// Intersects interface `i`, clips at its aperture and refracts (flat interfaces refract too
    /// when the media differ, which is a no-op for the usual stop in air).
    fn cross(
        &self,
        i: usize,
        ray: LensRay,
        towards_scene: bool,
        clipping: ApertureClipping,
    ) -> Result<LensRay, TraceFailure> {
        let s = &self.interfaces[i];
        let (t, normal) = if s.radius == 0.0 {
            let t = (s.vertex_z - ray.origin.z) / ray.dir.z;
            (t, DVec3::Z)
        } else {
            let center = DVec3::new(0.0, 0.0, s.center_z());
            let oc = ray.origin - center;
            let b = oc.dot(ray.dir);
            let c = oc.length_squared() - s.radius * s.radius;
            let disc = b * b - c;
            if disc < 0.0 {
                return Err(TraceFailure::Missed { surface: i });
            }
            // Cancellation-free roots of t² + 2bt + c = 0.
            let q = -b - b.signum() * disc.sqrt();
            let (mut t0, mut t1) = (q, if q != 0.0 { c / q } else { 0.0 });
            if t0 > t1 {
                std::mem::swap(&mut t0, &mut t1);
            }
            // The vertex is the sphere's extreme point in +z when the radius is positive (centre
            // towards the film), so a ray moving in +z meets that cap on its way out.
            let t = if (ray.dir.z > 0.0) == (s.radius > 0.0) {
                t1
            } else {
                t0
            };
            let p = ray.origin + t * ray.dir;
            (t, (p - center) / s.radius.abs())
        };
        if !(t > 0.0 && t.is_finite()) {
            return Err(TraceFailure::Missed { surface: i });
        }
        let p = ray.origin + t * ray.dir;
        if clipping == ApertureClipping::Clip
            && p.x * p.x + p.y * p.y > s.aperture_radius * s.aperture_radius
        {
            return Err(TraceFailure::Blocked { surface: i });
        }
        let (n_in, n_out) = if towards_scene {
            (s.index_film_side, s.index_scene_side)
        } else {
            (s.index_scene_side, s.index_film_side)
        };
        if n_in == n_out {
            return Ok(LensRay {
                origin: p,
                dir: ray.dir,
            });
        }
        let dir = refract(ray.dir, normal, n_in / n_out)
            .ok_or(TraceFailure::TotalInternalReflection { surface: i })?;
        Ok(LensRay { origin: p, dir })
    }
}

/// Snell refraction of unit `d` at a surface with unit normal `n` (either orientation);
/// `eta` = n_incident / n_transmitted. None on total internal reflection.
fn refract(d: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let mut n = n;
    let mut cos_i = -n.dot(d);
    if cos_i < 0.0 {
        n = -n;
        cos_i = -cos_i;
    }
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    // Unit in, unit out (up to round-off, which does not accumulate over a dozen surfaces).
    Some(eta * d + (eta * cos_i - cos_t) * n)
}
