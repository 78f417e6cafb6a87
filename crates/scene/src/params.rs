//! Typed parameter lists (`"float fov" [ 45 ]`) with use tracking.
//!
//! Every lookup marks the parameter as used; whatever is left unused once an object has
//! been built is reported with its location (a misspelt name, a parameter the object
//! does not take). Asking for a name that is present with another type is an error.

use std::cell::Cell;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use glam::{Vec2, Vec3};

use super::error::{FileLoc, SceneError, Warning};
use radiant_math::color::Rgb;

/// The values of one parameter, by pbrt-v4 type.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    Int(Vec<i32>),
    Float(Vec<f32>),
    Bool(Vec<bool>),
    String(Vec<String>),
    Point2(Vec<Vec2>),
    Vector2(Vec<Vec2>),
    Point3(Vec<Vec3>),
    Vector3(Vec<Vec3>),
    Normal3(Vec<Vec3>),
    Rgb(Vec<Rgb>),
    /// `"blackbody" [T]`: colour temperature in kelvin.
    Blackbody(Vec<f32>),
    /// `"spectrum"`: either (wavelength, value) pairs or a named spectrum.
    SpectrumSamples(Vec<f32>),
    SpectrumNamed(Vec<String>),
    /// `"texture"`: names of textures.
    Texture(Vec<String>),
}

impl ParamValue {
    /// The type name as written in pbrt files.
    pub fn type_name(&self) -> &'static str {
        match self {
            ParamValue::Int(_) => "integer",
            ParamValue::Float(_) => "float",
            ParamValue::Bool(_) => "bool",
            ParamValue::String(_) => "string",
            ParamValue::Point2(_) => "point2",
            ParamValue::Vector2(_) => "vector2",
            ParamValue::Point3(_) => "point3",
            ParamValue::Vector3(_) => "vector3",
            ParamValue::Normal3(_) => "normal",
            ParamValue::Rgb(_) => "rgb",
            ParamValue::Blackbody(_) => "blackbody",
            ParamValue::SpectrumSamples(_) | ParamValue::SpectrumNamed(_) => "spectrum",
            ParamValue::Texture(_) => "texture",
        }
    }

    fn len(&self) -> usize {
        match self {
            ParamValue::Int(v) => v.len(),
            ParamValue::Float(v) | ParamValue::Blackbody(v) | ParamValue::SpectrumSamples(v) => {
                v.len()
            }
            ParamValue::Bool(v) => v.len(),
            ParamValue::String(v) | ParamValue::SpectrumNamed(v) | ParamValue::Texture(v) => {
                v.len()
            }
            ParamValue::Point2(v) | ParamValue::Vector2(v) => v.len(),
            ParamValue::Point3(v) | ParamValue::Vector3(v) | ParamValue::Normal3(v) => v.len(),
            ParamValue::Rgb(v) => v.len(),
        }
    }
}

/// One parameter: name, values and where it was written.
#[derive(Clone, Debug)]
pub struct Param {
    pub name: String,
    pub value: ParamValue,
    pub loc: FileLoc,
    used: Cell<bool>,
    /// For a copy of an `Attribute` default: the flag of the parameter as the
    /// `Attribute` wrote it, set when any copy is used, so that a default no later
    /// directive reads can be reported once.
    origin: Option<Arc<AtomicBool>>,
}

impl Param {
    pub fn new(name: impl Into<String>, value: ParamValue, loc: FileLoc) -> Param {
        Param {
            name: name.into(),
            value,
            loc,
            used: Cell::new(false),
            origin: None,
        }
    }

    /// Marks the parameter as used, so that it is never reported (for parameters that
    /// a single "unsupported" warning covers).
    pub fn mark_used(&self) {
        self.used.set(true);
        if let Some(origin) = &self.origin {
            origin.store(true, Ordering::Relaxed);
        }
    }

    /// Starts tracking the uses of this parameter's copies (see [`Param::inherited`]);
    /// the flag returned turns true when one of them is used.
    pub fn track_uses(&mut self) -> Arc<AtomicBool> {
        let flag = Arc::new(AtomicBool::new(false));
        self.origin = Some(flag.clone());
        flag
    }

    /// A copy for one directive that inherits it as a default: never reported by that
    /// directive (a default one kind of shape ignores is not worth a warning per
    /// shape), but its use counts for the original.
    pub fn inherited(&self) -> Param {
        Param {
            used: Cell::new(true),
            ..self.clone()
        }
    }
}

/// The parameter list of one directive.
#[derive(Clone, Debug, Default)]
pub struct ParamSet {
    pub params: Vec<Param>,
}

macro_rules! single_getter {
    ($fn_name:ident, $list_fn:ident, $variant:ident, $t:ty, $tyname:expr) => {
        #[doc = concat!("A single `", $tyname, "` value, or `default` when absent.")]
        pub fn $fn_name(&self, name: &str, default: $t) -> Result<$t, SceneError> {
            match self.$list_fn(name)? {
                None => Ok(default),
                Some((values, loc)) => match values {
                    [v] => Ok(v.clone()),
                    _ => Err(SceneError::at(
                        loc,
                        format!(
                            "parameter \"{name}\" needs exactly one value, found {}",
                            values.len()
                        ),
                    )),
                },
            }
        }

        #[doc = concat!("All `", $tyname, "` values of a parameter, with its location.")]
        pub fn $list_fn(&self, name: &str) -> Result<Option<(&[$t], &FileLoc)>, SceneError> {
            match self.lookup(name) {
                None => Ok(None),
                Some(p) => match &p.value {
                    ParamValue::$variant(v) => Ok(Some((v.as_slice(), &p.loc))),
                    other => Err(wrong_type(p, other, $tyname)),
                },
            }
        }
    };
}

fn wrong_type(p: &Param, found: &ParamValue, expected: &str) -> SceneError {
    SceneError::at(
        &p.loc,
        format!(
            "parameter \"{}\" has type \"{}\", expected \"{}\"",
            p.name,
            found.type_name(),
            expected
        ),
    )
}

impl ParamSet {
    pub fn new() -> ParamSet {
        ParamSet::default()
    }

    /// Adds a parameter (builder style, for scenes built in code).
    pub fn with(mut self, name: &str, value: ParamValue) -> ParamSet {
        self.push(Param::new(name, value, FileLoc::builtin("params")));
        self
    }

    /// Adds a parameter; a later parameter with the same name replaces an earlier one.
    pub fn push(&mut self, p: Param) {
        self.params.retain(|q| q.name != p.name);
        self.params.push(p);
    }

    /// Finds a parameter by name and marks it used.
    pub fn lookup(&self, name: &str) -> Option<&Param> {
        let p = self.params.iter().find(|p| p.name == name)?;
        p.mark_used();
        Some(p)
    }

    /// True when the parameter is present (marks it used).
    pub fn contains(&self, name: &str) -> bool {
        self.lookup(name).is_some()
    }

    single_getter!(float, floats, Float, f32, "float");
    single_getter!(int, ints, Int, i32, "integer");
    single_getter!(bool, bools, Bool, bool, "bool");
    single_getter!(string, strings, String, String, "string");
    single_getter!(point3, point3s, Point3, Vec3, "point3");
    single_getter!(vector3, vector3s, Vector3, Vec3, "vector3");
    single_getter!(point2, point2s, Point2, Vec2, "point2");
    single_getter!(normal, normals, Normal3, Vec3, "normal");
    single_getter!(texture, textures, Texture, String, "texture");

    /// A non-negative integer parameter (counts, resolutions, seeds).
    pub fn count(&self, name: &str, default: u32) -> Result<u32, SceneError> {
        let v = self.int(name, default as i32)?;
        u32::try_from(v).map_err(|_| {
            let loc = &self.lookup(name).expect("present").loc;
            SceneError::at(loc, format!("parameter \"{name}\" must be >= 0, got {v}"))
        })
    }

    /// A float that must be finite; NaN/Inf in a scene file is an input error.
    pub fn finite_float(&self, name: &str, default: f32) -> Result<f32, SceneError> {
        let v = self.float(name, default)?;
        if v.is_finite() {
            Ok(v)
        } else {
            let loc = &self.lookup(name).expect("present").loc;
            Err(SceneError::at(
                loc,
                format!("parameter \"{name}\" must be finite"),
            ))
        }
    }

    /// A finite float that must also satisfy `valid`; `requirement` says what that is
    /// ("must be positive"), and the error names the parameter's location and value.
    pub fn float_where(
        &self,
        name: &str,
        default: f32,
        requirement: &str,
        valid: impl Fn(f32) -> bool,
    ) -> Result<f32, SceneError> {
        let v = self.finite_float(name, default)?;
        if valid(v) {
            return Ok(v);
        }
        let loc = &self.lookup(name).expect("a default is valid").loc;
        Err(SceneError::at(
            loc,
            format!("parameter \"{name}\" {requirement}, got {v}"),
        ))
    }

    /// Marks every parameter as used (one "unsupported" warning then covers them all).
    pub fn mark_all_used(&self) {
        self.params.iter().for_each(Param::mark_used);
    }

    /// True when a parameter of this name is present; does not mark it used.
    pub fn has(&self, name: &str) -> bool {
        self.params.iter().any(|p| p.name == name)
    }

    /// Parameters never looked up, as warnings naming the object they were given to.
    pub fn unused_warnings(&self, owner: &str) -> Vec<Warning> {
        self.params
            .iter()
            .filter(|p| !p.used.get())
            .map(|p| Warning {
                loc: p.loc.clone(),
                message: format!(
                    "parameter \"{} {}\" is not used by {owner}",
                    p.value.type_name(),
                    p.name
                ),
            })
            .collect()
    }

    /// Number of values of a parameter (0 when absent); does not mark it used.
    pub fn value_count(&self, name: &str) -> usize {
        self.params
            .iter()
            .find(|p| p.name == name)
            .map_or(0, |p| p.value.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookups_mark_use_and_report_the_rest() {
        let ps = ParamSet::new()
            .with("fov", ParamValue::Float(vec![45.0]))
            .with("fvo", ParamValue::Float(vec![30.0]));
        assert_eq!(ps.float("fov", 90.0).unwrap(), 45.0);
        assert_eq!(ps.float("lensradius", 0.0).unwrap(), 0.0);
        let w = ps.unused_warnings("Camera \"perspective\"");
        assert_eq!(w.len(), 1);
        assert!(w[0].message.contains("fvo"));
    }

    #[test]
    fn wrong_type_and_wrong_count_are_errors() {
        let ps = ParamSet::new()
            .with("fov", ParamValue::String(vec!["wide".into()]))
            .with("maxdepth", ParamValue::Int(vec![1, 2]));
        let e = ps.float("fov", 90.0).unwrap_err().to_string();
        assert!(e.contains("expected \"float\""), "{e}");
        assert!(ps.int("maxdepth", 5).is_err());
        assert!(ps.count("maxdepth", 5).is_err());
    }
}
