//! pbrt-v4's named spectra, reduced to what radiant renders: glasses become one index of
//! refraction, metals one complex index per RGB band.
//!
//! Metal data (wavelength µm, n, k) are the published measurements as tabulated in the
//! public-domain refractiveindex.info database (M. Polyanskiy), visible range only:
//! - Ag, Au, Cu: P. B. Johnson and R. W. Christy, "Optical constants of the noble
//!   metals", Phys. Rev. B 6, 4370 (1972).
//! - Al: A. D. Rakić, "Algorithm for the determination of intrinsic optical constants
//!   of metal films: application to aluminum", Appl. Opt. 34, 4755 (1995).
//! - CuZn (brass, 70 % Cu, 30 % Zn): M. R. Querry, "Optical constants", Contractor
//!   Report CRDC-CR-85034 (1985).
//!
//! The RGB values are band averages ([`super::spectrum::band_average`]), computed when
//! a scene asks for them.

use super::spectrum::band_average;
use radiant_math::color::Rgb;

type NkTable = &'static [(f64, f64, f64)];

const AG: NkTable = &[
    (0.3815, 0.05, 1.864),
    (0.3974, 0.05, 2.070),
    (0.4133, 0.05, 2.275),
    (0.4305, 0.04, 2.462),
    (0.4509, 0.04, 2.657),
    (0.4714, 0.05, 2.869),
    (0.4959, 0.05, 3.093),
    (0.5209, 0.05, 3.324),
    (0.5486, 0.06, 3.586),
    (0.5821, 0.05, 3.858),
    (0.6168, 0.06, 4.152),
    (0.6595, 0.05, 4.483),
    (0.7045, 0.04, 4.838),
    (0.7560, 0.03, 5.242),
];

const AU: NkTable = &[
    (0.3815, 1.46, 1.933),
    (0.3974, 1.47, 1.952),
    (0.4133, 1.46, 1.958),
    (0.4305, 1.45, 1.948),
    (0.4509, 1.38, 1.914),
    (0.4714, 1.31, 1.849),
    (0.4959, 1.04, 1.833),
    (0.5209, 0.62, 2.081),
    (0.5486, 0.43, 2.455),
    (0.5821, 0.29, 2.863),
    (0.6168, 0.21, 3.272),
    (0.6595, 0.14, 3.697),
    (0.7045, 0.13, 4.103),
    (0.7560, 0.14, 4.542),
];

const CU: NkTable = &[
    (0.3815, 1.33, 2.045),
    (0.3974, 1.32, 2.116),
    (0.4133, 1.28, 2.207),
    (0.4305, 1.25, 2.305),
    (0.4509, 1.24, 2.397),
    (0.4714, 1.25, 2.483),
    (0.4959, 1.22, 2.564),
    (0.5209, 1.18, 2.608),
    (0.5486, 1.02, 2.577),
    (0.5821, 0.70, 2.704),
    (0.6168, 0.30, 3.205),
    (0.6595, 0.22, 3.747),
    (0.7045, 0.21, 4.205),
    (0.7560, 0.24, 4.665),
];

const AL: NkTable = &[
    (0.36466, 0.39877, 4.3957),
    (0.41328, 0.52135, 5.0008),
    (0.44280, 0.60790, 5.3676),
    (0.47687, 0.72780, 5.7781),
    (0.51660, 0.87340, 6.2418),
    (0.56357, 1.0728, 6.7839),
    (0.61993, 1.3660, 7.4052),
    (0.65225, 1.5724, 7.7354),
    (0.68881, 1.8301, 8.0601),
    (0.72932, 2.1606, 8.3565),
];

const CUZN: NkTable = &[
    (0.380, 1.487, 1.818),
    (0.390, 1.471, 1.813),
    (0.400, 1.445, 1.805),
    (0.410, 1.405, 1.794),
    (0.420, 1.350, 1.786),
    (0.430, 1.278, 1.784),
    (0.440, 1.191, 1.797),
    (0.450, 1.094, 1.829),
    (0.460, 0.994, 1.883),
    (0.470, 0.900, 1.957),
    (0.480, 0.816, 2.046),
    (0.490, 0.745, 2.145),
    (0.500, 0.686, 2.250),
    (0.510, 0.639, 2.358),
    (0.520, 0.602, 2.464),
    (0.530, 0.573, 2.568),
    (0.540, 0.549, 2.668),
    (0.550, 0.527, 2.765),
    (0.560, 0.505, 2.860),
    (0.570, 0.484, 2.958),
    (0.580, 0.468, 3.059),
    (0.590, 0.460, 3.159),
    (0.600, 0.450, 3.253),
    (0.610, 0.452, 3.345),
    (0.620, 0.449, 3.434),
    (0.630, 0.445, 3.522),
    (0.640, 0.444, 3.609),
    (0.650, 0.444, 3.695),
    (0.660, 0.445, 3.778),
    (0.670, 0.444, 3.860),
    (0.680, 0.444, 3.943),
    (0.690, 0.445, 4.025),
    (0.700, 0.446, 4.106),
    (0.710, 0.448, 4.186),
    (0.720, 0.450, 4.266),
];

/// pbrt-v4's glass names with the catalogue index at the helium d line (587.6 nm,
/// Schott optical glass data sheets: N-BK7, N-BAF10, N-FK51A, N-LASF9, SF5, SF10,
/// SF11). Dispersion is dropped: radiant renders one index for all wavelengths.
const GLASSES: [(&str, f32); 7] = [
    ("glass-BK7", 1.5168),
    ("glass-BAF10", 1.67003),
    ("glass-FK51A", 1.48656),
    ("glass-LASF9", 1.85025),
    ("glass-F5", 1.67270),
    ("glass-F10", 1.72825),
    ("glass-F11", 1.78472),
];

/// The d-line index of a named glass.
pub fn glass_eta(name: &str) -> Option<f32> {
    GLASSES.iter().find(|g| g.0 == name).map(|g| g.1)
}

fn metal_table(metal: &str) -> Option<NkTable> {
    match metal {
        "Ag" => Some(AG),
        "Au" => Some(AU),
        "Cu" => Some(CU),
        "Al" => Some(AL),
        "CuZn" => Some(CUZN),
        _ => None,
    }
}

/// `metal-<X>-eta` / `metal-<X>-k` as band-averaged RGB.
pub fn metal_spectrum(name: &str) -> Option<Rgb> {
    let rest = name.strip_prefix("metal-")?;
    let (metal, part) = rest.rsplit_once('-')?;
    let table = metal_table(metal)?;
    let column = |pick: fn(&(f64, f64, f64)) -> f64| -> Vec<(f64, f64)> {
        table.iter().map(|r| (r.0 * 1000.0, pick(r))).collect()
    };
    match part {
        "eta" => Some(band_average(&column(|r| r.1))),
        "k" => Some(band_average(&column(|r| r.2))),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Normal-incidence reflectance of a conductor, ((n-1)² + k²) / ((n+1)² + k²).
    fn r0(n: f32, k: f32) -> f32 {
        ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
    }

    #[test]
    fn metals_keep_their_colour() {
        let rgb = |m: &str| {
            let eta = metal_spectrum(&format!("metal-{m}-eta")).unwrap();
            let k = metal_spectrum(&format!("metal-{m}-k")).unwrap();
            Rgb::new(r0(eta.r, k.r), r0(eta.g, k.g), r0(eta.b, k.b))
        };
        // Gold and copper reflect red far more than blue; silver and aluminium are
        // nearly neutral and bright (> 0.85 in every band).
        for m in ["Au", "Cu", "CuZn"] {
            let c = rgb(m);
            assert!(c.r > c.g && c.g > c.b, "{m}: {c:?}");
        }
        for m in ["Ag", "Al"] {
            let c = rgb(m);
            assert!(c.min_component() > 0.85, "{m}: {c:?}");
        }
        // Gold's red reflectance from the band-averaged n, k: ~0.95 (J&C at 650 nm
        // gives n = 0.16, k = 3.6, R = 0.955).
        assert!((rgb("Au").r - 0.95).abs() < 0.03);
    }

    #[test]
    fn unknown_names_are_none() {
        assert!(metal_spectrum("metal-Xx-eta").is_none());
        assert!(metal_spectrum("metal-Au-n").is_none());
        assert_eq!(glass_eta("glass-BK7"), Some(1.5168));
        assert!(glass_eta("glass-XYZ").is_none());
    }
}
