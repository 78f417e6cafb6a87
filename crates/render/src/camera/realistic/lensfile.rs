//! Lens description files (the format of Kolb et al. 1995 as used by pbrt): one row per
//! interface from the front element to the rear, four columns in millimetres:
//! radius of curvature, thickness to the next surface, refractive index of the medium behind the
//! surface (towards the film) and aperture diameter. Radius 0 marks a flat aperture; the first such
//! row is the aperture stop. Index 0 means air. `#` starts a comment. The last thickness is
//! ignored: the camera replaces it with the focused film distance.

use super::LensError;
use std::path::Path;

/// One interface of a lens prescription, in millimetres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensSurface {
    /// Radius of curvature; positive when the centre lies towards the film; 0 for a flat aperture.
    pub radius: f64,
    /// Axial distance to the next interface towards the film.
    pub thickness: f64,
    /// Refractive index of the medium behind this surface (towards the film); 1 for air.
    pub index: f64,
    /// Clear aperture diameter.
    pub aperture_diameter: f64,
}

impl LensSurface {
    /// True for a flat aperture (radius 0).
    pub fn is_flat(&self) -> bool {
        self.radius == 0.0
    }
}

/// A lens prescription: interfaces from the front element to the rear, as read from a file.
#[derive(Clone, Debug, PartialEq)]
pub struct LensPrescription {
    /// Where it came from (file name or a label), used in messages.
    pub name: String,
    /// Interfaces from the front element to the rear.
    pub surfaces: Vec<LensSurface>,
}

impl LensPrescription {
    /// Reads and parses a lens file; errors name `file:line`.
    pub fn from_file(path: impl AsRef<Path>) -> Result<LensPrescription, LensError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| LensError::Io {
            path: path.display().to_string(),
            source,
        })?;
        LensPrescription::parse(&text, &path.display().to_string())
    }

    /// Parses the text of a lens file; `name` labels error messages (`name:line: ...`).
    pub fn parse(text: &str, name: &str) -> Result<LensPrescription, LensError> {
        let mut surfaces = Vec::new();
        for (line_index, raw_line) in text.lines().enumerate() {
            let line = line_index + 1;
            let content = raw_line.split('#').next().unwrap_or("").trim();
            if content.is_empty() {
                continue;
            }
            surfaces.push(parse_row(content, name, line)?);
        }
        if surfaces.is_empty() {
            return Err(LensError::Syntax {
                file: name.to_string(),
                line: text.lines().count().max(1),
                message: "no lens surfaces in the file".to_string(),
            });
        }
        if !surfaces.iter().any(LensSurface::is_flat) {
            return Err(LensError::NoStop {
                file: name.to_string(),
            });
        }
        let prescription = LensPrescription {
            name: name.to_string(),
            surfaces,
        };
        prescription.validate()?;
        Ok(prescription)
    }

    /// Index of the aperture stop: the first flat (radius 0) surface.
    pub fn stop_index(&self) -> Option<usize> {
        self.surfaces.iter().position(LensSurface::is_flat)
    }

    /// Checks what the file format cannot express but tracing needs: finite numbers, positive
    /// apertures and indices, non-negative thicknesses, an aperture no wider than its sphere,
    /// and a stop. Used for prescriptions built in code as well as parsed ones.
    pub fn validate(&self) -> Result<(), LensError> {
        let invalid = |surface: usize, message: String| LensError::InvalidSurface {
            lens: self.name.clone(),
            surface,
            message,
        };
        if self.surfaces.is_empty() {
            return Err(LensError::NoStop {
                file: self.name.clone(),
            });
        }
        for (i, s) in self.surfaces.iter().enumerate() {
            let values = [s.radius, s.thickness, s.index, s.aperture_diameter];
            if values.iter().any(|v| !v.is_finite()) {
                return Err(invalid(i, format!("non-finite value in {values:?}")));
            }
            if s.aperture_diameter <= 0.0 {
                return Err(invalid(i, "aperture diameter must be positive".into()));
            }
            if s.index < 1.0 {
                return Err(invalid(
                    i,
                    format!("refractive index {} below 1 (0 is read as air)", s.index),
                ));
            }
            if s.thickness < 0.0 {
                return Err(invalid(i, format!("negative thickness {}", s.thickness)));
            }
            if !s.is_flat() && 0.5 * s.aperture_diameter > s.radius.abs() {
                return Err(invalid(
                    i,
                    format!(
                        "aperture radius {} exceeds the radius of curvature {}",
                        0.5 * s.aperture_diameter,
                        s.radius
                    ),
                ));
            }
        }
        if self.stop_index().is_none() {
            return Err(LensError::NoStop {
                file: self.name.clone(),
            });
        }
        Ok(())
    }
}

fn parse_row(content: &str, file: &str, line: usize) -> Result<LensSurface, LensError> {
    let syntax = |message: String| LensError::Syntax {
        file: file.to_string(),
        line,
        message,
    };
    let columns: Vec<&str> = content.split_whitespace().collect();
    if columns.len() != 4 {
        return Err(syntax(format!(
            "expected 4 columns (radius, thickness, index, aperture), found {}",
            columns.len()
        )));
    }
    let mut values = [0.0f64; 4];
    const NAMES: [&str; 4] = ["radius", "thickness", "index", "aperture"];
    for (k, column) in columns.iter().enumerate() {
        let v: f64 = column
            .parse()
            .map_err(|_| syntax(format!("{} '{}' is not a number", NAMES[k], column)))?;
        if !v.is_finite() {
            return Err(syntax(format!("{} '{}' is not finite", NAMES[k], column)));
        }
        values[k] = v;
    }
    let [radius, thickness, index, aperture_diameter] = values;
    if aperture_diameter <= 0.0 {
        return Err(syntax(format!(
            "aperture diameter must be positive, found {aperture_diameter}"
        )));
    }
    if thickness < 0.0 {
        return Err(syntax(format!(
            "thickness must not be negative, found {thickness}"
        )));
    }
    if index < 0.0 || (index > 0.0 && index < 1.0) {
        return Err(syntax(format!(
            "refractive index must be 0 (air) or at least 1, found {index}"
        )));
    }
    if radius != 0.0 && 0.5 * aperture_diameter > radius.abs() {
        return Err(syntax(format!(
            "aperture radius {} exceeds the radius of curvature {radius}",
            0.5 * aperture_diameter
        )));
    }
    Ok(LensSurface {
        radius,
        thickness,
        // Index 0 is the format's way of writing air (used on the stop row).
        index: if index == 0.0 { 1.0 } else { index },
        aperture_diameter,
    })
}
