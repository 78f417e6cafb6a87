//! First-order (paraxial) optics of the lens system by ray-transfer (ABCD) matrices acting on
//! (height y, reduced angle n·u): refraction at a surface of power φ = (n' − n)/R is
//! `[1 0; −φ 1]`, a gap of thickness t in index n is `[1 t/n; 0 1]` (see e.g. Gerrard & Burch,
//! "Introduction to Matrix Methods in Optics", 1975; Smith, "Modern Optical Engineering").
//! Everything here is in design space: z from the front vertex, +z towards the film, mm.

use super::{LensError, LensSystem};

/// A 2×2 ray-transfer matrix acting on (y, n·u).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Abcd {
    /// Height from height.
    pub a: f64,
    /// Height from reduced angle.
    pub b: f64,
    /// Reduced angle from height (−power).
    pub c: f64,
    /// Reduced angle from reduced angle.
    pub d: f64,
}

impl Abcd {
    /// The matrix that changes nothing.
    pub const IDENTITY: Abcd = Abcd {
        a: 1.0,
        b: 0.0,
        c: 0.0,
        d: 1.0,
    };

    /// Refraction at a surface of power `phi` (1/mm).
    pub fn refraction(phi: f64) -> Abcd {
        Abcd {
            a: 1.0,
            b: 0.0,
            c: -phi,
            d: 1.0,
        }
    }

    /// Transfer over `thickness` in a medium of refractive `index`.
    pub fn transfer(thickness: f64, index: f64) -> Abcd {
        Abcd {
            a: 1.0,
            b: thickness / index,
            c: 0.0,
            d: 1.0,
        }
    }

    /// `next ∘ self`: first `self`, then `next`.
    pub fn then(self, next: Abcd) -> Abcd {
        Abcd {
            a: next.a * self.a + next.b * self.c,
            b: next.a * self.b + next.b * self.d,
            c: next.c * self.a + next.d * self.c,
            d: next.c * self.b + next.d * self.d,
        }
    }

    /// Applies the matrix to (y, n·u).
    pub fn apply(&self, y: f64, nu: f64) -> (f64, f64) {
        (self.a * y + self.b * nu, self.c * y + self.d * nu)
    }

    /// n_in / n_out for a physical system (1 between air spaces).
    pub fn determinant(&self) -> f64 {
        self.a * self.d - self.b * self.c
    }
}

/// Thick-lens (first-order) data of a lens system. Positions are design-space z (front vertex =
/// 0, +z towards the film) unless the name says otherwise; all in mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParaxialData {
    /// System matrix from the front vertex to the rear vertex.
    pub abcd: Abcd,
    /// Effective focal length, −1/C.
    pub efl: f64,
    /// Back focal distance: rear vertex to rear focal point (positive towards the film).
    pub bfd: f64,
    /// Front focal distance: front focal point to front vertex (positive when the focal point is
    /// in front of the lens).
    pub ffd: f64,
    /// Front (object-side) principal plane H.
    pub h1_z: f64,
    /// Rear (image-side) principal plane H'.
    pub h2_z: f64,
    /// Front vertex to rear vertex.
    pub total_track: f64,
    /// Index of the aperture stop (front element = 0).
    pub stop_index: usize,
    /// Aperture stop position and (current) diameter.
    pub stop_z: f64,
    /// Current stop diameter.
    pub stop_diameter: f64,
    /// Entrance pupil (paraxial image of the stop through the elements in front of it).
    pub entrance_pupil_z: f64,
    /// Entrance pupil diameter.
    pub entrance_pupil_diameter: f64,
    /// Exit pupil position relative to the rear vertex (negative: in front of it).
    pub exit_pupil_from_rear: f64,
    /// Exit pupil diameter.
    pub exit_pupil_diameter: f64,
    /// Paraxial f-number EFL / entrance-pupil diameter (the stop limits the axial bundle).
    pub f_number: f64,
    /// Paraxial f-number of the axial bundle limited by whichever aperture cuts it first.
    pub f_number_limited: f64,
    /// The surface that limits the axial bundle from infinity.
    pub axial_limiting_surface: usize,
}

impl ParaxialData {
    /// Paraxial data for the system with its current stop diameter.
    pub fn new(system: &LensSystem) -> Result<ParaxialData, LensError> {
        let s = system.interfaces();
        let n = s.len();
        let stop = system.stop_index();
        let surface_matrix = |i: usize| {
            let phi = if s[i].radius == 0.0 {
                0.0
            } else {
                (s[i].index_film_side - s[i].index_scene_side) / s[i].radius
            };
            Abcd::refraction(phi)
        };
        let gap_matrix =
            |i: usize| Abcd::transfer(s[i].vertex_z - s[i + 1].vertex_z, s[i].index_film_side);

        // Front vertex → rear vertex, front vertex → stop plane, and stop plane → rear vertex.
        let mut system_m = Abcd::IDENTITY;
        let mut front_to_stop = Abcd::IDENTITY;
        let mut stop_to_rear = Abcd::IDENTITY;
        for i in 0..n {
            let m = surface_matrix(i);
            system_m = system_m.then(m);
            if i < stop {
                front_to_stop = front_to_stop.then(m);
            } else if i > stop {
                stop_to_rear = stop_to_rear.then(m);
            }
            if i + 1 < n {
                let t = gap_matrix(i);
                system_m = system_m.then(t);
                if i < stop {
                    front_to_stop = front_to_stop.then(t);
                } else {
                    stop_to_rear = stop_to_rear.then(t);
                }
            }
        }
        let Abcd { a, c, d, .. } = system_m;
        if c == 0.0 || !c.is_finite() {
            return Err(LensError::Afocal {
                lens: system.name.clone(),
            });
        }
        let total_track = system.total_track();
        let efl = -1.0 / c;
        // Object space is air (index 1); image space has the rear medium's index.
        let n_image = s[n - 1].index_film_side;
        let bfd = -a / c * n_image;
        let ffd = -d / c;
        let h1_z = -ffd + efl;
        let h2_z = total_track + bfd - efl * n_image;

        let stop_z = total_track - s[stop].vertex_z;
        let stop_diameter = system.stop_diameter();

        // Entrance pupil: a ray through the stop centre, (0, 1) at the stop, traced back to the
        // front vertex is (−b, a)/det; in object space it crosses the axis at z = b/a. A ray
        // leaving the pupil plane at height 1 reaches the stop at height a (conjugate planes).
        let Abcd {
            a: af, b: bf, c: _, ..
        } = front_to_stop;
        let entrance_pupil_z = bf / af;
        let entrance_pupil_diameter = stop_diameter / af.abs();

        // Exit pupil: the stop-centre ray leaves the rear vertex as (b, d) and crosses the axis
        // after −b·n/d; the stop-edge ray (1, 0) leaves as (a, c).
        let Abcd {
            a: ar,
            b: br,
            c: cr,
            d: dr,
        } = stop_to_rear;
        let exit_pupil_from_rear = -br * n_image / dr;
        let exit_pupil_diameter = stop_diameter * (ar + cr / n_image * exit_pupil_from_rear).abs();

        let f_number = efl / entrance_pupil_diameter;

        // Axial bundle from infinity: the largest entrance height that clears every aperture.
        let (mut y, mut nu) = (1.0f64, 0.0f64);
        let mut max_height = f64::INFINITY;
        let mut axial_limiting_surface = stop;
        for (i, surface) in s.iter().enumerate() {
            let allowed = surface.aperture_radius / y.abs();
            if allowed < max_height {
                max_height = allowed;
                axial_limiting_surface = i;
            }
            (y, nu) = surface_matrix(i).apply(y, nu);
            if i + 1 < n {
                (y, nu) = gap_matrix(i).apply(y, nu);
            }
        }
        let f_number_limited = efl / (2.0 * max_height);

        Ok(ParaxialData {
            abcd: system_m,
            efl,
            bfd,
            ffd,
            h1_z,
            h2_z,
            total_track,
            stop_index: stop,
            stop_z,
            stop_diameter,
            entrance_pupil_z,
            entrance_pupil_diameter,
            exit_pupil_from_rear,
            exit_pupil_diameter,
            f_number,
            f_number_limited,
            axial_limiting_surface,
        })
    }
}
